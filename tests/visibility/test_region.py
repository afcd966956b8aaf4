"""Tests for pegame.visibility: Algorithm 1's visibility region with occlusion, line of sight."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.ndimage import binary_dilation

from pegame.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid, point_cell
from pegame.types import Camera, Pose, Region
from pegame.visibility import (
    MaskRegion,
    VisibilityRegion,
    body_in_view,
    fov_wedge,
    in_view,
    line_of_sight,
    visibility_region,
    visibility_region_reference,
)
from pegame.visibility.rays import directions, ray_tables
from pegame.visibility.sight import _line_of_sight_reference

CAMERA = Camera(fov=math.pi / 3, near=0.3, far=3.0, angle_step=0.0016, distance_step=0.05)
BOTH = [visibility_region, visibility_region_reference]


def empty_grid(height=80, width=80, resolution=0.1, origin=(0.0, 0.0, 0.0)):
    return OccupancyGrid(np.full((height, width), FREE, dtype=np.int8), resolution, origin)


def random_grid(rng, height, width, resolution, origin=(0.0, 0.0, 0.0), density=0.1):
    """Free cells with a sprinkle of occupied and unknown ones."""
    data = np.full((height, width), FREE, dtype=np.int8)
    data[rng.random((height, width)) < density] = OCCUPIED
    data[rng.random((height, width)) < density / 5] = UNKNOWN
    return OccupancyGrid(data, resolution, origin)


def random_free_pose(rng, grid):
    """A pose at a random point of a random free cell, random heading."""
    rows, cols = np.nonzero(grid.free)
    k = rng.integers(rows.size)
    x, y = grid.cell_to_world(rows[k], cols[k])
    jitter = rng.uniform(-0.45, 0.45, 2) * grid.resolution
    return Pose(x + jitter[0], y + jitter[1], rng.uniform(-math.pi, math.pi))


def random_camera(rng):
    return Camera(
        fov=rng.uniform(0.3, 2 * math.pi),
        near=rng.uniform(0.0, 0.8),
        far=rng.uniform(1.0, 4.0),
        angle_step=rng.uniform(0.004, 0.03),
        distance_step=rng.uniform(0.02, 0.15),
    )


def polar(grid, pose, rows, cols):
    """Range (m) and bearing from the optical axis (rad) of the given cells' centres."""
    x, y = grid.cell_to_world(rows, cols)
    dx, dy = np.asarray(x) - pose.x, np.asarray(y) - pose.y
    angle = np.arctan2(dy, dx) - pose.theta
    bearing = np.arctan2(np.sin(angle), np.cos(angle))
    return np.hypot(dx, dy), bearing


# ----------------------------------------------------------------------- ray tables


def test_ray_tables_span_fov_and_range_inclusively():
    angles, distances, first = ray_tables(CAMERA)
    assert angles[0] == -CAMERA.fov / 2 and angles[-1] == CAMERA.fov / 2
    assert np.all(np.diff(angles) > 0) and np.all(np.diff(angles) <= CAMERA.angle_step + 1e-12)
    assert distances[0] == 0.0 and distances[-1] == CAMERA.far
    assert np.all(np.diff(distances) > 0)
    assert np.all(np.diff(distances) <= CAMERA.distance_step + 1e-12)
    assert distances[first] >= CAMERA.near > distances[first - 1]


# ----------------------------------------------------------------- visibility region


@pytest.mark.parametrize("seed", range(4))
def test_visible_cells_lie_in_the_wedge_and_range(seed):
    rng = np.random.default_rng(seed)
    grid = random_grid(rng, 60, 70, 0.1, origin=(rng.uniform(-2, 2), rng.uniform(-2, 2), 0.0))
    for _ in range(10):
        camera, pose = random_camera(rng), random_free_pose(rng, grid)
        mask = visibility_region(grid, pose, camera)
        rows, cols = np.nonzero(mask)
        assert not np.any(grid.blocked[rows, cols])
        dist, bearing = polar(grid, pose, rows, cols)
        res = grid.resolution
        assert np.all((dist >= camera.near - res) & (dist <= camera.far + res))
        far_enough = dist > res
        tolerance = np.arctan(res / dist[far_enough])
        assert np.all(np.abs(bearing[far_enough]) <= camera.fov / 2 + tolerance)


