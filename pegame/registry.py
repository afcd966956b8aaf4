"""Entry-point registries: lazy lookup of plugins by name, with clear errors.

Each config group (``sim``, ``detector``, ...) has an entry-point group
``pegame.<plural>``; a plugin's entry-point name equals its config file stem and the
``name:`` key inside it. Nothing is imported until a plugin is asked for, so
``import pegame`` loads no plugin. Built-in plugins register through the same entry
points (in pegame's own pyproject.toml) as third-party ones.
"""

from __future__ import annotations

import difflib
import itertools
import warnings
from collections.abc import Iterable, Mapping
from functools import cache
from importlib.metadata import EntryPoint, entry_points
from typing import Any, Literal, overload

from pegame.api import (
    INTERFACES,
    PLUGIN_KINDS,
    Detector,
    Estimator,
    Evader,
    Plugin,
    Pursuer,
    Recorder,
    Simulator,
)
from pegame.errors import ConfigError, PegameError

#: config group -> entry-point group, derived from :data:`pegame.api.PLUGIN_KINDS`
GROUPS: dict[str, str] = {kind: spec.entry_point_group for kind, spec in PLUGIN_KINDS.items()}


class PluginError(PegameError, LookupError):
    """A plugin is unknown, fails to import, or does not implement its interface."""


def _entry_point_group(group: str) -> str:
    try:
        return GROUPS[group]
    except KeyError:
        raise PluginError(
            f"Unknown plugin group '{group}'. Available: {', '.join(GROUPS)}."
        ) from None


def unique_by_name(points: Iterable[EntryPoint]) -> dict[str, EntryPoint]:
    """One entry point per name, sorted by name. When several distributions register the
    same name, warn naming them and keep the first in distribution-name order, so which
    plugin wins does not depend on the order of sys.path (the pattern of xarray's
    ``backends/plugins.py``)."""
    ranked = sorted(points, key=lambda ep: (ep.name, distribution_of(ep), ep.value))
    unique = {}
    for name, group in itertools.groupby(ranked, key=lambda ep: ep.name):
        same = list(group)
        if len(same) > 1:
            who = ", ".join(f"{distribution_of(ep)} ({ep.value})" for ep in same)
            warnings.warn(
                f"{len(same)} distributions register the plugin name '{name}' under "
                f"'{same[0].group}': {who}. Using the one from '{distribution_of(same[0])}'; "
                f"uninstall or rename the others.",
                RuntimeWarning,
                stacklevel=2,
            )
        unique[name] = same[0]
    return unique


@cache
def _entry_points(group: str) -> dict[str, EntryPoint]:
    return unique_by_name(entry_points(group=_entry_point_group(group)))


def refresh() -> None:
    """Discover the entry points again (after installing or removing a plugin
    distribution in a running session, e.g. a notebook)."""
    _entry_points.cache_clear()


def available(group: str) -> list[str]:
    """Names registered in ``group`` (for example ``available('pursuer')``), sorted."""
    return list(_entry_points(group))


def entry_point(group: str, name: str) -> EntryPoint:
    """The entry point of plugin ``name`` in ``group``; PluginError with suggestions if unknown."""
    points = _entry_points(group)
    if name in points:
        return points[name]
    close = difflib.get_close_matches(str(name), points, n=1)
    hint = f" Did you mean '{close[0]}'?" if close else ""
    raise PluginError(
        f"Unknown {group} '{name}'.{hint} Available: {', '.join(points) or '(none)'}. "
        f"Plugins register under the entry-point group '{GROUPS[group]}'."
    )


def distribution_of(point: EntryPoint) -> str:
    """The name of the distribution that provides ``point``, or '?' when unknown."""
    dist = getattr(point, "dist", None)
    return dist.name if dist is not None else "?"


@overload
def load(group: Literal["sim"], name: str) -> type[Simulator]: ...
@overload
def load(group: Literal["detector"], name: str) -> type[Detector]: ...
@overload
def load(group: Literal["estimator"], name: str) -> type[Estimator]: ...
@overload
def load(group: Literal["pursuer"], name: str) -> type[Pursuer]: ...
@overload
def load(group: Literal["evader"], name: str) -> type[Evader]: ...
@overload
def load(group: Literal["recorder"], name: str) -> type[Recorder]: ...
@overload
def load(group: str, name: str) -> type[Plugin]: ...
def load(group: str, name: str) -> type[Plugin]:
    """Import and return the plugin class ``name`` of ``group``, checking its interface."""
    point = entry_point(group, name)
    try:
        cls = point.load()
    except (ImportError, AttributeError) as exc:
        missing, dist = getattr(exc, "name", None), distribution_of(point)
        # A module's name is not a package name on an index: advising `pip install
        # <module>` could install someone else's package (typosquatting). The distribution
        # that declares the entry point knows its dependencies.
        source = f"the distribution '{dist}'" if dist != "?" else "the distribution"
        hint = (
            f" The module '{missing}' is not installed: reinstall {source} that declares this "
            "plugin, from where it came (its source directory or index), so that its "
            "dependencies are installed with it."
            if missing
            else ""
        )
        raise PluginError(
            f"The {group} plugin '{name}' (distribution '{dist}', "
            f"{point.value}) failed to import: {exc}.{hint}"
        ) from exc
    check_interface(group, name, point, cls)
    return cls


def check_interface(group: str, name: str, point: EntryPoint, cls: Any) -> None:
    """PluginError unless ``cls`` is a concrete subclass of the group's interface; the
    message names the plugin, its distribution and the methods it does not implement."""
    interface = INTERFACES[group]
    where = f"The {group} plugin '{name}' (distribution '{distribution_of(point)}', {point.value})"
    if not (isinstance(cls, type) and issubclass(cls, interface)):
        raise PluginError(
            f"{where} must be a subclass of pegame.api.{interface.__name__}, got {cls!r}. "
            f"Derive it from pegame.api.{interface.__name__} and implement "
            f"{', '.join(sorted(interface.__abstractmethods__))}."
        )
    abstract = sorted(getattr(cls, "__abstractmethods__", ()))
    if abstract:
        raise PluginError(
            f"{where} does not implement pegame.api.{interface.__name__}: missing "
            f"{', '.join(abstract)}."
        )


def make_config(
    group: str, cls: type[Plugin], params: Mapping[str, Any], node: str | None = None
) -> Any:
    """Build a validated ``cls.Config`` from a config node's ``params`` (without ``name``);
    ConfigError names the full key under the node (``group``, or ``node`` for a team
    member, e.g. ``team.pursuers[1]``) and the allowed keys or range."""
    from pegame.config import typed

    node = node or group
    try:
        return typed(params, cls.Config, node)
    except ConfigError as error:
        raise error.under(node, group) from None


def describe(group: str) -> list[tuple[str, str, str]]:
    """(name, distribution, one-line description) of every plugin in ``group``; loads them."""
    rows = []
    for name, point in _entry_points(group).items():
        try:
            text = next(iter((load(group, name).description or "").strip().splitlines()), "")
        except PluginError as exc:
            text = f"(broken: {exc})"
        rows.append((name, distribution_of(point), text))
    return rows
