"""Conformance kit for plugin authors: does a plugin keep the contract of :mod:`pegame.api`?

Two forms, in the manner of Gymnasium's ``check_env`` and Hydra's ``LauncherTestSuite``:

- :func:`check_plugin` runs every check and raises :class:`ConformanceError` on the first
  failure; it needs no pytest::

      from pegame.testing import check_plugin
      check_plugin("pursuer", Spinner, bad_values={"turn_rate": -1.0})

- pytest base classes, one per plugin kind (:class:`SimulatorConformance`,
  :class:`DetectorConformance`, :class:`EstimatorConformance`,
  :class:`PursuerConformance`, :class:`EvaderConformance`, :class:`RecorderConformance`),
  whose test methods are the same checks; a plugin's test module subclasses one in a line::

      class TestSpinner(PursuerConformance):
          plugin = "spinner"
          bad_values = {"turn_rate": -1.0}

What is checked:

1. *Interface*: the class subclasses its kind's interface, implements every abstract
   method, has a one-line ``description`` and a dataclass ``Config`` that extends the
   interface's ``Config`` (the pursuer's and evader's body fields); it is registered under
   its entry-point group, and :func:`pegame.registry.load` returns it.
2. *Config*: the defaults construct; an unknown key, a non-number for a numeric field and
   every value of ``bad_values`` raise :class:`pegame.errors.ConfigError` naming the key
   (``pursuer.turn_rate``); the config file Hydra finds (``conf/<kind>/<name>.yaml``) has
   ``name: <name>`` and holds only values that differ from the ``Config`` defaults.
3. *Determinism*: two games with the plugin selected, built from the same seed, give equal
   results and trajectories (so the plugin draws only from the generator it is given, as
   DESIGN.md's one-generator-per-component rule asks), and neither touches numpy's global
   generator.

It also holds a small map with known walls and a context on it (:func:`small_map`,
:func:`small_context`) for a plugin's own unit tests, and :func:`missing_dependency_error`
to test that a plugin without its heavy dependency fails with a clear message.
"""

from __future__ import annotations

import dataclasses
import math
import sys
import tempfile
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from pegame import registry
from pegame.api import INTERFACES, Context, Plugin
from pegame.errors import ConfigError
from pegame.types import Body, Camera

if TYPE_CHECKING:  # pragma: no cover - typing only
    from pegame.grid import OccupancyGrid

__all__ = [
    "BLOCK",
    "WALL_X",
    "ConformanceError",
    "DetectorConformance",
    "EstimatorConformance",
    "EvaderConformance",
    "PluginConformance",
    "PursuerConformance",
    "RecorderConformance",
    "SimulatorConformance",
    "check_config_errors",
    "check_config_file",
    "check_interface",
    "check_plugin",
    "check_same_seed_same_game",
    "missing_dependency_error",
    "small_context",
    "small_map",
]


class ConformanceError(AssertionError):
    """A plugin breaks its contract; the message says which rule and how to keep it."""


def _fail_unless(ok: bool, message: str) -> None:
    if not ok:
        raise ConformanceError(message)


def _interface(kind: str) -> type[Plugin]:
    _fail_unless(
        kind in INTERFACES, f"Unknown plugin kind '{kind}'. Kinds: {', '.join(INTERFACES)}."
    )
    return INTERFACES[kind]


def registered_name(kind: str, cls: type[Plugin]) -> str | None:
    """The entry-point name under which ``cls`` is registered for ``kind``, without
    importing any plugin; None when it is not registered."""
    target = f"{cls.__module__}:{cls.__qualname__}"
    for name in registry.available(kind):
        if registry.entry_point(kind, name).value.replace(" ", "") == target:
            return name
    return None


# ------------------------------------------------------------------------ the checks


