"""Property-based tests of the move of the grid simulator (pegame.sims.grid) on generated
commands, bodies, poses and grids: saturation and acceleration keep to the limits, the
unicycle follows the exact arc, the swept collision kernel equals its reference, and a
moving agent keeps to its limits, never enters an inflated cell and moves along the arc
in free space. Units: metres, seconds and radians in the map frame."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from pegame.api import Context
from pegame.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from pegame.navigation import inflate
from pegame.sims.grid import (
    GridSimulator,
    _sweep,
    _sweep_reference,
    accelerate,
    saturate,
    unicycle,
)
from pegame.types import Body, Camera, Pose, Velocity, wrap_angle

#: commands beyond any body's limits, zero and near-zero turn rates among them
COMMANDS = st.builds(
    Velocity,
    st.floats(-3.0, 3.0),
    st.just(0.0) | st.floats(-1e-8, 1e-8) | st.floats(-6.0, 6.0),
)
#: bodies of the paper's size, with or without acceleration limits (m/s^2, rad/s^2)
BODIES = st.builds(
    Body,
    radius=st.floats(0.05, 0.3),
    v_max=st.floats(0.1, 1.5),
    w_max=st.floats(0.1, 3.0),
    a_max=st.just(math.inf) | st.floats(0.1, 5.0),
    alpha_max=st.just(math.inf) | st.floats(0.1, 10.0),
)
POSES = st.builds(Pose, st.floats(-5.0, 5.0), st.floats(-5.0, 5.0), st.floats(-4.0, 4.0))
DTS = st.sampled_from([0.1, 0.05]) | st.floats(0.001, 0.5)


@settings(max_examples=200)
@given(COMMANDS, BODIES, COMMANDS, DTS)
def test_saturate_and_accelerate_keep_to_the_limits(
    cmd: Velocity, body: Body, current: Velocity, dt: float
) -> None:
    saturated = saturate(cmd, body)
    assert abs(saturated.v) <= body.v_max and abs(saturated.w) <= body.w_max
    assert saturated.v * cmd.v >= 0.0 and saturated.w * cmd.w >= 0.0  # the same direction
    if abs(cmd.v) <= body.v_max and abs(cmd.w) <= body.w_max:
        assert saturated == cmd
    reached = accelerate(current, saturated, body, dt)
    for now, target, then, limit in [
        (current.v, saturated.v, reached.v, body.a_max * dt),
        (current.w, saturated.w, reached.w, body.alpha_max * dt),
    ]:
        if math.isinf(limit):
            assert then == target
        else:
            # |clamp(target - now, limit)| <= limit; adding it to now rounds by half an ulp.
            assert abs(then - now) <= limit + 2 * math.ulp(max(abs(now), abs(then)))
            assert abs(then - target) <= abs(now - target)  # towards the command
            if abs(target - now) <= limit:
                assert math.isclose(then, target, abs_tol=1e-12)  # and there when in reach


#: Gauss-Legendre nodes (on [-1, 1]) and weights: exact for the arc's integrand, smooth
#: over a turn of at most 3 rad, to round-off
NODES, WEIGHTS = np.polynomial.legendre.leggauss(20)


def arc_by_quadrature(pose: Pose, cmd: Velocity, dt: float) -> tuple[float, float]:
    """Plain reference of the arc's end: the integral of v (cos, sin)(theta + w t) over
    t in [0, dt] by 20-point Gauss-Legendre quadrature (m)."""
    t = 0.5 * dt * (NODES + 1.0)
    heading = pose.theta + cmd.w * t
    scale = 0.5 * dt * cmd.v
    dx, dy = scale * WEIGHTS @ np.cos(heading), scale * WEIGHTS @ np.sin(heading)
    return pose.x + float(dx), pose.y + float(dy)


def arc_error_bound(pose: Pose, cmd: Velocity, dt: float) -> float:
    """The arc's known error (m) on top of round-off, kept so that games stay bit for bit
    those of the committed studies (unicycle's docstring). From w = 1e-9 rad/s up, the
    difference of sines times v / w carries each sine's rounding (half an ulp of 1) and
    that of the end heading theta + w dt (half an ulp of it, through the sine), both scaled
    by |v / w|; below, the straight line misses the arc by at most |v| dt^2 |w| / 2."""
    if abs(cmd.w) >= 1e-9:
        heading_ulp = math.ulp(abs(pose.theta) + abs(cmd.w * dt))
        return abs(cmd.v / cmd.w) * 2.0 * (2.3e-16 + heading_ulp)
    return 0.5 * abs(cmd.v) * dt * dt * abs(cmd.w)


@settings(max_examples=300)
@example(Pose(0.0, 0.0, 1.0), Velocity(1.0, 2.254773023057906e-09), 0.1)  # see below
@given(POSES, COMMANDS, DTS)
def test_unicycle_follows_the_exact_arc(pose: Pose, cmd: Velocity, dt: float) -> None:
    """To 1e-12 m plus the known error bound. The example: a turn rate just above
    1e-9 rad/s, where the difference of sines loses 2.2e-8 m (0.1 m straight ahead comes
    out 0.09999997768 m long), within the bound there."""
    moved = unicycle(pose, cmd, dt)
    assert abs(wrap_angle(moved.theta - pose.theta - cmd.w * dt)) <= 1e-12
    x, y = arc_by_quadrature(pose, cmd, dt)
    assert math.hypot(moved.x - x, moved.y - y) <= 1e-12 + arc_error_bound(pose, cmd, dt)


@settings(max_examples=100)
@given(POSES, COMMANDS, DTS, DTS)
def test_unicycle_arcs_compose(pose: Pose, cmd: Velocity, first: float, second: float) -> None:
    """Holding a command for two periods is one period of their sum (to 1e-9 m, plus the
    known error bound of each of the three arcs)."""
    twice = unicycle(unicycle(pose, cmd, first), cmd, second)
    once = unicycle(pose, cmd, first + second)
    slack = 1e-9 + 3 * arc_error_bound(pose, cmd, first + second)
    assert math.isclose(twice.x, once.x, abs_tol=slack)
    assert math.isclose(twice.y, once.y, abs_tol=slack)
    assert abs(wrap_angle(twice.theta - once.theta)) <= 1e-9


@st.composite
def rooms(draw: st.DrawFn) -> OccupancyGrid:
    """Up to 24 x 24 cells of 5 or 10 cm, mostly free, any origin."""
    shape = (draw(st.integers(4, 24)), draw(st.integers(4, 24)))
    cells = st.sampled_from([FREE] * 12 + [OCCUPIED, UNKNOWN])
    yaw = draw(st.just(0.0) | st.floats(-math.pi, math.pi))
    origin = (draw(st.floats(-1.0, 1.0)), draw(st.floats(-1.0, 1.0)), yaw)
    data = draw(arrays(np.int8, shape, elements=cells))
    return OccupancyGrid(data, draw(st.sampled_from([0.05, 0.1])), origin)


def point_on(grid: OccupancyGrid, u: float, v: float) -> tuple[float, float]:
    """The map point (m) at (u, v) cells along the grid's columns and rows."""
    c, s = grid.frame.cos_yaw, grid.frame.sin_yaw
    u, v = u * grid.resolution, v * grid.resolution
    return grid.origin[0] + c * u - s * v, grid.origin[1] + s * u + c * v


#: grid coordinates (cells) on and off a room, often on cell edges and corners
CELL_COORDINATES = st.integers(-2, 52).map(lambda k: 0.5 * k) | st.floats(-2.0, 26.0)


@settings(max_examples=100)
@given(rooms(), st.floats(0.0, 0.3), CELL_COORDINATES, CELL_COORDINATES, POSES, st.integers(1, 20))
def test_sweep_kernel_equals_reference(
    grid: OccupancyGrid, radius: float, u: float, v: float, towards: Pose, n: int
) -> None:
    blocked = inflate(grid, radius)
    sx, sy = point_on(grid, u, v)
    tx, ty = sx + 0.1 * towards.x, sy + 0.1 * towards.y
    fast = _sweep(blocked, sx, sy, tx, ty, n, grid.kernel_frame)
    assert fast == _sweep_reference(grid, blocked, sx, sy, tx, ty, n)


def simulator(grid: OccupancyGrid, body: Body, dt: float) -> GridSimulator:
    """A grid simulator whose pursuer and evader both have ``body``."""
    context = Context(grid, body, body, Camera(), dt, 1.0)
    return GridSimulator(GridSimulator.Config(), context, np.random.default_rng(0))


@settings(max_examples=60)
@given(rooms(), BODIES, DTS, st.data())
def test_moves_keep_to_the_limits_and_out_of_inflated_cells(
    grid: OccupancyGrid, body: Body, dt: float, data: st.DataObject
) -> None:
    blocked = inflate(grid, body.radius)
    free = np.argwhere(~blocked)
    assume(free.size > 0)
    row, col = free[data.draw(st.integers(0, len(free) - 1))]
    start = Pose(*point_on(grid, col + 0.5, row + 0.5), data.draw(st.floats(-4.0, 4.0)))
    sim = simulator(grid, body, dt)
    sim.reset((start,), (start,))
    for cmd in data.draw(st.lists(COMMANDS, min_size=1, max_size=30)):
        before = sim.poses[0][0]
        sim.step_one("pursuer", (cmd,), dt)
        after = sim.poses[0][0]
        cell = grid.world_to_cell(after.x, after.y)
        assert grid.contains(*cell) and not blocked[cell]
        bound = arc_error_bound(before, saturate(cmd, body), dt)  # the arc's known error
        assert before.distance_to(after) <= body.v_max * dt * (1 + 1e-9) + bound
        assert abs(wrap_angle(after.theta - before.theta)) <= body.w_max * dt * (1 + 1e-9)


@settings(max_examples=150)
@given(BODIES, COMMANDS, DTS, st.tuples(st.floats(2.5, 3.5), st.floats(2.5, 3.5), st.floats(-4, 4)))
def test_free_motion_is_the_unicycle_arc_of_the_saturated_command(
    body: Body, cmd: Velocity, dt: float, pose: tuple[float, float, float]
) -> None:
    """Far from any wall, with no acceleration limits: the agent ends where the arc does,
    to round-off (the sweep's last sample is start + (end - start) n / n)."""
    body = Body(body.radius, body.v_max, body.w_max)
    grid = OccupancyGrid(np.zeros((60, 60), np.int8), 0.1)
    start = Pose(*pose)  # 2.5 m from the walls, beyond any move (at most 0.75 m)
    sim = simulator(grid, body, dt)
    sim.reset((start,), (start,))
    sim.step_one("pursuer", (cmd,), dt)
    expected = unicycle(start, saturate(cmd, body), dt)
    moved = sim.poses[0][0]
    assert moved.theta == expected.theta
    assert math.isclose(moved.x, expected.x, abs_tol=1e-12)
    assert math.isclose(moved.y, expected.y, abs_tol=1e-12)
