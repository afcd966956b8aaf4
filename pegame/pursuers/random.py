"""The paper's random pursuer (baseline R-*): wanders to random reachable goals, or takes a
random action at each decision (``pursuer.model``, see :mod:`pegame.wander`), and ignores
what it sees (paper, Sec. "Random Pursuer and Evader")."""

from __future__ import annotations

from dataclasses import dataclass

from pegame.api import Pursuer, PursuerObservation
from pegame.errors import require
from pegame.types import Plan, Velocity
from pegame.wander import MODELS, random_agent


class RandomPursuer(Pursuer):
    """A random pursuer, ``model`` as :mod:`pegame.wander` describes: ``waypoint`` drives to
    uniformly random reachable free goals (a new one on arrival or when stuck); ``action``
    draws a random (v, w) at each decision and holds it."""

    description = (
        "Baseline: random reachable goals (model=waypoint) or random (v, w) actions (model=action)."
    )

    @dataclass
    class Config(Pursuer.Config):
        model: str = "waypoint"  # waypoint: random reachable goals; action: random (v, w) actions

        def __post_init__(self) -> None:
            super().__post_init__()
            require(self.model in MODELS, "model", " or ".join(MODELS), self.model)

    def __init__(self, config, context, rng) -> None:
        super().__init__(config, context, rng)
        self.wanderer = random_agent(config.model, context.grid, context.pursuer, rng)

    def reset(self, pose) -> None:
        self.wanderer.reset(pose)

    def decide(self, observation: PursuerObservation) -> Plan:
        return self.wanderer.decide(observation.pose)

    def control(self, observation: PursuerObservation) -> Velocity:
        return self.wanderer.control(observation.pose)
