"""Tests for the elusive evader: hidden goals, flee versus hide by speed, the grown
regions against a plain reference, its config."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.ndimage import binary_dilation

from pegame.api import Context, EvaderObservation
from pegame.evaders.elusive import ElusiveEvader
from pegame.grid import FREE, OccupancyGrid
from pegame.registry import make_config
from pegame.testing import EvaderConformance
from pegame.types import Body, Camera, Pose
from pegame.visibility import body_in_view, visibility_region


@pytest.mark.slow
class TestConformance(EvaderConformance):
    plugin = "elusive"
    bad_values = {
        "horizon": 0,
        "flee_weight": -1,
        "hide_weight": -1,
        "horizon_p": 0,
        "exposed_penalty": -1,
        "turn_weight": -1,
        "hide_margin": -1,
        "sight_angle_step": 0,
    }


def pillar_context(pursuer_speed: float = 0.5) -> Context:
    """8 m x 8 m at 0.1 m with a 1 m square pillar at (4.5-5.5, 3.5-4.5) m."""
    data = np.full((80, 80), FREE, dtype=np.int8)
    data[35:45, 45:55] = 100
    grid = OccupancyGrid(data, 0.1)
    return Context(grid, Body(0.2, pursuer_speed, 1.8), Body(0.25, 0.5, 1.8), Camera(), 0.1, 1.0)


def make(context: Context, **params) -> ElusiveEvader:
    evader = ElusiveEvader(
        make_config("evader", ElusiveEvader, params), context, np.random.default_rng(0)
    )
    evader.reset(Pose(0.0, 0.0))
    return evader


ALL_ROUND = dataclasses.replace(Camera(), fov=2 * math.pi)


def test_goal_is_out_of_the_pursuers_line_of_sight():
    """With a pillar to hide behind, the goal is hidden from the pursuer turning round."""
    context = pillar_context()
    evader = make(context)
    pursuer, me = Pose(2.0, 4.0, 0.0), Pose(4.0, 3.0, 0.0)
    plan = evader.decide(EvaderObservation(0.0, me, pursuer))
    assert plan.goal is not None and len(plan.path) > 0
    assert not body_in_view(context.grid, ALL_ROUND, pursuer, plan.goal, context.evader.radius)
    assert plan.goal[0] > 5.5  # behind the pillar


def test_faster_evader_flees_further_than_a_slower_one_hides():
    """Out of sight in the open, a faster evader walks away from the pursuer (flee_weight)
    while a slower one stays near (hide_weight)."""
    me, pursuer = Pose(4.0, 1.0, 0.0), Pose(1.0, 7.0, -0.5)
    goals = {}
    for speed in (0.25, 1.0):
        context = pillar_context(speed)
        goals[speed] = make(context).decide(EvaderObservation(0.0, me, pursuer)).goal
    far = {s: math.hypot(g[0] - pursuer.x, g[1] - pursuer.y) for s, g in goals.items()}
    near = {s: math.hypot(g[0] - me.x, g[1] - me.y) for s, g in goals.items()}
    assert far[0.25] > far[1.0] and near[0.25] > near[1.0]


def test_candidates_are_outside_the_grown_view():
    context = pillar_context()
    evader = make(context)
    pursuer, me = Pose(2.0, 4.0, 0.0), Pose(3.0, 4.2, 0.0)
    cost = evader.costs(me, pursuer)
    seen = visibility_region(context.grid, pursuer, context.camera)
    grown = binary_dilation(seen, np.ones((7, 7), bool))  # 0.3 m at 0.1 m per cell
    assert np.isfinite(cost).any()
    assert not np.isfinite(cost[grown.ravel()]).any()


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("margin", [0.0, 0.1, 0.25, 0.3])
def test_grown_equals_square_dilation(seed, margin):
    """The windowed running maximum equals a full-grid dilation by the square margin."""
    context = pillar_context()
    evader = make(context, hide_margin=margin)
    rng = np.random.default_rng(seed)
    mask = np.zeros((80, 80), bool)
    r0, c0 = rng.integers(0, 70, 2)
    mask[r0 : r0 + rng.integers(1, 12), c0 : c0 + rng.integers(1, 12)] = rng.random() < 2
    mask &= rng.random(mask.shape) < 0.5
    rows, cols = np.nonzero(mask)
    bounds = (rows.min(), rows.max() + 1, cols.min(), cols.max() + 1) if rows.size else (0, 0, 0, 0)
    reach = int(margin / 0.1 + 1e-9)
    expected = binary_dilation(mask, np.ones((2 * reach + 1,) * 2, bool)) if reach else mask
    assert np.array_equal(evader._grown(mask, bounds), expected)


def test_no_candidate_keeps_the_plan():
    """A map with no free cell: the evader has nowhere to go and keeps its (empty) plan."""
    data = np.full((20, 20), 100, dtype=np.int8)
    context = dataclasses.replace(pillar_context(), grid=OccupancyGrid(data, 0.1))
    evader = make(context)
    plan = evader.decide(EvaderObservation(0.0, Pose(1.0, 1.0), Pose(0.5, 0.5)))
    assert plan.goal is None


def open_context(pursuer_speed: float = 0.5) -> Context:
    """12 m x 12 m at 0.1 m with nothing to hide behind within the camera's 5 m range."""
    grid = OccupancyGrid(np.full((120, 120), FREE, dtype=np.int8), 0.1)
    return Context(grid, Body(0.2, pursuer_speed, 1.8), Body(0.25, 0.5, 1.8), Camera(), 0.1, 1.0)


