"""The batched envs (pegame.envs.vector) play the single env's games: step by step against
gymnasium's SyncVectorEnv of the single envs with the same seeds, through autoresets."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest
from gymnasium.vector import SyncVectorEnv

from pegame.envs.parallel import parallel_env
from pegame.envs.single import EvasionEnv, PursuitEnv
from pegame.envs.vector import (
    EvasionVectorEnv,
    PursuitVectorEnv,
    SelfPlayVectorEnv,
    vector_env,
)
from pegame.errors import ConfigError

#: short games on a paper map; a few steps more than one game, to cross an autoreset
SHORT = ["env=enclosed", "game.t_max=2"]
#: the measures of the estimator, which a batched game does not run
ESTIMATION = ("mean_estimation_error", "n_eff_mean", "n_eff_min", "resamplings")


def assert_infos_equal(batched: dict, synced: dict, path: str = "info") -> None:
    """The same infos, but for the loss causes, which a batched game does not keep (None)."""
    assert sorted(batched) == sorted(synced), path
    for key, value in synced.items():
        if key == "loss_causes":
            assert all(cause is None for cause in batched[key][batched[f"_{key}"]]), path
            continue
        if isinstance(value, dict):
            assert_infos_equal(batched[key], value, f"{path}.{key}")
        else:
            got = np.asarray(batched[key])
            assert got.dtype == value.dtype, f"{path}.{key}: {got.dtype} != {value.dtype}"
            assert got.tolist() == value.tolist(), f"{path}.{key}"


def play_side_by_side(batched, synced, seed: int, steps: int, rng) -> int:
    """Step both envs with the same random actions; returns the games that ended."""
    obs_b, info_b = batched.reset(seed=seed)
    obs_s, info_s = synced.reset(seed=seed)
    np.testing.assert_array_equal(obs_b, obs_s)
    assert_infos_equal(info_b, info_s)
    ended = 0
    for _ in range(steps):
        actions = rng.uniform(-1.0, 1.0, (batched.num_envs, 2)).astype(np.float32)
        out_b, out_s = batched.step(actions), synced.step(actions)
        for got, want in zip(out_b[:4], out_s[:4]):
            np.testing.assert_array_equal(got, want)
        assert_infos_equal(out_b[4], out_s[4])
        ended += int(out_s[3].sum())
    return ended


@pytest.mark.parametrize(
    ("opponent", "model"),
    [("random", "action"), ("random", "waypoint"), ("smart", None)],
)
def test_pursuit_plays_the_single_envs_games(opponent, model):
    overrides = SHORT + ([f"evader.model={model}"] if model else [])
    n = 3
    batched = vector_env(n, overrides=overrides, opponent=opponent, decision_period=0.2)
    synced = SyncVectorEnv(
        [
            lambda: PursuitEnv(overrides=overrides, opponent=opponent, decision_period=0.2)
            for _ in range(n)
        ]
    )
    ended = play_side_by_side(batched, synced, seed=7, steps=14, rng=np.random.default_rng(0))
    assert ended == n  # one game each ended, and the next ones played on identically


def test_acceleration_limits_and_substeps_are_played_not_ignored():
    """The batched move ramps the velocities (a_max, alpha_max) and integrates the
    physics substeps as the grid simulator does: the single env's games, bit for bit."""
    overrides = [
        *SHORT,
        "evader.model=action",
        "pursuer.a_max=0.5",
        "pursuer.alpha_max=1.0",
        "evader.a_max=0.8",
        "game.physics_hz=30",
    ]
    batched = vector_env(2, overrides=overrides, opponent="random")
    synced = SyncVectorEnv(
        [lambda: PursuitEnv(overrides=overrides, opponent="random") for _ in range(2)]
    )
    ended = play_side_by_side(batched, synced, seed=4, steps=24, rng=np.random.default_rng(5))
    assert ended == 2


