"""One source for each default: every plugin's ``Config`` dataclass is the source, and each
config file (``conf/<group>/<name>.yaml`` of pegame, of the plugin distributions and of the
example) repeats it exactly: the same keys, the same values of the same types, the same
comment per field, and ``name:`` equal to the file stem and to the entry-point name in the
distribution's pyproject.toml. The body nodes of conf/config.yaml repeat ``Pursuer.Config``
and ``Evader.Config``, and its game and camera nodes ``GameConfig`` and ``Camera``."""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import io
import re
import textwrap
import tokenize
from pathlib import Path
from typing import Any

import pytest
import yaml

from pegame.api import INTERFACES
from pegame.config import GameConfig
from pegame.registry import GROUPS
from pegame.types import Camera

tomllib = pytest.importorskip("tomllib")  # Python >= 3.11

ROOT = Path(__file__).resolve().parents[1]
#: distribution directory -> its config root (pegame's conf/ is the package pegame.conf)
DISTRIBUTIONS = {
    ROOT: ROOT / "pegame" / "conf",
    ROOT / "plugins" / "pegame_pybullet": None,
    ROOT / "plugins" / "pegame_vision": None,
    ROOT / "examples" / "pegame_spinner": None,
}
GROUP_OF = {entry_group: group for group, entry_group in GROUPS.items()}


def project_of(dist: Path) -> dict[str, Any]:
    """The [project] table of a distribution's pyproject.toml."""
    return tomllib.loads((dist / "pyproject.toml").read_text())["project"]


def config_root(dist: Path) -> Path:
    """Where a distribution's ``<group>/<name>.yaml`` files live: its pegame.configs package."""
    if DISTRIBUTIONS[dist] is not None:
        return DISTRIBUTIONS[dist]
    (package,) = project_of(dist)["entry-points"]["pegame.configs"].values()
    return dist.joinpath(*package.split("."))


def options() -> list[tuple[Path, str, str, str]]:
    """(distribution dir, group, name, "module:Class") of every registered plugin."""
    found = []
    for dist in DISTRIBUTIONS:
        project = project_of(dist)
        for entry_group, points in project.get("entry-points", {}).items():
            if entry_group in GROUP_OF:
                found += [
                    (dist, GROUP_OF[entry_group], name, target) for name, target in points.items()
                ]
    return found


OPTIONS = options()


def option_id(option: tuple[Path, str, str, str]) -> str:
    return f"{option[0].name}:{option[1]}={option[2]}"


def import_plugin(dist: Path, target: str, monkeypatch) -> type:
    """The class ``module:Class`` of a distribution, skipping when a dependency is missing."""
    monkeypatch.syspath_prepend(str(dist))  # the example is not installed
    module, _, name = target.partition(":")
    try:
        return getattr(importlib.import_module(module), name)
    except ImportError as exc:
        if exc.name and exc.name.split(".")[0] in {"pegame", module.split(".")[0]}:
            raise
        pytest.skip(f"{target} needs {exc.name}")


# ------------------------------------------------------------------ reading comments


def field_comments(config: type) -> dict[str, str]:
    """The comment after each field of the dataclass ``config`` (and of its bases), by name:
    ``radius: float = 0.2  # body radius (m)`` gives ``{"radius": "body radius (m)"}``."""
    comments: dict[str, str] = {}
    for cls in reversed(config.__mro__):
        if not dataclasses.is_dataclass(cls) or not cls.__dict__.get("__annotations__"):
            continue
        tokens = tokenize.generate_tokens(
            io.StringIO(textwrap.dedent(inspect.getsource(cls))).readline
        )
        depth, line, name = 0, [], None
        for token in tokens:
            if token.type == tokenize.INDENT:
                depth += 1
            elif token.type == tokenize.DEDENT:
                depth -= 1
            elif token.type == tokenize.NEWLINE:
                line, name = [], None
            elif token.type == tokenize.COMMENT and name is not None:
                comments[name] = token.string.lstrip("#").strip()
            elif depth == 1 and token.type not in (tokenize.NL, tokenize.COMMENT):
                line.append(token)
                if len(line) == 2 and line[0].type == tokenize.NAME and line[1].string == ":":
                    name = line[0].string
    return comments


def yaml_comments(text: str) -> dict[str, str]:
    """The comment after each top-level key of a YAML file, by key (a '#' inside quotes or
    not preceded by a space is part of the value)."""
    comments = {}
    for line in text.splitlines():
        match = re.match(r"(\w+):(.*)$", line)
        if not match:
            continue
        rest, quote = match.group(2), None
        for k, char in enumerate(rest):
            if char in "\"'" and quote in (None, char):
                quote = None if quote else char
            elif char == "#" and quote is None and rest[k - 1 : k].isspace():
                comments[match.group(1)] = rest[k + 1 :].strip()
                break
    return comments


