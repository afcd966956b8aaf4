"""Tests for pegame.evaders.smart: the paper's smart evader (Algorithm 2 on top of Alg. 1)."""

from __future__ import annotations

import heapq
import logging
import math
from collections import deque
from importlib.resources import files
from pathlib import Path

import numpy as np
import pytest
from scipy.ndimage import distance_transform_edt

from pegame.api import Context, EvaderObservation
from pegame.errors import ConfigError
from pegame.evaders.escape import (
    MAX_RECORDED_CANDIDATES,
    _grow,
    _sample_positions,
    disc_half_widths,
)
from pegame.evaders.smart import SmartEvader
from pegame.grid import FREE, OCCUPIED, OccupancyGrid, load_map
from pegame.navigation import Planner
from pegame.registry import make_config
from pegame.types import Body, Camera, Pose
from pegame.visibility import VisibilityRegion, visibility_region

MAPS_DIR = Path(str(files("pegame.maps")))

RES = 0.1  # m per cell in every test grid
CAMERA = Camera(fov=math.pi / 3, near=0.3, far=5.0, angle_step=0.004, distance_step=0.05)
EVADER = Body(radius=0.12, v_max=0.5, w_max=1.8)
PURSUER = Body(radius=0.08, v_max=0.5, w_max=1.8)


def walled_grid(height: int, width: int, blocks=()) -> OccupancyGrid:
    """A free grid of RES-metre cells with a one-cell outer wall and occupied blocks given
    as (row0, row1, col0, col1) half-open index ranges."""
    data = np.full((height, width), FREE, dtype=np.int8)
    data[[0, -1], :] = OCCUPIED
    data[:, [0, -1]] = OCCUPIED
    for r0, r1, c0, c1 in blocks:
        data[r0:r1, c0:c1] = OCCUPIED
    return OccupancyGrid(data, RES)


def make_evader(
    grid, distance="euclidean", camera=CAMERA, evader=EVADER, pursuer=PURSUER, **params
):
    config = make_config(
        "evader",
        SmartEvader,
        {
            "radius": evader.radius,
            "v_max": evader.v_max,
            "w_max": evader.w_max,
            "distance": distance,
            **params,
        },
    )
    context = Context(grid, pursuer, evader, camera, control_dt=0.1, decision_dt=1.0)
    smart = SmartEvader(config, context, np.random.default_rng(0))
    return smart


def centre(row: int, col: int) -> tuple[float, float]:
    """Centre (m) of cell (row, col) of a test grid (origin 0, yaw 0)."""
    return (col + 0.5) * RES, (row + 0.5) * RES


def cell_of(xy) -> tuple[int, int]:
    return int(math.floor(xy[1] / RES)), int(math.floor(xy[0] / RES))


# ------------------------------------------------------------------ brute-force reference


def bfs_reachable(traversable: np.ndarray, start: tuple[int, int]) -> np.ndarray:
    """4-connected flood fill of ``traversable`` from ``start``."""
    reached = np.zeros_like(traversable)
    reached[start] = True
    queue = deque([start])
    while queue:
        r, c = queue.popleft()
        for dr, dc in ((1, 0), (-1, 0), (0, 1), (0, -1)):
            nr, nc = r + dr, c + dc
            if 0 <= nr < reached.shape[0] and 0 <= nc < reached.shape[1]:
                if traversable[nr, nc] and not reached[nr, nc]:
                    reached[nr, nc] = True
                    queue.append((nr, nc))
    return reached


def dijkstra(traversable: np.ndarray, start: tuple[int, int]) -> np.ndarray:
    """Geodesic distance (m) over 8-connected moves without corner cutting; inf if unreachable."""
    height, width = traversable.shape
    dist = np.full(traversable.shape, np.inf)
    dist[start] = 0.0
    queue = [(0.0, start)]
    while queue:
        d, (r, c) = heapq.heappop(queue)
        if d > dist[r, c]:
            continue
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                nr, nc = r + dr, c + dc
                if (dr, dc) == (0, 0) or not (0 <= nr < height and 0 <= nc < width):
                    continue
                if not traversable[nr, nc]:
                    continue
                if dr and dc and not (traversable[r + dr, c] and traversable[r, c + dc]):
                    continue
                step = RES * (math.sqrt(2.0) if dr and dc else 1.0)
                if d + step < dist[nr, nc]:
                    dist[nr, nc] = d + step
                    heapq.heappush(queue, (d + step, (nr, nc)))
    return dist


