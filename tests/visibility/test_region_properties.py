"""Property-based tests of Algorithm 1's region (pegame.visibility.region and .lazy): the
numba ray march against its numpy reference and the on-demand region against the whole
mask, on generated small grids, poses and cameras; and the region's geometry: inside the
field of view and the range, in line of sight, growing with the range and shrinking with
the obstacles. Units: metres and radians in the map frame."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from pegame.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from pegame.types import Camera, Pose
from pegame.visibility import VisibilityRegion, visibility_region, visibility_region_reference
from pegame.visibility.rays import ray_directions, ray_tables

#: cell values drawn for generated grids: mostly free, and both kinds of blocked
CELLS = st.sampled_from([FREE] * 6 + [OCCUPIED, UNKNOWN])


@st.composite
def grids(draw: st.DrawFn) -> OccupancyGrid:
    """A small grid: 3-16 cells a side, a round or arbitrary resolution, an origin anywhere
    near (0, 0) with no yaw or any."""
    shape = (draw(st.integers(3, 16)), draw(st.integers(3, 16)))
    data = draw(arrays(np.int8, shape, elements=CELLS))
    resolution = draw(st.sampled_from([0.05, 0.1, 0.25]) | st.floats(0.05, 0.3))
    yaw = draw(st.just(0.0) | st.floats(-math.pi, math.pi))
    origin = (draw(st.floats(-3.0, 3.0)), draw(st.floats(-3.0, 3.0)), yaw)
    return OccupancyGrid(data, resolution, origin)


@st.composite
def poses(draw: st.DrawFn, grid: OccupancyGrid) -> Pose:
    """A pose over the grid (or up to a cell off it), often on a cell corner and looking
    along a grid axis (where samples fall on cell edges)."""
    u = draw(
        st.integers(0, grid.width) | st.floats(0.0, grid.width) | st.floats(-1.0, grid.width + 1.0)
    )
    v = draw(
        st.integers(0, grid.height)
        | st.floats(0.0, grid.height)
        | st.floats(-1.0, grid.height + 1.0)
    )
    yaw = grid.origin[2]
    turn = draw(st.sampled_from([0.0, 0.5, 1.0, -0.5]).map(lambda k: k * math.pi + yaw))
    theta = draw(st.just(turn) | st.floats(-4.0, 4.0))
    c, s, res = math.cos(yaw), math.sin(yaw), grid.resolution
    x = grid.origin[0] + (c * u - s * v) * res
    y = grid.origin[1] + (s * u + c * v) * res
    return Pose(x, y, theta)


@st.composite
def cameras(draw: st.DrawFn, max_distance_step: float = 0.3) -> Camera:
    """A camera of any FOV up to a full turn, a short range and coarse steps (few rays)."""
    near = draw(st.just(0.0) | st.floats(0.0, 1.0))
    return Camera(
        fov=draw(st.floats(0.05, 2 * math.pi)),
        near=near,
        far=near + draw(st.floats(0.1, 2.5)),
        angle_step=draw(st.floats(0.01, 0.2)),
        distance_step=draw(st.floats(0.02, max_distance_step)),
    )


@st.composite
def scenes(draw: st.DrawFn) -> tuple[OccupancyGrid, Pose, Camera]:
    """A grid, a pose on it and a camera."""
    grid = draw(grids())
    return grid, draw(poses(grid)), draw(cameras())


def grid_coordinates(
    grid: OccupancyGrid, x: np.ndarray, y: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Continuous (u, v) of map points (m) in cells along the columns and rows."""
    c, s = grid.frame.cos_yaw, grid.frame.sin_yaw
    dx, dy = np.asarray(x) - grid.origin[0], np.asarray(y) - grid.origin[1]
    return (c * dx + s * dy) / grid.resolution, (-s * dx + c * dy) / grid.resolution


@settings(max_examples=150)
@given(scenes())
def test_kernel_equals_reference(scene: tuple[OccupancyGrid, Pose, Camera]) -> None:
    mask = visibility_region(*scene)
    assert np.array_equal(mask, visibility_region_reference(*scene))
    grid = scene[0]
    assert not np.any(mask & grid.blocked)


@settings(max_examples=100)
@given(scenes(), st.data())
def test_on_demand_region_equals_the_whole_mask(
    scene: tuple[OccupancyGrid, Pose, Camera], data: st.DataObject
) -> None:
    grid = scene[0]
    whole = visibility_region(*scene)
    drawn = data.draw(st.lists(st.integers(-1, grid.blocked.size - 1), max_size=30))
    cells = np.asarray(drawn, dtype=np.int64)
    expected = np.where(cells >= 0, whole.ravel()[np.maximum(cells, 0)], False)
    assert np.array_equal(VisibilityRegion(*scene).holds(cells), expected)
    top, left = data.draw(st.integers(-3, grid.height)), data.draw(st.integers(-3, grid.width))
    bottom, right = top + data.draw(st.integers(0, 6)), left + data.draw(st.integers(0, 6))
    over = VisibilityRegion(*scene).mask_over((top, bottom), (left, right))
    block = np.s_[max(top, 0) : max(bottom + 1, 0), max(left, 0) : max(right + 1, 0)]
    assert np.array_equal(over[block], whole[block])
    assert not np.any(over & ~whole)