@pytest.mark.parametrize("region", BOTH)
def test_wall_across_the_fov_hides_the_cells_behind_it(region):
    data = np.full((80, 80), FREE, dtype=np.int8)
    data[:, 40] = OCCUPIED  # the wall x in [4.0, 4.1) m
    grid = OccupancyGrid(data, 0.1)
    mask = region(grid, Pose(2.0, 4.0, 0.0), CAMERA)
    assert not mask[:, 40:].any()
    assert mask[35:45, 39].all()  # the free cells in front of the wall are seen


@pytest.mark.parametrize("origin", [(0.0, 0.0, 0.0), (-3.2, 1.7, 0.0), (1.0, -2.0, 0.6)])
def test_empty_map_sees_the_whole_wedge_interior(origin):
    grid = empty_grid(origin=origin)
    cx, cy = grid.cell_to_world(40, 20)
    pose = Pose(cx + 0.013, cy - 0.021, origin[2] + 0.2)
    mask = visibility_region(grid, pose, CAMERA)
    rows, cols = np.indices(mask.shape)
    dist, bearing = polar(grid, pose, rows, cols)
    res = grid.resolution
    interior = (
        (dist >= CAMERA.near + res)
        & (dist <= CAMERA.far - res)
        & (np.abs(bearing) <= CAMERA.fov / 2 - 1e-3)
    )
    assert interior.sum() > 300
    assert mask[interior].all()


@pytest.mark.parametrize("seed", range(6))
def test_fast_mask_equals_reference_mask(seed):
    rng = np.random.default_rng(100 + seed)
    height, width = rng.integers(10, 60, 2)
    resolution = float(rng.choice([0.05, 0.1, 0.25]))
    yaw = 0.0 if seed % 2 else float(rng.uniform(-math.pi, math.pi))
    origin = (rng.uniform(-5, 5), rng.uniform(-5, 5), yaw)
    grid = random_grid(rng, height, width, resolution, origin, density=rng.uniform(0.0, 0.3))
    for _ in range(25):
        camera, pose = random_camera(rng), random_free_pose(rng, grid)
        fast = visibility_region(grid, pose, camera)
        assert np.array_equal(fast, visibility_region_reference(grid, pose, camera))


@pytest.mark.parametrize("yaw", [0.0, 0.5])
def test_fast_mask_equals_reference_with_samples_on_cell_edges(yaw):
    # A camera on a cell corner looking along a grid axis puts samples on cell edges, where
    # multiplying by 1 / resolution and dividing by it can floor differently.
    rng = np.random.default_rng(11)
    grid = random_grid(rng, 120, 120, 0.05, origin=(0.0, 0.0, yaw), density=0.02)
    camera = Camera(fov=0.2, near=0.1, far=4.0, angle_step=0.05, distance_step=0.05)
    for _ in range(30):
        corner = grid.cell_to_world(*rng.integers(20, 100, 2))
        x, y = np.round(np.asarray(corner) / 0.05 - 0.5) * 0.05
        pose = Pose(x, y, yaw + float(rng.choice([0.0, 0.5, 1.0, -0.5])) * math.pi)
        fast = visibility_region(grid, pose, camera)
        assert np.array_equal(fast, visibility_region_reference(grid, pose, camera))


@pytest.mark.parametrize("seed", range(6))
def test_region_over_a_block_equals_the_whole_mask_there(seed):
    # Random grids (rotated origins too), cameras (up to a full turn of FOV), poses on and
    # off the grid, and blocks of cells small and large, inside, across the edge and off it.
    rng = np.random.default_rng(300 + seed)
    height, width = rng.integers(20, 70, 2)
    resolution = float(rng.choice([0.05, 0.1]))
    yaw = 0.0 if seed % 2 else float(rng.uniform(-math.pi, math.pi))
    grid = random_grid(
        rng, height, width, resolution, (rng.uniform(-3, 3), rng.uniform(-3, 3), yaw)
    )
    partial = 0
    for _ in range(60):
        camera, pose = random_camera(rng), random_free_pose(rng, grid)
        whole = visibility_region(grid, pose, camera)
        top, left = rng.integers(-5, [height, width])
        bottom, right = top + rng.integers(0, 15), left + rng.integers(0, 15)
        over = VisibilityRegion(grid, pose, camera).mask_over((top, bottom), (left, right))
        block = np.s_[max(top, 0) : max(bottom + 1, 0), max(left, 0) : max(right + 1, 0)]
        assert np.array_equal(over[block], whole[block])
        assert not np.any(over & ~whole)
        partial += over.sum() < whole.sum()
    assert partial > 20  # most blocks needed only part of the region


