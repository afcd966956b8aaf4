"""Tests for pegame.navigation: inflation, grid planning and the pure-pursuit follower."""

from __future__ import annotations

import gc
import math
import pickle
import weakref

import numpy as np
import pytest

from pegame.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from pegame.navigation import (
    LARGE_GRID_CELLS,
    TIE_QUANTUM,
    PathFollower,
    Planner,
    inflate,
    shared_inflation,
)
from pegame.navigation.follower import _follow, _follow_reference
from pegame.navigation.search import astar_reference, distance_field_reference
from pegame.types import STOP, Body, Pose

SEEDS = [0, 1, 2, 3, 4]
MOVES = [(1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (1, -1), (-1, 1), (-1, -1)]


def random_grid(seed, height=24, width=30, resolution=0.1, origin=(0.0, 0.0, 0.0)):
    """Free space with random rectangular blocks and a sprinkle of occupied/unknown cells."""
    rng = np.random.default_rng(seed)
    data = np.full((height, width), FREE, dtype=np.int8)
    for _ in range(6):
        r, c = rng.integers(0, height), rng.integers(0, width)
        h, w = rng.integers(1, 6, size=2)
        data[r : r + h, c : c + w] = OCCUPIED
    data[rng.random((height, width)) < 0.02] = OCCUPIED
    data[rng.random((height, width)) < 0.01] = UNKNOWN
    return OccupancyGrid(data, resolution, origin)


def random_points(rng, planner, count):
    """Random map points inside random traversable cells."""
    rows, cols = np.nonzero(planner.traversable)
    pick = rng.integers(0, rows.size, count)
    res = planner.grid.resolution
    out = []
    for r, c in zip(rows[pick], cols[pick]):
        x, y = planner.grid.cell_to_world(r, c)
        out.append((x + rng.uniform(-0.49, 0.49) * res, y + rng.uniform(-0.49, 0.49) * res))
    return out


def bellman_ford(traversable, multipliers, weighted, resolution, source):
    """Least path costs by repeated relaxation of every allowed move until nothing changes."""
    height, width = traversable.shape
    dist = np.full((height, width), np.inf)
    dist[source] = 0.0
    changed = True
    while changed:
        changed = False
        for r in range(height):
            for c in range(width):
                if not np.isfinite(dist[r, c]):
                    continue
                for dr, dc in MOVES:
                    nr, nc = r + dr, c + dc
                    if not (0 <= nr < height and 0 <= nc < width and traversable[nr, nc]):
                        continue
                    if dr and dc and not (traversable[r, nc] and traversable[nr, c]):
                        continue  # no corner cutting
                    step = resolution * (math.sqrt(2) if dr and dc else 1.0)
                    if weighted:
                        step *= 0.5 * (multipliers[r, c] + multipliers[nr, nc])
                    if dist[r, c] + step < dist[nr, nc] - 1e-12:
                        dist[nr, nc] = dist[r, c] + step
                        changed = True
    return dist


def assert_path_clear(planner, path, samples_per_cell=10):
    """Every point densely sampled along every segment lies in a traversable cell."""
    step = planner.grid.resolution / samples_per_cell
    for a, b in zip(path[:-1], path[1:]):
        n = max(2, int(math.ceil(np.hypot(*(b - a)) / step)) + 1)
        t = np.linspace(0.0, 1.0, n)[:, None]
        pts = a + t * (b - a)
        rows, cols = planner.grid.world_to_cell(pts[:, 0], pts[:, 1])
        assert planner.grid.contains(rows, cols).all()
        assert planner.traversable[rows, cols].all()


# --------------------------------------------------------------------------- inflate


@pytest.mark.parametrize("seed", SEEDS)
def test_inflate_matches_brute_force(seed):
    rng = np.random.default_rng(seed)
    height, width = rng.integers(5, 14, size=2)
    res = float(rng.choice([0.05, 0.1, 0.25]))
    data = np.where(rng.random((height, width)) < 0.15, OCCUPIED, FREE).astype(np.int8)
    grid = OccupancyGrid(data, res)
    # Blocked cell centres, with the ring of cells just outside the grid.
    rr, cc = np.meshgrid(np.arange(-1, height + 1), np.arange(-1, width + 1), indexing="ij")
    outside = (rr < 0) | (rr >= height) | (cc < 0) | (cc >= width)
    inner = np.zeros_like(outside)
    inner[1:-1, 1:-1] = grid.blocked
    br, bc = rr[outside | inner], cc[outside | inner]
    for radius in [0.0, res, 1.5 * res, float(rng.uniform(0, 4 * res)), 2.0]:
        expected = np.zeros((height, width), dtype=bool)
        for r in range(height):
            for c in range(width):
                d = np.hypot((br - r) * res, (bc - c) * res).min()
                expected[r, c] = d <= radius + 1e-9
        np.testing.assert_array_equal(inflate(grid, radius), expected)


def test_inflate_counts_the_border_and_unknown_cells():
    data = np.full((9, 9), FREE, dtype=np.int8)
    data[4, 4] = UNKNOWN
    mask = inflate(OccupancyGrid(data, 0.1), 0.1)
    assert mask[4, 4] and mask[3, 4] and mask[4, 5] and not mask[3, 3]
    assert mask[0, :].all() and mask[:, -1].all() and not mask[1, 1]


# --------------------------------------------------------------------------- planner


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("weighted", [False, True])
def test_distance_field_matches_reference_and_bellman_ford(seed, weighted):
    grid = random_grid(seed, height=12, width=15, origin=(1.0, -2.0, 0.0))
    planner = Planner(grid, 0.05, clearance=0.3)
    rng = np.random.default_rng(seed)
    for xy in random_points(rng, planner, 3):
        field = planner.distance_field(xy, weighted)
        assert field.shape == grid.data.shape and field.dtype == np.float64
        source = grid.world_to_cell(*xy)
        args = (planner.traversable, planner.multipliers, weighted, grid.resolution, source)
        reference = distance_field_reference(*args)
        brute = bellman_ford(*args)
        np.testing.assert_array_equal(np.isfinite(field), np.isfinite(brute))
        np.testing.assert_array_equal(np.isfinite(field), planner.reachable(xy))
        finite = np.isfinite(field)
        np.testing.assert_allclose(field[finite], reference[finite], rtol=0, atol=1e-9)
        np.testing.assert_allclose(field[finite], brute[finite], rtol=0, atol=1e-9)


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize(
    ("landmarks", "tie_quantum"), [(0, 0.0), (3, 0.0), (0, TIE_QUANTUM), (3, TIE_QUANTUM)]
)
def test_plans_are_clear_optimal_and_match_the_reference(seed, landmarks, tie_quantum):
    grid = random_grid(seed)
    planner = Planner(grid, 0.12, landmarks=landmarks, tie_quantum=tie_quantum)
    rng = np.random.default_rng(seed)
    starts, goals = random_points(rng, planner, 12), random_points(rng, planner, 12)
    for start, goal in zip(starts, goals):
        result = planner.plan(start, goal)
        s, g = grid.world_to_cell(*start), grid.world_to_cell(*goal)
        costs = bellman_ford(planner.traversable, planner.multipliers, True, grid.resolution, s)
        optimum = costs[g]
        ref_cost, ref_cells = astar_reference(
            planner.traversable, planner.multipliers, grid.resolution, s, g
        )
        assert result.reachable == np.isfinite(optimum)
        if not result.reachable:
            assert result.path.shape == (0, 2) and result.reason and not ref_cells
            continue
        assert result.reason == ""
        assert result.cost == pytest.approx(optimum, abs=1e-9)
        assert result.cost == pytest.approx(ref_cost, abs=1e-9)
        np.testing.assert_allclose(result.path[0], grid.cell_to_world(*s))
        np.testing.assert_allclose(result.path[-1], goal)
        assert result.length == pytest.approx(np.hypot(*np.diff(result.path, axis=0).T).sum())
        assert_path_clear(planner, result.path)


@pytest.mark.parametrize("seed", SEEDS)
def test_unweighted_plan_length_is_the_grid_optimum(seed):
    grid = random_grid(seed, height=14, width=16)
    planner = Planner(grid, 0.1, clearance_weight=0.0)
    rng = np.random.default_rng(seed + 100)
    for start, goal in zip(random_points(rng, planner, 6), random_points(rng, planner, 6)):
        result = planner.plan(start, goal)
        s, g = grid.world_to_cell(*start), grid.world_to_cell(*goal)
        costs = bellman_ford(planner.traversable, planner.multipliers, False, grid.resolution, s)
        optimum = costs[g]
        if result.reachable:
            # The cell path is optimal; the appended goal point adds less than one cell.
            assert optimum - 1e-9 <= result.length <= optimum + grid.resolution


def test_clearance_keeps_paths_away_from_walls():
    data = np.full((30, 40), FREE, dtype=np.int8)
    data[10:20, 15:25] = OCCUPIED  # a pillar between start and goal
    grid = OccupancyGrid(data, 0.1)
    plain = Planner(grid, 0.1, clearance_weight=0.0).plan((0.5, 1.5), (3.5, 1.5))
    clear = Planner(grid, 0.1, clearance=0.5, clearance_weight=5.0).plan((0.5, 1.5), (3.5, 1.5))
    assert clear.reachable and plain.reachable
    assert pillar_gap(clear.path) > pillar_gap(plain.path) + 0.1
    assert clear.length > plain.length


def pillar_gap(path):
    """Least distance (m) from the path's waypoints to the pillar [1.5, 2.5] x [1, 2]."""
    dx = np.maximum(np.maximum(1.5 - path[:, 0], path[:, 0] - 2.5), 0.0)
    dy = np.maximum(np.maximum(1.0 - path[:, 1], path[:, 1] - 2.0), 0.0)
    return np.hypot(dx, dy).min()


def walled_room_grid():
    """A 4 m x 3 m map with a closed 1.4 m square room in its right half."""
    data = np.full((30, 40), FREE, dtype=np.int8)
    data[8:23, 22:37] = OCCUPIED
    data[9:22, 23:36] = FREE
    return OccupancyGrid(data, 0.1)


def test_unreachable_goals_give_a_reason_not_an_exception():
    planner = Planner(walled_room_grid(), 0.1)
    inside_room = planner.plan((0.5, 0.5), (2.95, 1.55))
    assert not inside_room.reachable and inside_room.reason == "goal is not reachable from start"
    assert inside_room.path.shape == (0, 2) and inside_room.length == 0.0

    data = np.full((40, 40), FREE, dtype=np.int8)
    data[5:35, 15:35] = OCCUPIED
    planner = Planner(OccupancyGrid(data, 0.1), 0.1)
    deep = planner.plan((0.5, 0.5), (2.5, 2.0))  # 1 m from the block's nearest free cell
    assert not deep.reachable and deep.reason == "goal is inside an obstacle"
    far = planner.plan((0.5, 0.5), (50.0, 50.0))
    assert not far.reachable and far.reason == "goal is outside the map"


def test_goal_near_a_wall_snaps_to_the_nearest_reachable_cell():
    planner = Planner(walled_room_grid(), 0.1)
    goal = (2.15, 1.5)  # inside the room's left wall, 0.05 m from its outer face
    result = planner.plan((0.5, 0.5), goal)
    assert result.reachable
    end = result.path[-1]
    row, col = planner.grid.world_to_cell(*end)
    assert planner.traversable[row, col] and end[0] < 2.2  # outside the room
    assert math.dist(end, goal) <= planner.goal_snap
    assert_path_clear(planner, result.path)


def test_start_in_the_inflation_zone_still_plans():
    data = np.full((20, 30), FREE, dtype=np.int8)
    data[:, 0] = OCCUPIED
    grid = OccupancyGrid(data, 0.1)
    planner = Planner(grid, 0.15)
    start = (0.25, 1.0)  # 0.2 m from the wall's centres: inside radius + margin
    assert not planner.traversable[grid.world_to_cell(*start)]
    result = planner.plan(start, (2.5, 1.0))
    assert result.reachable
    first = grid.world_to_cell(*result.path[0])
    assert planner.traversable[first] and math.dist(result.path[0], start) < 0.15
    assert_path_clear(planner, result.path)
    assert planner.nearest_traversable(start) == pytest.approx(tuple(result.path[0]))


def test_shared_planners_and_masks_are_built_once_per_grid_and_parameters():
    grid, other = random_grid(0), random_grid(1)
    planner = Planner.shared(grid, 0.1)
    assert Planner.shared(grid, 0.1, margin=0.05) is planner  # defaults count as given
    assert Planner.shared(grid, 0.1, margin=0.1) is not planner
    assert Planner.shared(grid, 0.2) is not planner and Planner.shared(other, 0.1) is not planner
    fresh = Planner(grid, 0.1)
    np.testing.assert_array_equal(planner.traversable, fresh.traversable)
    np.testing.assert_array_equal(planner.multipliers, fresh.multipliers)
    assert not planner.traversable.flags.writeable and not planner.multipliers.flags.writeable
    mask = shared_inflation(grid, 0.1)
    assert shared_inflation(grid, 0.1) is mask and not mask.flags.writeable
    np.testing.assert_array_equal(mask, inflate(grid, 0.1))
    assert inflate(grid, 0.1).flags.writeable


def test_keys_are_rounded_by_default_only_on_large_grids():
    small = Planner(random_grid(0), 0.1)
    assert small.tie_quantum == 0.0 and small.landmarks == 0  # the paper's maps: exact keys
    large = OccupancyGrid(np.zeros((1000, LARGE_GRID_CELLS // 1000), dtype=np.int8), 0.05)
    assert Planner(large, 0.1).tie_quantum == TIE_QUANTUM and Planner(large, 0.1).landmarks == 0
    assert Planner(large, 0.1, tie_quantum=0.0).tie_quantum == 0.0


def test_the_shared_cache_lives_and_dies_with_its_grid():
    grid = random_grid(0)
    planner = Planner.shared(grid, 0.1)
    copied = pickle.loads(pickle.dumps(grid))  # the cache is not pickled along
    assert Planner.shared(copied, 0.1) is not planner and Planner.shared(copied, 0.1).grid is copied
    alive = weakref.ref(grid)
    del grid, planner
    gc.collect()
    assert alive() is None


def test_searches_leave_no_state_behind():
    # A shared planner reuses scratch memory between searches: any order of searches must
    # give what a fresh planner gives.
    grid = random_grid(3)
    shared = Planner(grid, 0.1)
    rng = np.random.default_rng(3)
    points = random_points(rng, shared, 20) + [(-1.0, 0.5), (1.0, 1.0), (50.0, 2.0)]
    for _ in range(40):
        a, b = (points[i] for i in rng.integers(0, len(points), 2))
        if rng.random() < 0.3:
            weighted = bool(rng.random() < 0.5)
            np.testing.assert_array_equal(
                shared.distance_field(a, weighted), Planner(grid, 0.1).distance_field(a, weighted)
            )
        ours, theirs = shared.plan(a, b), Planner(grid, 0.1).plan(a, b)
        assert (ours.reachable, ours.reason) == (theirs.reachable, theirs.reason)
        assert ours.cost == theirs.cost or not ours.reachable
        np.testing.assert_array_equal(ours.path, theirs.path)


def test_reachable_and_nearest_traversable():
    planner = Planner(walled_room_grid(), 0.1)
    outside, room = planner.reachable((0.5, 0.5)), planner.reachable((2.95, 1.55))
    assert outside.any() and room.any() and not (outside & room).any()
    assert not (outside & ~planner.traversable).any()
    assert planner.nearest_traversable((0.55, 0.55)) == pytest.approx((0.55, 0.55))
    blocked = OccupancyGrid(np.full((5, 5), OCCUPIED, dtype=np.int8), 0.1)
    nothing = Planner(blocked, 0.1)
    assert nothing.nearest_traversable((0.2, 0.2)) is None
    assert not nothing.reachable((0.2, 0.2)).any()
    assert np.isinf(nothing.distance_field((0.2, 0.2))).all()
    assert nothing.plan((0.2, 0.2), (0.3, 0.3)).reason == "no traversable cell in the map"


# --------------------------------------------------------------------------- follower

BODY = Body(radius=0.2, v_max=0.5, w_max=1.2)
DT = 0.1


def simulate(follower, pose, seconds):
    """Integrate the unicycle at 10 Hz; return the poses and commands."""
    poses, commands = [pose], []
    for _ in range(int(seconds / DT)):
        cmd = follower.command(pose)
        commands.append(cmd)
        theta = pose.theta + cmd.w * DT
        pose = Pose(
            pose.x + cmd.v * DT * math.cos(pose.theta + 0.5 * cmd.w * DT),
            pose.y + cmd.v * DT * math.sin(pose.theta + 0.5 * cmd.w * DT),
            math.remainder(theta, 2 * math.pi),
        )
        poses.append(pose)
    return poses, commands


def dense(points, spacing=0.05):
    """A polyline through ``points`` resampled every ``spacing`` metres, like a grid path."""
    out = [np.asarray(points[0], dtype=float)]
    for a, b in zip(points[:-1], points[1:]):
        a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        n = int(math.ceil(np.hypot(*(b - a)) / spacing))
        out.extend(a + (b - a) * (i / n) for i in range(1, n + 1))
    return np.array(out)


def distance_to_polyline(point, path):
    a, b = path[:-1], path[1:]
    d = b - a
    t = np.clip(np.einsum("ij,ij->i", point - a, d) / np.einsum("ij,ij->i", d, d), 0, 1)
    return np.hypot(*(a + t[:, None] * d - point).T).min()


def test_follower_kernel_equals_reference():
    rng = np.random.default_rng(5)
    for _ in range(300):
        count = int(rng.integers(1, 40))
        signs = rng.choice([-1.0, 1.0], size=(count, 2))
        steps = rng.choice([0.0, 0.05, 0.0707], size=(count, 1)) * signs
        path = np.cumsum(steps, axis=0) + rng.uniform(-2, 2, 2)
        if count > 3 and rng.random() < 0.3:
            path[-3:] = path[:3][::-1]  # a path passing near itself
        seg = np.diff(path, axis=0)
        seg_len = np.hypot(seg[:, 0], seg[:, 1])
        arc = np.concatenate([[0.0], np.cumsum(seg_len)])
        progress = float(rng.uniform(0.0, arc[-1] + 0.2))
        x, y = path[int(rng.integers(count))] + rng.normal(0.0, 0.1, 2)
        lookahead = float(rng.choice([0.05, 0.5, 2.0]))
        args = (path, seg_len, arc, progress, lookahead, x, y)
        assert _follow(*args) == _follow_reference(*args)


def test_follower_tracks_an_l_shaped_path_within_limits():
    path = dense([(0.0, 0.0), (3.0, 0.0), (3.0, 2.0)])
    follower = PathFollower(BODY)
    follower.set_path(path)
    assert follower.remaining == pytest.approx(5.0)
    poses, commands = simulate(follower, Pose(0.0, 0.0, 0.0), 30.0)
    assert follower.done and follower.remaining == 0.0
    assert poses[-1].distance_to(Pose(3.0, 2.0)) <= follower.goal_tolerance
    assert all(0.0 <= c.v <= BODY.v_max and abs(c.w) <= BODY.w_max for c in commands)
    assert max(distance_to_polyline(p.xy, path) for p in poses) < 0.3
    assert commands[-1] == STOP
    assert max(c.v for c in commands) == pytest.approx(BODY.v_max)


def test_follower_rotates_in_place_for_a_goal_behind():
    follower = PathFollower(BODY)
    follower.set_path(dense([(0.0, 0.0), (-2.0, 0.0)]))
    first = follower.command(Pose(0.0, 0.0, 0.0))
    assert first.v == 0.0 and abs(first.w) == pytest.approx(BODY.w_max)
    poses, commands = simulate(follower, Pose(0.0, 0.0, 0.0), 20.0)
    assert follower.done and poses[-1].distance_to(Pose(-2.0, 0.0)) <= follower.goal_tolerance
    turning = [c for c in commands if c.v == 0.0 and c.w != 0.0]
    assert len(turning) >= 2  # it turned before driving


def test_follower_progress_does_not_skip_ahead_on_a_hairpin():
    # Out 2 m and back on a parallel lane 0.4 m away; the agent starts nearer the return
    # lane, which must not be taken as progress.
    path = dense([(0.0, 0.0), (2.0, 0.0), (2.0, 0.4), (0.0, 0.4)])
    follower = PathFollower(BODY)
    follower.set_path(path)
    poses, _ = simulate(follower, Pose(0.5, 0.25, 0.0), 30.0)
    assert follower.done
    assert max(p.x for p in poses) > 1.7


def test_follower_with_no_path_stops():
    follower = PathFollower(BODY)
    assert follower.done and follower.command(Pose(1.0, 1.0, 0.0)) == STOP
    follower.set_path(np.array([[1.0, 1.05]]))
    assert follower.command(Pose(1.0, 1.0, 0.0)) == STOP and follower.done
