"""The built-in 2D simulator: unicycles on the occupancy grid (one pursuer and one evader, or
teams of them).

State x = (x, y, theta) in the map frame and the current velocity (v, w); a command (v, w)
is saturated to the agent's limits, its change from the current velocity is limited to
``a_max * dt`` and ``alpha_max * dt`` (each step; infinite limits, the default, take the
command at once) and the result is integrated exactly over dt (arc motion). An agent never enters a cell of the
grid inflated by its radius (:func:`pegame.navigation.inflate`): a move that would enter
one is cut at the last free sample, so the agent stops at the wall and may still turn.
The agents do not collide with each other (the paper's agents never need to touch; the
spawn starts them apart).

An agent's move is one numba kernel (:func:`move`: saturation, acceleration limits, the
arc of :func:`arc`, the swept collision check :func:`_sweep`) on a batch of agents' state
arrays: each agent of this simulator runs it on a batch of one, the batched game
(:mod:`pegame.vector`) on every game's pursuer and evader. ``_sweep_reference`` is the
plain-Python loop the sweep reproduces, which the tests compare it against.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from operator import attrgetter

import numpy as np
from numba import njit

from pegame.api import Context, Simulator
from pegame.grid import OccupancyGrid, cell_blocked, point_cell
from pegame.grid.occupancy import RESOLUTION
from pegame.navigation import shared_inflation
from pegame.numerics import ceil_of_hypot, hypot, wrap_angle
from pegame.types import STOP, Body, Pose, SensorFrame, Velocity, clamp

#: columns of the bodies' rows the move kernel reads: radius (m), v_max (m/s), w_max
#: (rad/s), a_max (m/s^2), alpha_max (rad/s^2)
RADIUS, V_MAX, W_MAX, A_MAX, ALPHA_MAX = range(5)


def body_rows(*bodies: Body) -> np.ndarray:
    """The (A, 5) float64 rows of :func:`move`'s ``bodies``, one per body."""
    rows = [[b.radius, b.v_max, b.w_max, b.a_max, b.alpha_max] for b in bodies]
    return np.array(rows, dtype=np.float64)


def saturate(cmd: Velocity, body: Body) -> Velocity:
    """Clip a command to |v| <= v_max (m/s) and |w| <= w_max (rad/s)."""
    return Velocity(clamp(cmd.v, body.v_max), clamp(cmd.w, body.w_max))


def accelerate(current: Velocity, cmd: Velocity, body: Body, dt: float) -> Velocity:
    """The velocity reached after dt seconds of driving from ``current`` towards the
    (saturated) ``cmd`` at most ``body.a_max`` (m/s^2) and ``body.alpha_max`` (rad/s^2);
    ``cmd`` itself, untouched, for infinite limits."""
    return Velocity(
        _ramp(current.v, cmd.v, body.a_max * dt), _ramp(current.w, cmd.w, body.alpha_max * dt)
    )


@njit(cache=True, inline="always")
def _clamp(value: float, limit: float) -> float:
    """:func:`pegame.types.clamp`: min(max(value, -limit), limit) with Python's min/max."""
    low = value if value > -limit else -limit
    return low if low < limit else limit


@njit(cache=True, inline="always")
def _ramp(current: float, target: float, limit: float) -> float:
    """``target``, or ``current`` moved towards it by at most ``limit``."""
    if math.isinf(limit):
        return target  # no limit: exactly today's command, not current + (target - current)
    return current + _clamp(target - current, limit)


@njit(cache=True, inline="always")
def arc(
    x: float, y: float, theta: float, v: float, w: float, dt: float
) -> tuple[float, float, float]:
    """The end pose (x, y, theta) (m, rad in (-pi, pi]; map frame) of the arc of (v, w)
    held for ``dt`` s from (x, y, theta): :func:`unicycle`."""
    end = theta + w * dt
    if abs(w) < 1e-9:
        dx, dy = v * dt * math.cos(theta), v * dt * math.sin(theta)
    else:
        radius = v / w
        dx = radius * (math.sin(end) - math.sin(theta))
        dy = -radius * (math.cos(end) - math.cos(theta))
    return x + dx, y + dy, wrap_angle(end)