@pytest.mark.parametrize(
    "theta",
    [math.pi, -math.pi, math.nextafter(math.pi, 0.0), math.nextafter(-math.pi, 0.0), 3 * math.pi],
)
def test_region_over_a_block_is_exact_where_bearings_wrap_at_pi(theta):
    # The rays reaching a block are found from bearings wrapped to (-pi, pi] (the one angle
    # wrap of pegame.numerics); a camera looking along -x at blocks around that bearing puts
    # the bearings on both sides of the seam.
    grid = empty_grid(60, 60, 0.1)
    pose = Pose(5.0, 3.0, theta)
    camera = Camera(fov=0.8, near=0.0, far=4.5, angle_step=0.004, distance_step=0.05)
    whole = visibility_region(grid, pose, camera)
    for top in range(20, 40, 3):
        for left in (2, 10, 20, 35):
            over = VisibilityRegion(grid, pose, camera).mask_over((top, top + 2), (left, left + 3))
            block = np.s_[top : top + 3, left : left + 4]
            assert np.array_equal(over[block], whole[block])
    assert whole[30, 20] and not whole[30, 55]


@pytest.mark.parametrize("seed", range(4))
def test_region_holds_exactly_the_mask_cells_asked_about(seed):
    # Clouds of cells around random points, some in view and some behind the camera or out
    # of range, plus "no cell" entries; FOVs below and above pi.
    rng = np.random.default_rng(700 + seed)
    yaw = 0.0 if seed % 2 else 0.8
    grid = random_grid(rng, 60, 60, 0.05, (rng.uniform(-2, 2), rng.uniform(-2, 2), yaw))
    skipped = 0
    for _ in range(40):
        camera, pose = random_camera(rng), random_free_pose(rng, grid)
        centre = rng.integers(0, 60, 2)
        rows = np.clip(centre[0] + rng.integers(-8, 9, 300), 0, 59)
        cols = np.clip(centre[1] + rng.integers(-8, 9, 300), 0, 59)
        cells = np.where(rng.random(300) < 0.1, -1, rows * 60 + cols)
        whole = visibility_region(grid, pose, camera).ravel()
        expected = np.where(cells >= 0, whole[np.maximum(cells, 0)], False)
        region = VisibilityRegion(grid, pose, camera)
        assert np.array_equal(region.holds(cells), expected)
        skipped += region._whole is None
        assert np.array_equal(MaskRegion(whole.reshape(60, 60)).holds(cells), expected)
    assert skipped == 40  # the whole mask was never needed


@pytest.mark.parametrize("seed", range(3))
def test_region_bounds_hold_exactly_its_cells(seed):
    rng = np.random.default_rng(900 + seed)
    yaw = 0.0 if seed % 2 else 0.7
    grid = random_grid(rng, 50, 70, 0.05, (rng.uniform(-2, 2), rng.uniform(-2, 2), yaw))
    empty = 0
    for _ in range(40):
        region = VisibilityRegion(grid, random_free_pose(rng, grid), random_camera(rng))
        rows, cols = np.nonzero(region.mask)
        given = MaskRegion(region.mask).bounds
        if rows.size:
            expected = (rows.min(), rows.max() + 1, cols.min(), cols.max() + 1)
            assert region.bounds == expected and given == expected
        else:
            r0, r1, _, _ = region.bounds
            assert r1 <= r0 and given == (0, 0, 0, 0)
            empty += 1
    assert empty < 40  # not every region is empty


def test_region_mask_is_computed_once_and_read_only():
    grid = random_grid(np.random.default_rng(5), 40, 40, 0.1)
    region = VisibilityRegion(grid, Pose(2.0, 2.0, 0.3), CAMERA)
    assert region.shape == (40, 40)
    mask = region.mask
    assert region.mask is mask and not mask.flags.writeable
    assert np.array_equal(mask, visibility_region(grid, Pose(2.0, 2.0, 0.3), CAMERA))
    assert region.mask_over((0, 0), (0, 0)) is mask  # once whole, always whole
    given = MaskRegion(np.eye(3, dtype=bool))
    assert given.shape == (3, 3) and not given.mask.flags.writeable


