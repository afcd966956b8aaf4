"""A learned pursuer: plays a trained policy on the observation of ``pegame/Pursuit-v0``.

The policy is a linear-policy ``.npz`` (``examples/train_cem.py``) or any callable
``package.module:function`` mapping the observation vector to a scaled (v, w) action; see
:mod:`pegame.policies`. It commands velocities directly and makes no plan.
"""

from __future__ import annotations

from dataclasses import dataclass

from pegame.api import Pursuer, PursuerObservation
from pegame.policies import PolicyOptions, PolicyPlayer
from pegame.types import Plan, Pose, Velocity


class PolicyPursuer(Pursuer):
    """A trained policy (linear .npz or a callable) on the pursuer's env observation."""

    description = (
        "A learned policy (linear .npz or module:function) on the pegame.envs observation."
    )

    @dataclass
    class Config(Pursuer.Config, PolicyOptions):
        def __post_init__(self) -> None:
            Pursuer.Config.__post_init__(self)
            self.check("pursuer")

    def __init__(self, config, context, rng) -> None:
        super().__init__(config, context, rng)
        self.player = PolicyPlayer(config, "pursuer", context)

    def reset(self, pose: Pose) -> None:
        self.player.reset()

    def decide(self, observation: PursuerObservation) -> Plan:
        return self.player.plan()

    def control(self, observation: PursuerObservation) -> Velocity:
        return self.player.control(observation)