@settings(max_examples=100)
@given(scenes())
def test_region_cells_lie_in_the_field_of_view_and_range(
    scene: tuple[OccupancyGrid, Pose, Camera],
) -> None:
    """Each region cell holds a ray sample at a range in [near, far] and a bearing within
    fov/2, so its centre lies within half a cell diagonal r of one: its range within
    [near - r, far + r], its bearing within fov/2 + asin(r / range)."""
    grid, pose, camera = scene
    rows, cols = np.nonzero(visibility_region(*scene))
    x, y = grid.cell_to_world(rows, cols)
    dx, dy = np.asarray(x) - pose.x, np.asarray(y) - pose.y
    distance = np.hypot(dx, dy)
    half_diagonal = grid.resolution / math.sqrt(2.0) + 1e-9
    assert np.all(distance >= camera.near - half_diagonal)
    assert np.all(distance <= camera.far + half_diagonal)
    off_axis = np.abs(np.angle(np.exp(1j * (np.arctan2(dy, dx) - pose.theta))))
    away = distance > half_diagonal
    slack = np.arcsin(half_diagonal / distance[away]) + 1e-9
    assert np.all(off_axis[away] <= 0.5 * camera.fov + slack)


@st.composite
def fine_scenes(draw: st.DrawFn) -> tuple[OccupancyGrid, Pose, Camera]:
    """A scene whose samples are less than a cell apart along a ray."""
    grid = draw(grids())
    camera = draw(cameras(max_distance_step=0.9 * grid.resolution))
    return grid, draw(poses(grid)), camera


@settings(max_examples=100)
@given(fine_scenes())
def test_region_cells_are_in_line_of_sight(scene: tuple[OccupancyGrid, Pose, Camera]) -> None:
    """A continuous line of sight, checked apart from the ray samples: every region cell is
    reached by a ray whose segment from the camera avoids the core of every blocked cell
    (the cell shrunk by distance_step / 2 on every side), since each point of that segment
    is within distance_step / 2 of a free sample. The segments are checked at 1/8 cell."""
    grid, pose, camera = scene
    seen = visibility_region(*scene)
    _, distances, first = ray_tables(camera)
    cos_a, sin_a = ray_directions(pose, camera)
    dense = np.arange(0.0, camera.far + grid.resolution / 8, grid.resolution / 8)
    u, v = grid_coordinates(
        grid, pose.x + dense[None, :] * cos_a[:, None], pose.y + dense[None, :] * sin_a[:, None]
    )
    row, col = np.floor(v).astype(np.int64), np.floor(u).astype(np.int64)
    on_grid = grid.contains(row, col)
    margin = 0.5 * camera.distance_step / grid.resolution + 1e-9
    in_core = on_grid & (np.minimum(u - col, col + 1 - u) > margin)
    in_core &= np.minimum(v - row, row + 1 - v) > margin
    in_core[on_grid] &= grid.blocked[row[on_grid], col[on_grid]]
    # The range of each ray's first dense point in a core (inf when it has none).
    hit = np.where(in_core.any(axis=1), dense[np.argmax(in_core, axis=1)], np.inf)
    clear = distances[None, :] < hit[:, None]
    clear[:, :first] = False
    rows, cols = grid.world_to_cell(
        pose.x + distances[None, :] * cos_a[:, None], pose.y + distances[None, :] * sin_a[:, None]
    )
    clear &= grid.contains(rows, cols)
    in_sight = np.zeros(seen.shape, dtype=bool)
    in_sight[rows[clear], cols[clear]] = True
    assert not np.any(seen & ~in_sight)


@settings(max_examples=100)
@given(scenes(), st.integers(0, 20), st.integers(0, 20), st.floats(0.0, 1.0))
def test_region_grows_with_the_range(
    scene: tuple[OccupancyGrid, Pose, Camera], steps: int, more: int, nearer: float
) -> None:
    """A far range further by whole distance steps samples every point of the shorter one
    (both on the lattice of the step, which the sample distances follow), and more; a
    nearer near range marks the same samples and more."""
    grid, pose, camera = scene
    step = camera.distance_step
    beyond_near = math.ceil(camera.near / step) + 1 + steps  # (beyond_near * step > near)
    short = replace(camera, far=beyond_near * step)
    longer = replace(camera, far=(beyond_near + more) * step)
    closer = replace(short, near=nearer * short.near)
    seen = visibility_region(grid, pose, short)
    assert not np.any(seen & ~visibility_region(grid, pose, longer))
    assert not np.any(seen & ~visibility_region(grid, pose, closer))


@settings(max_examples=100)
@given(scenes(), st.data())
def test_region_shrinks_with_the_obstacles(
    scene: tuple[OccupancyGrid, Pose, Camera], data: st.DataObject
) -> None:
    """Blocking more cells stops every ray at the same sample or sooner."""
    grid, pose, camera = scene
    more = data.draw(arrays(bool, grid.data.shape))
    walled = OccupancyGrid(np.where(more, OCCUPIED, grid.data), grid.resolution, grid.origin)
    seen = visibility_region(walled, pose, camera)
    assert not np.any(seen & ~visibility_region(grid, pose, camera))
