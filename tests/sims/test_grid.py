"""Tests for pegame.sims.grid: unicycle integration, saturation and swept wall collisions."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pegame.api import Context
from pegame.navigation import inflate
from pegame.sims.grid import (
    GridSimulator,
    _sweep,
    _sweep_reference,
    accelerate,
    saturate,
    unicycle,
)
from pegame.testing import walled_room
from pegame.types import Body, Camera, Pose, Velocity, wrap_angle

PURSUER = Body(radius=0.2, v_max=0.5, w_max=1.8)
EVADER = Body(radius=0.25, v_max=0.5, w_max=1.8)
DT = 0.1


def simulator(grid):
    context = Context(grid, PURSUER, EVADER, Camera(), DT, 1.0)
    return GridSimulator(GridSimulator.Config(), context, np.random.default_rng(0))


def test_saturate_clips_to_the_body_limits():
    assert saturate(Velocity(2.0, -5.0), PURSUER) == Velocity(0.5, -1.8)
    assert saturate(Velocity(-0.3, 0.4), PURSUER) == Velocity(-0.3, 0.4)
    assert math.isnan(saturate(Velocity(math.nan, 0.0), PURSUER).v)


def test_free_motion_is_the_exact_unicycle_arc():
    sim = simulator(walled_room())
    start = Pose(1.0, 1.0, 0.3)
    sim.reset((start,), (Pose(3.5, 2.5),))
    for cmd in (Velocity(0.4, 0.0), Velocity(0.4, 1.0), Velocity(-0.2, -0.5)):
        sim.step((cmd,), (Velocity(),), DT)
        expected = unicycle(start, cmd, DT)
        assert sim.poses[0][0] == expected
        start = expected
    # Closed form of the arc: centre at distance v / w to the left of the heading.
    v, w, theta = 0.4, 1.0, 0.3
    moved = unicycle(Pose(0.0, 0.0, theta), Velocity(v, w), 1.0)
    cx, cy = -v / w * math.sin(theta), v / w * math.cos(theta)
    assert math.hypot(moved.x - cx, moved.y - cy) == pytest.approx(v / w)
    assert moved.theta == pytest.approx(theta + w)


def test_an_agent_stops_at_a_wall_and_can_still_turn():
    grid = walled_room()
    sim = simulator(grid)
    # heading at the pillar's left face x = 1.75
    sim.reset((Pose(1.0, 1.5, 0.0),), (Pose(3.5, 2.5),))
    for _ in range(40):
        sim.step((Velocity(0.5, 0.0),), (Velocity(),), DT)
    stopped = sim.poses[0][0]
    assert 1.75 - PURSUER.radius - 0.05 <= stopped.x <= 1.75 - PURSUER.radius and stopped.y == 1.5
    sim.step((Velocity(0.5, 1.0),), (Velocity(),), DT)
    assert sim.poses[0][0].theta == pytest.approx(0.1)


@pytest.mark.parametrize("origin", [(0.0, 0.0, 0.0), (-1.2, 0.7, 0.4)])
def test_random_commands_never_enter_inflated_cells(origin):
    grid = walled_room(origin)
    sim = simulator(grid)
    rng = np.random.default_rng(1)
    sim.reset((Pose(*grid.cell_to_world(10, 10)),), (Pose(*grid.cell_to_world(50, 70)),))
    masks = inflate(grid, PURSUER.radius), inflate(grid, EVADER.radius)
    moved = 0.0
    for _ in range(3000):
        before = sim.poses
        commands = [(Velocity(*rng.uniform(-1.0, 1.0, 2) * [0.8, 3.0]),) for _ in range(2)]
        sim.step(*commands, DT)
        for (pose,), (old,), mask in zip(sim.poses, before, masks):
            row, col = grid.world_to_cell(pose.x, pose.y)
            assert grid.contains(row, col) and not mask[row, col]
            moved += pose.distance_to(old)
    assert moved > 50.0  # the agents did get around


def test_fast_sweep_equals_reference():
    rng = np.random.default_rng(2)
    for origin in [(0.0, 0.0, 0.0), (0.3, -0.2, 1.1)]:
        grid = walled_room(origin)
        blocked = inflate(grid, PURSUER.radius)
        frame = grid.frame
        stops = 0
        for _ in range(2000):
            sx, sy = rng.uniform(-0.5, 4.5), rng.uniform(-0.5, 3.5)
            if rng.random() < 0.3:  # starts and ends on cell edges
                sx, sy = round(sx / 0.05) * 0.05, round(sy / 0.05) * 0.05
            tx, ty = sx + rng.normal(0.0, 0.3), sy + rng.normal(0.0, 0.3)
            n = int(rng.integers(1, 20))
            fast = _sweep(blocked, sx, sy, tx, ty, n, frame)
            assert fast == _sweep_reference(grid, blocked, sx, sy, tx, ty, n)
            stops += fast != (tx, ty)
        assert 100 < stops < 2000


def _move_reference(
    grid, blocked, body: Body, pose: Pose, velocity: Velocity, cmd: Velocity, dt: float
) -> tuple[Pose, Velocity]:
    """The agent's move in plain Python, as the simulator played it before its kernel:
    saturation, the acceleration ramp, the arc's difference of sines, the chord sampled at
    half-cell spacing through the reference sweep."""
    limited = not (math.isinf(body.a_max) and math.isinf(body.alpha_max))
    command = saturate(cmd, body)
    if limited:
        command = accelerate(velocity, command, body, dt)
    v, w = command.v, command.w
    theta = pose.theta + w * dt
    if abs(w) < 1e-9:
        dx, dy = v * dt * math.cos(pose.theta), v * dt * math.sin(pose.theta)
    else:
        dx = v / w * (math.sin(theta) - math.sin(pose.theta))
        dy = -v / w * (math.cos(theta) - math.cos(pose.theta))
    tx, ty = pose.x + dx, pose.y + dy
    n = max(1, math.ceil(2 * math.hypot(tx - pose.x, ty - pose.y) / grid.resolution))
    x, y = _sweep_reference(grid, blocked, pose.x, pose.y, tx, ty, n)
    stopped = math.hypot(tx - x, ty - y) > 1e-9
    return Pose(x, y, wrap_angle(theta)), Velocity(0.0, w) if stopped else command


@pytest.mark.parametrize("a_max", [math.inf, 0.8])
@pytest.mark.parametrize("origin", [(0.0, 0.0, 0.0), (-1.2, 0.7, 0.4)])
def test_the_move_kernel_on_a_batch_of_one_is_the_plain_move(a_max, origin):
    """The simulator's agents run the move kernel (the batched game's) on a batch of one:
    the plain-Python move, bit for bit, through walls, ramps and turns."""
    grid = walled_room(origin)
    body = Body(0.2, 0.5, 1.8, a_max, 2 * a_max)
    context = Context(grid, body, EVADER, Camera(), DT, 1.0)
    sim = GridSimulator(GridSimulator.Config(), context, np.random.default_rng(0))
    start = Pose(*grid.cell_to_world(10, 10), 0.3)
    sim.reset((start,), (Pose(*grid.cell_to_world(50, 70)),))
    blocked = inflate(grid, body.radius)
    pose, velocity = start, Velocity(0.0, 0.0)
    rng = np.random.default_rng(4)
    for _ in range(400):  # long enough to run into walls
        cmd = Velocity(rng.uniform(-0.7, 0.7), rng.uniform(-2.5, 2.5))
        pose, velocity = _move_reference(grid, blocked, body, pose, velocity, cmd, DT)
        sim.step((cmd,), (Velocity(),), DT)
        assert sim.poses[0][0] == pose


def test_start_inside_an_obstacle_is_refused():
    sim = simulator(walled_room())
    with pytest.raises(ValueError, match="inside an obstacle"):
        sim.reset((Pose(0.1, 1.0),), (Pose(3.5, 2.5),))


def test_infinite_acceleration_takes_the_command_exactly():
    """Not current + (command - current), which can differ in the last ulp: infinite
    limits (the default) must give today's games bit for bit."""
    current, cmd = Velocity(0.1, -0.7), Velocity(0.3, 0.2)
    assert (0.1 + (0.3 - 0.1), -0.7 + (0.2 + 0.7)) != (0.3, 0.2)  # why it matters
    assert accelerate(current, cmd, PURSUER, DT) == cmd


