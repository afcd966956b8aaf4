"""The ``policy`` pursuer and evader: loading, settings, and the same play as in the envs."""

from __future__ import annotations

import dataclasses
from importlib.metadata import EntryPoint
from pathlib import Path

import numpy as np
import pytest

from pegame import registry
from pegame.config import compose
from pegame.errors import ConfigError
from pegame.evaders.policy import PolicyEvader
from pegame.game import Game
from pegame.observe.observations import ObservationSettings
from pegame.policies import LinearPolicy, load_policy
from pegame.pursuers.policy import PolicyPursuer
from pegame.testing import chase, flee

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SHORT = ["env=enclosed", "game.t_max=3", "recorder=none"]


@pytest.fixture(autouse=True)
def policy_entry_points(monkeypatch):
    """Register the policy strategies when the installed distribution does not (yet)."""
    found = registry._entry_points
    classes = {"pursuer": PolicyPursuer, "evader": PolicyEvader}

    def with_policy(group: str) -> dict[str, EntryPoint]:
        points = dict(found(group))
        if group in classes and "policy" not in points:
            cls = classes[group]
            points["policy"] = EntryPoint(
                "policy", f"{cls.__module__}:{cls.__name__}", registry.GROUPS[group]
            )
        return points

    monkeypatch.setattr(registry, "_entry_points", with_policy)


def game(*overrides: str, seed: int = 5) -> Game:
    return Game(compose([*SHORT, *overrides, f"game.seed={seed}"]))


def env_rollout(env_id: str, policy, opponent: str, seed: int = 5, **settings) -> np.ndarray:
    """Poses (pursuer x, y, theta, evader x, y, theta) of every tick of one env game."""
    gymnasium = pytest.importorskip("gymnasium")
    import pegame.envs  # noqa: F401

    env = gymnasium.make(env_id, overrides=SHORT, opponent=opponent, **settings).unwrapped
    obs, _ = env.reset(seed=seed)
    loop, rows, truncated = env.game.loop, [], False
    while not truncated:
        rows.append((*dataclasses.astuple(loop.pursuer), *dataclasses.astuple(loop.evader)))
        obs, _, _, truncated, _ = env.step(np.clip(policy(obs), -1.0, 1.0))
    return np.array(rows)


def trajectory(outcome) -> np.ndarray:
    return np.array([row[2:8] for row in outcome.trajectory])


@pytest.mark.parametrize("evader", ["smart", "random"])
def test_a_policy_pursuer_plays_exactly_as_in_pursuit_env(evader):
    outcome = game("pursuer=policy", "pursuer.path=pegame.testing:chase", f"evader={evader}").play(
        "unused"
    )
    assert np.array_equal(trajectory(outcome), env_rollout("pegame/Pursuit-v0", chase, evader))
    assert outcome.result["pursuer"] == "policy"


def test_a_policy_evader_plays_exactly_as_in_evasion_env():
    outcome = game("evader=policy", "evader.path=pegame.testing:flee", "pursuer=smart").play(
        "unused"
    )
    assert np.array_equal(trajectory(outcome), env_rollout("pegame/Evasion-v0", flee, "smart"))


def test_a_linear_policy_file_brings_its_observation_settings(tmp_path):
    settings = ObservationSettings(crop_cells=4, crop_resolution=0.5)
    weights = np.zeros((2, 8 + 16))
    weights[0, 5], weights[1, 6] = 4.0, 3.0
    path = tmp_path / "p.npz"
    LinearPolicy(weights, np.array([-1.2, 0.0]), "pursuer", settings, decision_period=0.2).save(
        path
    )
    loaded = load_policy(str(path), "pursuer")
    assert loaded.settings == settings and loaded.decision_period == 0.2
    assert np.array_equal(loaded.weights, weights)
    outcome = game("pursuer=policy", f"pursuer.path={path}").play("unused")
    expected = env_rollout(
        "pegame/Pursuit-v0", loaded, "smart", crop_cells=4, crop_resolution=0.5, decision_period=0.2
    )
    # The env steps every 0.2 s; compare the poses at those ticks.
    assert np.array_equal(trajectory(outcome)[::2], expected)