def brute_costs(grid, evader_pose, pursuer_pose, distance, margin=0.0) -> np.ndarray:
    """Algorithm 2's cost (H, W) for every candidate cell by plain loops; inf elsewhere.
    Candidates lie more than ``margin`` m (centre to centre) from every visible cell."""
    visible = visibility_region(grid, pursuer_pose, CAMERA)
    in_region = np.argwhere(visible)
    e_trav = Planner(grid, EVADER.radius).traversable
    p_trav = Planner(grid, PURSUER.radius).traversable
    e_cell, p_cell = (
        cell_of((evader_pose.x, evader_pose.y)),
        cell_of((pursuer_pose.x, pursuer_pose.y)),
    )
    reach = bfs_reachable(e_trav, e_cell)
    if distance == "geodesic":
        e_dist, p_dist = dijkstra(e_trav, e_cell), dijkstra(p_trav, p_cell)
    cost = np.full(grid.data.shape, np.inf)
    for r in range(grid.height):
        for c in range(grid.width):
            if grid.data[r, c] != FREE or not reach[r, c] or visible[r, c]:
                continue
            if (
                margin > 0
                and len(in_region)
                and np.hypot(*(in_region - (r, c)).T).min() * RES <= margin
            ):
                continue
            if distance == "euclidean":
                x, y = centre(r, c)
                effort = math.hypot(x - evader_pose.x, y - evader_pose.y)
                dist = math.hypot(x - pursuer_pose.x, y - pursuer_pose.y)
            else:
                effort, dist = e_dist[r, c], p_dist[r, c]
            cost[r, c] = math.inf if dist == 0 else effort / dist
    return cost


def brute_argmin(cost: np.ndarray) -> tuple[int, int]:
    """Lowest cost, then lowest row-major index, by a plain loop (costs equal up to 1e-12)."""
    best, best_cell = math.inf, None
    for r in range(cost.shape[0]):
        for c in range(cost.shape[1]):
            if cost[r, c] < best * (1 - 1e-12):
                best, best_cell = cost[r, c], (r, c)
    return best_cell


def random_scene(seed: int, size: int = 30, n_blocks: int = 5):
    """A size x size grid with random blocks, a pursuer pose and an evader pose (in view
    when possible), both in cells traversable for their bodies."""
    rng = np.random.default_rng(seed)
    blocks = []
    for _ in range(n_blocks):
        r, c = rng.integers(3, size - 5, 2)
        blocks.append((r, r + rng.integers(1, 5), c, c + rng.integers(1, 5)))
    grid = walled_grid(size, size, blocks)
    p_rows, p_cols = np.nonzero(Planner(grid, PURSUER.radius).traversable)
    k = rng.integers(p_rows.size)
    pursuer = Pose(*centre(p_rows[k], p_cols[k]), rng.uniform(-math.pi, math.pi))
    e_trav = Planner(grid, EVADER.radius).traversable
    in_view = e_trav & visibility_region(grid, pursuer, CAMERA)
    e_rows, e_cols = np.nonzero(in_view if in_view.any() else e_trav)
    k = rng.integers(e_rows.size)
    jitter = rng.uniform(-0.4, 0.4, 2) * RES
    x, y = centre(e_rows[k], e_cols[k])
    return grid, pursuer, Pose(x + jitter[0], y + jitter[1], rng.uniform(-math.pi, math.pi))


# ---------------------------------------------------------------------------- tests


@pytest.mark.parametrize("distance", ["euclidean", "geodesic"])
@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("margin", [0.0, 0.3])
def test_goal_is_the_brute_force_argmin(distance, seed, margin):
    grid, pursuer, me = random_scene(seed)
    smart = make_evader(grid, distance, hide_margin=margin)
    smart.reset(me)
    plan = smart.decide(EvaderObservation(0.0, me, pursuer))
    cost = brute_costs(grid, me, pursuer, distance, margin)
    expected = brute_argmin(cost)
    goal = cell_of(plan.goal)
    assert goal == expected
    assert not visibility_region(grid, pursuer, CAMERA)[goal]
    assert Planner(grid, EVADER.radius).reachable((me.x, me.y))[goal]
    assert plan.info["escape_cost"] == pytest.approx(cost[expected], rel=1e-9, abs=1e-12)
    assert len(plan.path) > 0


