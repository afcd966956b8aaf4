"""Every config option against the registry, and config validation errors."""

from __future__ import annotations

import math
from importlib.resources import files
from pathlib import Path

import pytest
from omegaconf import OmegaConf

from pegame import registry
from pegame.api import PLUGIN_KINDS
from pegame.config import (
    EnvConfig,
    GameConfig,
    Schema,
    check_known_keys,
    compose,
    resolve_map_path,
    typed,
)
from pegame.errors import ConfigError, PegameError
from pegame.grid import load_map
from pegame.types import Camera

CONF = Path(str(files("pegame.conf")))


def options(group: str) -> list[str]:
    return sorted(p.stem for p in (CONF / group).glob("*.yaml"))


@pytest.mark.parametrize("group", list(registry.GROUPS))
def test_every_option_matches_its_registry_entry(group, compose_config):
    assert options(group), f"conf/{group}/ has no options"
    builtins = {name for name, dist, _ in registry.describe(group) if dist == "pegame"}
    assert set(options(group)) == builtins  # third-party plugins bring their own configs
    for option in options(group):
        cfg = compose_config([f"{group}={option}"])
        assert cfg[group].name == option
        cls = registry.load(group, option)
        params = {k: v for k, v in cfg[group].items() if k != "name"}
        registry.make_config(group, cls, params)  # the yaml is valid for the plugin


@pytest.mark.parametrize("env", options("env"))
def test_every_env_option_loads_its_map(env, compose_config):
    cfg = compose_config([f"env={env}"])
    settings = typed(cfg.env, EnvConfig, "env")
    grid = load_map(resolve_map_path(settings.map))
    assert settings.name == env == grid.name


def test_default_config_validates(compose_config):
    cfg = compose_config()
    assert typed(cfg.game, GameConfig, "game").t_max == 90.0
    assert typed(cfg.camera, Camera, "camera") == Camera()


@pytest.mark.parametrize(
    ("node", "key", "params", "message"),
    [
        ("game", GameConfig, {"t_max": -1.0}, "'game.t_max'"),
        ("game", GameConfig, {"control_hz": 0.0}, "'game.control_hz'"),
        ("game", GameConfig, {"speed_ratio": -2.0}, "'game.speed_ratio'"),
        ("game", GameConfig, {"decision_hz": 20.0}, "'game.decision_hz'"),
        ("game", GameConfig, {"t_max": "abc"}, "'game.t_max'"),
        (
            "game",
            GameConfig,
            {"t_maxx": 3},
            "Unknown key 'game.t_maxx'. Did you mean 'game.t_max'?",
        ),
        ("game", GameConfig, {"t_maxx": 3}, "Allowed keys under 'game': seed, t_max"),
        ("game", GameConfig, {"seed": -1}, "'game.seed': -1"),
        ("game", GameConfig, {"t_max": 0.01}, "at least one control tick, 0.1 s"),
        ("game", GameConfig, {"decision_hz": 3.0}, "divides game.control_hz=10 into whole ticks"),
        ("game", GameConfig, {"decision_hz": 3.0}, "10, 5, 3.33333, 2.5, 2, 1.66667"),
        ("game", GameConfig, {"control_hz": 30.0, "decision_hz": 4.0}, "30, 15, 10, 7.5, 6, 5"),
        ("camera", Camera, {"fov": 7.0}, "'camera.fov'"),
        ("camera", Camera, {"fov": 0.0}, "(0, 2*pi]"),
        ("camera", Camera, {"far": 0.1}, "'camera.far'"),
    ],
)
def test_bad_values_name_the_key_and_the_allowed_range(node, key, params, message):
    with pytest.raises(ConfigError) as info:
        typed(OmegaConf.create(params), key, node)
    assert message in str(info.value)


@pytest.mark.parametrize(
    ("group", "option", "params", "key"),
    [
        ("evader", "random", {"v_max": 0.0}, "evader.v_max"),
        ("evader", "random", {"radius": -0.1}, "evader.radius"),
        ("pursuer", "random", {"w_max": 0.0}, "pursuer.w_max"),
        ("pursuer", "random", {"speed": 1.0}, "pursuer.speed"),
        ("detector", "oracle", {"miss_probability": 2.0}, "detector.miss_probability"),
    ],
)
def test_plugin_config_errors_name_the_key(group, option, params, key):
    cls = registry.load(group, option)
    with pytest.raises(ConfigError, match=key.replace(".", r"\.")):
        registry.make_config(group, cls, params)


