"""Property-based tests of the egocentric crop (pegame.observe.crop): the crop's kernels, the
lattice route and the division, against :func:`local_crop_reference` on generated grids,
crop sizes and resolutions, and poses anywhere on or off the map, on cell corners and
edges and along the grid's axes; and more obstacles never free a crop cell. Units:
metres and radians in the map frame."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from pegame.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from pegame.observe.crop import LocalCrop, _crop, lattice_crop, local_crop_reference


@st.composite
def grids(draw: st.DrawFn) -> OccupancyGrid:
    """Up to 20 x 20 cells, mostly free, a round or arbitrary resolution, any origin."""
    shape = (draw(st.integers(1, 20)), draw(st.integers(1, 20)))
    cells = st.sampled_from([FREE] * 6 + [OCCUPIED, UNKNOWN])
    resolution = draw(st.sampled_from([0.05, 0.1]) | st.floats(0.02, 0.3))
    yaw = draw(st.just(0.0) | st.sampled_from([0.4, -2.0]) | st.floats(-math.pi, math.pi))
    origin = (draw(st.floats(-2.0, 2.0)), draw(st.floats(-2.0, 2.0)), yaw)
    return OccupancyGrid(draw(arrays(np.int8, shape, elements=cells)), resolution, origin)


@st.composite
def crops(draw: st.DrawFn, grid: OccupancyGrid) -> tuple[int, float]:
    """(cells, resolution m): 1-10 crop cells a side, of 1/2 to 5 map cells."""
    ratio = draw(st.sampled_from([1.0, 2.0, 4.0, 0.5, 1.5]) | st.floats(0.5, 5.0))
    return draw(st.integers(1, 10)), ratio * grid.resolution


@st.composite
def poses(draw: st.DrawFn, grid: OccupancyGrid) -> tuple[float, float, float]:
    """(x m, y m, theta rad) on the map or off it, often on a cell corner or edge midpoint
    and along the grid's axes (where the crop's samples fall on cell edges)."""
    u = draw(
        st.integers(-4, 2 * grid.width + 4).map(lambda k: 0.5 * k) | st.floats(-2, grid.width + 2)
    )
    v = draw(
        st.integers(-4, 2 * grid.height + 4).map(lambda k: 0.5 * k) | st.floats(-2, grid.height + 2)
    )
    yaw = grid.origin[2]
    turn = st.sampled_from([0.0, 0.5, 1.0, -0.5, -1.0]).map(lambda k: yaw + k * math.pi)
    theta = draw(turn | st.floats(-7.0, 7.0))
    c, s, res = math.cos(yaw), math.sin(yaw), grid.resolution
    return grid.origin[0] + (c * u - s * v) * res, grid.origin[1] + (s * u + c * v) * res, theta


@st.composite
def scenes(draw: st.DrawFn) -> tuple[OccupancyGrid, int, float, tuple[float, float, float]]:
    """A grid, a crop on it and a pose."""
    grid = draw(grids())
    cells, resolution = draw(crops(grid))
    return grid, cells, resolution, draw(poses(grid))


Scene = tuple[OccupancyGrid, int, float, tuple[float, float, float]]


@settings(max_examples=150)
@given(scenes())
def test_crop_equals_the_reference(scene: Scene) -> None:
    grid, cells, resolution, pose = scene
    expected = local_crop_reference(grid, *pose, cells, resolution)
    assert np.array_equal(LocalCrop(grid, cells, resolution)(*pose), expected.ravel())
    assert set(np.unique(expected)) <= {0.0, 1.0}


@settings(max_examples=150)
@given(scenes())
def test_both_routes_give_the_reference_cells(scene: Scene) -> None:
    """The lattice, whenever it decides every cell, and the division, always."""
    grid, cells, resolution, (x, y, theta) = scene
    crop = LocalCrop(grid, cells, resolution)
    expected = local_crop_reference(grid, x, y, theta, cells, resolution).ravel()
    pose = (x, y, math.cos(theta), math.sin(theta))
    lattice = np.full(crop.size, np.nan, dtype=np.float32)
    if lattice_crop(crop._lattice, pose, lattice, 0, crop._scratch):
        assert np.array_equal(lattice, expected)
    divided = np.full(crop.size, np.nan, dtype=np.float32)
    _crop(crop._samples, grid.kernel_frame, pose, divided)
    assert np.array_equal(divided, expected)


@settings(max_examples=80)
@given(scenes(), st.data())
def test_more_obstacles_never_free_a_crop_cell(scene: Scene, data: st.DataObject) -> None:
    grid, cells, resolution, pose = scene
    more = data.draw(arrays(bool, grid.data.shape))
    walled = OccupancyGrid(np.where(more, OCCUPIED, grid.data), grid.resolution, grid.origin)
    before = LocalCrop(grid, cells, resolution)(*pose)
    assert np.all(LocalCrop(walled, cells, resolution)(*pose) >= before)
