"""Property-based tests of the visibility outlines (pegame.visibility.outlines) on
generated grids, poses and cameras: the numba kernel, which jumps over free cells,
against the plain reference that samples every cell; closed rings at the given height
with every ray's end within the camera's range; and no ray reaching farther when more
cells are blocked. Units: metres and radians in the map frame."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from pegame.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from pegame.types import Camera
from pegame.visibility.outlines import (
    NEAR_ARC_POINTS,
    simplify_outlines,
    visibility_outlines,
)

Poses = tuple[list[float], list[float], list[float]]


@st.composite
def scenes(draw: st.DrawFn) -> tuple[OccupancyGrid, Poses, Camera, int]:
    """A grid of up to 30 x 30 cells (mostly free, so that the kernel's jumps are long),
    1-3 poses on it, a camera and 1-16 rays."""
    shape = (draw(st.integers(1, 30)), draw(st.integers(1, 30)))
    cells = st.sampled_from([FREE] * 20 + [OCCUPIED, UNKNOWN])
    resolution = draw(st.sampled_from([0.05, 0.1]) | st.floats(0.03, 0.3))
    yaw = draw(st.just(0.0) | st.floats(-math.pi, math.pi))
    origin = (draw(st.floats(-1.0, 1.0)), draw(st.floats(-1.0, 1.0)), yaw)
    grid = OccupancyGrid(draw(arrays(np.int8, shape, elements=cells)), resolution, origin)
    count = draw(st.integers(1, 3))
    us = draw(st.lists(st.floats(0.0, shape[1]), min_size=count, max_size=count))
    vs = draw(st.lists(st.floats(0.0, shape[0]), min_size=count, max_size=count))
    c, s = math.cos(yaw), math.sin(yaw)
    xs = [origin[0] + (c * u - s * v) * resolution for u, v in zip(us, vs)]
    ys = [origin[1] + (s * u + c * v) * resolution for u, v in zip(us, vs)]
    thetas = draw(st.lists(st.floats(-4.0, 4.0), min_size=count, max_size=count))
    near = draw(st.floats(0.0, 0.5))
    camera = Camera(
        fov=draw(st.floats(0.1, 2 * math.pi)), near=near, far=near + draw(st.floats(0.1, 2.5))
    )
    return grid, (xs, ys, thetas), camera, draw(st.integers(1, 16))


@settings(max_examples=150)
@given(scenes(), st.floats(-1.0, 1.0))
def test_kernel_equals_reference_and_draws_closed_rings_in_range(
    scene: tuple[OccupancyGrid, Poses, Camera, int], z: float
) -> None:
    grid, (xs, ys, thetas), camera, rays = scene
    fast = visibility_outlines(grid, xs, ys, thetas, camera, rays, z)
    slow = visibility_outlines(grid, xs, ys, thetas, camera, rays, z, compiled=False)
    assert np.array_equal(fast, slow)
    assert fast.shape == (len(xs), rays + NEAR_ARC_POINTS + 1, 3) and fast.dtype == np.float32
    assert np.array_equal(fast[:, 0], fast[:, -1])
    assert np.all(fast[:, :, 2] == np.float32(z))
    reach = np.hypot(fast[:, :rays, 0] - np.c_[xs], fast[:, :rays, 1] - np.c_[ys])
    slack = 1e-6 * (1.0 + np.abs(np.c_[xs]) + np.abs(np.c_[ys]) + camera.far)  # float32
    assert np.all(reach >= camera.near - slack) and np.all(reach <= camera.far + slack)


@settings(max_examples=100)
@given(scenes(), st.data())
def test_more_obstacles_never_lengthen_a_ray(
    scene: tuple[OccupancyGrid, Poses, Camera, int], data: st.DataObject
) -> None:
    """The kernel's jumps, planned from the blocked grid's free runs, never pass a newly
    blocked cell: each ray ends at the same sample or sooner."""
    grid, (xs, ys, thetas), camera, rays = scene
    more = data.draw(arrays(bool, grid.data.shape))
    walled = OccupancyGrid(np.where(more, OCCUPIED, grid.data), grid.resolution, grid.origin)
    ends = [visibility_outlines(g, xs, ys, thetas, camera, rays) for g in (grid, walled)]
    before, after = (np.hypot(e[:, :rays, 0] - np.c_[xs], e[:, :rays, 1] - np.c_[ys]) for e in ends)
    assert np.all(after <= before)


def _segment_distance(point: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    """Distance (m) in the plane from ``point`` to the segment a-b (plain numpy)."""
    d, p = b[:2] - a[:2], point[:2] - a[:2]
    length = float(d @ d)
    t = 0.0 if length == 0.0 else min(1.0, max(0.0, float(p @ d) / length))
    return float(np.hypot(*(p - t * d)))


@settings(max_examples=150)
@given(scenes(), st.floats(0.0, 0.2))
def test_simplified_outlines_keep_the_ends_and_drop_only_vertices_near_the_drawn_line(
    scene: tuple[OccupancyGrid, Poses, Camera, int], tolerance: float
) -> None:
    grid, (xs, ys, thetas), camera, rays = scene
    outlines = visibility_outlines(grid, xs, ys, thetas, camera, rays)
    points, lengths = simplify_outlines(outlines, tolerance)
    plain = simplify_outlines(outlines, tolerance, compiled=False)
    assert np.array_equal(points, plain[0]) and np.array_equal(lengths, plain[1])
    assert lengths.sum() == len(points)
    for polygon, kept in zip(outlines, np.split(points, np.cumsum(lengths)[:-1])):
        # the kept vertices are the polygon's, in order, with its first and last
        assert np.array_equal(kept[0], polygon[0]) and np.array_equal(kept[-1], polygon[-1])
        indices = [0]
        for vertex in kept[1:-1]:  # each found after the one before it
            later = np.flatnonzero((polygon[indices[-1] + 1 :] == vertex).all(axis=1))
            assert later.size, "a kept vertex is the polygon's, in order"
            indices.append(indices[-1] + 1 + int(later[0]))
        indices.append(len(polygon) - 1)
        assert indices == sorted(set(indices))
        for start, stop in zip(indices, indices[1:]):
            for dropped in polygon[start + 1 : stop]:
                gap = _segment_distance(dropped, polygon[start], polygon[stop])
                assert gap <= tolerance + 1e-5