def test_finite_acceleration_ramps_towards_the_command():
    body = Body(0.2, 0.5, 1.8, a_max=1.0, alpha_max=2.0)
    ramped = accelerate(Velocity(0.1, 0.5), Velocity(0.5, -1.8), body, DT)
    assert ramped == Velocity(pytest.approx(0.2), pytest.approx(0.3))
    assert accelerate(Velocity(0.1, 0.5), Velocity(0.15, 0.45), body, DT) == Velocity(0.15, 0.45)


def test_a_wall_stops_the_forward_speed_and_keeps_the_turn_rate():
    body = Body(0.2, 0.5, 1.8, a_max=1.0, alpha_max=2.0)
    context = Context(walled_room(), body, EVADER, Camera(), DT, 1.0)
    sim = GridSimulator(GridSimulator.Config(), context, np.random.default_rng(0))
    sim.reset((Pose(1.0, 1.5, 0.0),), (Pose(3.5, 2.5),))  # heading at the pillar's left face
    for _ in range(40):
        sim.step((Velocity(0.5, 0.0),), (Velocity(),), DT)
    assert sim._pursuers[0].velocity == Velocity(0.0, 0.0)
    at_wall = sim.poses[0][0]
    sim.step((Velocity(0.5, 1.0),), (Velocity(),), DT)  # still pressed against the wall, turning
    assert sim._pursuers[0].velocity == Velocity(0.0, pytest.approx(0.2))
    assert sim.poses[0][0].theta == pytest.approx(at_wall.theta + 0.2 * DT)


def test_step_one_moves_one_agent_and_pauses_the_other():
    body = Body(0.2, 0.5, 1.8, a_max=1.0, alpha_max=2.0)
    context = Context(walled_room(), body, body, Camera(), DT, 1.0)
    sim = GridSimulator(GridSimulator.Config(), context, np.random.default_rng(0))
    sim.reset((Pose(1.0, 1.0, 0.0),), (Pose(3.0, 2.5, 0.0),))
    sim.step((Velocity(0.5, 0.0),), (Velocity(0.5, 0.0),), DT)
    ((pursuer,), (evader,)), paused = sim.poses, sim._evaders[0].velocity
    sim.step_one("pursuer", (Velocity(0.5, 0.0),), DT)
    assert sim.poses[1][0] == evader and sim._evaders[0].velocity == paused
    assert sim.poses[0][0].x > pursuer.x
    sim.step_one("evader", (Velocity(0.5, 0.0),), DT)
    assert sim.poses[1][0].x == pytest.approx(evader.x + 0.2 * DT)  # resumed from its kept 0.1 m/s