def unicycle(pose: Pose, cmd: Velocity, dt: float) -> Pose:
    """Exact unicycle integration of (v, w) held for dt seconds from ``pose``: the circular
    arc of radius v / w (a straight line below 1e-9 rad/s).

    Known limit, kept so that games stay bit for bit those of the committed studies: the
    difference of sines times v / w loses digits to cancellation when w is just above
    1e-9 rad/s: the sines' and the end heading's rounding, times |v / w| (2.2e-8 m on a
    0.1 m step at w = 2.3e-9 rad/s; tests/sims/test_grid_properties.py derives the bound
    and holds the move to it). The
    chord form v dt sin(h) / h along theta + h, h = w dt / 2, is accurate for every w,
    and changes the last bits of every turning move: it belongs to a release that may
    change games.
    """
    return Pose(*arc(pose.x, pose.y, pose.theta, cmd.v, cmd.w, dt))


@njit(cache=True)
def _sweep(
    blocked: np.ndarray,
    sx: float,
    sy: float,
    tx: float,
    ty: float,
    n: int,
    frame: tuple | np.ndarray,
) -> tuple[float, float]:
    """The last of the points k/n along the chord from (sx, sy) to (tx, ty) (m, map frame),
    k = 1..n, before the first one whose cell is off the grid or True in ``blocked``;
    (sx, sy) when that is the first. ``frame``: the grid's :class:`pegame.grid.GridFrame`."""
    x, y = sx, sy
    for k in range(1, n + 1):
        nx = sx + (tx - sx) * k / n
        ny = sy + (ty - sy) * k / n
        row, col = point_cell(nx, ny, frame)
        if cell_blocked(blocked, row, col):
            break
        x, y = nx, ny
    return x, y


@njit(cache=True, inline="always")
def move(
    blocked: np.ndarray,
    frame: np.ndarray,
    bodies: np.ndarray,
    poses: np.ndarray,
    velocities: np.ndarray,
    k: int,
    agent: int,
    v: float,
    w: float,
    dt: float,
) -> tuple[float, float, float]:
    """Move ``agent`` of batch entry ``k`` by the command (v m/s, w rad/s) for ``dt`` s:
    saturated to its body's limits, its change from the current velocity limited by
    a_max and alpha_max (the velocity kept only with a finite limit), the arc
    (:func:`arc`), cut at the last free sample of the chord at half-cell spacing
    (:func:`_sweep` on ``blocked``, the agent's collision mask; an agent stopped by a wall
    loses its forward speed and keeps its turn rate). ``frame``: the grid's kernel_frame
    as float64; bodies (A, 5): columns RADIUS..ALPHA_MAX per agent; poses (B, A, 3) (x, y,
    theta) and velocities (B, A, 2) (v, w), updated in place. Returns the new pose.
    Elements are read by index, not through row views, and arrays are passed, not
    NamedTuples: the batched game inlines it per game, where a view, and an inlined
    function given a NamedTuple, cost a reference count per array."""
    x0, y0, theta0 = poses[k, agent, 0], poses[k, agent, 1], poses[k, agent, 2]
    v = _clamp(v, bodies[agent, V_MAX])
    w = _clamp(w, bodies[agent, W_MAX])
    a_max, alpha_max = bodies[agent, A_MAX], bodies[agent, ALPHA_MAX]
    limited = not (math.isinf(a_max) and math.isinf(alpha_max))
    if limited:
        v = _ramp(velocities[k, agent, 0], v, a_max * dt)
        w = _ramp(velocities[k, agent, 1], w, alpha_max * dt)
    tx, ty, theta = arc(x0, y0, theta0, v, w, dt)
    n = max(1, ceil_of_hypot(tx - x0, ty - y0, frame[RESOLUTION]))
    x, y = _sweep(blocked, x0, y0, tx, ty, n, frame)
    poses[k, agent, 0], poses[k, agent, 1], poses[k, agent, 2] = x, y, theta
    if limited:
        stopped = hypot(tx - x, ty - y) > 1e-9
        velocities[k, agent, 0] = 0.0 if stopped else v
        velocities[k, agent, 1] = w
    return x, y, theta


def _sweep_reference(
    grid: OccupancyGrid,
    blocked: np.ndarray,
    sx: float,
    sy: float,
    tx: float,
    ty: float,
    n: int,
) -> tuple[float, float]:
    """Plain-Python reference of :func:`_sweep` on ``grid``."""
    x, y = sx, sy
    for k in range(1, n + 1):
        nx = sx + (tx - sx) * k / n
        ny = sy + (ty - sy) * k / n
        row, col = grid.world_to_cell(nx, ny)
        if not grid.contains(row, col) or blocked[row, col]:
            break
        x, y = nx, ny
    return x, y


