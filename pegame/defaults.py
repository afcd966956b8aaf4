"""Each plugin option's defaults in one place, its plugin's ``Config`` dataclass.

A plugin option is a file ``<group>/<name>.yaml`` (``pursuer/smart.yaml``) of a config
package: ``pegame.conf`` or a plugin distribution's (entry-point group ``pegame.configs``,
``spinner = "spinner.conf"``). It holds ``name: <name>`` and only the values that differ
from the plugin's ``Config`` defaults (usually none). Hydra reads these packages through
:class:`PluginOptionSource` (scheme ``pegame://``), which merges each option file over its
plugin's ``Config`` defaults: the composed node holds every key of the plugin, so
``pursuer.standoff=1`` overrides a default without Hydra's ``+``, and a key that is no
field (``+pursuer.standof=1``) is refused when the game builds the plugin's Config, with
the closest key (:func:`pegame.config.typed`). Only the chosen option's plugin is
imported, when Hydra loads its file.
"""

from __future__ import annotations

import functools
import sys
from collections.abc import Mapping
from dataclasses import fields
from importlib.metadata import entry_points
from importlib.resources import files
from typing import TYPE_CHECKING, Any

from hydra._internal.core_plugins.importlib_resources_config_source import (
    ImportlibResourcesConfigSource,
)
from hydra.core.config_search_path import ConfigSearchPath
from hydra.plugins.config_source import ConfigResult
from hydra.plugins.search_path_plugin import SearchPathPlugin
from omegaconf import DictConfig, OmegaConf

from pegame import registry
from pegame.api import PLUGIN_KINDS

if TYPE_CHECKING:  # pragma: no cover - typing only; importlib.resources.abc is 3.11+
    if sys.version_info >= (3, 11):
        from importlib.resources.abc import Traversable
    else:
        from importlib.abc import Traversable

#: the scheme of :class:`PluginOptionSource` on Hydra's search path
SCHEME = "pegame"
#: pegame's own config package
PEGAME_CONF = "pegame.conf"


def config_packages() -> dict[str, str]:
    """The config packages by provider name: pegame's, then the plugin distributions' in
    the order of their entry-point names (``pegame-plugin-spinner: spinner.conf``)."""
    points = sorted(entry_points(group="pegame.configs"), key=lambda p: p.name)
    return {"pegame": PEGAME_CONF, **{f"pegame-plugin-{p.name}": p.value for p in points}}


def option_file(kind: str, name: str) -> Traversable | None:
    """The file Hydra reads for ``kind=name``: ``<kind>/<name>.yaml`` of the first config
    package (:func:`config_packages`) that has it, or None."""
    for package in config_packages().values():
        try:
            file = files(package) / kind / f"{name}.yaml"
        except ModuleNotFoundError:
            continue
        if file.is_file():
            return file
    return None


def plugin_defaults(kind: str, name: str) -> dict[str, Any]:
    """The defaults of every field of the ``Config`` of plugin ``name`` of group ``kind``
    (imports the plugin; a field without a default is ``'???'``, Hydra's missing value)."""
    return dict(_defaults_of(registry.load(kind, name).Config))


@functools.cache
def _defaults_of(config: type) -> dict[str, Any]:
    """:func:`plugin_defaults` of the dataclass ``config``, read once per class (0.8 ms)."""
    values = OmegaConf.to_container(OmegaConf.structured(config))
    assert isinstance(values, dict)
    return {f.name: values[f.name] for f in fields(config)}


def merged(base: dict[str, Any], over: Mapping[Any, Any]) -> dict[str, Any]:
    """``over`` merged into ``base`` as OmegaConf.merge merges mappings (a mapping into a
    mapping key by key, any other value replacing), for plain containers."""
    return {
        **base,
        **{
            key: merged(base[key], value)
            if isinstance(value, dict) and isinstance(base.get(key), dict)
            else value
            for key, value in over.items()
        },
    }


def option_kind(config_path: str) -> str | None:
    """The plugin group of a config path ``<group>/<name>[.yaml]``, else None."""
    group, slash, name = config_path.partition("/")
    return group if slash and "/" not in name and group in PLUGIN_KINDS else None


class PluginOptionSource(ImportlibResourcesConfigSource):
    """Hydra's ``pkg://`` source for a config package, with each plugin option file
    merged over its plugin's ``Config`` defaults (module docstring). Other files, and an
    option file without ``name:`` (Hydra's own error then), load as they are."""

    @staticmethod
    def scheme() -> str:
        return SCHEME

    def load_config(self, config_path: str) -> ConfigResult:
        result = super().load_config(config_path)
        kind = option_kind(config_path)
        written = result.config
        if kind is not None and isinstance(written, DictConfig) and "name" in written:
            name = str(written.name)
            own = OmegaConf.to_container(written)  # interpolations kept as written
            assert isinstance(own, dict)
            # Plain containers: OmegaConf.merge of the nodes takes three times as long.
            result.config = OmegaConf.create(
                merged({"name": name, **plugin_defaults(kind, name)}, own)
            )
        return result


class PluginSearchPath(SearchPathPlugin):
    """Puts every config package on Hydra's search path through
    :class:`PluginOptionSource`: pegame's first (ahead of its plain ``pkg://`` entry, so
    that its option files get their defaults), the plugin distributions' last, so
    ``python -m pegame pursuer=spinner`` needs no extra flag."""

    def manipulate_search_path(self, search_path: ConfigSearchPath) -> None:
        for provider, package in config_packages().items():
            path = f"{SCHEME}://{package}"
            if package == PEGAME_CONF:
                search_path.prepend(provider=provider, path=path)
            else:
                search_path.append(provider=provider, path=path)
