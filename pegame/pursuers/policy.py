"""A learned pursuer: plays a trained policy on the observation of ``pegame/Pursuit-v0``
(a linear-policy ``.npz`` of ``examples/train_cem.py`` or a callable
``package.module:function``); the policy strategy of :mod:`pegame.policies` as the pursuer."""

from __future__ import annotations

from pegame.api import Pursuer
from pegame.policies import PolicyOptions, PolicyStrategy
from pegame.roles import for_role

PolicyPursuer = for_role(PolicyStrategy, PolicyOptions, Pursuer, __name__)