def test_the_strategy_holds_its_action_for_the_decision_period():
    calls = []

    def counting(obs):
        calls.append(obs)
        return np.zeros(2)

    cfg = compose(
        [
            *SHORT,
            "pursuer=policy",
            "pursuer.path=pegame.testing:chase",
            "pursuer.decision_period=0.5",
        ]
    )
    pursuer = game_with_policy(cfg)
    pursuer.player.policy = counting
    for tick in range(10):
        pursuer.control(observation_at(pursuer, tick))
    assert len(calls) == 2


def game_with_policy(cfg):
    return Game(cfg).plugins.pursuer


def observation_at(pursuer, tick):
    from pegame.api import PursuerObservation
    from pegame.types import EMPTY_BELIEF, Pose

    return PursuerObservation(
        0.1 * tick, Pose(5.0, 5.0, 0.0), None, EMPTY_BELIEF, np.zeros((1, 1), bool)
    )


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({"path": "policy.txt"}, "'pursuer.path'"),
        ({"path": "x.npz", "crop_cells": 0}, "'pursuer.crop_cells'"),
        ({"path": "x.npz", "decision_period": -1.0}, "'pursuer.decision_period'"),
        ({"path": "x.npz", "radius": -1.0}, "'pursuer.radius'"),
    ],
)
def test_config_errors_name_the_key(params, message):
    with pytest.raises(ConfigError, match=message):
        registry.make_config("pursuer", PolicyPursuer, params)


def test_the_evader_has_no_belief_option():
    with pytest.raises(ConfigError, match="'evader.belief'"):
        registry.make_config("evader", PolicyEvader, {"path": "x.npz", "belief": True})


@pytest.mark.parametrize(
    ("path", "message"),
    [
        ("", "Missing value for 'pursuer.path'"),
        ("missing.npz", "does not exist"),
        ("no_such_module:f", "cannot load"),
        ("pegame.testing:RESOLUTION", "not callable"),
    ],
)
def test_unusable_policies_are_config_errors(path, message):
    with pytest.raises(ConfigError, match=message):
        game("pursuer=policy", f"pursuer.path='{path}'")


def test_policy_files_are_checked(tmp_path):
    bad = tmp_path / "bad.npz"
    np.savez(bad, weights=np.zeros((2, 3)))
    with pytest.raises(ConfigError, match="not a pegame linear policy"):
        load_policy(str(bad), "pursuer")
    evader = tmp_path / "evader.npz"
    LinearPolicy(np.zeros((2, 3)), np.zeros(2), "evader", ObservationSettings()).save(evader)
    with pytest.raises(ConfigError, match="policy for the evader"):
        load_policy(str(evader), "pursuer")
    with pytest.raises(ConfigError, match="expects 3 observation values"):
        game("evader=policy", f"evader.path={evader}")


def test_a_nan_action_is_an_error_and_large_ones_are_clipped():
    with pytest.raises(ValueError, match="finite"):
        game("pursuer=policy", "pursuer.path=pegame.testing:nan_policy").play("unused")
    pursuer = game_with_policy(
        compose([*SHORT, "pursuer=policy", "pursuer.path=pegame.testing:chase"])
    )
    pursuer.player.policy = lambda obs: np.array([10.0, -10.0])
    command = pursuer.control(observation_at(pursuer, 0))
    body = pursuer.context.pursuer
    assert (command.v, command.w) == (body.v_max, -body.w_max)


@pytest.mark.skipif(not (EXAMPLES / "cem_pursuer.npz").exists(), reason="no shipped policy")
def test_the_shipped_example_policy_plays():
    outcome = game("pursuer=policy", f"pursuer.path={EXAMPLES / 'cem_pursuer.npz'}").play("unused")
    assert 0.0 <= outcome.result["tracking_rate"] <= 1.0
