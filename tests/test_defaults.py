"""One source for each default (pegame.defaults): a plugin's ``Config`` dataclass holds its
defaults, its config file ``<group>/<name>.yaml`` only ``name:`` and what differs, and
Hydra composes the node from both; conf/config.yaml holds choices, no values of the
game, camera, team or bodies (their dataclasses give them)."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import pytest
from omegaconf import OmegaConf

from pegame import defaults, overrides, registry
from pegame.api import INTERFACES
from pegame.config import GameConfig, TeamConfig, compose
from pegame.errors import ConfigError
from pegame.game import Game
from pegame.pursuers.smart import SmartPursuer
from pegame.registry import GROUPS
from pegame.testing import ConformanceError, check_config_file
from pegame.types import Camera

tomllib = pytest.importorskip("tomllib")  # Python >= 3.11

ROOT = Path(__file__).resolve().parents[1]
#: the distributions with plugins: pegame, the two plugin distributions and the example
DISTRIBUTIONS = [
    ROOT,
    ROOT / "plugins" / "pegame_pybullet",
    ROOT / "plugins" / "pegame_vision",
    ROOT / "examples" / "pegame_spinner",
]
GROUP_OF = {entry_group: group for group, entry_group in GROUPS.items()}


def project_of(dist: Path) -> dict[str, Any]:
    """The [project] table of a distribution's pyproject.toml."""
    project: dict[str, Any] = tomllib.loads((dist / "pyproject.toml").read_text())["project"]
    return project


def config_root(dist: Path) -> Path:
    """Where a distribution's ``<group>/<name>.yaml`` files live."""
    if dist == ROOT:
        return ROOT / "pegame" / "conf"
    (package,) = project_of(dist)["entry-points"]["pegame.configs"].values()
    return dist.joinpath(*package.split("."))


def options() -> list[tuple[Path, str, str, str]]:
    """(distribution dir, group, name, "module:Class") of every registered plugin."""
    found = []
    for dist in DISTRIBUTIONS:
        for entry_group, points in project_of(dist).get("entry-points", {}).items():
            if entry_group in GROUP_OF:
                found += [
                    (dist, GROUP_OF[entry_group], name, target) for name, target in points.items()
                ]
    return found


OPTIONS = options()


def option_id(option: tuple[Path, str, str, str]) -> str:
    return f"{option[0].name}:{option[1]}={option[2]}"


@pytest.fixture
def installed(monkeypatch):
    """``installed(dist, group, name, target)``: the plugin's class, with the example
    distribution (not installed) made importable and its config package searched;
    skips when a dependency of the plugin is missing."""

    def install(dist: Path, group: str, name: str, target: str) -> type:
        if dist == DISTRIBUTIONS[-1]:
            monkeypatch.syspath_prepend(str(dist))
            (package,) = project_of(dist)["entry-points"]["pegame.configs"].values()
            packages = {**defaults.config_packages(), "pegame-plugin-spinner": package}
            for module in (defaults, overrides):  # the search path, the choices' check
                monkeypatch.setattr(module, "config_packages", lambda: packages)
            point = registry.EntryPoint(name, target, GROUPS[group])
            known = registry._entry_points

            def with_example(kind: str) -> dict[str, registry.EntryPoint]:
                return {**known(kind), name: point} if kind == group else known(kind)

            monkeypatch.setattr(registry, "_entry_points", with_example)
        try:
            return registry.load(group, name)
        except registry.PluginError as exc:
            missing = getattr(exc.__cause__, "name", None)
            if missing and missing.split(".")[0] not in {"pegame", target.split(".")[0]}:
                pytest.skip(f"{target} needs {missing}")
            raise

    return install


def test_every_registered_plugin_has_one_config_file_and_every_file_a_plugin():
    assert len(OPTIONS) == 24  # 19 built in, pybullet + segmentation, vision + person, spinner
    registered = {(config_root(dist) / group / f"{name}.yaml") for dist, group, name, _ in OPTIONS}
    files = {
        path
        for dist in DISTRIBUTIONS
        for group in GROUPS
        for path in (config_root(dist) / group).glob("*.yaml")
    }
    assert files == registered


@pytest.mark.parametrize("option", OPTIONS, ids=option_id)
def test_the_config_file_holds_only_what_differs(option, installed):
    cls = installed(*option)
    check_config_file(option[1], cls, option[2])


