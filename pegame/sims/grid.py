"""The built-in 2D simulator: two unicycles on the occupancy grid.

State x = (x, y, theta) in the map frame; a command (v, w) is saturated to the agent's
limits and integrated exactly over dt (arc motion). An agent never enters a cell of the
grid inflated by its radius (:func:`pegame.navigation.inflate`): a move that would enter
one is cut at the last free sample, so the agent stops at the wall and may still turn.
The agents do not collide with each other (the paper's agents never need to touch).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pegame.api import Body, Pose, SensorFrame, Simulator, Velocity, wrap_angle
from pegame.navigation import inflate


def saturate(cmd: Velocity, body: Body) -> Velocity:
    """Clip a command to |v| <= v_max (m/s) and |w| <= w_max (rad/s)."""
    return Velocity(
        float(np.clip(cmd.v, -body.v_max, body.v_max)), float(np.clip(cmd.w, -body.w_max, body.w_max))
    )


def unicycle(pose: Pose, cmd: Velocity, dt: float) -> Pose:
    """Exact unicycle integration of (v, w) held for dt seconds from ``pose``."""
    theta = pose.theta + cmd.w * dt
    if abs(cmd.w) < 1e-9:
        dx, dy = cmd.v * dt * math.cos(pose.theta), cmd.v * dt * math.sin(pose.theta)
    else:
        radius = cmd.v / cmd.w
        dx = radius * (math.sin(theta) - math.sin(pose.theta))
        dy = -radius * (math.cos(theta) - math.cos(pose.theta))
    return Pose(pose.x + dx, pose.y + dy, wrap_angle(theta))


class _Agent:
    """One agent's body, its collision mask and its pose."""

    def __init__(self, grid, body: Body) -> None:
        self.grid = grid
        self.body = body
        self.blocked = inflate(grid, body.radius)
        self.pose = Pose(0.0, 0.0, 0.0)

    def collides(self, x: float, y: float) -> bool:
        row, col = self.grid.world_to_cell(x, y)
        return not self.grid.contains(row, col) or bool(self.blocked[row, col])

    def move(self, cmd: Velocity, dt: float) -> None:
        target = unicycle(self.pose, saturate(cmd, self.body), dt)
        # Sample the chord at half-cell spacing so that no move skips over a thin wall.
        start = self.pose
        n = max(1, math.ceil(2 * start.distance_to(target) / self.grid.resolution))
        x, y = start.x, start.y
        for k in range(1, n + 1):
            nx = start.x + (target.x - start.x) * k / n
            ny = start.y + (target.y - start.y) * k / n
            if self.collides(nx, ny):
                break
            x, y = nx, ny
        self.pose = Pose(x, y, target.theta)


class GridSimulator(Simulator):
    """Kinematic unicycles on the occupancy grid, stopped by walls; the camera frame
    carries the ground-truth evader pose for the oracle detector."""

    description = "2D kinematic unicycles on the occupancy grid; agents stop at walls."

    @dataclass
    class Config:
        """No parameters: the bodies come from the pursuer and evader configs."""

    def __init__(self, config, context, rng) -> None:
        super().__init__(config, context, rng)
        self._pursuer = _Agent(context.grid, context.pursuer)
        self._evader = _Agent(context.grid, context.evader)

    def reset(self, pursuer: Pose, evader: Pose) -> None:
        for agent, pose in ((self._pursuer, pursuer), (self._evader, evader)):
            if agent.collides(pose.x, pose.y):
                raise ValueError(f"start pose {pose} is inside an obstacle for radius {agent.body.radius} m")
            agent.pose = pose

    def step(self, pursuer_cmd: Velocity, evader_cmd: Velocity, dt: float) -> None:
        self._pursuer.move(pursuer_cmd, dt)
        self._evader.move(evader_cmd, dt)

    @property
    def poses(self) -> tuple[Pose, Pose]:
        return self._pursuer.pose, self._evader.pose

    def sense(self, time: float) -> SensorFrame:
        return SensorFrame(time=time, camera_pose=self._pursuer.pose, evader_truth=self._evader.pose)
