"""Tests for the smart pursuer (paper, Sec. "Smart Pursuer"): the reactive controller on a
detection, collision safety, navigation to the estimate when lost, and its config."""

from __future__ import annotations

import logging
import math

import numpy as np
import pytest

from pegame.api import Context, PursuerObservation
from pegame.errors import ConfigError
from pegame.grid import FREE, OCCUPIED, OccupancyGrid
from pegame.navigation import inflate
from pegame.pursuers.smart import (
    SCAN,
    SEARCH,
    TRACK,
    SmartPursuer,
    _straight_clear,
    _straight_clear_reference,
)
from pegame.registry import make_config
from pegame.types import EMPTY_BELIEF, Belief, Body, BoundingBox, Camera, Detection, Pose, Velocity

RES = 0.1  # m per cell
V_MAX, W_MAX, RADIUS = 0.5, 1.8, 0.2
CAMERA = Camera()  # 640 px wide


def open_grid(size: int = 60) -> OccupancyGrid:
    """A size x size free grid of RES-metre cells (6 m x 6 m by default)."""
    return OccupancyGrid(np.full((size, size), FREE, dtype=np.int8), RES)


def make_pursuer(grid: OccupancyGrid, **params) -> SmartPursuer:
    config = make_config("pursuer", SmartPursuer, params)
    context = Context(
        grid=grid,
        pursuer=Body(config.radius, V_MAX, config.w_max),
        evader=Body(0.25, 0.5, 1.8),
        camera=CAMERA,
        control_dt=0.1,
        decision_dt=1.0,
    )
    return SmartPursuer(config, context, np.random.default_rng(0))


def seen(center_x: float, depth: float) -> Detection:
    """A detection whose 40 px wide box is centred on image column ``center_x`` (px)."""
    return Detection(BoundingBox(center_x - 20.0, 100.0, 40.0, 200.0), depth, (0.0, 0.0))


def observe(pose: Pose, detection: Detection | None = None, mean=None, time: float = 0.0):
    belief = EMPTY_BELIEF if mean is None else Belief(mean=mean)
    return PursuerObservation(time, pose, detection, belief, np.zeros((1, 1), dtype=bool))


def step(pose: Pose, cmd: Velocity, dt: float = 0.1) -> Pose:
    """Euler step of the unicycle, saturated to the pursuer's limits."""
    v, w = float(np.clip(cmd.v, -V_MAX, V_MAX)), float(np.clip(cmd.w, -W_MAX, W_MAX))
    return Pose(
        pose.x + v * dt * math.cos(pose.theta),
        pose.y + v * dt * math.sin(pose.theta),
        math.remainder(pose.theta + w * dt, 2 * math.pi),
    )


CENTRE = Pose(3.0, 3.0, 0.0)  # the middle of the open grid, facing +x


# ------------------------------------------------------------------------ tracking


@pytest.mark.parametrize(
    ("center_x", "sign"), [(500.0, -1), (140.0, 1), (320.0, 0)], ids=["right", "left", "centred"]
)
def test_turns_toward_the_box(center_x, sign):
    pursuer = make_pursuer(open_grid())
    cmd = pursuer.control(observe(CENTRE, seen(center_x, 1.5)))
    if sign == 0:
        assert abs(cmd.w) < 1e-9
    else:
        assert np.sign(cmd.w) == sign
        assert abs(cmd.w) > 0.5


def test_offset_follows_the_papers_equation():
    pursuer = make_pursuer(open_grid(), k_w=2.0)
    # Box x_b = 380, w_b = 40: offset = 380 + 20 - 320 = 80 px, i.e. 0.125 of the width.
    cmd = pursuer.control(observe(CENTRE, seen(400.0, 1.5)))
    assert cmd.w == pytest.approx(-2.0 * 80 / 640)


def test_depth_sets_the_speed():
    pursuer = make_pursuer(open_grid(), standoff=1.5, k_v=1.0)
    near = pursuer.control(observe(CENTRE, seen(320.0, 1.0)))
    far = pursuer.control(observe(CENTRE, seen(320.0, 1.8)))
    at = pursuer.control(observe(CENTRE, seen(320.0, 1.5)))
    assert near.v == pytest.approx(-0.5)
    assert far.v == pytest.approx(0.3)
    assert at.v == pytest.approx(0.0)


def test_commands_saturate_at_the_body_limits():
    pursuer = make_pursuer(open_grid(), k_v=10.0, k_w=50.0)
    far_right = pursuer.control(observe(CENTRE, seen(630.0, 5.0)))
    near_left = pursuer.control(observe(CENTRE, seen(10.0, 0.3)))
    assert (far_right.v, far_right.w) == pytest.approx((V_MAX, -W_MAX))
    assert (near_left.v, near_left.w) == pytest.approx((-V_MAX, W_MAX))


def wall_grid() -> OccupancyGrid:
    """Open grid with a wall along x in [4.0, 4.3] m."""
    data = np.full((60, 60), FREE, dtype=np.int8)
    data[:, 40:43] = OCCUPIED
    return OccupancyGrid(data, RES)