class _Agent:
    """One agent's body, its collision mask (shared, read-only) and its pose: a batch of
    one of :func:`move`'s arrays."""

    def __init__(self, grid: OccupancyGrid, body: Body) -> None:
        self.grid = grid
        self.body = body
        self.blocked = shared_inflation(grid, body.radius)
        self.frame = grid.kernel_frame
        self._frame = np.array(grid.kernel_frame, dtype=np.float64)
        self._bodies = body_rows(body)
        self._poses = np.zeros((1, 1, 3))
        self._velocities = np.zeros((1, 1, 2))
        self._pose = Pose(0.0, 0.0, 0.0)
        # Without acceleration limits the command is the velocity: no state to keep.
        self.limited = not (math.isinf(body.a_max) and math.isinf(body.alpha_max))

    @property
    def pose(self) -> Pose:
        return self._pose

    @pose.setter
    def pose(self, pose: Pose) -> None:
        self._pose = pose
        self._poses[0, 0] = (pose.x, pose.y, pose.theta)

    @property
    def velocity(self) -> Velocity:
        """The current velocity (kept with acceleration limits only)."""
        v, w = self._velocities[0, 0].tolist()
        return Velocity(v, w)

    @velocity.setter
    def velocity(self, velocity: Velocity) -> None:
        self._velocities[0, 0] = (velocity.v, velocity.w)

    def collides(self, x: float, y: float) -> bool:
        return cell_blocked(self.blocked, *point_cell(x, y, self.frame))

    def move(self, cmd: Velocity, dt: float) -> None:
        x, y, theta = move(
            self.blocked,
            self._frame,
            self._bodies,
            self._poses,
            self._velocities,
            0,
            0,
            cmd.v,
            cmd.w,
            dt,
        )
        self._pose = Pose(x, y, theta)


#: an agent's pose, read in C by map
_POSE = attrgetter("pose")


class GridSimulator(Simulator):
    """Kinematic unicycles on the occupancy grid, stopped by walls; the camera frame
    carries the ground-truth evader pose for the oracle detector. Plays teams: N
    pursuers and M evaders, each pursuer with its own camera frame."""

    description = "2D kinematic unicycles on the occupancy grid; agents stop at walls."
    teams = True

    @dataclass
    class Config:
        """No parameters: the bodies come from the pursuer and evader configs."""

    def __init__(self, config: Config, context: Context, rng: np.random.Generator) -> None:
        super().__init__(config, context, rng)
        self._pursuers = [_Agent(context.grid, context.pursuer)]
        self._evaders = [_Agent(context.grid, context.evader)]

    def reset(self, pursuers: Sequence[Pose], evaders: Sequence[Pose]) -> None:
        context = self.context
        for agents, poses, body in (
            (self._pursuers, pursuers, context.pursuer),
            (self._evaders, evaders, context.evader),
        ):
            while len(agents) < len(poses):  # the masks are shared: an agent costs little
                agents.append(_Agent(context.grid, body))
            del agents[len(poses) :]
            for agent, pose in zip(agents, poses):
                if agent.collides(pose.x, pose.y):
                    raise ValueError(
                        f"start pose {pose} is inside an obstacle for radius {agent.body.radius} m"
                    )
                agent.pose, agent.velocity = pose, STOP

    def step(
        self, pursuer_cmds: Sequence[Velocity], evader_cmds: Sequence[Velocity], dt: float
    ) -> None:
        for agent, cmd in zip(self._pursuers, pursuer_cmds):
            agent.move(cmd, dt)
        for agent, cmd in zip(self._evaders, evader_cmds):
            agent.move(cmd, dt)

    def step_one(self, role: str, cmds: Sequence[Velocity], dt: float) -> None:
        for agent, cmd in zip(self._pursuers if role == "pursuer" else self._evaders, cmds):
            agent.move(cmd, dt)

    @property
    def poses(self) -> tuple[tuple[Pose, ...], tuple[Pose, ...]]:
        return tuple(map(_POSE, self._pursuers)), tuple(map(_POSE, self._evaders))

    def sense(self, time: float) -> tuple[SensorFrame, ...]:
        if len(self._pursuers) == 1 and len(self._evaders) == 1:  # a 1v1 frame: no list
            pose, evader = self._pursuers[0].pose, self._evaders[0].pose
            return (SensorFrame(time=time, camera_pose=pose, evader_truth=evader),)
        evaders = tuple(map(_POSE, self._evaders))
        return tuple(
            [
                SensorFrame(
                    time=time, camera_pose=a.pose, evader_truth=evaders[0], evaders_truth=evaders
                )
                for a in self._pursuers
            ]
        )
