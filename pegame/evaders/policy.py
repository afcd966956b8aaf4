"""A learned evader: plays a trained policy on the observation of ``pegame/Evasion-v0``.

The policy is a linear-policy ``.npz`` or any callable ``package.module:function``
mapping the observation vector to a scaled (v, w) action; see :mod:`pegame.policies`. It
commands velocities directly and makes no plan.
"""

from __future__ import annotations

from dataclasses import dataclass

from pegame.api import Evader, EvaderObservation
from pegame.policies import PolicyOptions, PolicyPlayer
from pegame.types import Plan, Pose, Velocity


class PolicyEvader(Evader):
    """A trained policy (linear .npz or a callable) on the evader's env observation."""

    description = (
        "A learned policy (linear .npz or module:function) on the pegame.envs observation."
    )

    @dataclass
    class Config(Evader.Config, PolicyOptions):
        def __post_init__(self) -> None:
            Evader.Config.__post_init__(self)
            self.check("evader")

    def __init__(self, config, context, rng) -> None:
        super().__init__(config, context, rng)
        self.player = PolicyPlayer(config, "evader", context)

    def reset(self, pose: Pose) -> None:
        self.player.reset()

    def decide(self, observation: EvaderObservation) -> Plan:
        return self.player.plan()

    def control(self, observation: EvaderObservation) -> Velocity:
        return self.player.control(observation)