def check_interface(kind: str, cls: type[Plugin], name: str | None = None) -> None:
    """Rule 1: ``cls`` implements the ``kind`` interface and is what the registry loads for
    ``name`` (default: the name it is registered under)."""
    interface = _interface(kind)
    _fail_unless(
        isinstance(cls, type) and issubclass(cls, interface),
        f"{cls!r} must subclass pegame.api.{interface.__name__} to be a {kind} plugin.",
    )
    missing = sorted(getattr(cls, "__abstractmethods__", ()))
    _fail_unless(
        not missing,
        f"{cls.__name__} does not implement {', '.join(missing)} of {interface.__name__}.",
    )
    description = cls.description
    _fail_unless(
        isinstance(description, str)
        and description.strip() != ""
        and "\n" not in description.strip(),
        f"{cls.__name__}.description must be a one-line summary (python -m pegame.catalog "
        f"shows it), got {description!r}.",
    )
    config = cls.Config
    _fail_unless(
        dataclasses.is_dataclass(config) and isinstance(config, type),
        f"{cls.__name__}.Config must be a dataclass of the plugin's parameters.",
    )
    required = [f.name for f in dataclasses.fields(interface.Config)]
    _fail_unless(
        not required or issubclass(config, interface.Config),
        f"{cls.__name__}.Config must extend {interface.__name__}.Config (the game reads its "
        f"fields {required}).",
    )
    name = name or registered_name(kind, cls)
    _fail_unless(
        name is not None,
        f"{cls.__module__}:{cls.__qualname__} is not registered: add it to the entry-point group "
        f"'{registry.GROUPS[kind]}' of its distribution's pyproject.toml and reinstall it.",
    )
    loaded = registry.load(kind, str(name))
    _fail_unless(loaded is cls, f"registry.load('{kind}', '{name}') gives {loaded!r}, not {cls!r}.")


def check_config_errors(
    kind: str, cls: type[Plugin], bad_values: Mapping[str, Any] | None = None
) -> None:
    """Rule 2, the dataclass: defaults construct; an unknown key, a non-number for each
    numeric field and each ``bad_values`` item raise ConfigError naming ``kind.key``."""
    try:
        defaults = cls.Config()
    except Exception as exc:
        raise ConformanceError(
            f"{cls.__name__}.Config() must construct from its defaults: {exc}"
        ) from exc
    _fail_unless(
        registry.make_config(kind, cls, {}) == defaults,
        f"registry.make_config('{kind}', {cls.__name__}, {{}}) must equal {cls.__name__}.Config().",
    )
    cases: dict[str, Any] = {"no_such_key": 1}
    for field in dataclasses.fields(defaults):
        value = getattr(defaults, field.name)
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            cases[field.name] = "not a number"
    for key, value in {**cases, **(bad_values or {})}.items():
        try:
            registry.make_config(kind, cls, {key: value})
        except ConfigError as exc:
            _fail_unless(
                f"{kind}.{key}" in str(exc),
                f"The ConfigError for {kind}.{key}={value!r} must name '{kind}.{key}': {exc}",
            )
        except Exception as exc:
            raise ConformanceError(
                f"{kind}.{key}={value!r} must raise pegame.errors.ConfigError (call "
                f"pegame.errors.require in Config.__post_init__), not {type(exc).__name__}: {exc}"
            ) from exc
        else:
            raise ConformanceError(
                f"{kind}.{key}={value!r} must be refused with a ConfigError naming "
                f"'{kind}.{key}', but the config was accepted."
            )


def check_config_file(kind: str, cls: type[Plugin], name: str) -> None:
    """Rule 2, the file: the option Hydra finds for ``kind=name`` says ``name: <name>`` and
    holds only what differs from ``cls.Config``'s defaults (which are the one place of
    each default, :mod:`pegame.defaults`): fields of the Config, none repeating its
    default."""
    from omegaconf import OmegaConf

    from pegame.defaults import option_file

    file = option_file(kind, name)
    _fail_unless(file is not None, f"no config file {kind}/{name}.yaml on pegame's search path.")
    assert file is not None
    written = OmegaConf.to_container(OmegaConf.create(file.read_text()))
    where = f"{kind}/{name}.yaml"
    _fail_unless(
        isinstance(written, dict) and written.get("name") == name,
        f"{where} must say 'name: {name}', not {written!r}.",
    )
    assert isinstance(written, dict)
    fields = [f.name for f in dataclasses.fields(cls.Config)]
    unknown = sorted(set(written) - {"name", "defaults", *fields})
    _fail_unless(
        not unknown, f"{where} sets {unknown}, which are no fields of {cls.__name__}.Config."
    )
    params = {k: v for k, v in written.items() if k in fields}
    config, defaults = registry.make_config(kind, cls, params), cls.Config()
    repeated = sorted(k for k in params if getattr(config, k) == getattr(defaults, k))
    _fail_unless(
        not repeated,
        f"{where} repeats {cls.__name__}.Config's defaults of {repeated}: a default is "
        f"written once, in the Config; the file holds only the values that differ.",
    )


def _global_generator_state() -> tuple[bytes, int]:
    """Where numpy's legacy global generator (np.random.*) stands: its key and position."""
    state = np.random.get_state(legacy=False)  # noqa: NPY002 - the global generator is the subject
    assert isinstance(state, dict)
    return bytes(state["state"]["key"]), int(state["state"]["pos"])