@pytest.mark.parametrize("decision_hz", [10.0, 5.0, 2.5, 2.0, 1.0, 0.5, 10 / 3])
def test_decision_rates_that_divide_into_whole_ticks_are_accepted(decision_hz):
    settings = GameConfig(control_hz=10.0, decision_hz=decision_hz)
    assert settings.control_hz / settings.decision_hz == pytest.approx(round(10.0 / decision_hz))


@pytest.mark.parametrize(
    ("overrides", "message"),
    [
        (["+foo=1"], "Unknown key 'foo'. Allowed top-level keys: game, camera, env, sim"),
        (["+gmae.t_max=5"], "Unknown key 'gmae'. Did you mean 'game'?"),
        (["+rsume=true"], "Did you mean 'resume'?"),
    ],
)
def test_unknown_top_level_keys_are_rejected(compose_config, overrides, message):
    with pytest.raises(ConfigError) as info:
        check_known_keys(compose_config(overrides))
    assert message in str(info.value)


def test_the_default_config_has_only_known_keys(compose_config):
    check_known_keys(compose_config())


def test_the_schema_has_one_node_per_plugin_kind():
    from dataclasses import fields

    names = [f.name for f in fields(Schema)]
    assert [n for n in names if n in PLUGIN_KINDS] == list(PLUGIN_KINDS)
    assert set(names) - set(PLUGIN_KINDS) == {"game", "camera", "env", "team", "resume"}


@pytest.mark.parametrize(
    ("override", "key", "allowed"),
    [
        ("game.t_max=inf", "game.t_max", "a finite number"),
        ("game.t_max=1e400", "game.t_max", "a finite number"),  # YAML reads it as inf
        ("game.t_max=1e300", "game.t_max", "at most 8640000 simulator steps per game"),
        ("game.control_hz=1e300", "game.t_max", "at most 8640000 simulator steps per game"),
        ("game.physics_hz=nan", "game.physics_hz", "a finite number"),
        ("camera.far=inf", "camera.far", "a finite number"),
        ("camera.far=1e308", "camera.far", "at most 100000 rays per view"),
        ("camera.far=1e12", "camera.far", "at most 100000 rays per view"),
        ("camera.angle_step=1e-9", "camera.angle_step", "at most 100000 rays per view"),
        ("evader.v_max=inf", "evader.v_max", "a finite number"),
        ("pursuer.a_max=nan", "pursuer.a_max", "a number or .inf"),
    ],
)
def test_infinite_and_unbounded_values_are_refused_before_the_first_game(
    compose_config, tmp_path, override, key, allowed
):
    from pegame.job import run_job

    with pytest.raises(ConfigError) as info:
        run_job(compose_config(["recorder=none", "env=hall", override]), tmp_path)
    assert f"Invalid value for '{key}'" in str(info.value) and allowed in str(info.value)
    assert not (tmp_path / "results.jsonl").exists()


def test_infinity_stays_a_setting_where_it_is_the_default(compose_config):
    from pegame.game import Scenario

    scenario = Scenario(compose_config(["pursuer.a_max=inf", "evader.alpha_max=inf"]))
    assert scenario.context.pursuer.a_max == math.inf == scenario.context.evader.alpha_max


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["env=hal"], "Unknown map 'hal'. Did you mean 'hall'?"),
        (["-m", "env=hall,hal"], "Unknown map 'hal'. Did you mean 'hall'?"),
        (["pursuer=smrt"], "Unknown pursuer 'smrt'. Did you mean 'smart'?"),
        (["game.tmax=5"], "Unknown key 'game.tmax'. Did you mean 'game.t_max'?"),
        (["camera.fav=1"], "Unknown key 'camera.fav'. Did you mean 'camera.fov'?"),
        (["gmae.t_max=5"], "Unknown key 'gmae.t_max'. Did you mean 'game'?"),
    ],
)
def test_misspelt_choices_and_keys_get_did_you_mean_before_hydra(args, message):
    from pegame.overrides import check_overrides

    with pytest.raises(PegameError, match=message):
        check_overrides(args)
    with pytest.raises(PegameError, match=message):
        compose([a for a in args if a != "-m"])


def test_added_keys_and_deletions_are_left_to_hydra_and_the_schema():
    from pegame.overrides import check_overrides

    check_overrides(
        [
            "+game.extra=1",
            "~recorder",
            "++resume=true",
            "hydra.run.dir=x",
            "hydra/launcher=joblib",
            "pursuer.k_v=1",
        ]
    )