#: the perception model as the batched game plays it: the paper's conditions but their
#: turns (which no env plays), and every part it plays at once, with frequent misses
PERCEPTION = {
    "paper": ["+experiment=paper_conditions", "game.turn_order=simultaneous"],
    "parts": [
        "detector.rate=3",
        "detector.latency=0.25",
        "detector.detection_range=5",
        "detector.miss_range_start=1",
        "detector.miss_at_range=0.8",
        "detector.occlusion_miss=0.5",
    ],
    "noise": [
        "detector.miss_probability=0.3",
        "detector.range_noise=0.05",
        "detector.range_noise_growth=0.02",
        "detector.bearing_noise=0.03",
        "detector.miss_range_start=1",
        "detector.miss_at_range=0.5",
        "detector.rate=5",
        "detector.burst_miss_fraction=0.3",
        "detector.burst_length=0.4",
        "detector.false_positive_rate=2",
    ],
}


@pytest.mark.parametrize(
    ("conditions", "role", "opponent"),
    [
        ("paper", "pursuer", "smart"),
        ("parts", "pursuer", "random"),
        ("paper", "evader", "smart"),
        ("noise", "pursuer", "random"),
    ],
)
def test_the_perception_model_plays_the_single_envs_games(conditions, role, opponent):
    """Rate, latency, detection range, the range and occlusion misses, the independent
    misses and the depth and bearing noise: the pipeline and the miss chance are the
    scalar detector's kernels, run on the batch, and the draws are the oracle's, drawn
    ahead in its order."""
    overrides = ["env=enclosed", *PERCEPTION[conditions], "game.t_max=4"]
    if opponent == "random":
        overrides.append(f"{'evader' if role == 'pursuer' else 'pursuer'}.model=action")
    single = PursuitEnv if role == "pursuer" else EvasionEnv
    batched = vector_env(3, overrides=overrides, opponent=opponent, role=role, decision_period=0.2)
    synced = SyncVectorEnv(
        [
            lambda: single(overrides=overrides, opponent=opponent, decision_period=0.2)
            for _ in range(3)
        ]
    )
    ended = play_side_by_side(batched, synced, seed=2, steps=24, rng=np.random.default_rng(6))
    assert ended == 3
    assert batched.game.state.drawn.sum() > 0  # the misses were drawn for
    if conditions == "noise":  # each kind of draw taken in some game
        assert (batched.game.state.noise_drawn.max(axis=0) > 0).all()


@pytest.mark.parametrize(("opponent", "model"), [("random", "action"), ("smart", None)])
def test_a_belief_observation_plays_the_single_envs_games(opponent, model):
    """With ``belief=True`` each game runs the estimator in Python, as the single env
    does: the belief part of the observation and the estimation measures are its own."""
    overrides = SHORT + ([f"evader.model={model}"] if model else [])
    settings = {"decision_period": 0.2, "belief": True}
    batched = vector_env(2, overrides=overrides, opponent=opponent, **settings)
    synced = SyncVectorEnv(
        [lambda: PursuitEnv(overrides=overrides, opponent=opponent, **settings) for _ in range(2)]
    )
    ended = play_side_by_side(batched, synced, seed=3, steps=13, rng=np.random.default_rng(4))
    assert ended == 2
    belief = batched.layout["belief"]
    assert np.any(batched.game.observations("pursuer")[:, belief] != 0.0)  # read, not zeros