def _game_overrides(
    kind: str, name: str, overrides: Sequence[str], env: str | None, t_max: float, seed: int
) -> list[str]:
    chosen = [f"{kind}={name}", f"game.t_max={t_max}", f"game.seed={seed}"]
    if kind != "recorder":
        chosen.append("recorder=none")
    if env is not None:
        chosen.append(f"env={env}")
    return chosen + list(overrides)


def check_same_seed_same_game(
    kind: str,
    name: str,
    overrides: Sequence[str] = (),
    *,
    env: str | None = None,
    t_max: float = 3.0,
    seed: int = 0,
) -> None:
    """Rule 3: two games with ``kind=name`` (plus Hydra ``overrides``, on ``env``, ``t_max``
    seconds, ``seed``) play the same, and leave numpy's global generator alone."""
    from pegame.config import compose
    from pegame.game import Game

    chosen = _game_overrides(kind, name, overrides, env, t_max, seed)
    global_state = _global_generator_state()
    outcomes = []
    with tempfile.TemporaryDirectory(prefix="pegame-conformance-") as out:
        for k in range(2):
            out_dir = Path(out) / str(k)
            out_dir.mkdir()
            outcomes.append(Game(compose(chosen)).play(out_dir))
    first, second = outcomes
    _fail_unless(
        len(first.trajectory) == first.result["ticks"] > 0,
        f"A {t_max} s game must play every tick, got {len(first.trajectory)} rows.",
    )
    _fail_unless(
        first.result == second.result,
        f"Two games with {chosen} gave different results: {first.result} != {second.result}. "
        f"A plugin must draw only from the generator it is given (self.rng).",
    )
    differing = next(
        (i for i, (a, b) in enumerate(zip(first.trajectory, second.trajectory)) if a != b), None
    )
    _fail_unless(
        differing is None,
        f"Two games with {chosen} diverge at tick {differing}: "
        f"{first.trajectory[differing or 0]} != {second.trajectory[differing or 0]}.",
    )
    _fail_unless(
        _global_generator_state() == global_state,
        f"A game with {chosen} drew from numpy's global generator (np.random.*); use self.rng.",
    )
    if kind != "recorder":
        _fail_unless(
            first.result[kind] == name,
            f"The game's result names {kind} {first.result[kind]!r}, not {name!r}.",
        )


def check_plugin(
    kind: str,
    cls: type[Plugin],
    *,
    name: str | None = None,
    overrides: Sequence[str] = (),
    bad_values: Mapping[str, Any] | None = None,
    env: str | None = None,
    t_max: float = 3.0,
    seed: int = 0,
) -> None:
    """Run every check on the ``kind`` plugin ``cls`` (registered as ``name``, found if
    None); raise ConformanceError on the first broken rule.

    ``overrides`` are Hydra overrides the games need (``["sim=pybullet"]`` for a detector of
    rendered frames, ``["pursuer.path=..."]``); ``bad_values`` maps config keys to values
    its ``Config`` must refuse; ``env``, ``t_max`` (s) and ``seed`` set the two games.
    """
    check_interface(kind, cls, name)
    name = name or registered_name(kind, cls)
    assert name is not None  # check_interface refused an unregistered plugin
    check_config_errors(kind, cls, bad_values)
    check_config_file(kind, cls, name)
    check_same_seed_same_game(kind, name, overrides, env=env, t_max=t_max, seed=seed)


# ------------------------------------------------------------------ pytest base classes


class PluginConformance:
    """Base of the pytest conformance suites: a subclass named ``Test...`` sets ``plugin``
    (the entry-point name) and, if needed, ``overrides``, ``bad_values``, ``env`` and
    ``t_max`` (see :func:`check_plugin`); each rule is then a test of its own."""

    kind: ClassVar[str]
    plugin: ClassVar[str]
    overrides: ClassVar[Sequence[str]] = ()
    bad_values: ClassVar[Mapping[str, Any]] = {}
    env: ClassVar[str | None] = None
    t_max: ClassVar[float] = 3.0

    @classmethod
    def plugin_class(cls) -> type[Plugin]:
        """The plugin's class, as the registry loads it."""
        loaded: type[Plugin] = registry.load(cls.kind, cls.plugin)
        return loaded

    def test_implements_its_interface(self) -> None:
        check_interface(self.kind, self.plugin_class(), self.plugin)

    def test_config_errors_name_the_key(self) -> None:
        check_config_errors(self.kind, self.plugin_class(), self.bad_values)

    def test_config_file_holds_only_what_differs(self) -> None:
        check_config_file(self.kind, self.plugin_class(), self.plugin)

    def test_same_seed_same_game(self) -> None:
        check_same_seed_same_game(
            self.kind, self.plugin, self.overrides, env=self.env, t_max=self.t_max
        )