def assert_same_escape(smart, me, pursuer):
    """The fast escape equals the numpy reference exactly, and so does the goal found
    with the region computed only where the search looks (Euclidean); returns it."""
    fast, slow = smart.search.escape(me, pursuer), smart.search.escape_reference(me, pursuer)
    assert (fast.cell, fast.cost, fast.count) == (slow.cell, slow.cost, slow.count)
    np.testing.assert_array_equal(fast.sample, slow.sample)
    if smart.config.distance == "euclidean":
        assert smart.search.goal(me, pursuer) == (slow.cell, slow.cost)
    return fast


@pytest.mark.parametrize("distance", ["euclidean", "geodesic"])
@pytest.mark.parametrize(("margin", "stride"), [(0.0, 1), (0.15, 1), (0.3, 1), (0.3, 3)])
def test_escape_kernels_match_the_numpy_reference(distance, margin, stride):
    for seed in range(25):
        # Small rooms, and larger ones where most tiles are out of view and skipped.
        size, n_blocks = (30, 5) if seed % 2 else (90, 40)
        grid, pursuer, me = random_scene(seed, size, n_blocks)
        smart = make_evader(grid, distance, hide_margin=margin, candidate_stride=stride)
        assert_same_escape(smart, me, pursuer)


@pytest.mark.parametrize("distance", ["euclidean", "geodesic"])
def test_the_games_region_gives_the_same_decisions(distance):
    """The region the game passes (whole, computed in part, or not yet computed) gives the
    decisions the evader makes computing its own."""
    for seed in range(12):
        grid, pursuer, me = random_scene(seed, 40, 8)
        own, told = make_evader(grid, distance), make_evader(grid, distance)
        for step, offset in enumerate((0.0, 0.3, -0.2)):
            p = Pose(pursuer.x, pursuer.y, pursuer.theta + offset)
            region = VisibilityRegion(grid, p, CAMERA)
            if step == 1:
                region.holds(np.arange(0, grid.height * grid.width, 7))  # as the estimator asks
            if step == 2:
                _ = region.mask  # already computed whole, as a recorder does
            mine = own.decide(EvaderObservation(float(step), me, p))
            given = told.decide(EvaderObservation(float(step), me, p, region))
            assert given.goal == mine.goal and np.array_equal(given.path, mine.path)
            np.testing.assert_array_equal(given.info["candidates"], mine.info["candidates"])
            assert given.info["escape_cost"] == mine.info["escape_cost"]
            fast = told.search.escape(me, p, region)
            slow = told.search.escape_reference(me, p)
            assert (fast.cell, fast.cost, fast.count) == (slow.cell, slow.cost, slow.count)


def test_the_evader_escapes_the_region_it_is_given():
    """With a region given, the evader does not build its own: a region of another camera
    gives the decision of an evader built with that camera."""
    grid, pursuer, me = random_scene(3, 40, 8)
    wide = Camera(fov=2.5, near=0.1, far=3.0, angle_step=0.004, distance_step=0.05)
    wide_region = VisibilityRegion(grid, pursuer, wide)
    told = make_evader(grid).decide(EvaderObservation(0.0, me, pursuer, wide_region))
    built = make_evader(grid, camera=wide).decide(EvaderObservation(0.0, me, pursuer))
    own = make_evader(grid).decide(EvaderObservation(0.0, me, pursuer))
    assert told.goal == built.goal and told.info["escape_cost"] == built.info["escape_cost"]
    assert told.info["escape_cost"] != own.info["escape_cost"]


