"""The paper's random pursuer (baseline R-*): wanders to random reachable goals and
ignores what it sees (paper, Sec. "Random Pursuer and Evader")."""

from __future__ import annotations

from pegame.api import Pursuer, PursuerObservation
from pegame.types import Plan, Velocity
from pegame.wander import Wanderer


class RandomPursuer(Pursuer):
    """Drives to uniformly random reachable free goals, a new one on arrival or when stuck."""

    description = "Baseline: drives to uniformly random reachable free goals."

    def __init__(self, config, context, rng) -> None:
        super().__init__(config, context, rng)
        self.wanderer = Wanderer(context.grid, context.pursuer, rng)

    def reset(self, pose) -> None:
        self.wanderer.reset(pose)

    def decide(self, observation: PursuerObservation) -> Plan:
        return self.wanderer.decide(observation.pose)

    def control(self, observation: PursuerObservation) -> Velocity:
        return self.wanderer.control(observation.pose)