class SimulatorConformance(PluginConformance):
    kind = "sim"


class DetectorConformance(PluginConformance):
    kind = "detector"


class EstimatorConformance(PluginConformance):
    kind = "estimator"


class PursuerConformance(PluginConformance):
    kind = "pursuer"


class EvaderConformance(PluginConformance):
    kind = "evader"


class RecorderConformance(PluginConformance):
    kind = "recorder"


# ------------------------------------------------------------- worlds for unit tests

RESOLUTION = 0.05  # m per cell of the small map
WALL_X = 2.0  # m, the near face of the small map's interior wall
BLOCK = (45, 51, 10, 21)  # rows and cols [start, stop) of the small map's occupied block


def chase(observation: np.ndarray) -> np.ndarray:
    """A pursuer policy for ``pursuer=policy pursuer.path=pegame.testing:chase``: turn toward
    the last detection's bearing (feature 6) and close to about 1.5 m (feature 5)."""
    return np.array([4.0 * observation[5] - 1.2, 3.0 * observation[6]])


def nan_policy(observation: np.ndarray) -> np.ndarray:
    """A broken policy (a NaN speed), for the policy plugins' error tests."""
    return np.array([np.nan, 0.0])


def flee(observation: np.ndarray) -> np.ndarray:
    """An evader policy for ``evader=policy evader.path=pegame.testing:flee``: full speed,
    turning away from the pursuer's bearing (the env observation's feature 9, normalised
    to [-1, 1])."""
    return np.array([1.0, -5.0 * observation[9]])


def small_map() -> OccupancyGrid:
    """4 m x 3 m at 5 cm: an interior wall two cells thick at x = 2.0-2.1 m from y = 0 to
    2.0 m, an occupied block (:data:`BLOCK`), unknown cells in the top-right corner."""
    from pegame.grid import OccupancyGrid

    data = np.zeros((60, 80), dtype=np.int8)
    col = int(round(WALL_X / RESOLUTION))
    data[:40, col : col + 2] = 100
    data[BLOCK[0] : BLOCK[1], BLOCK[2] : BLOCK[3]] = 100
    data[55:, 75:] = -1
    return OccupancyGrid(data, RESOLUTION, name="small")


def walled_room(origin: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> OccupancyGrid:
    """4 m x 3 m at 5 cm with a one-cell wall all round, a 0.5 m square pillar at
    x 1.75-2.25 m, y 1.25-1.75 m (from ``origin``) and three unknown cells at y = 0.5 m."""
    from pegame.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid

    data = np.full((60, 80), FREE, dtype=np.int8)
    data[[0, -1], :] = OCCUPIED
    data[:, [0, -1]] = OCCUPIED
    data[25:35, 35:45] = OCCUPIED
    data[10, 60:63] = UNKNOWN
    return OccupancyGrid(data, RESOLUTION, origin)


def small_context(grid: OccupancyGrid | None = None) -> Context:
    """A context with the default bodies and camera (pi/3 FOV, 0.3-5 m, 640x480 px), 10 Hz
    control and 1 Hz decisions, on ``grid`` (default :func:`small_map`)."""
    return Context(
        grid if grid is not None else small_map(),
        Body(0.2, 0.5, 1.8),
        Body(0.25, 0.5, 1.8),
        Camera(fov=math.pi / 3),
        0.1,
        1.0,
    )


@contextmanager
def _without(module: str, package: str) -> Iterator[None]:
    """While inside: ``import module`` fails and ``package`` is imported afresh; after, both
    are as they were."""

    def affected(name: str) -> bool:
        return name == module or name.startswith(module + ".") or name.split(".")[0] == package

    saved = {name: mod for name, mod in sys.modules.items() if affected(name)}
    for name in saved:
        del sys.modules[name]
    sys.modules[module] = None  # type: ignore[assignment]  # makes "import module" fail
    try:
        yield
    finally:
        for name in [n for n in sys.modules if affected(n)]:
            del sys.modules[name]
        sys.modules.update(saved)


def missing_dependency_error(
    kind: str, name: str, module: str, package: str
) -> registry.PluginError:
    """The PluginError of loading the ``kind`` plugin ``name`` (from the import package
    ``package``) as if ``module`` were not installed; fails if loading does not raise one.
    The message should name ``module``: assert that in the plugin's test."""
    with _without(module, package):
        try:
            registry.load(kind, name)
        except registry.PluginError as exc:
            return exc
    raise ConformanceError(f"Loading {kind} '{name}' without '{module}' must raise a PluginError.")
