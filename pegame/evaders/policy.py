"""A learned evader: plays a trained policy on the observation of ``pegame/Evasion-v0``
(a linear-policy ``.npz`` or a callable ``package.module:function``); the policy strategy
of :mod:`pegame.policies` as the evader."""

from __future__ import annotations

from pegame.api import Evader
from pegame.policies import PolicyOptions, PolicyStrategy
from pegame.roles import for_role

PolicyEvader = for_role(PolicyStrategy, PolicyOptions, Evader, __name__)