def test_does_not_drive_into_a_wall_ahead():
    pursuer = make_pursuer(wall_grid())
    # The inflated wall starts at x = 3.8 m, 0.2 m ahead: inside the 0.25 m look-ahead.
    pose = Pose(3.6, 3.0, 0.0)
    cmd = pursuer.control(observe(pose, seen(500.0, 4.0)))
    assert cmd.v <= 0.0
    assert cmd.w < 0.0  # it still turns toward the evader
    # Facing away from the wall it approaches as usual.
    away = pursuer.control(observe(Pose(3.6, 3.0, math.pi), seen(320.0, 4.0)))
    assert away.v > 0.0


def test_does_not_back_into_a_wall_behind():
    pursuer = make_pursuer(wall_grid())
    backing = pursuer.control(observe(Pose(3.6, 3.0, math.pi), seen(320.0, 0.5)))
    assert backing.v == 0.0
    free = pursuer.control(observe(Pose(2.0, 3.0, math.pi), seen(320.0, 0.5)))
    assert free.v < 0.0


def test_commanded_tracking_never_enters_the_inflated_wall():
    pursuer = make_pursuer(wall_grid(), k_v=5.0)
    pose = Pose(2.0, 3.0, 0.0)
    for _ in range(100):  # an evader far ahead behind the wall pulls it forward
        pose = step(pose, pursuer.control(observe(pose, seen(320.0, 5.0))))
        row, col = pursuer.context.grid.world_to_cell(pose.x, pose.y)
        assert not pursuer.blocked[row, col]
    assert pose.x > 3.0  # it did approach


@pytest.mark.parametrize("origin", [(0.0, 0.0, 0.0), (0.4, -1.3, 0.8)])
def test_fast_look_ahead_check_equals_reference(origin):
    data = np.full((40, 50), FREE, dtype=np.int8)
    data[10:30, 20:24] = OCCUPIED
    grid = OccupancyGrid(data, RES, origin)
    blocked = inflate(grid, RADIUS)
    frame = grid.frame
    rng = np.random.default_rng(4)
    outcomes = set()
    for _ in range(2000):
        x, y = grid.cell_to_world(*rng.integers(-2, 42, 2))
        if rng.random() < 0.5:
            x, y = x + rng.uniform(-0.05, 0.05), y + rng.uniform(-0.05, 0.05)
        theta = rng.uniform(-math.pi, math.pi)
        distance = rng.choice([-1.0, 1.0]) * rng.uniform(0.01, 1.5)
        n = max(1, math.ceil(2 * abs(distance) / RES))
        fast = _straight_clear(blocked, x, y, math.cos(theta), math.sin(theta), distance, n, frame)
        assert fast == _straight_clear_reference(grid, blocked, x, y, theta, distance, n)
        outcomes.add(fast)
    assert outcomes == {True, False}


# ------------------------------------------------------------------------ searching


def obstacle_grid() -> OccupancyGrid:
    """Open grid with a block in x [2.5, 3.5] m, y [1.5, 4.5] m between start and estimate."""
    data = np.full((60, 60), FREE, dtype=np.int8)
    data[15:45, 25:35] = OCCUPIED
    return OccupancyGrid(data, RES)


def test_lost_pursuer_plans_to_the_estimate():
    pursuer = make_pursuer(obstacle_grid())
    start, estimate = Pose(1.0, 3.0, 0.0), (5.0, 3.0)
    plan = pursuer.decide(observe(start, mean=estimate))
    assert plan.goal == estimate
    assert plan.info["mode"] == SEARCH
    assert len(plan.path) > 2
    assert np.allclose(plan.path[-1], estimate)


def test_lost_pursuer_reaches_the_estimate():
    pursuer = make_pursuer(obstacle_grid())
    pose, estimate = Pose(1.0, 3.0, 0.0), (5.0, 3.0)
    pursuer.reset(pose)
    for tick in range(400):
        obs = observe(pose, mean=estimate, time=0.1 * tick)
        if tick % 10 == 0:
            pursuer.decide(obs)
        pose = step(pose, pursuer.control(obs))
        if pursuer.mode == SCAN:
            break
    assert math.hypot(pose.x - estimate[0], pose.y - estimate[1]) < 0.5
    # Arrived and still seeing nothing: it scans in place.
    cmd = pursuer.control(observe(pose, mean=estimate))
    assert cmd.v == 0.0 and abs(cmd.w) == pytest.approx(1.0)


def test_losing_the_evader_starts_the_search_at_once():
    pursuer = make_pursuer(open_grid())
    pursuer.reset(CENTRE)
    pursuer.control(observe(CENTRE, seen(320.0, 2.0)))
    # No decision in between: the next control tick already heads for the estimate.
    cmd = pursuer.control(observe(CENTRE, mean=(5.0, 3.0)))
    assert pursuer.mode == SEARCH
    assert cmd.v > 0.0


def test_a_detection_switches_back_to_tracking():
    pursuer = make_pursuer(open_grid())
    pursuer.decide(observe(CENTRE, mean=(5.0, 3.0)))
    assert pursuer.mode == SEARCH
    cmd = pursuer.control(observe(CENTRE, seen(500.0, 1.0), mean=(5.0, 3.0)))
    assert pursuer.mode == TRACK
    assert cmd.v < 0.0 and cmd.w < 0.0
    plan = pursuer.decide(observe(CENTRE, seen(320.0, 1.5)))
    assert plan.info["mode"] == TRACK


