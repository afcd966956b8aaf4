"""The paper's random evader (baseline *-R): wanders to random reachable goals, or takes a
random action at each decision (``evader.model``), with no knowledge of the pursuer; the
random agent of :mod:`pegame.wander` as the evader."""

from __future__ import annotations

from pegame.api import Evader
from pegame.roles import for_role
from pegame.wander import RandomOptions, RandomStrategy

RandomEvader = for_role(RandomStrategy, RandomOptions, Evader, __name__)
