"""The rays of Algorithm 1, shared by every visibility path: per-camera tables and directions.

Rays leave the camera at angles theta + a for a from -fov/2 to +fov/2 in steps of
``camera.angle_step`` (both ends included), and each ray is sampled at distances 0,
``camera.distance_step``, ..., ``camera.far`` (both ends included). Every visibility path
(the whole mask, its numpy reference and the lazy partial region) takes its angles and
directions from here, so they all sample the same points.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from numba import njit

from pegame.numerics import MAX_ANGLE, sin_cos
from pegame.types import Camera, Pose


def _inclusive_range(stop: float, step: float) -> np.ndarray:
    """0, step, 2 step, ... below ``stop``, then ``stop`` itself exactly (float64)."""
    count = math.ceil(stop / step - 1e-9)
    return np.append(np.arange(max(count, 0)) * step, stop)


@lru_cache(maxsize=64)
def ray_tables(camera: Camera) -> tuple[np.ndarray, np.ndarray, int]:
    """Per-camera tables of Algorithm 1, computed once per camera.

    Returns (angles, distances, first): ray angles relative to the heading (rad, from
    -fov/2 to +fov/2 inclusive), sample distances along a ray (m, from 0 to far
    inclusive), and the index of the first distance >= near. Arrays are read-only. The
    camera validates its own fields (positive steps, 0 <= near < far, 0 < fov <= 2 pi).
    """
    angles = _inclusive_range(camera.fov, camera.angle_step) - 0.5 * camera.fov
    distances = _inclusive_range(camera.far, camera.distance_step)
    first = int(np.searchsorted(distances, camera.near, side="left"))
    angles.setflags(write=False)
    distances.setflags(write=False)
    return angles, distances, first


def ray_directions(pose: Pose, camera: Camera) -> tuple[np.ndarray, np.ndarray]:
    """Unit direction (cos, sin) of every ray of ``camera`` at ``pose``, map frame."""
    angles = ray_tables(camera)[0]
    return directions(float(pose.theta), angles, 0, angles.size)


@njit(cache=True)
def directions(
    theta: float, angles: np.ndarray, first: int, stop: int
) -> tuple[np.ndarray, np.ndarray]:
    """Unit directions (cos, sin) (each (stop - first,)) of the rays at angles[first:stop]
    (rad) from the heading theta (rad), by the vectorised :func:`pegame.numerics.sin_cos`.
    Every path takes its directions from here, so they all sample the same points."""
    count = stop - first
    cos_a, sin_a = np.empty(count), np.empty(count)
    for i in range(count):
        sin_a[i], cos_a[i] = sin_cos(theta + angles[first + i])
    if not abs(theta) <= MAX_ANGLE - math.pi:  # beyond sin_cos's range: libm's
        for i in range(count):
            towards = theta + angles[first + i]
            cos_a[i], sin_a[i] = math.cos(towards), math.sin(towards)
    return cos_a, sin_a