def test_no_estimate_scans_in_place(caplog):
    pursuer = make_pursuer(open_grid(), scan_rate=0.7)
    with caplog.at_level(logging.INFO, logger="pegame.pursuers.smart"):
        plan = pursuer.decide(observe(CENTRE))
    assert plan.info["mode"] == SCAN and plan.goal is None
    assert "no estimate" in caplog.text
    for _ in range(3):
        cmd = pursuer.control(observe(CENTRE))
        assert cmd.v == 0.0 and abs(cmd.w) == pytest.approx(0.7)


def test_unreachable_estimate_scans_toward_it(caplog):
    data = np.full((60, 60), FREE, dtype=np.int8)
    data[5:25, 35:55] = OCCUPIED
    data[7:23, 37:53] = FREE  # a sealed room, x and y in [3.7, 5.3] m and [0.7, 2.3] m
    pursuer = make_pursuer(OccupancyGrid(data, RES))
    pose, estimate = Pose(3.0, 4.0, math.pi / 2), (4.5, 1.5)  # the room is to its right
    with caplog.at_level(logging.INFO, logger="pegame.pursuers.smart"):
        plan = pursuer.decide(observe(pose, mean=estimate))
    assert plan.info["mode"] == SCAN
    assert "unreachable" in caplog.text
    cmd = pursuer.control(observe(pose, mean=estimate))
    assert cmd == Velocity(0.0, -1.0)  # clockwise, toward the estimate's bearing


# --------------------------------------------------------------------------- config


@pytest.mark.parametrize(
    ("params", "key"),
    [
        ({"standoff": 0.0}, "pursuer.standoff"),
        ({"k_w": -1.0}, "pursuer.k_w"),
        ({"k_v": 0.0}, "pursuer.k_v"),
        ({"scan_rate": -0.5}, "pursuer.scan_rate"),
        ({"track": "chase"}, "pursuer.track"),
        ({"radius": 0.0}, "pursuer.radius"),
    ],
)
def test_bad_config_names_the_key(params, key):
    with pytest.raises(ConfigError, match=key.replace(".", r"\.")):
        make_config("pursuer", SmartPursuer, params)


def test_a_blocked_approach_detours_around_the_wall_end_unless_the_detour_is_off():
    data = np.full((60, 60), FREE, dtype=np.int8)
    data[:30, 40:43] = OCCUPIED  # a wall at x 4.0-4.3 m up to y = 3 m
    grid = OccupancyGrid(data, RES)
    pose = Pose(3.6, 2.0, 0.0)  # facing the wall, 0.2 m from its inflated face
    beyond = Detection(BoundingBox(300.0, 100.0, 40.0, 200.0), 2.0, (5.0, 3.8))
    detour = make_pursuer(grid).control(observe(pose, beyond))
    wait = make_pursuer(grid, detour=False).control(observe(pose, beyond))
    assert detour.w > 0.0  # it turns left, onto the planned path round the wall end
    assert wait.v == 0.0 and wait.w == pytest.approx(0.0)  # it stays, the evader centred


# ------------------------------------------------------------------------ track=goal


def test_goal_tracking_drives_to_the_standoff_point_of_a_detection_and_faces_it():
    pursuer = make_pursuer(open_grid(), track="goal", standoff=1.5)
    pose = Pose(1.0, 3.0, 0.5)  # facing away from the person by 0.5 rad
    seen_at = Detection(BoundingBox(300.0, 100.0, 40.0, 200.0), 4.0, (5.0, 3.0))
    pursuer.reset(pose)
    for _ in range(200):  # the same (held) detection: one goal, followed on the pose
        pose = step(pose, pursuer.control(observe(pose, seen_at)))
    assert pursuer.mode == TRACK
    assert math.hypot(pose.x - 5.0, pose.y - 3.0) == pytest.approx(1.5, abs=0.2)
    assert abs(pose.theta) < 0.05  # faces the detected position
    cmd = pursuer.control(observe(pose, seen_at))
    assert cmd.v == 0.0


def test_goal_tracking_replans_for_a_new_detection_only():
    pursuer = make_pursuer(open_grid(), track="goal")
    first = Detection(BoundingBox(300.0, 100.0, 40.0, 200.0), 4.0, (5.0, 3.0))
    pursuer.control(observe(Pose(1.0, 3.0, 0.0), first))
    path = pursuer.follower.path.copy()
    pursuer.control(observe(Pose(1.2, 3.0, 0.0), first))
    assert np.array_equal(pursuer.follower.path, path)  # held detection: the same goal
    second = Detection(BoundingBox(300.0, 100.0, 40.0, 200.0), 4.0, (5.0, 5.0))
    pursuer.control(observe(Pose(1.2, 3.0, 0.0), second))
    assert not np.array_equal(pursuer.follower.path, path)


def test_servo_is_the_default_tracking():
    assert make_pursuer(open_grid()).config.track == "servo"