def test_both_regions_are_regions_and_agree():
    # Observations name the Region protocol, not a kernel class: a region known by its mask
    # is its own class (no VisibilityRegion with empty grid, pose and camera fields) and
    # answers every question of the protocol as the computed region does.
    members = [name for name in vars(Region) if not name.startswith("_")]
    assert sorted(members) == ["bounds", "holds", "mask", "shape"]
    grid = random_grid(np.random.default_rng(6), 40, 50, 0.1)
    rng = np.random.default_rng(7)
    for _ in range(10):
        computed = VisibilityRegion(grid, random_free_pose(rng, grid), random_camera(rng))
        given = MaskRegion(computed.mask.copy())
        assert not hasattr(VisibilityRegion, "given") and not hasattr(given, "grid")
        cells = rng.integers(-5, grid.data.size, 500)
        assert given.shape == computed.shape == grid.data.shape
        assert np.array_equal(given.mask, computed.mask)
        assert np.array_equal(given.holds(cells), computed.holds(cells))
        if computed.mask.any():
            assert given.bounds == computed.bounds


@pytest.mark.parametrize("region", BOTH)
def test_camera_in_a_blocked_cell_or_off_the_map_sees_nothing(region):
    data = np.full((40, 40), FREE, dtype=np.int8)
    data[20, 20] = OCCUPIED
    data[10, 10] = UNKNOWN
    grid = OccupancyGrid(data, 0.1)
    for x, y in [(2.05, 2.05), (1.05, 1.05), (-1.0, 2.0)]:
        mask = region(grid, Pose(x, y, 0.3), CAMERA)
        assert mask.shape == grid.blocked.shape and not mask.any()


# --------------------------------------------------------------------- line of sight


def test_line_of_sight_is_symmetric_on_a_random_grid():
    rng = np.random.default_rng(7)
    grid = random_grid(rng, 40, 40, 0.1, origin=(0.5, -0.5, 0.3), density=0.05)
    for _ in range(200):
        a, b = random_free_pose(rng, grid), random_free_pose(rng, grid)
        assert line_of_sight(grid, a.xy, b.xy) == line_of_sight(grid, b.xy, a.xy)


@pytest.mark.parametrize("yaw", [0.0, 0.7])
def test_fast_line_of_sight_equals_reference(yaw):
    rng = np.random.default_rng(8)
    grid = random_grid(rng, 50, 40, 0.05, origin=(-1.3, 0.4, yaw), density=0.03)
    outcomes = set()
    for _ in range(400):
        a, b = random_free_pose(rng, grid).xy, random_free_pose(rng, grid).xy
        if rng.random() < 0.2:  # endpoints off the grid and on cell edges too
            b = b + rng.choice([-3.0, 3.0], 2)
        if rng.random() < 0.2:
            a = np.round(a / grid.resolution) * grid.resolution
        step = float(rng.choice([0.5 * grid.resolution, 0.013, 0.2]))
        fast = line_of_sight(grid, a, b, step)
        assert fast == _line_of_sight_reference(grid, a, b, step)
        outcomes.add(fast)
    assert outcomes == {True, False}


def test_point_cell_matches_world_to_cell():
    rng = np.random.default_rng(9)
    for yaw in (0.0, -2.1):
        grid = empty_grid(resolution=0.05, origin=(0.35, -1.2, yaw))
        frame = grid.frame
        # Cell edges are where a float quotient may round either way.
        on_edges = np.round(rng.uniform(-5, 5, (500, 2)) / 0.05) * 0.05
        xy = np.concatenate([rng.uniform(-5, 5, (500, 2)), on_edges])
        for x, y in xy:
            assert point_cell(x, y, frame) == grid.world_to_cell(x, y)


def test_line_of_sight_is_broken_by_a_wall_and_blocked_endpoints():
    data = np.full((40, 40), FREE, dtype=np.int8)
    data[:, 20] = OCCUPIED  # x in [2.0, 2.1) m
    grid = OccupancyGrid(data, 0.1)
    assert line_of_sight(grid, (0.5, 1.0), (1.9, 3.5))
    assert not line_of_sight(grid, (0.5, 1.0), (3.5, 3.0))
    assert not line_of_sight(grid, (3.5, 3.0), (0.5, 1.0))
    assert not line_of_sight(grid, (0.5, 1.0), (2.05, 1.0))
    assert not line_of_sight(grid, (0.5, 1.0), (-0.5, 1.0))
    assert line_of_sight(grid, (0.5, 1.0), (0.5, 1.0))


