"""The paper's random pursuer (baseline R-*): wanders to random reachable goals, or takes a
random action at each decision (``pursuer.model``), and ignores what it sees; the random
agent of :mod:`pegame.wander` as the pursuer."""

from __future__ import annotations

from pegame.api import Pursuer
from pegame.roles import for_role
from pegame.wander import RandomOptions, RandomStrategy

RandomPursuer = for_role(RandomStrategy, RandomOptions, Pursuer, __name__)
