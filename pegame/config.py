"""Typed run configuration: the schema Hydra validates against, and its checks.

The composed config has one node per plugin group (``sim``, ``detector``, ``estimator``,
``pursuer``, ``evader``, ``recorder``), each with a ``name`` that the registry resolves;
those nodes are validated by the plugin's own ``Config`` dataclass. The fixed nodes
(``game``, ``camera``, ``env``, ``team``) are validated here, as a structured-config schema that
Hydra applies at composition (unknown keys, wrong types) and range checks that
:func:`game_settings` applies before a game starts.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, fields, make_dataclass
from pathlib import Path
from typing import Any, get_type_hints

from hydra.core.config_store import ConfigStore
from hydra.core.plugins import Plugins
from omegaconf import MISSING, DictConfig, OmegaConf
from omegaconf.errors import OmegaConfBaseException

from pegame.api import PLUGIN_KINDS
from pegame.defaults import PluginOptionSource, PluginSearchPath
from pegame.errors import ConfigError, require
from pegame.types import Camera

#: game.turn_order: both agents move in every simulator step, or the paper's "First the
#: evader moves and then pursuer moves" (see :mod:`pegame.loop`)
TURN_ORDERS = ("simultaneous", "evader_first")

#: the most simulator steps one game may take (ticks x substeps): a bound on one game's
#: time and memory (its trajectory has a row per tick), not on the model: a day of game
#: time at 100 Hz (a 90 s game at 10 Hz is 900)
MAX_STEPS = 8_640_000


@dataclass
class GameConfig:
    """The game protocol (paper, Sec. "Simulation based validation")."""

    seed: int = 0  # master seed; every component gets its own generator from it
    t_max: float = 90.0  # game length (s), the paper's t_max
    control_hz: float = 10.0  # sensing, estimation and velocity commands (Hz)
    decision_hz: float = 1.0  # both strategies decide at this rate (Hz), the paper's 1 Hz nodes
    speed_ratio: float = 1.0  # v_p / v_e: the pursuer's max speed is this times evader.v_max
    trials: int = 1  # games per job, seeds seed, seed+1, ...; each appends a line to results.jsonl
    physics_hz: float | None = (
        None  # simulator integration rate (Hz), a whole multiple of control_hz; null: control_hz
    )
    turn_order: str = "simultaneous"  # simultaneous, or evader_first: each tick the evader moves, then the pursuer

    def __post_init__(self) -> None:
        require(
            self.seed >= 0, "game.seed", "a whole number >= 0 (numpy's SeedSequence)", self.seed
        )
        require(self.t_max > 0, "game.t_max", "a positive duration in seconds", self.t_max)
        require(self.trials >= 1, "game.trials", "a whole number >= 1", self.trials)
        for key in ("control_hz", "decision_hz", "speed_ratio"):
            value = getattr(self, key)
            require(value > 0 and math.isfinite(value), f"game.{key}", "a positive number", value)
        require(
            self.ticks >= 1,
            "game.t_max",
            f"at least one control tick, {1 / self.control_hz:g} s at game.control_hz={self.control_hz:g}",
            self.t_max,
        )
        require(
            self.ticks * self.substeps <= MAX_STEPS,
            "game.t_max",
            f"at most {MAX_STEPS} simulator steps per game (t_max * physics_hz, or * "
            f"control_hz without physics_hz): {MAX_STEPS / (self.control_hz * self.substeps):g} s "
            f"at these rates",
            self.t_max,
        )
        require(
            self.decision_hz <= self.control_hz,
            "game.decision_hz",
            f"a rate no higher than game.control_hz ({self.control_hz} Hz)",
            self.decision_hz,
        )
        require(
            self.turn_order in TURN_ORDERS,
            "game.turn_order",
            " or ".join(TURN_ORDERS),
            self.turn_order,
        )
        if self.physics_hz is not None:
            require(
                self.physics_hz > 0 and math.isfinite(self.physics_hz),
                "game.physics_hz",
                "null (= game.control_hz) or a positive number",
                self.physics_hz,
            )
            substeps = self.physics_hz / self.control_hz
            multiples = ", ".join(f"{self.control_hz * k:.6g}" for k in range(1, 6))
            require(
                substeps >= 1 - 1e-9 and abs(substeps - round(substeps)) <= 1e-6 * substeps,
                "game.physics_hz",
                f"null or a whole multiple of game.control_hz={self.control_hz:g}: {multiples}, ... Hz "
                "(each control tick is integrated in whole substeps)",
                self.physics_hz,
            )
        ratio = self.control_hz / self.decision_hz
        whole = ", ".join(f"{self.control_hz / k:.6g}" for k in range(1, 7))
        require(
            abs(ratio - round(ratio)) <= 1e-6 * ratio,
            "game.decision_hz",
            f"a rate that divides game.control_hz={self.control_hz:g} into whole ticks, "
            f"control_hz / k for a whole k: {whole}, ... Hz",
            self.decision_hz,
        )

    @property
    def ticks(self) -> int:
        """Control ticks in one game: ``t_max * control_hz``, rounded."""
        return int(round(self.t_max * self.control_hz))

    @property
    def substeps(self) -> int:
        """Simulator steps per control tick: ``physics_hz / control_hz`` (1 when null)."""
        if self.physics_hz is None:
            return 1
        return max(1, int(round(self.physics_hz / self.control_hz)))

    @property
    def decide_every(self) -> int:
        """Control ticks per decision: ``control_hz / decision_hz``, a whole number."""
        return max(1, int(round(self.control_hz / self.decision_hz)))


@dataclass
class TeamConfig:
    """The teams: how many pursuers and evaders play, and which plugin each one is.

    ``pursuers`` (and ``evaders``) is a count N >= 1 of copies of the ``pursuer`` node's
    plugin, or a list with one member per pursuer: a plugin name (``random``) or a node
    ``{name: smart, standoff: 1.0}`` whose keys override the ``pursuer`` node's for that
    member (every member has the role's body: the bodies are set in the ``pursuer`` node).
    Member 0 of a 1v1 game (the default, 1 and 1) is today's game.
    """

    pursuers: Any = 1  # N copies of pursuer's plugin, or a list of members (names or nodes)
    evaders: Any = 1  # M copies of evader's plugin, or a list of members (names or nodes)


#: the most members a team may have: a bound on the spawn's work, not on the model
MAX_TEAM = 16


def team_members(value: Any, role: str) -> list[dict[str, Any]]:
    """The members of ``team.<role>s`` as override nodes (``{}`` for a copy of the role's
    node): a count gives that many copies, a list one node per entry. ConfigError naming
    the key and what is allowed for anything else."""
    key = f"team.{role}s"
    allowed = (
        f"a whole number of {role}s from 1 to {MAX_TEAM}, or a list of members, each a "
        f"{role} plugin name or a node with its name and the options that differ "
        f"(e.g. [smart, {{name: smart, standoff: 1.0}}])"
    )
    if isinstance(value, Mapping):
        raise ConfigError(f"Invalid value for '{key}': {dict(value)!r}. Allowed: {allowed}.")
    if isinstance(value, Sequence) and not isinstance(value, str):
        entries = list(value)
        members: list[dict[str, Any]] = []
        for entry in entries:
            if isinstance(entry, str) and entry:
                members.append({"name": entry})
            elif isinstance(entry, Mapping) and isinstance(entry.get("name"), str):
                members.append(dict(entry))
            else:
                raise ConfigError(f"Invalid member {entry!r} in '{key}'. Allowed: {allowed}.")
        require(1 <= len(members) <= MAX_TEAM, key, allowed, entries)
        return members
    count_ok = isinstance(value, int) and not isinstance(value, bool)
    require(count_ok and 1 <= value <= MAX_TEAM, key, allowed, value)
    return [{} for _ in range(value)]


@dataclass
class EnvConfig:
    """The environment: a ROS map_server YAML (absolute, relative to the working
    directory, or the name of a map shipped with pegame, e.g. ``hall.yaml``)."""

    name: str = MISSING
    map: str = MISSING


def _schema_of(frozen: type) -> type:
    """A mutable dataclass with the fields, types and defaults of the frozen value type
    ``frozen``: Hydra needs writable schema nodes; range checks run on ``typed(node, frozen)``."""
    hints = get_type_hints(frozen)
    return make_dataclass(
        f"{frozen.__name__}Schema",
        [(f.name, hints[f.name], field(default=f.default)) for f in fields(frozen)],
    )


#: The whole run config: the fixed nodes, one node per plugin kind of
#: :data:`pegame.api.PLUGIN_KINDS` (typed by its plugin's Config when a game is built), and
#: ``resume`` (skip games already stored in the job's results.jsonl).
Schema = make_dataclass(
    "Schema",
    [
        ("game", GameConfig, field(default_factory=GameConfig)),
        ("camera", Any, field(default_factory=_schema_of(Camera))),
        ("env", EnvConfig, field(default_factory=EnvConfig)),
        *[(kind, Any, field(default=MISSING)) for kind in PLUGIN_KINDS],
        ("team", TeamConfig, field(default_factory=TeamConfig)),
        ("resume", bool, field(default=False)),
    ],
)


def check_known_keys(cfg: Mapping[str, Any]) -> None:
    """ConfigError for a top-level key that is not pegame's (``+foo=1``, ``+gmae.t_max=5``):
    Hydra's ``+`` adds keys past the schema, and a misspelt key would be ignored silently.
    Keys inside game, camera and env are checked by :func:`typed`, plugin nodes by their
    plugin's Config."""
    allowed = [f.name for f in fields(Schema)]
    for key in cfg:
        if key not in allowed and key != "hydra":
            raise ConfigError(
                f"Unknown key '{key}'.{did_you_mean(str(key), allowed)} Allowed top-level "
                f"keys: {', '.join(allowed)}."
            )


def did_you_mean(word: str, choices: Sequence[str]) -> str:
    """`` Did you mean 'x'?`` for the closest of ``choices`` to ``word``, else ''."""
    close = difflib.get_close_matches(word, list(choices), n=1)
    return f" Did you mean '{close[0]}'?" if close else ""


def register_schema() -> None:
    """Make the schema available to config.yaml's defaults list as ``pegame_schema`` and
    read the config packages, pegame's and the plugin distributions', with each plugin
    option over its plugin's Config defaults (:mod:`pegame.defaults`)."""
    ConfigStore.instance().store(name="pegame_schema", node=Schema)
    Plugins.instance().register(PluginOptionSource)
    Plugins.instance().register(PluginSearchPath)


def resolve_map_path(map_path: str, base_dir: str | Path | None = None) -> Path:
    """Find a map YAML: absolute path, else relative to ``base_dir`` (the directory the
    user launched from), else a map shipped in pegame's ``maps/``."""
    from importlib.resources import files

    path = Path(map_path).expanduser()
    if path.is_absolute():
        return path
    candidate = Path(base_dir or Path.cwd()) / path
    if candidate.exists():
        return candidate
    shipped = Path(str(files("pegame.maps"))) / path
    return shipped if shipped.exists() else candidate


def plain(node: DictConfig, resolve: bool = False) -> dict[str, Any]:
    """A config node as plain containers (OmegaConf.to_container), interpolations
    ``resolve``d or kept."""
    container = OmegaConf.to_container(node, resolve=resolve)
    if not isinstance(container, dict):
        raise TypeError(f"Expected a mapping config node, got {type(container).__name__}.")
    return {str(key): value for key, value in container.items()}


def typed(node: Mapping[str, Any], schema: type, key: str) -> Any:
    """Build the dataclass ``schema`` from a config ``node`` found at ``key`` (e.g.
    ``game``), running its range checks. Unknown keys and wrong types raise ConfigError
    naming the full key and what is allowed."""
    params = plain(node) if isinstance(node, DictConfig) else dict(node)
    allowed = [f.name for f in fields(schema)]
    unknown = sorted(set(params) - set(allowed))
    if unknown:
        raise ConfigError(
            f"Unknown key '{key}.{unknown[0]}'."
            f"{did_you_mean(f'{key}.{unknown[0]}', [f'{key}.{name}' for name in allowed])} "
            f"Allowed keys under '{key}': {', '.join(allowed)}."
        )
    try:
        merged = OmegaConf.merge(OmegaConf.structured(schema), params)
        assert isinstance(merged, DictConfig)  # a dataclass schema merges to a mapping
        check_finite(merged, schema, key)
        return OmegaConf.to_object(merged)
    except OmegaConfBaseException as exc:
        where = f"{key}.{exc.full_key}" if getattr(exc, "full_key", None) else key
        reason = str(exc).splitlines()[0]
        raise ConfigError(f"Invalid value for '{where}': {reason}.") from None


def check_finite(node: DictConfig, schema: type, key: str) -> None:
    """ConfigError for a NaN, and for an infinite value of a field whose default is
    finite: infinity is a setting only where the default is one (``a_max: .inf``, no
    limit); elsewhere it would overflow or never end. Checked before the dataclass's own
    range checks, which may compute with the value."""
    for item in fields(schema):
        value = node.get(item.name)
        if not isinstance(value, float) or math.isfinite(value):
            continue
        default = item.default
        infinite_default = isinstance(default, float) and math.isinf(default)
        allowed = "a number or .inf" if infinite_default else "a finite number"
        require(infinite_default and not math.isnan(value), f"{key}.{item.name}", allowed, value)


def compose(overrides: Sequence[str] = ()) -> DictConfig:
    """The config the app would receive for these command-line ``overrides``, composed
    without running the app (for scripts, benchmarks and tests)."""
    from hydra import compose as hydra_compose
    from hydra import initialize_config_module

    from pegame.overrides import check_overrides

    check_overrides(overrides)
    register_schema()
    with initialize_config_module(config_module="pegame.conf", version_base=None):
        return hydra_compose(config_name="config", overrides=list(overrides))