@pytest.mark.parametrize("distance", ["euclidean", "geodesic"])
def test_escape_kernels_match_the_reference_on_a_paper_map(distance):
    grid = load_map(MAPS_DIR / "enclosed.yaml")
    camera, evader, pursuer_body = Camera(), Body(0.25, 0.5, 1.8), Body(0.2, 0.5, 1.8)
    smart = make_evader(grid, distance, camera=camera, evader=evader, pursuer=pursuer_body)
    rows, cols = np.nonzero(smart.planner.traversable)
    rng = np.random.default_rng(31)
    recorded = []
    for k in range(10 if distance == "euclidean" else 3):
        i, j = rng.integers(rows.size, size=2)
        pursuer = Pose(*grid.cell_to_world(rows[i], cols[i]), rng.uniform(-math.pi, math.pi))
        in_rows, in_cols = np.nonzero(
            visibility_region(grid, pursuer, camera) & smart.planner.traversable
        )
        if k % 2 and in_rows.size:  # the evader in the region: the search has to go far
            i = rng.integers(in_rows.size)
            me = Pose(*grid.cell_to_world(in_rows[i], in_cols[i]), 0.0)
        else:
            me = Pose(*grid.cell_to_world(rows[j], cols[j]), 0.0)
        recorded.append(assert_same_escape(smart, me, pursuer).sample.size)
    assert max(recorded) > MAX_RECORDED_CANDIDATES / 2  # thousands of candidates, subsampled


@pytest.mark.parametrize("resolution", [0.05, 0.1])
@pytest.mark.parametrize("margin", [0.0, 0.05, 0.123, 0.3, 0.31])
def test_grown_view_matches_the_distance_transform(resolution, margin):
    rng = np.random.default_rng(32)
    for _ in range(10):
        visible = np.zeros((40, 50), dtype=bool)
        for _ in range(rng.integers(1, 4)):
            r, c = rng.integers(0, 40), rng.integers(0, 50)
            visible[r : r + rng.integers(1, 15), c : c + rng.integers(1, 20)] = True
        visible &= rng.random(visible.shape) < 0.9  # holes and ragged runs
        expected = distance_transform_edt(~visible) * resolution <= margin
        rows, cols = np.nonzero(visible)
        window, top, left = _grow(
            visible,
            rows.min(),
            rows.max() + 1,
            cols.min(),
            cols.max() + 1,
            disc_half_widths(margin, resolution),
        )
        grown = np.zeros_like(visible)
        grown[top : top + window.shape[0], left : left + window.shape[1]] = window
        np.testing.assert_array_equal(grown, expected)


def test_sample_positions_skip_the_hidden_entries():
    rng = np.random.default_rng(33)
    for _ in range(200):
        size = int(rng.integers(1, 300))
        skipped = np.flatnonzero(rng.random(size) < rng.random())
        kept = np.setdiff1d(np.arange(size), skipped)
        step = int(rng.integers(1, 20))
        np.testing.assert_array_equal(_sample_positions(skipped, kept.size, step), kept[::step])


def test_evader_in_another_room_gets_that_room_s_candidates():
    # A full-height wall at cols 30..31 splits the grid into two rooms.
    grid = walled_grid(40, 60, [(0, 40, 30, 32)])
    smart = make_evader(grid)
    pursuer = Pose(1.05, 2.05, 0.0)
    for me in (Pose(1.55, 1.05, 0.0), Pose(4.55, 3.05, 0.0), Pose(1.55, 3.05, 0.0)):
        found = assert_same_escape(smart, me, pursuer)
        room = Planner(grid, EVADER.radius).reachable((me.x, me.y))
        assert room.ravel()[found.cell] and room.ravel()[found.sample].all()


def test_hidden_spot_behind_a_wall_beats_open_space():
    # Pursuer at the left looking right (+x) at the evader, a wall just behind the evader.
    wall = (22, 38, 35, 37)  # rows 22..37 (y 2.2-3.8 m), cols 35..36 (x 3.5-3.7 m)
    pursuer = Pose(1.05, 3.05, 0.0)
    me = Pose(3.05, 3.05, 0.0)
    walled = walled_grid(60, 60, [wall])
    plan = make_evader(walled).decide(EvaderObservation(0.0, me, pursuer))
    goal_x, goal_y = plan.goal
    assert goal_x > 3.7 and 2.2 < goal_y < 3.8  # in the wall's shadow
    # Every candidate outside the shadow costs more by the formula.
    cost = brute_costs(walled, me, pursuer, "euclidean")
    rows, cols = np.nonzero(np.isfinite(cost))
    x, y = (cols + 0.5) * RES, (rows + 0.5) * RES
    open_space = ~((x > 3.7) & (y > 2.2) & (y < 3.8))
    assert cost[rows, cols][open_space].min() > plan.info["escape_cost"]
    # Without the wall the same scene sends the evader out of the FOV wedge instead.
    open_plan = make_evader(walled_grid(60, 60)).decide(EvaderObservation(0.0, me, pursuer))
    bearing = math.atan2(open_plan.goal[1] - pursuer.y, open_plan.goal[0] - pursuer.x)
    assert abs(bearing) > CAMERA.fov / 2


