"""How a learning agent observes and acts (:class:`EnvSettings`): the observation's
options, the decision period and action clipping. The environments (:mod:`pegame.envs`,
whose :func:`pegame.envs.config.env_settings` validates them), the batched game
(:mod:`pegame.vector`) and the ``policy`` strategies (:mod:`pegame.policies`) share them,
so a policy plays in a game with the settings it was trained with."""

from __future__ import annotations

import math
from dataclasses import dataclass

from pegame.errors import require
from pegame.observe.observations import ObservationSettings


@dataclass(frozen=True)
class EnvSettings(ObservationSettings):
    """Observation options (crop_cells, crop_resolution, belief) plus:"""

    decision_period: float | None = (
        None  # s between actions, a whole number of control ticks; None: one tick
    )
    clip_actions: bool = False  # clip out-of-range actions to [-1, 1] instead of raising ValueError

    def __post_init__(self) -> None:
        super().__post_init__()
        period = self.decision_period
        require(
            period is None or (period > 0 and math.isfinite(period)),
            "decision_period",
            "a positive duration in s, or None for one control tick",
            period,
        )

    @property
    def observation(self) -> ObservationSettings:
        """The observation part of these settings."""
        return ObservationSettings(self.crop_cells, self.crop_resolution, self.belief)

    def ticks_per_action(self, control_dt: float) -> int:
        """Control ticks (period ``control_dt`` s) per action; ConfigError unless the
        decision period is a whole number of them."""
        if self.decision_period is None:
            return 1
        ticks = round(self.decision_period / control_dt)
        require(
            ticks >= 1
            and math.isclose(ticks * control_dt, self.decision_period, rel_tol=1e-9, abs_tol=1e-12),
            "decision_period",
            f"a whole multiple of the control period {control_dt:g} s (1 / game.control_hz)",
            self.decision_period,
        )
        return ticks
