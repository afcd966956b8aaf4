"""The tick loop: one advance for a 1v1 game and a team's; external roles' commands."""

from __future__ import annotations

import numpy as np
import pytest

from pegame.config import compose
from pegame.game import Game
from pegame.types import Velocity


def _ticks(overrides: list[str]) -> list:
    game = Game(compose(["recorder=none", "game.t_max=12", "game.seed=4", *overrides]))
    loop = game.start()
    ticks = []
    while not loop.done:
        tick = loop.advance()
        belief = tick.belief
        ticks.append(
            (
                tick.step,
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
    return ticks, loop.metrics.summary()


@pytest.mark.parametrize("team", ["team.pursuers=1", "team.evaders=1"])
def test_a_team_of_one_against_one_is_the_1v1_game(team):
    # one advance: a team config of one pursuer and one evader plays the 1v1 game's ticks
    one = _ticks(["pursuer=smart", "evader=smart", "env=enclosed"])
    assert one == _ticks(["pursuer=smart", "evader=smart", "env=enclosed", team])
    assert len(one[0]) == 120


@pytest.mark.parametrize("external", [("pursuer",), ("evader",), ("pursuer", "evader")])
def test_external_roles_move_by_the_commands_given(external):
    game = Game(compose(["recorder=none", "game.t_max=6", "game.seed=2", "env=hall"]))
    loop = game.start(external=external)
    rng = np.random.default_rng(0)
    for _ in range(60):
        commands = {
            role: Velocity(float(rng.uniform(0.0, 0.5)), float(rng.uniform(-1.0, 1.0)))
            for role in external
        }
        tick = loop.advance(commands)
        for k, role in enumerate(("pursuer", "evader")):
            if role in external:
                assert tick.commands[k] == commands[role]
    assert loop.done


def test_a_missing_external_command_is_refused():
    loop = Game(compose(["recorder=none", "game.t_max=2"])).start(external=("evader",))
    with pytest.raises(ValueError, match="No command for the external role"):
        loop.advance({"pursuer": Velocity(0.1, 0.0)})


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
