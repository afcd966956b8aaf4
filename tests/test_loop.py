"""The tick loop's fast 1v1 form plays the same ticks as its general form."""

from __future__ import annotations

import pytest

from pegame.config import compose
from pegame.game import Game

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


def test_external_roles_and_turns_take_the_general_tick():
    game = Game(compose(["recorder=none", "game.t_max=2"]))
    assert not game.start(external=("pursuer",)).one_on_one
    turns = Game(compose(["recorder=none", "game.t_max=2", "game.turn_order=evader_first"]))
    assert not turns.start().one_on_one