# --------------------------------------------------------------------------- the rules


def defaults_of(config: type, skip: set[str] = frozenset()) -> dict[str, Any]:
    made = config()
    return {f.name: getattr(made, f.name) for f in dataclasses.fields(made) if f.name not in skip}


def same_values(written: dict[str, Any], defaults: dict[str, Any]) -> dict[str, tuple[Any, Any]]:
    """Keys whose written value differs from the default in value or type: (written, default)."""
    keys = set(written) | set(defaults)
    return {
        key: (written.get(key, "<missing>"), defaults.get(key, "<no such field>"))
        for key in sorted(keys)
        if key not in written
        or key not in defaults
        or written[key] != defaults[key]
        or type(written[key]) is not type(defaults[key])
    }


def body_fields(group: str) -> set[str]:
    """The fields every plugin of ``group`` inherits from its interface's Config (the
    pursuer's and evader's bodies), written once in conf/config.yaml."""
    return {f.name for f in dataclasses.fields(INTERFACES[group].Config)}


def test_every_registered_plugin_has_one_config_file_and_every_file_a_plugin():
    assert len(OPTIONS) == 20  # 16 built in, pybullet + segmentation, vision, spinner
    registered = {(config_root(dist) / group / f"{name}.yaml") for dist, group, name, _ in OPTIONS}
    files = {
        path
        for dist in DISTRIBUTIONS
        for group in GROUPS
        for path in (config_root(dist) / group).glob("*.yaml")
    }
    assert files == registered


@pytest.mark.parametrize("option", OPTIONS, ids=option_id)
def test_the_config_file_repeats_the_dataclass(option, monkeypatch):
    dist, group, name, target = option
    cls = import_plugin(dist, target, monkeypatch)
    path = config_root(dist) / group / f"{name}.yaml"
    text = path.read_text()
    written = yaml.safe_load(text)
    assert written.pop("name") == name == path.stem
    assert same_values(written, defaults_of(cls.Config, body_fields(group))) == {}
    comments = yaml_comments(text)
    comments.pop("name", None)
    assert comments == {k: c for k, c in field_comments(cls.Config).items() if k in written}


def config_yaml() -> tuple[str, dict[str, Any]]:
    text = (ROOT / "pegame" / "conf" / "config.yaml").read_text()
    return text, yaml.safe_load(text)


@pytest.mark.parametrize(
    ("node", "schema"),
    [
        ("pursuer", INTERFACES["pursuer"].Config),
        ("evader", INTERFACES["evader"].Config),
        ("game", GameConfig),
        ("camera", Camera),
    ],
)
def test_config_yaml_repeats_the_bodies_game_and_camera(node, schema):
    _, written = config_yaml()
    assert same_values(written[node], defaults_of(schema)) == {}


def node_comments(text: str, node: str) -> dict[str, str]:
    """The comments of the keys under the top-level ``node:`` of a YAML text."""
    block = re.search(rf"^{node}:.*\n((?:[ ]+.*\n)+)", text, flags=re.MULTILINE)
    assert block, f"no node {node} in conf/config.yaml"
    return yaml_comments(textwrap.dedent(block.group(1)))


@pytest.mark.parametrize(
    ("node", "schema"),
    [
        ("pursuer", INTERFACES["pursuer"].Config),
        ("evader", INTERFACES["evader"].Config),
        ("game", GameConfig),
    ],
)
def test_config_yaml_comments_are_the_dataclass_comments(node, schema):
    text, _ = config_yaml()
    assert node_comments(text, node) == field_comments(schema)


# ------------------------------------------------------------------- the readers


@dataclasses.dataclass
class _Commented:
    """A dataclass as the test reads it: a docstring, fields with and without comments."""

    plain: int = 1
    noted: float = 2.0  # m, a note: with a colon
    listed: list[str] = dataclasses.field(default_factory=lambda: ["#a"])  # '#rrggbb'

    def __post_init__(self) -> None:
        inner: int = 3  # not a field
        del inner


def test_field_comments_reads_field_lines_only():
    assert field_comments(_Commented) == {"noted": "m, a note: with a colon", "listed": "'#rrggbb'"}


def test_yaml_comments_skip_hashes_inside_values():
    text = 'name: x\ncolours: ["#cc1f1a", "#1f38a6"]  # the shirt\nplain: 3\nnote: a#b   # m\n'
    assert yaml_comments(text) == {"colours": "the shirt", "note": "m"}
