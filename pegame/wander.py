"""Random navigation, the paper's baseline behaviour for both agents.

An agent picks a goal uniformly at random among the free cells it can reach, plans a path
to it (:class:`pegame.navigation.Planner`) and follows it; it picks a new goal when it
arrives or when it has been stuck (moved less than ``stuck_distance`` m over a decision
period) for ``stuck_decisions`` decisions in a row.
"""

from __future__ import annotations

import numpy as np

from pegame.navigation import PathFollower, Planner
from pegame.types import STOP, Body, Plan, Pose, Velocity


class Wanderer:
    """Random goal navigation for one agent on ``grid`` with ``body``, drawing from ``rng``."""

    def __init__(
        self,
        grid,
        body: Body,
        rng: np.random.Generator,
        stuck_distance: float = 0.05,
        stuck_decisions: int = 2,
    ) -> None:
        self.grid = grid
        self.rng = rng
        self.planner = Planner.shared(grid, body.radius)
        self.follower = PathFollower(body)
        self.stuck_distance = stuck_distance
        self.stuck_decisions = stuck_decisions
        self.plan = Plan()
        self._last: Pose | None = None
        self._stuck = 0

    def reset(self, pose: Pose) -> None:
        self.plan, self._last, self._stuck = Plan(), None, 0
        self.follower.set_path(np.zeros((0, 2)))

    def decide(self, pose: Pose) -> Plan:
        """Keep the current goal unless arrived or stuck; otherwise draw a new one."""
        moved = self._last.distance_to(pose) if self._last is not None else np.inf
        self._stuck = self._stuck + 1 if moved < self.stuck_distance else 0
        self._last = pose
        if self.plan.goal is None or self.follower.done or self._stuck >= self.stuck_decisions:
            self.plan = self._new_plan(pose)
            self._stuck = 0
        return self.plan

    def control(self, pose: Pose) -> Velocity:
        return self.follower.command(pose) if self.plan.goal is not None else STOP

    def _new_plan(self, pose: Pose) -> Plan:
        rows, cols = np.nonzero(self.planner.reachable((pose.x, pose.y)))
        if rows.size == 0:
            self.follower.set_path(np.zeros((0, 2)))
            return Plan()
        k = int(self.rng.integers(rows.size))
        goal = self.grid.cell_to_world(rows[k], cols[k])
        result = self.planner.plan((pose.x, pose.y), goal)
        self.follower.set_path(result.path)
        return Plan(goal=goal, path=result.path) if result.reachable else Plan()