def test_cells_the_pursuer_cannot_reach_are_ideal_with_geodesic_distances():
    # A closet behind a 3-cell gap: wide enough for a small evader, not for a big pursuer.
    small, big = Body(0.05, 0.5, 1.8), Body(0.3, 0.5, 1.8)
    grid = walled_grid(40, 40, [(20, 21, 1, 20), (20, 21, 23, 39)])  # gap at cols 20..22
    pursuer, me = Pose(1.05, 0.85, 0.3), Pose(2.05, 1.05, 0.0)
    smart = make_evader(grid, "geodesic", evader=small, pursuer=big)
    plan = smart.decide(EvaderObservation(0.0, me, pursuer))
    closet = Planner(grid, small.radius).reachable((me.x, me.y)) & ~Planner(
        grid, big.radius
    ).reachable((pursuer.x, pursuer.y))
    hidden = closet & ~visibility_region(grid, pursuer, CAMERA)
    assert plan.info["escape_cost"] == 0.0
    rows, cols = np.nonzero(hidden)
    assert cell_of(plan.goal) == (rows[0], cols[0])  # ties: lowest row-major index


@pytest.mark.parametrize("distance", ["euclidean", "geodesic"])
def test_evader_out_of_sight_stays_put(distance):
    # Behind the pursuer, the evader's own cell is the cheapest by Algorithm 2.
    grid = walled_grid(40, 40)
    pursuer, me = Pose(2.05, 2.05, 0.0), Pose(1.03, 2.07, 0.0)
    plan = make_evader(grid, distance).decide(EvaderObservation(0.0, me, pursuer))
    goal, own = cell_of(plan.goal), cell_of((me.x, me.y))
    assert max(abs(goal[0] - own[0]), abs(goal[1] - own[1])) <= 1
    if distance == "geodesic":
        assert goal == own and plan.info["escape_cost"] == 0.0


def test_no_candidate_keeps_the_current_plan(caplog):
    # A 1 m room; a camera seeing all around covers every cell the evader can reach.
    grid = walled_grid(10, 10)
    everywhere = Camera(fov=2 * math.pi, near=0.0, far=2.0, angle_step=0.002, distance_step=0.02)
    smart = make_evader(grid, camera=everywhere)
    me = Pose(0.45, 0.45, 0.0)
    # A camera inside the wall sees nothing, so the first decision has a goal.
    first = smart.decide(EvaderObservation(0.0, me, Pose(0.05, 0.05, 0.0)))
    assert first.goal is not None
    with caplog.at_level(logging.INFO, logger="pegame.evaders.smart"):
        plan = smart.decide(EvaderObservation(1.0, me, Pose(0.55, 0.55, 0.0)))
    assert "keeping the current plan" in caplog.text
    assert plan.goal == first.goal and plan.path is first.path
    assert plan.info["candidates"].shape == (0, 2)
    assert plan.info["escape_cost"] == math.inf
    # From a fresh start there is no plan to keep: the evader stops.
    fresh = make_evader(grid, camera=everywhere)
    fresh.reset(me)
    assert fresh.decide(EvaderObservation(0.0, me, Pose(0.55, 0.55, 0.0))).goal is None
    command = fresh.control(EvaderObservation(0.0, me, Pose(0.55, 0.55, 0.0)))
    assert (command.v, command.w) == (0.0, 0.0)