# --------------------------------------------------------------------------- in view


def dilated(grid):
    """``grid`` with every blocked cell grown by two cells in each direction."""
    grown = binary_dilation(grid.blocked, np.ones((5, 5), dtype=bool))
    return OccupancyGrid(np.where(grown, OCCUPIED, FREE), grid.resolution, grid.origin)


def occlusion_class(grid, grown, pose, row, col):
    """How the blocked cells of ``grid`` (origin yaw 0) affect cell (row, col) seen from ``pose``.

    "clear": the segment to the cell centre stays at least one cell away from every blocked
    cell (line of sight on ``grown = dilated(grid)``). "hidden": every ray through the cell
    crosses a blocked cell well inside it (0.35 cells from its sides) at least 1.5 cells
    before the centre's range. None otherwise: a shadow edge, where sampled visibility may
    go either way.
    """
    centre = grid.cell_to_world(row, col)
    if line_of_sight(grown, pose.xy, centre, step=grid.resolution / 4):
        return "clear"
    camera = (pose.xy - grid.origin[:2]) / grid.resolution  # cell units, (x, y)
    reach = np.hypot(col + 0.5 - camera[0], row + 0.5 - camera[1]) - 1.5
    t = np.linspace(0.0, 1.0, int(reach * 10) + 2)[:, None]
    for u in np.linspace(0.0, 1.0, 5):
        for v in np.linspace(0.0, 1.0, 5):
            target = np.array([col + u, row + v])
            points = camera + t * (target - camera) / np.hypot(*(target - camera)) * reach
            cells = np.floor(points).astype(int)
            frac = points - cells
            deep = np.all((frac >= 0.35) & (frac <= 0.65), axis=1)
            if not np.any(deep & grid.blocked[cells[:, 1], cells[:, 0]]):
                return None
    return "hidden"


def pose_facing_a_block(rng, grid):
    """A free pose 1 to 2 m from a random blocked cell, heading roughly towards it."""
    rows, cols = np.nonzero(grid.blocked)
    while True:
        k = rng.integers(rows.size)
        target = np.array(grid.cell_to_world(rows[k], cols[k]))
        heading = rng.uniform(-math.pi, math.pi)
        x, y = target - rng.uniform(1.0, 2.0) * np.array([math.cos(heading), math.sin(heading)])
        if grid.is_free(x, y):
            return Pose(x, y, heading + rng.uniform(-0.3, 0.3))


@pytest.mark.parametrize("seed", range(3))
def test_in_view_agrees_with_the_mask_away_from_wedge_and_shadow_edges(seed):
    rng = np.random.default_rng(200 + seed)
    data = np.full((60, 60), FREE, dtype=np.int8)
    for _ in range(5):  # a few rectangular blocks
        r, c = rng.integers(5, 50, 2)
        data[r : r + rng.integers(2, 8), c : c + rng.integers(2, 8)] = OCCUPIED
    grid = OccupancyGrid(data, 0.1, origin=(1.0, 2.0, 0.0))
    grown = dilated(grid)
    margin = 2 * grid.resolution
    counts = {"clear": 0, "hidden": 0}
    for _ in range(4):
        pose = pose_facing_a_block(rng, grid)
        mask = visibility_region(grid, pose, CAMERA)
        rows, cols = np.nonzero(grid.free)
        dist, bearing = polar(grid, pose, rows, cols)
        excess = np.abs(bearing) - CAMERA.fov / 2  # angle beyond the wedge edge, rad
        edge_gap = dist * np.sin(np.minimum(-excess, math.pi / 2))
        outside_gap = dist * np.sin(np.minimum(excess, math.pi / 2))
        inside = (dist > CAMERA.near + margin) & (dist < CAMERA.far - margin) & (edge_gap > margin)
        outside = (dist > CAMERA.far + margin) | (outside_gap > margin)
        for r, c in zip(rows[outside], cols[outside]):
            assert not mask[r, c] and not in_view(grid, CAMERA, pose, grid.cell_to_world(r, c))
        for r, c in zip(rows[inside], cols[inside]):
            kind = occlusion_class(grid, grown, pose, r, c)
            if kind is not None:
                counts[kind] += 1
                expected = kind == "clear"
                assert mask[r, c] == expected, (r, c, kind)
                assert in_view(grid, CAMERA, pose, grid.cell_to_world(r, c)) == expected
    assert counts["clear"] > 100 and counts["hidden"] > 10, counts


