"""Timing as the paper had it: the simulator's integration step apart from the agents'
command rate (``game.physics_hz``), acceleration limits (``*.a_max``, ``*.alpha_max``) and
the paper's turn order (``game.turn_order=evader_first``), all off by default."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pegame.api import Context, Evader, Pursuer, Simulator
from pegame.config import GameConfig, compose
from pegame.errors import ConfigError
from pegame.game import Game
from pegame.loop import TickLoop
from pegame.navigation import inflate
from pegame.sims.grid import GridSimulator, unicycle
from pegame.testing import walled_room
from pegame.types import Body, Camera, Plan, Pose, Velocity

SHORT = ["recorder=none", "env=enclosed"]


class Constant:
    """A strategy mixin: the same command every tick, every observation kept."""

    command = Velocity(0.4, 0.0)

    def reset(self, pose):
        self.seen = []

    def decide(self, observation):
        return Plan()

    def control(self, observation):
        self.seen.append(observation)
        return self.command


class ConstantPursuer(Constant, Pursuer):
    pass


class ConstantEvader(Constant, Evader):
    command = Velocity(0.3, 0.5)


STRAIGHT, ARC = Velocity(0.4, 0.0), Velocity(0.3, 0.5)


def constant_game(overrides, pursuer=STRAIGHT, evader=ARC):
    """A game of ``overrides`` whose agents hold constant commands."""
    game = Game(compose([*SHORT, *overrides]))
    for role, cls, command in (
        ("pursuer", ConstantPursuer, pursuer),
        ("evader", ConstantEvader, evader),
    ):
        strategy = cls(cls.Config(), game.context, np.random.default_rng(0))
        strategy.command = command
        game.plugins = replace(game.plugins, **{f"{role}s": (strategy,)})
    return game


def poses_every(game, seconds=1.0):
    """The true (pursuer, evader) poses at the start of each tick, one per ``seconds``."""
    loop = game.start()
    every = int(round(seconds / game.context.control_dt))
    poses = []
    while not loop.done:
        tick = loop.advance()
        if tick.step % every == 0:
            poses.append((tick.pursuer, tick.evader))
    return poses


def test_the_defaults_are_todays_timing():
    settings_ = GameConfig()
    assert settings_.physics_hz is None and settings_.substeps == 1
    assert settings_.turn_order == "simultaneous"
    body = Body(0.2, 0.5, 1.8)
    assert math.isinf(body.a_max) and math.isinf(body.alpha_max)
    today = Game(compose([*SHORT, "game.t_max=5"])).play("unused").result
    explicit = ["game.t_max=5", "game.physics_hz=10", "game.turn_order=simultaneous"]
    assert Game(compose([*SHORT, *explicit])).play("unused").result == today


@pytest.mark.parametrize("evader", [Velocity(0.3, 0.0), Velocity(0.3, 0.5)])
def test_commands_held_over_substeps_drive_the_path_of_the_fast_control_rate(evader):
    """physics_hz=10 at control_hz=1: the same path, bit for bit, as control_hz=10 with
    the same commands (straight into walls, and arcs), which control_hz=1 alone is not."""
    common = ["game.t_max=30", "game.seed=3"]
    fast = poses_every(constant_game([*common, "game.control_hz=10"], evader=evader))
    held = poses_every(
        constant_game([*common, "game.control_hz=1", "game.physics_hz=10"], evader=evader)
    )
    coarse = poses_every(constant_game([*common, "game.control_hz=1"], evader=evader))
    assert held == fast
    assert coarse != fast  # 1 s steps cut the arcs' chords and stop short of walls
    stopped = [a[0] == b[0] for a, b in zip(held, held[1:])]
    assert any(stopped) and not all(stopped)  # the straight drive did reach a wall


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 2**16),
    substeps=st.integers(1, 12),
    control_dt=st.sampled_from([0.1, 0.5, 1.0]),
)
def test_substeps_never_enter_walls(seed, substeps, control_dt):
    grid = walled_room()
    pursuer, evader = Body(0.2, 0.8, 3.0), Body(0.25, 0.8, 3.0)
    context = Context(grid, pursuer, evader, Camera(), control_dt, control_dt)
    sim = GridSimulator(GridSimulator.Config(), context, np.random.default_rng(0))
    sim.reset((Pose(*grid.cell_to_world(10, 10)),), (Pose(*grid.cell_to_world(50, 70)),))
    masks = inflate(grid, pursuer.radius), inflate(grid, evader.radius)
    rng = np.random.default_rng(seed)
    for _ in range(30):
        commands = [(Velocity(*rng.uniform(-1.0, 1.0, 2) * [0.8, 3.0]),) for _ in range(2)]
        for _ in range(substeps):
            sim.step(*commands, control_dt / substeps)
            for (pose,), mask in zip(sim.poses, masks):
                row, col = grid.world_to_cell(pose.x, pose.y)
                assert grid.contains(row, col) and not mask[row, col]


@pytest.mark.parametrize(
    ("override", "key"),
    [
        ("game.physics_hz=15", "game.physics_hz"),  # not a whole multiple of 10 Hz
        ("game.physics_hz=5", "game.physics_hz"),  # slower than the control rate
        ("game.physics_hz=-10", "game.physics_hz"),
        ("game.turn_order=pursuer_first", "game.turn_order"),
        ("pursuer.a_max=0", "pursuer.a_max"),
        ("evader.alpha_max=-1", "evader.alpha_max"),
    ],
)
def test_bad_timing_values_name_their_key(override, key):
    with pytest.raises(ConfigError, match=key.replace(".", r"\.")):
        Game(compose([*SHORT, override]))


def test_whole_multiples_of_the_control_rate_are_substeps():
    assert GameConfig(control_hz=1.0, physics_hz=10.0).substeps == 10
    assert GameConfig(control_hz=10.0, physics_hz=240.0).substeps == 24
    assert GameConfig(control_hz=3.0, physics_hz=3.0).substeps == 1


def test_the_pybullet_sim_refuses_acceleration_limits_and_turns():
    pytest.importorskip("pegame_pybullet")
    with pytest.raises(ConfigError, match=r"pursuer\.a_max"):
        Game(compose([*SHORT, "sim=pybullet", "pursuer.a_max=1.0"]))
    with pytest.raises(ConfigError, match="step_one"):
        Game(compose([*SHORT, "sim=pybullet", "game.turn_order=evader_first"])).start()


def accelerating_sim(a_max=0.5, alpha_max=1.0):
    body = Body(0.2, 0.8, 3.0, a_max=a_max, alpha_max=alpha_max)
    context = Context(walled_room(), body, Body(0.25, 0.5, 1.8), Camera(), 0.1, 1.0)
    return GridSimulator(GridSimulator.Config(), context, np.random.default_rng(0))


def test_a_straight_drive_from_rest_ramps_at_a_max():
    sim, dt = accelerating_sim(a_max=0.5), 0.1
    sim.reset((Pose(0.5, 1.5, 0.0),), (Pose(3.5, 2.5),))
    x = [sim.poses[0][0].x]
    for _ in range(20):
        sim.step((Velocity(0.8, 0.0),), (Velocity(),), dt)
        x.append(sim.poses[0][0].x)
    speeds = np.diff(x) / dt
    expected = np.minimum(0.5 * dt * np.arange(1, 21), 0.8)
    np.testing.assert_allclose(speeds, expected, atol=1e-9)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**16), dt=st.sampled_from([0.01, 0.1, 0.25]))
def test_speed_and_turn_rate_change_at_most_a_max_dt_per_step(seed, dt):
    a_max, alpha_max = 0.5, 1.0
    sim = accelerating_sim(a_max, alpha_max)
    grid = walled_room()
    sim.reset((Pose(*grid.cell_to_world(10, 10)),), (Pose(*grid.cell_to_world(50, 70)),))
    rng = np.random.default_rng(seed)
    agent = sim._pursuers[0]
    for _ in range(100):
        before = agent.velocity
        sim.step((Velocity(*rng.uniform(-1.0, 1.0, 2) * [1.0, 4.0]),), (Velocity(),), dt)
        after = agent.velocity
        assert abs(after.w - before.w) <= alpha_max * dt + 1e-12 and abs(after.w) <= 3.0
        # the speed ramps by at most a_max * dt, or drops to 0 where a wall stops the agent
        assert abs(after.v - before.v) <= a_max * dt + 1e-12 or after.v == 0.0
        assert abs(after.v) <= 0.8


def test_acceleration_limits_reach_the_simulated_bodies():
    game = Game(compose([*SHORT, "pursuer.a_max=0.7", "evader.alpha_max=2.5"]))
    assert game.context.pursuer.a_max == 0.7 and math.isinf(game.context.pursuer.alpha_max)
    assert game.context.evader.alpha_max == 2.5 and math.isinf(game.context.evader.a_max)


def test_evader_first_the_pursuer_sees_the_evaders_move_and_the_evader_the_pursuers():
    """Each tick the evader commands on the world after the pursuer's last move and moves
    with the pursuer paused; then the tick is sensed and the pursuer commands on the world
    after the evader's move, and moves with the evader paused."""
    circles = {"pursuer": Velocity(0.05, 1.0), "evader": Velocity(0.04, -0.8)}  # clear of walls
    game = constant_game(["game.t_max=5", "game.turn_order=evader_first"], **circles)
    loop = game.start()
    dt = game.context.control_dt
    ticks = [loop.advance() for _ in range(loop.ticks)]
    pursuer, evader = game.plugins.pursuer, game.plugins.evader
    for k, tick in enumerate(ticks):
        e_obs, p_obs = evader.seen[k], pursuer.seen[k]
        # the evader moved first, the pursuer paused: the tick shows both after that move
        assert tick.evader == unicycle(e_obs.pose, evader.command, dt)
        assert tick.pursuer == e_obs.pursuer == p_obs.pose
        assert p_obs.time == tick.time == k * dt
        if k + 1 < len(ticks):
            # then the pursuer moved, the evader paused: what the next evader turn sees
            following = evader.seen[k + 1]
            assert following.pose == tick.evader
            assert following.pursuer == unicycle(tick.pursuer, pursuer.command, dt)