def test_turn_times_match_a_per_cell_reference():
    """The vectorised turn times equal the plain per-cell formula, 0 inside the wedge and
    (pi - fov / 2) / w_max straight behind the pursuer."""
    context = pillar_context()
    evader = make(context)
    pursuer = Pose(3.1, 5.2, 2.6)
    times = evader.turn_times(pursuer)
    grid, fov, w_max = context.grid, context.camera.fov, context.pursuer.w_max
    rng = np.random.default_rng(3)
    for index in rng.integers(0, times.size, 200):
        row, col = divmod(int(index), grid.width)
        x, y = grid.cell_to_world(row, col)
        off = abs(
            math.remainder(math.atan2(y - pursuer.y, x - pursuer.x) - pursuer.theta, 2 * math.pi)
        )
        assert times[index] == pytest.approx(max(0.0, off - fov / 2) / w_max, abs=1e-12)
    behind = grid.world_to_cell(pursuer.x - 2 * math.cos(2.6), pursuer.y - 2 * math.sin(2.6))
    assert times[behind[0] * grid.width + behind[1]] == pytest.approx(
        (math.pi - fov / 2) / w_max, abs=0.02
    )


def test_in_the_open_the_goal_is_where_the_pursuer_must_turn_longest():
    """Nothing hides the evader within the camera's range: it goes behind the pursuer,
    not just beside the wedge it stands in (regression: without the turn time every
    exposed cell cost the same and the goal was the nearest cell out of view; tracked
    98.9% in the hall at v_p/v_e = 1, like the smart evader)."""
    context = open_context()
    evader = make(context)
    pursuer, me = Pose(6.0, 6.0, 0.0), Pose(7.5, 6.3, 0.0)  # 1.5 m ahead, in view
    goal = evader.decide(EvaderObservation(0.0, me, pursuer)).goal
    bearing = abs(math.atan2(goal[1] - pursuer.y, goal[0] - pursuer.x))
    assert bearing > math.pi / 2  # across and behind the pursuer's heading
    without = make(context, turn_weight=0.0).decide(EvaderObservation(0.0, me, pursuer)).goal
    assert abs(math.atan2(without[1] - pursuer.y, without[0] - pursuer.x)) < bearing