def test_evasion_against_random_actions_plays_the_single_envs_games():
    overrides = SHORT + ["pursuer.model=action"]
    batched = vector_env(2, overrides=overrides, opponent="random", role="evader")
    synced = SyncVectorEnv(
        [lambda: EvasionEnv(overrides=overrides, opponent="random") for _ in range(2)]
    )
    rng = np.random.default_rng(1)
    ended = 0
    obs_b, _ = batched.reset(seed=3)
    obs_s, _ = synced.reset(seed=3)
    np.testing.assert_array_equal(obs_b, obs_s)
    for _ in range(25):
        actions = rng.uniform(-1.0, 1.0, (2, 2)).astype(np.float32)
        out_b, out_s = batched.step(actions), synced.step(actions)
        for got, want in zip(out_b[:4], out_s[:4]):
            np.testing.assert_array_equal(got, want)
        # The single env runs the estimator for the pursuer strategy, the batched one does
        # not: every other measure is the same.
        for key in ESTIMATION:
            out_s[4].get("metrics", {}).pop(key, None)
            out_s[4].get("metrics", {}).pop(f"_{key}", None)
            out_b[4].get("metrics", {}).pop(key, None)
            out_b[4].get("metrics", {}).pop(f"_{key}", None)
        assert_infos_equal(out_b[4], out_s[4])
        ended += int(out_s[3].sum())
    assert ended == 2


@pytest.mark.parametrize(("opponent", "model"), [("smart", None), ("random", "waypoint")])
def test_evasion_against_pursuer_strategies_plays_the_single_envs_games(opponent, model):
    """A pursuer strategy reads the belief: the batched game runs the estimator for it."""
    overrides = SHORT + ([f"pursuer.model={model}"] if model else [])
    batched = vector_env(2, overrides=overrides, opponent=opponent, role="evader")
    synced = SyncVectorEnv(
        [lambda: EvasionEnv(overrides=overrides, opponent=opponent) for _ in range(2)]
    )
    ended = play_side_by_side(batched, synced, seed=5, steps=22, rng=np.random.default_rng(3))
    assert ended == 2


@pytest.mark.parametrize("belief", [False, True])
def test_self_play_plays_the_parallel_envs_game(belief):
    batched = SelfPlayVectorEnv(1, overrides=SHORT, belief=belief)
    single = parallel_env(overrides=SHORT, belief=belief)
    obs_b, _ = batched.reset(seed=11)
    obs_s, _ = single.reset(seed=11)
    rng = np.random.default_rng(2)
    for role in ("pursuer", "evader"):
        np.testing.assert_array_equal(obs_b[role][0], obs_s[role])
    for _ in range(20):
        actions = {
            role: rng.uniform(-1, 1, (1, 2)).astype(np.float32) for role in ("pursuer", "evader")
        }
        obs_b, rew_b, _, trunc_b, info_b = batched.step(actions)
        obs_s, rew_s, _, trunc_s, info_s = single.step({r: a[0] for r, a in actions.items()})
        for role in ("pursuer", "evader"):
            np.testing.assert_array_equal(obs_b[role][0], obs_s[role])
            assert rew_b[role][0] == rew_s[role]
            assert trunc_b[role][0] == trunc_s[role]
        assert info_b["tracking_rate"][0] == info_s["pursuer"]["tracking_rate"]
        if trunc_s["pursuer"]:
            measures = {k: v[0] for k, v in info_b["metrics"].items() if not k.startswith("_")}
            assert measures.pop("loss_causes") is None  # not kept by the batched game
            assert measures == {
                k: v for k, v in info_s["pursuer"]["metrics"].items() if k != "loss_causes"
            }
            break
    else:
        pytest.fail("the game did not end")


def test_spaces_are_the_single_envs_batched():
    env = vector_env(5, overrides=SHORT, opponent="random")
    single = PursuitEnv(overrides=SHORT, opponent="random")
    assert env.single_observation_space == single.observation_space
    assert env.single_action_space == single.action_space
    assert env.observation_space.shape == (5, *single.observation_space.shape)
    assert env.action_space.shape == (5, 2)
    obs, info = env.reset(seed=0)
    assert obs in env.observation_space and info["_seed"].all()
    assert info["seed"].tolist() == [0, 1, 2, 3, 4]
    actions = env.action_space.sample()
    stepped, *_ = env.step(actions)
    assert stepped in env.observation_space
    # As gymnasium's env checker asks of a single env: seeded resets are deterministic and
    # the returned arrays are not reused by later calls.
    again, _ = env.reset(seed=0)
    np.testing.assert_array_equal(again, obs)
    assert not np.shares_memory(again, obs)
    np.testing.assert_array_equal(env.step(actions)[0], stepped)