def test_simultaneous_moves_are_sensed_before_both_move():
    game = constant_game(["game.t_max=3"])
    loop = game.start()
    ticks = [loop.advance() for _ in range(loop.ticks)]
    evader = game.plugins.evader
    for k, tick in enumerate(ticks):
        assert evader.seen[k].pose == tick.evader and evader.seen[k].pursuer == tick.pursuer


def test_evader_first_refuses_external_roles_and_sims_without_step_one():
    game = Game(compose([*SHORT, "game.turn_order=evader_first"]))
    with pytest.raises(ConfigError, match="external"):
        game.start(external=("pursuer",))

    class BothOnly(Simulator):
        """Moves both agents or none."""

        def __init__(self, inner):
            self.inner = inner

        def reset(self, pursuer, evader):
            self.inner.reset(pursuer, evader)

        def step(self, pursuer_cmd, evader_cmd, dt):
            self.inner.step(pursuer_cmd, evader_cmd, dt)

        @property
        def poses(self):
            return self.inner.poses

        def sense(self, time):
            return self.inner.sense(time)

    game.plugins = replace(game.plugins, sim=BothOnly(game.plugins.sim))
    with pytest.raises(ConfigError, match="step_one"):
        game.start()


def test_the_tick_loop_takes_whole_substeps_only():
    game = Game(compose(SHORT))
    with pytest.raises(ValueError, match="substeps"):
        TickLoop(game.plugins, game.context, 10, 10, substeps=0)
