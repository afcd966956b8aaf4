"""The tick loop's fast 1v1 form plays the same ticks as its general form."""

from __future__ import annotations

import numpy as np
import pytest

from pegame.config import compose
from pegame.game import Game
from pegame.types import Velocity

PAIRINGS = [
    ("smart", "smart", "enclosed"),
    ("anticipating", "elusive", "hall"),
    ("random", "random", "brick"),
    ("smart", "random", "brick"),
    ("anticipating", "smart", "enclosed"),
]


def _ticks(pursuer: str, evader: str, env: str, one_on_one: bool, extra=()) -> list:
    overrides = [f"pursuer={pursuer}", f"evader={evader}", f"env={env}", "recorder=none"]
    game = Game(compose([*overrides, "game.t_max=12", "game.seed=4", *extra]))
    loop = game.start()
    assert loop.one_on_one  # a 1v1 game of strategies moving together takes the fast form
    loop.one_on_one = one_on_one
    ticks = []
    while not loop.done:
        tick = loop.advance()
        belief = tick.belief
        ticks.append(
            (
                tick.step,
                tick.time,
                tick.pursuer,
                tick.evader,
                tick.detection,
                tick.in_view,
                tick.commands,
                belief.mean,
                None if belief.particles is None else belief.particles.tobytes(),
                tuple(plan.goal for plan in tick.plans),
            )
        )
    return ticks, loop.metrics.summary(), (loop.substeps, loop.decide_every)


@pytest.mark.parametrize(("pursuer", "evader", "env"), PAIRINGS)
def test_the_fast_1v1_tick_plays_the_general_tick(pursuer, evader, env):
    fast, fast_summary, _ = _ticks(pursuer, evader, env, one_on_one=True)
    general, general_summary, _ = _ticks(pursuer, evader, env, one_on_one=False)
    assert len(fast) == len(general) == 120
    assert fast == general
    assert fast_summary == general_summary


def test_the_fast_1v1_tick_plays_the_general_tick_over_substeps_and_slow_decisions():
    extra = ("game.physics_hz=40", "game.decision_hz=0.5")
    fast, _, timing = _ticks("smart", "smart", "hall", one_on_one=True, extra=extra)
    general, _, _ = _ticks("smart", "smart", "hall", one_on_one=False, extra=extra)
    assert timing == (4, 20)  # 4 simulator steps per tick, a decision every 20 ticks
    assert fast == general


@pytest.mark.parametrize("external", [("pursuer",), ("evader",), ("pursuer", "evader")])
def test_the_fast_1v1_tick_plays_external_roles_as_the_general_tick(external):
    def play(one_on_one: bool) -> list:
        game = Game(compose(["recorder=none", "game.t_max=6", "game.seed=2", "env=hall"]))
        loop = game.start(external=external)
        assert loop.one_on_one
        loop.one_on_one = one_on_one
        rng = np.random.default_rng(0)
        ticks = []
        while not loop.done:
            commands = {
                role: Velocity(float(rng.uniform(0.0, 0.5)), float(rng.uniform(-1.0, 1.0)))
                for role in external
            }
            tick = loop.advance(commands)
            ticks.append((tick.pursuer, tick.evader, tick.detection, tick.commands, tick.in_view))
        return ticks

    fast = play(True)
    assert fast == play(False)
    assert len(fast) == 60


def test_a_missing_external_command_is_refused_by_both_forms():
    for one_on_one in (True, False):
        loop = Game(compose(["recorder=none", "game.t_max=2"])).start(external=("evader",))
        loop.one_on_one = one_on_one
        with pytest.raises(ValueError, match="No command for the external role"):
            loop.advance({"pursuer": Velocity(0.1, 0.0)})


def test_turns_and_teams_take_the_general_tick():
    turns = Game(compose(["recorder=none", "game.t_max=2", "game.turn_order=evader_first"]))
    assert not turns.start().one_on_one
    team = Game(compose(["recorder=none", "game.t_max=2", "team.pursuers=2"]))
    assert not team.start().one_on_one


def test_a_pursuer_observation_without_the_regions_is_refused():
    """With an external pursuer and ``estimate=False`` no region is built: an observation
    would carry None where its region belongs."""
    loop = Game(compose(["recorder=none", "game.t_max=2"])).start(("pursuer",), estimate=False)
    assert loop.region is None
    with pytest.raises(RuntimeError, match="estimate=True"):
        loop.pursuer_observation(0)


def test_the_loop_plays_the_games_plugins_member_by_member():
    game = Game(compose(["recorder=none", "game.t_max=2", "team.pursuers=2"]))
    plugins, loop = game.plugins, game.start()
    assert plugins.pursuer is plugins.pursuers[0] and len(plugins.pursuers) == 2
    assert (
        plugins.detector is plugins.detectors[0][0] and plugins.estimator is plugins.estimators[0]
    )
    assert loop.sim is plugins.sim and loop.pursuer_strategies == plugins.pursuers