def test_in_view_checks_bearing_range_and_occlusion():
    data = np.full((40, 40), FREE, dtype=np.int8)
    data[15:25, 30] = OCCUPIED  # x in [3.0, 3.1) m
    grid = OccupancyGrid(data, 0.1)
    pose = Pose(1.0, 2.0, 0.0)
    assert in_view(grid, CAMERA, pose, (2.5, 2.0))
    assert not in_view(grid, CAMERA, pose, (3.5, 2.0))  # behind the wall
    assert not in_view(grid, CAMERA, pose, (1.1, 2.0))  # closer than near
    assert not in_view(grid, CAMERA, pose, (1.0, 3.5))  # outside the fov
    assert not in_view(grid, CAMERA, Pose(0.5, 0.2, 0.0), (3.8, 0.2))  # beyond far


def test_body_shows_past_a_wall_edge_or_the_fov_edge_while_its_centre_is_hidden():
    data = np.full((40, 40), FREE, dtype=np.int8)
    data[15:25, 30] = OCCUPIED  # a wall at x in [3.0, 3.1) m, y in [1.5, 2.5) m
    grid = OccupancyGrid(data, 0.1)
    pose, radius = Pose(1.0, 2.0, 0.0), 0.25
    behind_edge = (3.5, 2.6)  # centre hidden by the wall's end, one shoulder past it
    assert not in_view(grid, CAMERA, pose, behind_edge)
    assert body_in_view(grid, CAMERA, pose, behind_edge, radius)
    assert not body_in_view(grid, CAMERA, pose, (3.5, 2.0), radius)  # the wall hides it all
    past_fov = (1.0 + 2.0 * math.cos(0.6), 2.0 + 2.0 * math.sin(0.6))  # 0.076 rad past the edge
    assert not in_view(grid, CAMERA, pose, past_fov)
    assert body_in_view(grid, CAMERA, pose, past_fov, radius)
    assert not body_in_view(grid, CAMERA, pose, past_fov, 0.1)  # a thinner body stays out


@pytest.mark.parametrize("seed", range(3))
def test_body_in_view_whenever_its_centre_is(seed):
    rng = np.random.default_rng(500 + seed)
    grid = random_grid(rng, 50, 50, 0.1, density=0.1)
    for _ in range(300):
        pose, other = random_free_pose(rng, grid), random_free_pose(rng, grid)
        centre = (other.x, other.y)
        if in_view(grid, CAMERA, pose, centre):
            assert body_in_view(grid, CAMERA, pose, centre, 0.2)
        assert body_in_view(grid, CAMERA, pose, centre, 0.0) == in_view(grid, CAMERA, pose, centre)


# -------------------------------------------------------------------------- fov wedge


@pytest.mark.parametrize("near", [0.0, 0.3])
def test_fov_wedge_is_a_closed_ring_on_the_range_limits(near):
    camera = Camera(fov=1.2, near=near, far=2.5)
    pose = Pose(1.0, -2.0, 0.7)
    ring = fov_wedge(camera, pose, n=16)
    assert ring.shape == ((16 if near else 1) + 16 + 1, 2)
    assert np.array_equal(ring[0], ring[-1])
    d = ring - pose.xy
    dist = np.hypot(d[:, 0], d[:, 1])
    assert np.allclose(dist[-17:-1], camera.far)
    assert np.allclose(dist[: 16 if near else 1], near)
    bearing = np.arctan2(d[-17:-1, 1], d[-17:-1, 0]) - pose.theta
    assert np.allclose([bearing.min(), bearing.max()], [-0.6, 0.6])


def test_ray_directions_are_libm_s_beyond_the_polynomial_range():
    angles = np.linspace(-0.5, 0.5, 101)
    for theta in (0.3, -2.9, 1e7, -4e9):
        cos_a, sin_a = directions(theta, angles, 10, 90)
        np.testing.assert_allclose(cos_a, np.cos(theta + angles[10:90]), rtol=0, atol=2.3e-16)
        np.testing.assert_allclose(sin_a, np.sin(theta + angles[10:90]), rtol=0, atol=2.3e-16)