def test_evader_moves_toward_its_goal():
    grid = walled_grid(60, 60, [(22, 38, 35, 37)])
    pursuer, pose = Pose(1.05, 3.05, 0.0), Pose(3.05, 3.05, math.pi / 2)
    smart = make_evader(grid)
    smart.reset(pose)
    plan = smart.decide(EvaderObservation(0.0, pose, pursuer))
    start_gap = math.dist((pose.x, pose.y), plan.goal)
    dt = 0.1
    for step in range(100):  # 10 s of unicycle motion; the path around the wall is ~2.7 m
        cmd = smart.control(EvaderObservation(step * dt, pose, pursuer))
        assert abs(cmd.v) <= EVADER.v_max + 1e-9 and abs(cmd.w) <= EVADER.w_max + 1e-9
        theta = pose.theta + cmd.w * dt
        pose = Pose(
            pose.x + cmd.v * math.cos(theta) * dt, pose.y + cmd.v * math.sin(theta) * dt, theta
        )
        assert not grid.blocked[cell_of((pose.x, pose.y))]
    assert math.dist((pose.x, pose.y), plan.goal) < min(0.3, 0.5 * start_gap)


def test_same_goal_keeps_the_path_and_info_is_bounded():
    grid = walled_grid(60, 60, [(22, 38, 35, 37)])
    pursuer, me = Pose(1.05, 3.05, 0.0), Pose(3.05, 3.05, 0.0)
    smart = make_evader(grid)
    first = smart.decide(EvaderObservation(0.0, me, pursuer))
    second = smart.decide(EvaderObservation(1.0, me, pursuer))
    assert second.path is first.path and second.goal == first.goal
    candidates = second.info["candidates"]
    assert candidates.ndim == 2 and candidates.shape[1] == 2
    assert 0 < len(candidates) <= MAX_RECORDED_CANDIDATES
    assert np.array_equal(candidates, first.info["candidates"])


def test_candidate_stride_scores_every_kth_cell():
    grid, pursuer, me = random_scene(1)
    smart = make_evader(grid, candidate_stride=3)
    rows, cols = np.divmod(smart.search.candidates(me, pursuer), grid.width)
    assert rows.size > 0 and np.all(rows % 3 == 0) and np.all(cols % 3 == 0)
    assert rows.size < make_evader(grid).search.candidates(me, pursuer).size / 4
    goal = cell_of(smart.decide(EvaderObservation(0.0, me, pursuer)).goal)
    assert goal[0] % 3 == 0 and goal[1] % 3 == 0


@pytest.mark.parametrize(
    ("params", "key"),
    [
        ({"distance": "manhattan"}, "evader.distance"),
        ({"candidate_stride": 0}, "evader.candidate_stride"),
        ({"radius": -1.0}, "evader.radius"),
    ],
)
def test_bad_config_names_the_key(params, key):
    with pytest.raises(ConfigError, match=key.replace(".", r"\.")):
        make_config("evader", SmartEvader, params)


@pytest.mark.parametrize("margin", [0.12, 0.3])
def test_the_goal_found_in_part_of_the_region_is_the_references_with_the_evader_in_view(margin):
    """The pursuer close by and facing the evader, as in most decisions of a tracked
    evader: the search scores many tiles in and about the region, which it marches ray
    piece by ray piece; the goal and cost stay the reference's."""
    grid = load_map(MAPS_DIR / "enclosed.yaml")
    camera, evader, pursuer_body = Camera(), Body(0.25, 0.5, 1.8), Body(0.2, 0.5, 1.8)
    smart = make_evader(
        grid, camera=camera, evader=evader, pursuer=pursuer_body, hide_margin=margin
    )
    rows, cols = np.nonzero(smart.planner.traversable)
    rng = np.random.default_rng(5)
    for _ in range(40):
        i = rng.integers(rows.size)
        me = Pose(*grid.cell_to_world(rows[i], cols[i]), 0.0)
        distance, bearing = rng.uniform(0.3, 2.5), rng.uniform(-math.pi, math.pi)
        x, y = me.x - distance * math.cos(bearing), me.y - distance * math.sin(bearing)
        pursuer = Pose(x, y, bearing + rng.uniform(-0.4, 0.4))
        slow = smart.search.escape_reference(me, pursuer)
        assert smart.search.goal(me, pursuer) == (slow.cell, slow.cost)
