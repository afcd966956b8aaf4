"""Property-based tests of the line of sight (pegame.visibility.sight): the numba kernel
(the scalar function's and the batched game's, pegame.vector.camera) against its numpy
reference on generated grids, segments (on cell corners too) and sampling steps, and what a clear line means:
free end points, no clear line through more obstacles that was not clear before, a clear
line inside one free cell. Units: metres in the map frame."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from pegame.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from pegame.visibility import line_of_sight
from pegame.visibility.sight import _line_of_sight_reference

#: map points near the origin, often on the corners of 0.1 m cells
POINTS = st.tuples(
    st.floats(-1.0, 3.0) | st.integers(-10, 30).map(lambda k: k * 0.1),
    st.floats(-1.0, 3.0) | st.integers(-10, 30).map(lambda k: k * 0.1),
)


@st.composite
def grids(draw: st.DrawFn) -> OccupancyGrid:
    """Up to 20 x 20 cells of 0.1 m (mostly free) from the origin or near it, any yaw."""
    shape = (draw(st.integers(1, 20)), draw(st.integers(1, 20)))
    cells = st.sampled_from([FREE] * 8 + [OCCUPIED, UNKNOWN])
    origin = draw(st.just((0.0, 0.0, 0.0)) | st.tuples(*[st.floats(-0.5, 0.5)] * 3))
    return OccupancyGrid(draw(arrays(np.int8, shape, elements=cells)), 0.1, origin)


#: sampling steps (m): the default (half a cell) or any from a fiftieth of a cell to two
STEPS = st.none() | st.floats(0.002, 0.2)


@settings(max_examples=300)
@given(grids(), POINTS, POINTS, STEPS)
def test_kernel_equals_reference(
    grid: OccupancyGrid, a: tuple[float, float], b: tuple[float, float], step: float | None
) -> None:
    fast = line_of_sight(grid, a, b, step)
    sampled = 0.5 * grid.resolution if step is None else step
    assert fast == _line_of_sight_reference(grid, a, b, sampled)


#: a free 1 x 2 grid and a segment to a point a hair off it, where a + (b - a) rounds
#: back onto the grid: the line of sight once sampled that point instead of b
OFF_BY_ROUNDING = (OccupancyGrid(np.zeros((1, 2), np.int8), 0.1), (0.1, 0.0), (-1.9e-286, 0.0))


@settings(max_examples=150)
@example(*OFF_BY_ROUNDING, None)
@given(grids(), POINTS, POINTS, STEPS)
def test_a_clear_line_has_free_end_points(
    grid: OccupancyGrid, a: tuple[float, float], b: tuple[float, float], step: float | None
) -> None:
    clear = line_of_sight(grid, a, b, step)
    sampled = 0.5 * grid.resolution if step is None else step
    assert clear == _line_of_sight_reference(grid, a, b, sampled)
    if clear:
        assert grid.is_free(*a)
        assert grid.is_free(*b)


@settings(max_examples=150)
@given(grids(), POINTS, POINTS, STEPS, st.data())
def test_more_obstacles_never_clear_a_line(
    grid: OccupancyGrid,
    a: tuple[float, float],
    b: tuple[float, float],
    step: float | None,
    data: st.DataObject,
) -> None:
    more = data.draw(arrays(bool, grid.data.shape))
    walled = OccupancyGrid(np.where(more, OCCUPIED, grid.data), grid.resolution, grid.origin)
    if line_of_sight(walled, a, b, step):
        assert line_of_sight(grid, a, b, step)


@settings(max_examples=100)
@given(grids(), POINTS, st.floats(-math.pi, math.pi), st.floats(0.0, 0.05))
def test_a_line_within_one_free_cell_is_clear(
    grid: OccupancyGrid, a: tuple[float, float], heading: float, length: float
) -> None:
    """A segment from a point of a free cell that stays in that cell is clear."""
    b = (a[0] + length * math.cos(heading), a[1] + length * math.sin(heading))
    if grid.is_free(*a) and grid.world_to_cell(*a) == grid.world_to_cell(*b):
        assert line_of_sight(grid, a, b)
