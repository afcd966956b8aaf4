"""Property-based tests of Algorithm 1's rays (pegame.visibility.rays) on generated
cameras and headings: the tables span the field of view and the range inclusively in
steps no longer than the camera's, and the numba kernel's directions are libm's (within
2^-52, exactly beyond the polynomial's range). Units: metres and radians."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from pegame.numerics import MAX_ANGLE
from pegame.types import Camera
from pegame.visibility.rays import directions, ray_tables

CAMERAS = st.builds(
    Camera,
    fov=st.floats(1e-3, 2 * math.pi) | st.sampled_from([math.pi / 3, 2 * math.pi]),
    near=st.floats(0.0, 2.0),
    far=st.floats(2.01, 8.0),
    angle_step=st.floats(1e-3, 0.5) | st.sampled_from([0.0016, math.pi / 30]),
    distance_step=st.floats(5e-3, 1.0) | st.sampled_from([0.05, 0.1]),
)


def assert_inclusive_steps(values: np.ndarray, start: float, stop: float, step: float) -> None:
    """values run from start to stop, both exactly, increasing by at most ``step``."""
    assert values[0] == start and values[-1] == stop
    gaps = np.diff(values)
    assert np.all(gaps > 0.0)
    assert np.all(gaps <= step * (1 + 1e-9))


@settings(max_examples=150)
@given(CAMERAS)
def test_tables_span_the_fov_and_the_range_inclusively(camera: Camera) -> None:
    angles, distances, first = ray_tables(camera)
    assert_inclusive_steps(angles, -0.5 * camera.fov, 0.5 * camera.fov, camera.angle_step)
    assert_inclusive_steps(distances, 0.0, camera.far, camera.distance_step)
    assert distances[first] >= camera.near
    assert first == 0 or distances[first - 1] < camera.near
    assert not angles.flags.writeable and not distances.flags.writeable


@settings(max_examples=150)
@given(
    st.floats(-10.0, 10.0) | st.floats(-1e12, 1e12) | st.sampled_from([math.pi, MAX_ANGLE]),
    CAMERAS,
)
def test_directions_are_libms(theta: float, camera: Camera) -> None:
    angles = ray_tables(camera)[0]
    cos_a, sin_a = directions(theta, angles, 0, angles.size)
    towards = [theta + a for a in angles]
    want_cos = np.array([math.cos(t) for t in towards])
    want_sin = np.array([math.sin(t) for t in towards])
    if abs(theta) <= MAX_ANGLE - math.pi:  # the polynomial
        np.testing.assert_allclose(cos_a, want_cos, rtol=0, atol=2.0**-52)
        np.testing.assert_allclose(sin_a, want_sin, rtol=0, atol=2.0**-52)
    else:
        assert np.array_equal(cos_a, want_cos) and np.array_equal(sin_a, want_sin)
