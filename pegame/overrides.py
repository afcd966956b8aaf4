"""Command-line overrides checked before Hydra composes them, so that a misspelt choice
or key gets pegame's one paragraph with "Did you mean ...?" (exit status 2) instead of
Hydra's "Could not find" or its struct error: ``pursuer=smrt``, ``env=hal``,
``game.tmax=5``, ``gmae.t_max=5``. Used by the app (:mod:`pegame.__main__`) and by
:func:`pegame.config.compose` (the environments' ``overrides`` and ``opponent``)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import fields
from importlib.resources import files

from pegame.api import PLUGIN_KINDS
from pegame.config import EnvConfig, GameConfig, Schema, TeamConfig, did_you_mean
from pegame.defaults import config_packages
from pegame.errors import ConfigError, PluginChoiceError
from pegame.types import Camera

#: the config groups whose options are files: the plugin kinds and the maps
CHOICE_GROUPS = (*PLUGIN_KINDS, "env")

#: the fixed nodes, whose keys are their dataclass's fields
FIXED_NODES: dict[str, type] = {
    "game": GameConfig,
    "camera": Camera,
    "env": EnvConfig,
    "team": TeamConfig,
}


def plugin_options(kind: str) -> list[str]:
    """The config options of group ``kind`` that Hydra finds on pegame's search path:
    pegame's own ``conf/<kind>/*.yaml`` and those of plugin distributions."""
    options = set()
    for package in config_packages().values():
        try:
            folder = files(package) / kind
        except ModuleNotFoundError:
            continue
        if folder.is_dir():
            options |= {item.name[:-5] for item in folder.iterdir() if item.name.endswith(".yaml")}
    return sorted(options)


def check_overrides(args: Sequence[str]) -> None:
    """PluginChoiceError, with the closest option, for ``group=name`` when ``name`` is no
    option of that group (every value of a sweep ``pursuer=smart,smrt``); ConfigError,
    with the closest key, for a key that is not pegame's set without ``+`` (``game.tmax``,
    ``gmae.t_max``). Skipped when the user adds config directories, whose options and
    keys only Hydra knows, and for arguments Hydra's parser refuses (Hydra reports them)."""
    from hydra.core.override_parser.overrides_parser import OverridesParser

    if any(
        a.startswith(("--config-dir", "-cd", "--config-path", "-cp", "hydra.searchpath"))
        for a in args
    ):
        return
    candidates = [a for a in args if "=" in a and not a.startswith("-")]
    try:
        parsed = OverridesParser.create().parse_overrides(candidates)
    except Exception:
        return
    for override in parsed:
        if override.package or override.is_delete() or override.is_add():
            continue
        if override.is_force_add():
            continue
        key = override.key_or_group
        if key in CHOICE_GROUPS:
            values = (
                list(override.sweep_string_iterator())
                if override.is_sweep_override()
                else [override.get_value_element_as_str()]
            )
            check_choices(key, values)
        else:
            check_key(key)


def check_choices(kind: str, values: Sequence[str]) -> None:
    """PluginChoiceError for the first of ``values`` that is no option of group ``kind``."""
    options = plugin_options(kind)
    for value in values:
        if value not in options:
            what = "map" if kind == "env" else kind
            raise PluginChoiceError(
                f"Unknown {what} '{value}'.{did_you_mean(value, options)} Available: "
                f"{', '.join(options)}. An option is a file {kind}/<name>.yaml in pegame's "
                f"conf or a plugin distribution's (see python -m pegame.catalog)."
            )


def check_key(key: str) -> None:
    """ConfigError for a dotted ``key`` that names no top-level node or no field of a
    fixed node (plugin nodes' keys are their plugin's, checked when the game is built;
    Hydra's own keys and config groups such as ``hydra/launcher`` are Hydra's)."""
    if "/" in key or key.split(".", 1)[0] == "hydra":
        return
    top, _, rest = key.partition(".")
    allowed = [f.name for f in fields(Schema)]
    if top not in allowed and top != "hydra":
        raise ConfigError(
            f"Unknown key '{key}'.{did_you_mean(top, allowed)} Allowed top-level keys: "
            f"{', '.join(allowed)} (a new key needs '+': +{key}=...)."
        )
    schema = FIXED_NODES.get(top)
    name = rest.split(".", 1)[0]
    if schema is not None and rest:
        names = [f.name for f in fields(schema)]
        if name not in names:
            close = did_you_mean(f"{top}.{name}", [f"{top}.{n}" for n in names])
            raise ConfigError(
                f"Unknown key '{top}.{name}'.{close} Allowed keys under '{top}': "
                f"{', '.join(names)}."
            )
