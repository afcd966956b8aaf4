"""The paper's random evader (baseline *-R): wanders to random reachable goals, or takes a
random action at each decision (``evader.model``, see :mod:`pegame.wander`), with no
knowledge of the pursuer (paper, Sec. "Random Pursuer and Evader")."""

from __future__ import annotations

from dataclasses import dataclass

from pegame.api import Evader, EvaderObservation
from pegame.errors import require
from pegame.types import Plan, Velocity
from pegame.wander import MODELS, random_agent


class RandomEvader(Evader):
    """A random evader, ``model`` as :mod:`pegame.wander` describes: ``waypoint`` walks to
    uniformly random reachable free goals (a new one on arrival or when stuck); ``action``
    draws a random (v, w) at each decision and holds it."""

    description = (
        "Baseline: random reachable goals (model=waypoint) or random (v, w) actions (model=action)."
    )

    @dataclass
    class Config(Evader.Config):
        model: str = "waypoint"  # waypoint: random reachable goals; action: random (v, w) actions

        def __post_init__(self) -> None:
            super().__post_init__()
            require(self.model in MODELS, "model", " or ".join(MODELS), self.model)

    def __init__(self, config, context, rng) -> None:
        super().__init__(config, context, rng)
        self.wanderer = random_agent(config.model, context.grid, context.evader, rng)

    def reset(self, pose) -> None:
        self.wanderer.reset(pose)

    def decide(self, observation: EvaderObservation) -> Plan:
        return self.wanderer.decide(observation.pose)

    def control(self, observation: EvaderObservation) -> Velocity:
        return self.wanderer.control(observation.pose)