def test_gymnasium_vector_wrappers_run_on_it():
    """Gymnasium 1.x ships no vector-env checker; its vector wrappers exercise the API
    (spaces, step tuple, autoreset metadata, info masks)."""
    env = gymnasium.wrappers.vector.RecordEpisodeStatistics(
        vector_env(4, overrides=SHORT + ["evader.model=action"], opponent="random")
    )
    env.reset(seed=1)
    episodes = 0
    for _ in range(25):
        *_, infos = env.step(env.action_space.sample())
        if "episode" in infos:
            episodes += int(infos["_episode"].sum())
            assert (infos["episode"]["l"][infos["_episode"]] == 20).all()
    assert episodes == 4


def test_make_vec_builds_the_batched_env():
    """gymnasium.make_vec uses the registered vector_entry_point: the batched env, which
    plays the games of its "sync" mode (SyncVectorEnv of the single env)."""
    kwargs = {"overrides": SHORT + ["evader.model=action"], "opponent": "random"}
    batched = gymnasium.make_vec("pegame/Pursuit-v0", num_envs=3, **kwargs)
    synced = gymnasium.make_vec(
        "pegame/Pursuit-v0", num_envs=3, vectorization_mode="sync", **kwargs
    )
    assert isinstance(batched, PursuitVectorEnv) and isinstance(synced, SyncVectorEnv)
    assert isinstance(gymnasium.make_vec("pegame/Evasion-v0", num_envs=2), EvasionVectorEnv)
    assert play_side_by_side(batched, synced, 5, 25, np.random.default_rng(9)) == 3


def test_a_boolean_seed_is_a_clear_error():
    """True is an int to Python; as a seed it was iterated (a TypeError), as the single
    envs refuse it with a ValueError."""
    env = vector_env(2, overrides=SHORT + ["evader.model=action"], opponent="random")
    with pytest.raises(ValueError, match="got True"):
        env.reset(seed=True)


def test_bad_actions_and_unsupported_configs_are_clear_errors():
    env = vector_env(2, overrides=SHORT + ["evader.model=action"], opponent="random")
    with pytest.raises(RuntimeError, match="reset"):
        env.step(np.zeros((2, 2), np.float32))
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"\[-1, 1\]"):
        env.step(np.full((2, 2), 2.0, np.float32))
    with pytest.raises(ValueError, match="shape"):
        env.step(np.zeros((3, 2), np.float32))
    with pytest.raises(ConfigError, match="game.turn_order"):
        vector_env(2, overrides=SHORT + ["game.turn_order=evader_first"])
    with pytest.raises(ConfigError, match="role"):
        vector_env(2, overrides=SHORT, role="referee")


def test_a_team_is_refused_against_an_opponent_not_played_as_1v1():
    # vector_env(..., overrides=["team.pursuers=3", "team.evaders=2"]) played 1v1 silently;
    # the single-agent envs refuse a team too: a team plays in self-play
    with pytest.raises(ConfigError, match="'team.pursuers': 3 .*; 'team.evaders': 2 "):
        vector_env(2, overrides=["env=hall", "team.pursuers=3", "team.evaders=2"])
    with pytest.raises(ConfigError, match="'team.evaders' in a batched env: 2"):
        vector_env(2, overrides=["env=hall", "team.evaders=2"], role="evader")


