"""The paper's random evader (baseline *-R): wanders to random reachable goals with no
knowledge of the pursuer (paper, Sec. "Random Pursuer and Evader")."""

from __future__ import annotations

from pegame.api import Evader, EvaderObservation
from pegame.types import Plan, Velocity
from pegame.wander import Wanderer


class RandomEvader(Evader):
    """Walks to uniformly random reachable free goals, a new one on arrival or when stuck."""

    description = "Baseline: walks to uniformly random reachable free goals."

    def __init__(self, config, context, rng) -> None:
        super().__init__(config, context, rng)
        self.wanderer = Wanderer(context.grid, context.evader, rng)

    def reset(self, pose) -> None:
        self.wanderer.reset(pose)

    def decide(self, observation: EvaderObservation) -> Plan:
        return self.wanderer.decide(observation.pose)

    def control(self, observation: EvaderObservation) -> Velocity:
        return self.wanderer.control(observation.pose)
