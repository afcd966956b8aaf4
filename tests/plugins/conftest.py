"""Fixtures of the plugin tests: the small map of :mod:`plugin_worlds` and a context on it.

Imports no plugin, so that a test file skips cleanly when its plugin's dependency is missing.
"""

from __future__ import annotations

import math
import sys

import pytest

from pegame import registry
from pegame.api import Context
from pegame.types import Body, Camera
from pegame.grid import OccupancyGrid
from plugin_worlds import small_map


@pytest.fixture
def grid() -> OccupancyGrid:
    return small_map()


@pytest.fixture
def context(grid) -> Context:
    """The default bodies and camera (pi/3 FOV, 0.3-5 m, 640x480) on the small map."""
    return Context(grid, Body(0.2, 0.5, 1.8), Body(0.25, 0.5, 1.8), Camera(fov=math.pi / 3), 0.1, 1.0)


@pytest.fixture
def load_without(monkeypatch):
    """``load_without(module, package, group, name)``: the PluginError of loading the plugin
    ``name`` of ``group`` with ``module`` uninstalled and the plugin's ``package`` not yet
    imported."""

    def load(module: str, package: str, group: str, name: str) -> registry.PluginError:
        monkeypatch.setitem(sys.modules, module, None)
        for loaded in [m for m in sys.modules if m.startswith(package)]:
            monkeypatch.delitem(sys.modules, loaded)
        with pytest.raises(registry.PluginError) as info:
            registry.load(group, name)
        return info.value

    return load
