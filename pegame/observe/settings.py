"""The environments' configuration: their own options (:class:`EnvSettings`) and the
app's run config that sets up the game (:func:`env_config`)."""

from __future__ import annotations

import difflib
import math
from collections.abc import Sequence
from dataclasses import dataclass, fields
from typing import Any

from omegaconf import DictConfig, OmegaConf

from pegame.config import compose, plain
from pegame.errors import ConfigError, require
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


def env_settings(**options: Any) -> EnvSettings:
    """Validated :class:`EnvSettings`; an unknown option is a ConfigError that lists the
    allowed ones (and the closest match)."""
    allowed = [f.name for f in fields(EnvSettings)]
    for key in options:
        if key not in allowed:
            close = difflib.get_close_matches(key, allowed, n=1)
            hint = f" Did you mean '{close[0]}'?" if close else ""
            raise ConfigError(
                f"Unknown env option '{key}'.{hint} Allowed: {', '.join(allowed)}, "
                "plus config or overrides (and opponent for the single-agent envs)."
            )
    return EnvSettings(**options)


def env_config(
    config: DictConfig | None = None,
    overrides: Sequence[str] = (),
    opponents: dict[str, str] | None = None,
) -> DictConfig:
    """The run config of an environment: ``config`` (a composed DictConfig, copied) or the
    app's config composed with ``overrides``; ``opponents`` maps a role to the strategy
    that plays it (an override ``role=name``). Recording is always off in environments.
    """
    opponents = opponents or {}
    if config is None:
        picks = [f"{role}={name}" for role, name in opponents.items()]
        return compose([*overrides, *picks, "recorder=none"])
    if overrides:
        raise ConfigError("Pass either config (a composed DictConfig) or overrides, not both.")
    source = config if isinstance(config, DictConfig) else OmegaConf.create(config)
    cfg = OmegaConf.create(plain(source, resolve=True))
    for role, name in opponents.items():
        if cfg[role].name != name:
            raise ConfigError(
                f"opponent={name!r} but the given config's {role} is {cfg[role].name!r}; "
                f"compose the config with {role}={name} or leave opponent unset."
            )
    cfg.recorder = {"name": "none"}
    return cfg
