"""The batched smart evader (pegame.evaders.smart_batch) plays the strategy's games: a
batched env against it and one against the per-game strategy (SmartEvader driven game by
game in Python, as any evader strategy is) move the same, bit for bit, over whole games."""

from __future__ import annotations

import numpy as np
import pytest

from pegame.envs.vector import vector_env
from pegame.evaders.smart import SmartEvader
from pegame.navigation import goals
from pegame.vector.opponents import SmartEvaderOpponent, StrategyOpponent


def per_game_strategy(env) -> None:
    """Give ``env``'s batched game the smart evader as a per-game strategy opponent."""
    game = env.game
    config = game.scenario.configs["evader"]
    game.opponent = StrategyOpponent(SmartEvader, config, game.context, game.num_games)


@pytest.mark.parametrize(
    "overrides",
    [
        ["env=enclosed"],
        ["env=office", "evader.hide_margin=0", "evader.candidate_stride=2"],
        ["env=hall", "+experiment=paper_conditions", "game.turn_order=simultaneous"],
    ],
)
def test_the_batched_smart_evader_moves_as_the_strategy(overrides):
    assert_moves_as_the_strategy([*overrides, "game.t_max=40"], n=6)


def test_paths_longer_than_the_room_grow_it(monkeypatch):
    """Room for 4 waypoints at first: most new paths grow it, mid-tick, with the games
    before the one that did not fit already commanded."""
    monkeypatch.setattr(goals, "FIRST_CAPACITY", 4)
    env = assert_moves_as_the_strategy(["env=enclosed", "game.t_max=20"], n=4)
    assert env.game.opponent.batch.paths.waypoints.shape[1] > 4


def assert_moves_as_the_strategy(overrides, n):
    """Play ``n`` whole games of ``overrides`` against both opponents; the batched env."""
    batched, strategy = (vector_env(n, overrides=overrides, opponent="smart") for _ in range(2))
    assert isinstance(batched.game.opponent, SmartEvaderOpponent)
    per_game_strategy(strategy)
    rng = np.random.default_rng(3)
    for env in (batched, strategy):
        env.reset(seed=11)
    decided = 0
    for _ in range(batched.game.steps):
        actions = rng.uniform(-1.0, 1.0, (n, 2)).astype(np.float32)
        out_b, out_s = batched.step(actions), strategy.step(actions)
        for got, want in zip(out_b[:4], out_s[:4]):
            np.testing.assert_array_equal(got, want)
        np.testing.assert_array_equal(batched.game.state.poses, strategy.game.state.poses)
        decided += int((batched.game.opponent.batch.paths.goal_cell >= 0).sum())
    assert decided > 0  # the evaders had goals to follow, not only stops
    return batched


def test_geodesic_distances_are_played_by_the_per_game_strategy():
    env = vector_env(2, overrides=["env=hall", "evader.distance=geodesic"], opponent="smart")
    assert isinstance(env.game.opponent, StrategyOpponent)
