"""The named readings of the paper (pegame/conf/experiment/reading_*.yaml, docs/trends):
each composes on top of paper_conditions, is valid for the strategies it names, and
changes only the settings it is about."""

from __future__ import annotations

from functools import cache
from importlib.resources import files
from pathlib import Path

import pytest
from omegaconf import OmegaConf

from pegame import registry
from pegame.config import GameConfig, compose, typed

CONF = Path(str(files("pegame.conf")))
READINGS = sorted(p.stem for p in (CONF / "experiment").glob("reading_*.yaml"))
#: what each reading changes against paper_conditions (dotted key -> value)
CHANGES = {
    "reading_held_commands": {"game.control_hz": 1.0, "game.physics_hz": 10.0},
    "reading_goal_tracking": {"pursuer.track": "goal"},
}
PAIRING = ("pursuer=smart", "evader=smart")


@cache
def paper_conditions() -> dict:
    """paper_conditions' config for PAIRING, flattened (composed once per test session)."""
    return flat(compose(["+experiment=paper_conditions", *PAIRING]))


def flat(cfg) -> dict:
    """The config as {dotted key: value}, without Hydra's own node."""
    out: dict = {}

    def walk(node, prefix):
        for key, value in node.items():
            if isinstance(value, dict):
                walk(value, f"{prefix}{key}.")
            else:
                out[f"{prefix}{key}"] = value

    walk({k: v for k, v in OmegaConf.to_container(cfg).items() if k != "hydra"}, "")
    return out


def test_every_reading_is_listed():
    assert READINGS == sorted(CHANGES)


@pytest.mark.parametrize("reading", READINGS)
def test_a_reading_composes_on_paper_conditions_and_changes_only_its_keys(reading, compose_config):
    cfg = compose_config([f"+experiment={reading}", *PAIRING])
    typed(cfg.game, GameConfig, "game")  # the game's settings validate
    for kind in ("pursuer", "evader"):
        params = {k: v for k, v in cfg[kind].items() if k != "name"}
        registry.make_config(kind, registry.load(kind, cfg[kind].name), params)
    base = paper_conditions()
    changed = {k: v for k, v in flat(cfg).items() if base.get(k) != v}
    assert changed == CHANGES[reading]
