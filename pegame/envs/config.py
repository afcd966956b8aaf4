"""The environments' configuration: their constructor options, validated into
:class:`pegame.observe.settings.EnvSettings` (:func:`env_settings`), and the app's run
config that sets up their games (:func:`env_config`)."""

from __future__ import annotations

import difflib
from collections.abc import Sequence
from dataclasses import fields
from typing import Any

from omegaconf import DictConfig, OmegaConf

from pegame.config import compose, plain
from pegame.errors import ConfigError
from pegame.observe.settings import EnvSettings


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
