"""The batched smart evader (pegame.evaders.smart_batch) plays the strategy's games: a
batched env against it and one against the per-game strategy (SmartEvader driven game by
game in Python, as any evader strategy is) move the same, bit for bit, over whole games."""

from __future__ import annotations

import math

import numba
import numpy as np
import pytest

from pegame.api import Context, EvaderObservation
from pegame.envs.vector import vector_env
from pegame.evaders import smart_batch
from pegame.evaders.smart import SmartEvader
from pegame.evaders.smart_batch import SmartEvaderBatch
from pegame.grid import FREE, OCCUPIED, OccupancyGrid
from pegame.navigation import goals
from pegame.registry import make_config
from pegame.types import Body, Camera, Pose
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


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="numba has one thread")
def test_games_on_two_threads_move_as_the_strategy(monkeypatch):
    """The games spread over two threads (each with its own scratch memory) move as the
    per-game strategy does, which plays them one by one."""
    monkeypatch.setattr(smart_batch, "MIN_GAMES_PER_THREAD", 1)
    threads = numba.get_num_threads()
    numba.set_num_threads(2)
    try:
        env = assert_moves_as_the_strategy(["env=enclosed", "game.t_max=20"], n=6)
    finally:
        numba.set_num_threads(threads)
    pool, count = env.game.opponent.batch._threads
    assert count == 2
    env.close()  # the env's close stops the threads
    assert env.game.opponent.batch._threads is None
    with pytest.raises(RuntimeError, match="shutdown"):
        pool.submit(int)


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


def test_evaders_in_two_rooms_each_escape_in_their_own_room():
    """Games whose evaders stand in different connected components (a wall splits the
    map): each game's commands are those of a strategy of its own, the pool's second
    component found by its offsets."""
    data = np.full((40, 60), FREE, dtype=np.int8)
    data[[0, -1], :] = data[:, [0, -1]] = OCCUPIED
    data[:, 30:32] = OCCUPIED  # the wall between the rooms
    grid = OccupancyGrid(data, 0.1)
    camera = Camera(fov=math.pi / 3, near=0.3, far=5.0, angle_step=0.004, distance_step=0.05)
    evader, pursuer = Body(0.12, 0.5, 1.8), Body(0.08, 0.5, 1.8)
    context = Context(grid, pursuer, evader, camera, control_dt=0.1, decision_dt=1.0)
    config = make_config("evader", SmartEvader, {"radius": 0.12, "v_max": 0.5, "w_max": 1.8})
    # (pursuer, evader) per game: the right room's evaders come second and fourth
    starts = [((1.0, 2.0, 0.3), (1.6, 1.1, 0.0)), ((4.2, 2.0, 3.0), (4.6, 3.1, 1.0))] * 2
    poses = np.array(starts, dtype=float)
    batch = SmartEvaderBatch(config, context, len(starts))
    strategies = [SmartEvader(config, context, np.random.default_rng(0)) for _ in starts]
    for game, strategy in enumerate(strategies):
        batch.reset(game)
        strategy.reset(Pose(*poses[game, 1]))
    games = np.arange(len(starts))
    for tick in range(60):
        commands = np.zeros((len(starts), 2, 2))
        batch.command(poses, commands, games, np.full(len(starts), tick % 10 == 0))
        for game, strategy in enumerate(strategies):
            pursuer_pose, me = Pose(*poses[game, 0]), Pose(*poses[game, 1])
            observation = EvaderObservation(0.1 * tick, me, pursuer_pose)
            if tick % 10 == 0:
                strategy.decide(observation)
            want = strategy.control(observation)
            assert tuple(commands[game, 1]) == (want.v, want.w)
            v, w = want.v, want.w  # the evader moves by its command (Euler)
            x, y, theta = poses[game, 1]
            poses[game, 1] = (
                x + 0.1 * v * math.cos(theta),
                y + 0.1 * v * math.sin(theta),
                theta + 0.1 * w,
            )
    assert len(batch._components) == 2
    assert (batch.paths.goal_cell % grid.width >= 32).tolist() == [False, True, False, True]
