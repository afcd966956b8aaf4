"""Entry-point registries: lazy loading and the errors a user sees."""

from __future__ import annotations

import subprocess
import sys
from importlib.metadata import EntryPoint

import pytest

from pegame import registry
from pegame.api import INTERFACES, PLUGIN_KINDS


@pytest.fixture
def fake_points(monkeypatch):
    """Replace the pursuer registry by hand-made entry points."""

    def install(**values):
        points = {
            name: EntryPoint(name, value, "pegame.pursuers") for name, value in values.items()
        }
        monkeypatch.setattr(registry, "_entry_points", lambda group: points)

    return install


def test_builtins_are_registered_for_every_group():
    for group in registry.GROUPS:
        assert registry.available(group), group
    assert {"random", "smart"} <= set(registry.available("pursuer"))
    assert {"random", "smart"} <= set(registry.available("evader"))


def test_every_builtin_loads_and_implements_its_interface():
    for group in registry.GROUPS:
        for name in registry.available(group):
            cls = registry.load(group, name)
            assert issubclass(cls, INTERFACES[group])
            assert cls.description, f"{group} '{name}' has no description"


def test_unknown_name_suggests_the_closest_and_lists_all():
    with pytest.raises(registry.PluginError) as info:
        registry.load("pursuer", "smrt")
    assert str(info.value) == (
        "Unknown pursuer 'smrt'. Did you mean 'smart'? Available: anticipating, cooperative, "
        "policy, random, smart. "
        "Plugins register under the entry-point group 'pegame.pursuers'."
    )


def test_import_failure_names_plugin_distribution_and_install_hint(fake_points):
    fake_points(ghost="pegame_missing_dependency_xyz.module:Thing")
    with pytest.raises(registry.PluginError) as info:
        registry.load("pursuer", "ghost")
    text = str(info.value)
    assert "pursuer plugin 'ghost'" in text
    assert "distribution" in text
    assert "No module named 'pegame_missing_dependency_xyz'" in text
    assert "reinstall the distribution" in text
    assert "pip install pegame_missing_dependency_xyz" not in text  # a module is no package name


BROKEN_PLUGINS = '''
from pegame.api import Pursuer


class HalfPursuer(Pursuer):
    """Forgets to implement decide and control."""

    def reset(self, pose):
        pass


class NotAPlugin:
    """Implements nothing of the interface."""
'''


def test_class_that_is_not_the_interface_is_a_plugin_error_naming_the_methods(
    fake_points, tmp_path, monkeypatch
):
    (tmp_path / "fake_plugins.py").write_text(BROKEN_PLUGINS)
    monkeypatch.syspath_prepend(str(tmp_path))
    fake_points(alien="fake_plugins:NotAPlugin", half="fake_plugins:HalfPursuer")
    with pytest.raises(registry.PluginError, match="must be a subclass of pegame.api.Pursuer"):
        registry.load("pursuer", "alien")
    with pytest.raises(registry.PluginError) as info:
        registry.load("pursuer", "half")
    assert "does not implement pegame.api.Pursuer: missing control, decide" in str(info.value)
    assert "pursuer plugin 'half'" in str(info.value) and "fake_plugins:HalfPursuer" in str(
        info.value
    )


class FakeDistribution:
    def __init__(self, name):
        self.name = name


def point(name, value, dist):
    """An entry point of ``pegame.pursuers`` provided by the distribution ``dist``."""
    return EntryPoint(name, value, "pegame.pursuers")._for(FakeDistribution(dist))


def test_two_distributions_registering_one_name_warn_and_the_choice_is_stable():
    points = [
        point("smart", "b_pkg:Smart", "pegame-b"),
        point("smart", "a_pkg:Smart", "pegame-a"),
        point("random", "pegame.pursuers.random:RandomPursuer", "pegame"),
    ]
    with pytest.warns(RuntimeWarning) as record:
        unique = registry.unique_by_name(points)
    assert list(unique) == ["random", "smart"]
    assert unique["smart"].value == "a_pkg:Smart"
    with pytest.warns(RuntimeWarning):
        assert unique == registry.unique_by_name(reversed(points))  # independent of sys.path order
    text = str(record[0].message)
    assert (
        "'smart'" in text and "pegame-a (a_pkg:Smart)" in text and "pegame-b (b_pkg:Smart)" in text
    )


def test_the_installed_plugins_have_no_duplicate_names(recwarn):
    for group in registry.GROUPS:
        registry.refresh()
        registry.available(group)
    assert not [w for w in recwarn if "register the plugin name" in str(w.message)]


def test_groups_and_interfaces_come_from_the_one_list_of_plugin_kinds():
    assert list(registry.GROUPS) == list(PLUGIN_KINDS) == list(INTERFACES)
    for kind, spec in PLUGIN_KINDS.items():
        assert registry.GROUPS[kind] == spec.entry_point_group
        assert INTERFACES[kind] is spec.interface


def test_import_pegame_loads_no_plugin():
    code = (
        "import sys, pegame, pegame.registry, pegame.api;"
        "bad = [m for m in sys.modules if m.startswith(('pegame.sims', 'pegame.detectors',"
        " 'pegame.estimators', 'pegame.pursuers', 'pegame.evaders', 'rerun', 'pybullet', 'cv2'))];"
        "print(bad); sys.exit(1 if bad else 0)"
    )
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0


@pytest.mark.slow
def test_plugins_listing_shows_every_plugin_with_its_distribution():
    out = subprocess.run(
        [sys.executable, "-m", "pegame.catalog"], capture_output=True, text=True, check=True
    ).stdout
    for group, ep_group in registry.GROUPS.items():
        assert f"{group} ({ep_group})" in out
        for name in registry.available(group):
            dist = registry.distribution_of(registry.entry_point(group, name))
            assert any(line.split()[:2] == [name, dist] for line in out.splitlines()), name
