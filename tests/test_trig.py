"""The vectorisable sin_cos against libm (through numpy)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numba import njit

from pegame.trig import MAX_ANGLE, sin_cos


@njit(cache=True)
def sin_cos_of(angles):
    sines, cosines = np.empty(angles.size), np.empty(angles.size)
    for i in range(angles.size):
        sines[i], cosines[i] = sin_cos(angles[i])
    return sines, cosines


@pytest.mark.parametrize("limit", [math.pi, 100.0, 1e4, MAX_ANGLE])
def test_sin_cos_is_within_one_ulp_of_one_of_libm(limit):
    angles = np.random.default_rng(7).uniform(-limit, limit, 200_000)
    # quadrant boundaries and the exact values at 0, the worst cases of the reduction
    edges = np.arange(-8, 9) * (math.pi / 4)
    angles = np.concatenate([angles, edges, np.nextafter(edges, 10.0), [0.0, -0.0, limit, -limit]])
    sines, cosines = sin_cos_of(angles)
    tolerance = np.spacing(1.0)
    assert np.max(np.abs(sines - np.sin(angles))) <= tolerance
    assert np.max(np.abs(cosines - np.cos(angles))) <= tolerance
    assert sin_cos_of(np.array([0.0]))[0][0] == 0.0 and sin_cos_of(np.array([0.0]))[1][0] == 1.0
