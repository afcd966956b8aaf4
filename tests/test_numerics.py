"""pegame.numerics against what it reproduces: sin_cos against libm (through numpy), exps,
Python's hypot and angle wrap in numba bit for bit, and the particle filter's wrap."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numba import njit

from pegame import numerics
from pegame.numerics import (
    MAX_ANGLE,
    sin_cos,
    wrap_angle_kernel,
    wrap_angles,
    wrap_angles_reference,
)
from pegame.types import wrap_angle


@njit
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


def wrap_test_angles():
    period = 2.0 * math.pi
    edges = [
        0.0,
        -0.0,
        math.pi,
        -math.pi,
        period,
        -period,
        2 * period,
        -2 * period,
        3 * math.pi,
        -3 * math.pi,
        1e300,
        -1e300,
        math.inf,
        -math.inf,
        math.nan,
    ]
    edges += [np.nextafter(v, d) for v in edges[:10] for d in (math.inf, -math.inf)]
    return np.concatenate([edges, np.random.default_rng(30).uniform(-20.0, 20.0, 20000)])


def test_wrap_kernel_and_ufunc_equal_the_numpy_definition_bit_for_bit():
    angles = wrap_test_angles()
    with np.errstate(invalid="ignore"):  # inf and nan
        theirs = wrap_angles_reference(angles)
        vectorised = wrap_angles(angles)
    for ours in (np.array([wrap_angle_kernel(a) for a in angles]), vectorised):
        np.testing.assert_array_equal(ours, theirs)  # NaNs compare equal here
        assert np.array_equal(np.signbit(ours), np.signbit(theirs))


def test_wraps_land_in_minus_pi_to_pi_and_agree_with_the_scalar_wrap_within_ulps_of_pi():
    angles = wrap_test_angles()
    angles = angles[np.isfinite(angles) & (np.abs(angles) < 1e6)]
    wrapped = wrap_angles(angles)
    assert np.all((wrapped >= -math.pi) & (wrapped <= math.pi))
    # -pi only where the modulo rounds up to 2 pi: just above an odd multiple of pi
    odd = np.abs(angles[wrapped == -math.pi] - math.pi) % (2.0 * math.pi)
    assert np.all(odd <= 4 * np.spacing(math.pi))
    assert wrap_angles(-math.pi) == math.pi == wrap_angle(-math.pi)
    # pegame.types.wrap_angle (exact IEEE remainder) is kept apart: it rounds differently.
    scalar = np.array([wrap_angle(float(a)) for a in angles])
    gap = np.abs(scalar - wrapped)
    gap = np.minimum(gap, 2.0 * math.pi - gap)  # pi and -pi are the same angle
    assert np.max(gap) <= 4 * np.spacing(math.pi) * (1 + np.abs(angles).max() / math.pi)


def test_exps_is_within_one_ulp_of_libm_and_zero_below_the_normal_range():
    from pegame.numerics import EXP_MAX, EXP_NORMAL_MIN, exps

    rng = np.random.default_rng(41)
    xs = np.concatenate(
        [
            rng.uniform(EXP_NORMAL_MIN, EXP_MAX, 20000),
            rng.uniform(-2.0, 2.0, 20000),
            [
                0.0,
                -0.0,
                1e-300,
                -1e-300,
                math.log(2.0),
                -math.log(2.0),
                1.0,
                -1.0,
                EXP_NORMAL_MIN,
                EXP_MAX,
            ],
        ]
    )
    for x, ours in zip(xs, exps(xs)):
        exact = math.exp(x)
        assert abs(ours - exact) <= math.ulp(exact), x
    assert np.all(exps(np.array([EXP_NORMAL_MIN - 1e-9, -745.0, -1e308, -math.inf])) == 0.0)


def test_hypot_is_pythons_bit_for_bit():
    rng = np.random.default_rng(0)
    pairs = rng.uniform(-20.0, 20.0, (20000, 2))
    pairs[:200] *= 1e-300
    pairs[200:400] *= 1e300
    specials = [(0.0, 0.0), (-0.0, 3.0), (math.inf, 1.0), (1.0, -math.inf), (3.0, 4.0)]
    for x, y in [*pairs.tolist(), *specials]:
        assert numerics.hypot(x, y) == math.hypot(x, y), (x, y)
    assert math.isnan(numerics.hypot(math.nan, 1.0))


def test_wrap_angle_is_pegames_bit_for_bit():
    rng = np.random.default_rng(1)
    angles = rng.uniform(-12.0, 12.0, 20000).tolist()
    pi = math.pi
    edges = [pi, -pi, 3 * pi, -3 * pi, 2 * pi, -2 * pi, 48 * pi, -48 * pi, 0.0, -0.0, 1e4, -1e4]
    edges += [math.nextafter(a, b) for a in (pi, -pi, 3 * pi, -3 * pi) for b in (0.0, 10.0)]
    for angle in angles + edges:
        ours, theirs = numerics.wrap_angle(angle), wrap_angle(angle)
        assert ours == theirs and math.copysign(1.0, ours) == math.copysign(1.0, theirs), angle


def test_hypot_shortcuts_answer_as_the_exact_hypot():
    rng = np.random.default_rng(5)
    res = 0.05
    pairs = rng.uniform(-0.1, 0.1, (20000, 2)).tolist()
    # Lengths on the edges: whole numbers of half cells, and the camera's range limits.
    for length in (0.025, 0.05, 0.075, 0.3, 5.0):
        angles = rng.uniform(-math.pi, math.pi, 2000)
        pairs += np.column_stack([length * np.cos(angles), length * np.sin(angles)]).tolist()
    for x, y in pairs:
        assert numerics.ceil_of_hypot(x, y, res) == math.ceil(2 * math.hypot(x, y) / res)
        assert numerics.hypot_within(x, y, 0.3, 5.0) == (0.3 <= math.hypot(x, y) <= 5.0)
        assert numerics.hypot_within(x, y, 0.025, 0.075) == (0.025 <= math.hypot(x, y) <= 0.075)
