"""pegame.envs: the ecosystem's own API checkers, seeding, actions and observations (the crop's
own tests: tests/observe)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pegame.config import compose
from pegame.errors import ConfigError
from pegame.types import Pose

gymnasium = pytest.importorskip("gymnasium")
pettingzoo_test = pytest.importorskip("pettingzoo.test")

import pegame.envs
from pegame.envs import parallel_env

#: 3 s games on the smallest paper map keep every test short
SHORT = ["env=enclosed", "game.t_max=3"]
IDS = ["pegame/Pursuit-v0", "pegame/Evasion-v0"]


@pytest.fixture(scope="module")
def par_env():
    env = parallel_env(overrides=SHORT, crop_cells=8)
    yield env
    env.close()


def rollout(env, seed: int, action_seed: int = 0) -> list:
    """(observations, rewards, poses) of every step of one seeded game with random actions."""
    rng = np.random.default_rng(action_seed)
    obs, _ = env.reset(seed=seed)
    loop = env.game.loop
    steps = [(obs, None, (loop.pursuer, loop.evader))]
    while env.agents:
        actions = {agent: rng.uniform(-1, 1, 2).astype(np.float32) for agent in env.agents}
        obs, rewards, _, _, _ = env.step(actions)
        steps.append((obs, rewards, (loop.pursuer, loop.evader)))
    return steps


def same(a: list, b: list) -> bool:
    return len(a) == len(b) and all(
        pa == pb and ra == rb and all(np.array_equal(oa[k], ob[k]) for k in oa)
        for (oa, ra, pa), (ob, rb, pb) in zip(a, b)
    )


# ----------------------------------------------------------------- ecosystem checkers


def test_pettingzoo_parallel_api(par_env):
    pettingzoo_test.parallel_api_test(par_env, num_cycles=50)


def test_pettingzoo_parallel_seed():
    pettingzoo_test.parallel_seed_test(
        lambda: parallel_env(overrides=SHORT, crop_cells=8), num_cycles=10
    )


@pytest.mark.parametrize("env_id", IDS)
def test_gymnasium_check_env(env_id):
    from gymnasium.utils.env_checker import check_env

    env = gymnasium.make(
        env_id, overrides=[*SHORT, "game.t_max=1"], crop_cells=8, opponent="random"
    )
    check_env(env.unwrapped, skip_render_check=True)
    env.close()


def test_importing_registers_both_ids():
    assert set(IDS) <= set(gymnasium.registry)
    pegame.envs.register_envs()  # idempotent
    env = gymnasium.make("pegame.envs:pegame/Pursuit-v0", overrides=SHORT, crop_cells=4)
    assert env.observation_space.shape == (8 + 16,)


# --------------------------------------------------------------------------- seeding


def test_same_seed_same_trajectories_and_no_state_leaks(par_env):
    first = rollout(par_env, seed=7)
    rollout(par_env, seed=8)  # another game in between must not change the next one
    assert same(first, rollout(par_env, seed=7))
    assert not same(first, rollout(par_env, seed=9))
    fresh = parallel_env(overrides=SHORT, crop_cells=8)
    assert same(first, rollout(fresh, seed=7))


def test_seedless_resets_follow_the_last_seed(par_env):
    par_env.reset(seed=3)
    _, info_a = par_env.reset()
    par_env.reset(seed=3)
    _, info_b = par_env.reset()
    assert info_a["pursuer"]["seed"] == info_b["pursuer"]["seed"] != 3


@pytest.mark.parametrize("seed", [-1, 1.5, "0"])
def test_bad_seed_is_a_value_error(par_env, seed):
    with pytest.raises(ValueError, match="seed"):
        par_env.reset(seed=seed)


# --------------------------------------------------------------------------- actions


@pytest.mark.parametrize(
    ("action", "message"),
    [
        (np.array([np.nan, 0.0], np.float32), "finite"),
        (np.array([0.5, 0.2, 0.1], np.float32), "shape"),
        (np.array([1.5, 0.0], np.float32), r"\[-1, 1\]"),
        ("fast", "2 numbers"),
    ],
)
def test_bad_actions_raise_and_leave_the_game_untouched(par_env, action, message):
    par_env.reset(seed=0)
    loop = par_env.game.loop
    before = (loop.step, loop.pursuer, loop.evader)
    with pytest.raises(ValueError, match=message):
        par_env.step({"pursuer": np.zeros(2, np.float32), "evader": action})
    assert (loop.step, loop.pursuer, loop.evader) == before


def test_missing_or_unknown_agents_raise(par_env):
    par_env.reset(seed=0)
    with pytest.raises(ValueError, match="missing"):
        par_env.step({"pursuer": np.zeros(2, np.float32)})
    with pytest.raises(ValueError, match="unexpected"):
        par_env.step({"pursuer": np.zeros(2), "evader": np.zeros(2), "referee": np.zeros(2)})


def test_clip_actions_clips_finite_values_only():
    env = parallel_env(overrides=SHORT, crop_cells=4, clip_actions=True)
    clipped = rollout_with(env, np.array([3.0, -7.0], np.float32))
    exact = rollout_with(
        parallel_env(overrides=SHORT, crop_cells=4), np.array([1.0, -1.0], np.float32)
    )
    assert clipped == exact
    env.reset(seed=0)
    with pytest.raises(ValueError, match="finite"):
        env.step({"pursuer": np.array([np.inf, 0.0]), "evader": np.zeros(2)})


def rollout_with(env, action: np.ndarray) -> list[tuple[Pose, Pose]]:
    env.reset(seed=1)
    poses = []
    while env.agents:
        env.step({"pursuer": action, "evader": action})
        poses.append((env.game.loop.pursuer, env.game.loop.evader))
    return poses


def test_step_before_reset_raises():
    env = parallel_env(overrides=SHORT, crop_cells=4)
    with pytest.raises(RuntimeError, match="reset"):
        env.step({"pursuer": np.zeros(2), "evader": np.zeros(2)})


# ------------------------------------------------------------ rewards, infos, periods


def test_zero_sum_rewards_count_detections_and_info_ends_with_the_metrics(par_env):
    steps = rollout(par_env, seed=2)
    rewards = [r for _, r, _ in steps[1:]]
    assert all(r["pursuer"] == -r["evader"] in (0.0, 1.0) for r in rewards)
    assert len(rewards) == 30  # 3 s at 10 Hz, one control tick per step
    loop = par_env.game.loop
    summary = loop.metrics.summary()
    info = par_env.game.info()
    assert info["metrics"] == summary and info["tracking_rate"] == pytest.approx(
        summary["tracking_rate"]
    )
    # Rewards count detections at ticks 1..30, the measure ticks 0..29.
    first = loop.metrics.detected[0]
    assert sum(r["pursuer"] for r in rewards) == 30 * summary["tracking_rate"] - first + (
        loop.detection is not None
    )


def test_decision_period_holds_each_action_for_whole_ticks():
    env = parallel_env(overrides=SHORT, crop_cells=4, decision_period=0.4)
    rewards = [r for _, r, _ in rollout(env, seed=0)[1:]]
    assert len(rewards) == 8  # 30 ticks in steps of 4, the last one shorter
    assert all(0 <= r["pursuer"] <= 4 for r in rewards)
    with pytest.raises(ConfigError, match="decision_period"):
        parallel_env(overrides=SHORT, decision_period=0.15)


def test_single_agent_envs_play_against_the_chosen_opponent():
    env = gymnasium.make("pegame/Evasion-v0", overrides=SHORT, opponent="random", crop_cells=4)
    assert env.unwrapped.opponent == "random"
    obs, info = env.reset(seed=0)
    total = 0.0
    truncated = False
    while not truncated:
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        assert not terminated and reward <= 0.0
        total += reward
    assert "metrics" in info and obs in env.observation_space
    default = gymnasium.make("pegame/Pursuit-v0", overrides=SHORT, crop_cells=4)
    assert default.unwrapped.opponent == "smart"


def test_config_and_opponent_must_agree():
    cfg = compose([*SHORT, "evader=random"])
    env = gymnasium.make("pegame/Pursuit-v0", config=cfg, crop_cells=4)
    assert env.unwrapped.opponent == "random"
    with pytest.raises(ConfigError, match="opponent"):
        gymnasium.make("pegame/Pursuit-v0", config=cfg, opponent="smart")
    with pytest.raises(ConfigError, match="not both"):
        gymnasium.make("pegame/Pursuit-v0", config=cfg, overrides=SHORT)


def test_belief_summary_is_optional_and_runs_the_estimator():
    env = parallel_env(overrides=SHORT, crop_cells=4, belief=True)
    obs, _ = env.reset(seed=0)
    layout = env.layouts["pursuer"]
    assert layout["belief"] == slice(8, 12) and obs["pursuer"].shape == (12 + 16,)
    assert obs["pursuer"][8] == 1.0  # the particle filter starts on the first detection
    assert "belief" not in parallel_env(overrides=SHORT, crop_cells=4).layouts["pursuer"]


# ------------------------------------------------------------------------ observations


def test_observations_lie_in_their_space_and_start_with_a_detection(par_env):
    obs, _ = par_env.reset(seed=4)
    for agent, vector in obs.items():
        assert vector.dtype == np.float32 and vector in par_env.observation_space(agent)
    p = obs["pursuer"]
    assert p[4] == 1.0 and 0.0 < p[5] <= 1.0 and p[7] == 0.0  # seen now, in range, age 0
    layout = par_env.layouts["evader"]
    assert (
        set(layout) == {"pose", "pursuer", "relative", "crop"}
        and layout["crop"].stop == obs["evader"].size
    )


def test_pose_features_are_normalised_by_the_map_extent(par_env):
    par_env.reset(seed=4)
    loop = par_env.game.loop
    p = par_env.game.observations()["pursuer"]
    x0, x1, y0, y1 = loop.context.grid.extent
    pose = loop.pursuer
    assert p[0] == pytest.approx(2 * (pose.x - x0) / (x1 - x0) - 1, abs=1e-6)
    assert p[1] == pytest.approx(2 * (pose.y - y0) / (y1 - y0) - 1, abs=1e-6)
    assert p[2:4] == pytest.approx([math.cos(pose.theta), math.sin(pose.theta)], abs=1e-6)


def test_bench_reports_steps_per_second():
    figures = pegame.envs.bench_steps_per_second(seconds=0.2, overrides=SHORT)
    assert figures["steps_per_s"] > 0 and figures["reset_ms"] > 0


def test_unknown_options_suggest_the_closest():
    with pytest.raises(ConfigError, match="Did you mean 'crop_cells'"):
        parallel_env(overrides=SHORT, crop_cell=8)
    with pytest.raises(ConfigError, match="'crop_resolution'"):
        parallel_env(overrides=SHORT, crop_resolution=0.0)


@pytest.mark.parametrize(
    ("env_id", "team"), [(IDS[0], "team.pursuers=2"), (IDS[1], "team.evaders=2")]
)
def test_the_single_agent_envs_refuse_a_team_naming_the_key(env_id, team):
    # they built the team game and failed at reset with KeyError: 'pursuer' ('evader')
    key = team.split("=")[0]
    with pytest.raises(ConfigError, match=rf"Invalid value for '{key}' in {env_id}: 2"):
        gymnasium.make(env_id, overrides=[*SHORT, team])


def test_a_misspelt_opponent_gets_did_you_mean():
    from pegame.errors import PluginChoiceError

    with pytest.raises(PluginChoiceError, match="Unknown evader 'smrt'. Did you mean 'smart'?"):
        gymnasium.make(IDS[0], overrides=SHORT, opponent="smrt")


def test_the_old_observations_path_is_a_deprecated_re_export(monkeypatch):
    import importlib
    import sys

    import pegame.observe.observations as observations

    monkeypatch.delitem(sys.modules, "pegame.envs.observations", raising=False)
    with pytest.deprecated_call(match="pegame.observe.observations"):
        old = importlib.import_module("pegame.envs.observations")
    assert old.ObservationSettings is observations.ObservationSettings