@pytest.mark.parametrize("option", OPTIONS, ids=option_id)
def test_the_composed_node_holds_every_default_of_the_config(option, installed):
    dist, group, name, _ = option
    cls = installed(*option)
    node = OmegaConf.to_container(compose([f"{group}={name}"])[group])
    made = cls.Config()
    assert node == {
        "name": name,
        **{f.name: getattr(made, f.name) for f in dataclasses.fields(made)},
    }


class Shifted(SmartPursuer):
    """The smart pursuer with other defaults, one of them also written in its file."""

    @dataclasses.dataclass
    class Config(SmartPursuer.Config):
        standoff: float = 2.0  # m
        radius: float = 0.3  # m


def shifted_smart(monkeypatch) -> None:
    real = registry.load
    monkeypatch.setattr(
        registry,
        "load",
        lambda kind, name: Shifted if (kind, name) == ("pursuer", "smart") else real(kind, name),
    )


def test_a_default_changed_in_the_config_is_the_composed_default(monkeypatch):
    shifted_smart(monkeypatch)
    node = compose(["pursuer=smart"]).pursuer
    assert (node.standoff, node.radius, node.k_w) == (2.0, 0.3, 4.0)
    assert compose(["pursuer=smart", "pursuer.standoff=1.0"]).pursuer.standoff == 1.0


def package_with(tmp_path: Path, monkeypatch, group: str, name: str, text: str) -> str:
    """The name of a config package (one per test) holding only ``group/name.yaml`` with
    ``text``, the only one searched."""
    name_of_package = f"conf_{tmp_path.name}"
    package = tmp_path / name_of_package
    (package / group).mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / group / f"{name}.yaml").write_text(text)
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setattr(defaults, "config_packages", lambda: {"fake": name_of_package})
    return name_of_package


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            "name: smart\nstandoff: 1.5\nk_w: 3.0\n",
            r"repeats SmartPursuer.Config's defaults of \['standoff'\]",
        ),
        ("name: smart\nstandof: 1.0\n", r"sets \['standof'\], which are no fields"),
        ("name: smrt\n", "must say 'name: smart'"),
    ],
)
def test_the_kit_refuses_a_file_repeating_a_default_or_setting_no_field(
    tmp_path, monkeypatch, text, message
):
    package_with(tmp_path, monkeypatch, "pursuer", "smart", text)
    with pytest.raises(ConformanceError, match=message):
        check_config_file("pursuer", SmartPursuer, "smart")


def test_a_file_value_overrides_the_config_default(tmp_path, monkeypatch):
    package = package_with(
        tmp_path, monkeypatch, "pursuer", "smart", "name: smart\nstandoff: 1.0\n"
    )
    check_config_file("pursuer", SmartPursuer, "smart")
    node = OmegaConf.to_container(
        defaults.PluginOptionSource("fake", f"pegame://{package}")
        .load_config("pursuer/smart")
        .config
    )
    assert node["standoff"] == 1.0 and node["k_w"] == 4.0 and node["name"] == "smart"


def test_an_unknown_plugin_key_is_refused_with_the_closest():
    with pytest.raises(
        ConfigError, match="Unknown key 'pursuer.standof'. Did you mean 'pursuer.standoff'?"
    ):
        Game(compose(["+pursuer.standof=1.0"]))


@pytest.mark.parametrize(
    ("node", "schema"),
    [
        ("pursuer", INTERFACES["pursuer"].Config),
        ("evader", INTERFACES["evader"].Config),
        ("game", GameConfig),
        ("camera", Camera),
        ("team", TeamConfig),
    ],
)
def test_config_yaml_holds_no_values_and_the_nodes_are_the_dataclass_defaults(node, schema):
    text = (ROOT / "pegame" / "conf" / "config.yaml").read_text()
    assert set(OmegaConf.create(text)) == {"defaults", "hydra"}
    composed = compose([])[node]
    made = schema()
    assert {f.name: composed[f.name] for f in dataclasses.fields(made)} == dataclasses.asdict(made)


def test_option_files_merge_over_the_defaults_as_omegaconf_merges():
    base = {"name": "x", "nested": {"a": 1, "b": {"c": 2, "d": 3}}, "listed": [1, 2], "n": 3}
    over = {"nested": {"b": {"c": 5}}, "listed": [9], "interpolated": "${..n}"}
    expected = OmegaConf.to_container(OmegaConf.merge(base, over))
    assert defaults.merged(base, over) == expected