def play_teams_side_by_side(overrides: list[str], n: int, seed: int, steps: int) -> int:
    """A batched self-play env of ``n`` team games against ``n`` single PettingZoo envs
    seeded as its games are, stepped with the same random actions: every observation,
    reward, truncation and info the same, through an autoreset. Returns the games ended."""
    batched = SelfPlayVectorEnv(n, overrides=overrides, decision_period=0.3)
    singles = [parallel_env(overrides=overrides, decision_period=0.3) for _ in range(n)]
    assert batched.possible_agents == singles[0].possible_agents
    obs_b, _ = batched.reset(seed=seed)
    for i, single in enumerate(singles):
        obs_s, _ = single.reset(seed=seed + i)
        for agent in single.possible_agents:
            np.testing.assert_array_equal(obs_b[agent][i], obs_s[agent])
    rng, ended = np.random.default_rng(seed), 0
    for _ in range(steps):
        actions = {
            agent: rng.uniform(-1, 1, (n, 2)).astype(np.float32)
            for agent in batched.possible_agents
        }
        obs_b, rew_b, _, trunc_b, info_b = batched.step(actions)
        for i, single in enumerate(singles):
            if not single.agents:  # the batched game autoresets: the single env resets
                seed_i = int(info_b["seed"][i])
                obs_s, _ = single.reset(seed=seed_i)
                for agent in single.possible_agents:
                    np.testing.assert_array_equal(obs_b[agent][i], obs_s[agent])
                continue
            obs_s, rew_s, _, trunc_s, info_s = single.step(
                {agent: a[i] for agent, a in actions.items()}
            )
            for agent in single.possible_agents:
                np.testing.assert_array_equal(obs_b[agent][i], obs_s[agent])
                assert rew_b[agent][i] == rew_s[agent], agent
                assert trunc_b[agent][i] == trunc_s[agent]
            first = single.possible_agents[0]
            assert info_b["tracking_rate"][i] == info_s[first]["tracking_rate"]
            if trunc_s[first]:
                ended += 1
                got = {k: v[i] for k, v in info_b["metrics"].items() if not k.startswith("_")}
                assert got.pop("loss_causes") is None  # not kept by the batched game
                want = dict(info_s[first]["metrics"])
                want.pop("loss_causes")
                assert got == want
    return ended


@pytest.mark.slow
@pytest.mark.parametrize(
    "team",
    [
        ["team.pursuers=2", "team.evaders=2"],
        ["team.pursuers=3", "team.evaders=1"],
        ["team.pursuers=1", "team.evaders=2", *PERCEPTION["parts"], "pursuer.a_max=0.5"],
        ["team.pursuers=2", "team.evaders=2", *PERCEPTION["paper"]],
    ],
)
def test_team_self_play_plays_the_parallel_envs_team_games(team):
    """Every member's move, each detector pair's detection (its own miss stream and
    pipeline), the nearest pursuer, the team's rewards and TeamMetrics' measures."""
    overrides = ["env=enclosed", "game.t_max=3", "game.physics_hz=20", *team]
    ended = play_teams_side_by_side(overrides, n=2, seed=5, steps=14)
    assert ended == 2  # one game each ended, and the next ones played on identically


def test_a_team_game_hands_the_evader_over_and_sums_the_teams_reward():
    """The measures the team game adds are counted, not left at zero: the games of a
    two-pursuer team see handoffs, and the pursuers' reward is the sum of the evaders'."""
    overrides = ["env=hall", "game.t_max=20", "team.pursuers=3", "team.evaders=2"]
    env = SelfPlayVectorEnv(16, overrides=overrides)
    env.reset(seed=3)
    rng = np.random.default_rng(1)
    totals = dict.fromkeys(env.possible_agents, 0.0)
    while True:
        actions = {a: rng.uniform(-1, 1, (16, 2)).astype(np.float32) for a in env.possible_agents}
        _, rewards, _, trunc, infos = env.step(actions)
        np.testing.assert_array_equal(
            rewards["pursuer_0"], -(rewards["evader_0"] + rewards["evader_1"])
        )
        for agent, reward in rewards.items():
            totals[agent] += float(reward.sum())
        if trunc["pursuer_0"].all():
            break
    handoffs = infos["metrics"]["handoffs"]
    assert totals["pursuer_0"] > 0 and sum(handoffs) > 0
    assert all(len(rates) == 3 for rates in infos["metrics"]["tracking_rate_per_pursuer"])
