"""Random behaviour, the paper's baseline for both agents (paper, Sec. "Random Pursuer
and Evader"), in the two readings of the paper's text that ``model`` chooses between.

- ``waypoint`` (:class:`Wanderer`): "we make use of move_base package for path planning
  given a goal location to either the pursuer or evader", and the random pursuer "wanders
  on the map with the hope of detecting an evader". An agent picks a goal uniformly at
  random among the free cells it can reach, plans a path to it
  (:class:`pegame.navigation.Planner`) and follows it; it picks a new goal when it arrives
  or when it has been stuck (moved less than ``stuck_distance`` m over a decision period)
  for ``stuck_decisions`` decisions in a row.
- ``action`` (:class:`RandomActions`): Fig. 1, "The transparent arrows represent the
  possible random actions the agents can take", in a game "played in discrete intervals of
  1 unit each" by nodes "with a rate of 1Hz". At each decision the agent draws one action,
  a unicycle command (the paper's agents are unicycles that "cannot translate sideways"):
  forward speed v uniform in [0, v_max] (m/s) and turn rate w uniform in [-w_max, w_max]
  (rad/s) of its body, and holds it until the next decision (an arc of one decision
  period, an arrow of Fig. 1); a wall stops it there until the next draw.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from pegame.api import Context, EvaderObservation, PursuerObservation, Strategy
from pegame.errors import require
from pegame.grid import OccupancyGrid
from pegame.navigation import PathFollower, Planner
from pegame.types import STOP, Body, Plan, Pose, Velocity

#: the random agents' ``model`` values, in the order of the module docstring
MODELS = ("waypoint", "action")


class Wanderer:
    """Random goal navigation for one agent on ``grid`` with ``body``, drawing from ``rng``."""

    def __init__(
        self,
        grid: OccupancyGrid,
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


class RandomActions:
    """A random action at each decision for an agent with ``body``, drawing from ``rng``:
    (v, w) uniform in [0, v_max] x [-w_max, w_max], held until the next decision."""

    def __init__(self, body: Body, rng: np.random.Generator) -> None:
        self.body = body
        self.rng = rng
        self.action = STOP

    def reset(self, pose: Pose) -> None:
        self.action = STOP

    def decide(self, pose: Pose) -> Plan:
        v = float(self.rng.uniform(0.0, self.body.v_max))
        w = float(self.rng.uniform(-self.body.w_max, self.body.w_max))
        self.action = Velocity(v, w)
        return Plan(info={"action_v": v, "action_w": w})

    def control(self, pose: Pose) -> Velocity:
        return self.action


def random_agent(
    model: str, grid: OccupancyGrid, body: Body, rng: np.random.Generator
) -> Wanderer | RandomActions:
    """The random behaviour ``model`` (one of :data:`MODELS`) for one agent."""
    return Wanderer(grid, body, rng) if model == "waypoint" else RandomActions(body, rng)


@dataclass
class RandomOptions:
    """The ``random`` strategies' parameter (on top of the role's body parameters)."""

    model: str = "waypoint"  # waypoint: random reachable goals; action: random (v, w) actions

    def check(self, role: str) -> None:
        """``model`` is one of :data:`MODELS` (for either role)."""
        require(self.model in MODELS, "model", " or ".join(MODELS), self.model)


class RandomStrategy(Strategy[PursuerObservation | EvaderObservation]):
    """The paper's random agent for either role (paper, Sec. "Random Pursuer and Evader"),
    ``model`` as the module docstring describes; it ignores what it sees. The ``random``
    pursuer and evader are this behaviour (:func:`pegame.roles.for_role`)."""

    description = (
        "Baseline: random reachable goals (model=waypoint) or random (v, w) actions (model=action)."
    )
    #: 'pursuer' or 'evader', set by :func:`pegame.roles.for_role`
    role: str

    def __init__(self, config: Any, context: Context, rng: np.random.Generator) -> None:
        super().__init__(config, context, rng)
        self.wanderer = random_agent(config.model, context.grid, getattr(context, self.role), rng)

    def reset(self, pose: Pose) -> None:
        self.wanderer.reset(pose)

    def decide(self, observation: PursuerObservation | EvaderObservation) -> Plan:
        return self.wanderer.decide(observation.pose)

    def control(self, observation: PursuerObservation | EvaderObservation) -> Velocity:
        return self.wanderer.control(observation.pose)
