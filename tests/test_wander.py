"""The paper's random agents in both readings (pegame.wander): random reachable goals
(``model=waypoint``, the default and today's) and a random action at each decision
(``model=action``, the paper's Fig. 1 "possible random actions")."""

from __future__ import annotations

import numpy as np
import pytest

from pegame.config import compose
from pegame.errors import ConfigError
from pegame.game import Game
from pegame.navigation import inflate
from pegame.types import Body, Pose
from pegame.wander import RandomActions

RANDOM = ["recorder=none", "env=brick", "pursuer=random", "evader=random"]
ACTIONS = [*RANDOM, "pursuer.model=action", "evader.model=action"]


def ticks_of(overrides):
    loop = Game(compose(overrides)).start()
    return [loop.advance() for _ in range(loop.ticks)]


def test_waypoint_is_the_default_model_and_todays_game():
    today = Game(compose([*RANDOM, "game.t_max=8"])).play("unused")
    explicit = [*RANDOM, "game.t_max=8", "pursuer.model=waypoint", "evader.model=waypoint"]
    assert Game(compose(explicit)).play("unused").result == today.result


def test_actions_are_drawn_within_the_body_limits_and_cover_them():
    body = Body(0.2, 0.7, 1.5)
    agent = RandomActions(body, np.random.default_rng(4))
    agent.reset(Pose(0.0, 0.0, 0.0))
    actions = []
    for _ in range(2000):
        agent.decide(Pose(0.0, 0.0, 0.0))
        actions.append(agent.control(Pose(0.0, 0.0, 0.0)))
    v = np.array([a.v for a in actions])
    w = np.array([a.w for a in actions])
    assert v.min() >= 0.0 and v.max() <= body.v_max
    assert np.abs(w).max() <= body.w_max
    # uniform over the whole box: near every edge, and turning both ways
    assert v.min() < 0.05 * body.v_max and v.max() > 0.95 * body.v_max
    assert w.min() < -0.95 * body.w_max and w.max() > 0.95 * body.w_max


@pytest.mark.parametrize("speed_ratio", [0.5, 2.0])
def test_each_action_is_held_for_a_decision_period_within_each_body(speed_ratio):
    ticks = ticks_of([*ACTIONS, "game.t_max=12", f"game.speed_ratio={speed_ratio}"])
    game = Game(compose([*ACTIONS, f"game.speed_ratio={speed_ratio}"]))
    bodies = game.context.pursuer, game.context.evader
    decide_every = round(game.context.decision_dt / game.context.control_dt)
    for role, body in enumerate(bodies):
        commands = [tick.commands[role] for tick in ticks]
        for k, command in enumerate(commands):
            assert 0.0 <= command.v <= body.v_max and abs(command.w) <= body.w_max
            if k % decide_every:
                assert command == commands[k - 1]  # held between decisions
        drawn = {commands[k] for k in range(0, len(commands), decide_every)}
        assert len(drawn) == len(commands) // decide_every  # a new action each decision


def test_the_same_seed_gives_the_same_action_game():
    first = Game(compose([*ACTIONS, "game.t_max=10", "game.seed=5"])).play("unused")
    again = Game(compose([*ACTIONS, "game.t_max=10", "game.seed=5"])).play("unused")
    other = Game(compose([*ACTIONS, "game.t_max=10", "game.seed=6"])).play("unused")
    assert first.trajectory == again.trajectory and first.result == again.result
    assert first.trajectory != other.trajectory


def test_action_agents_move_and_stay_out_of_walls():
    ticks = ticks_of([*ACTIONS, "game.t_max=30"])
    game = Game(compose(ACTIONS))
    grid = game.context.grid
    masks = inflate(grid, game.context.pursuer.radius), inflate(grid, game.context.evader.radius)
    for tick in ticks:
        for pose, mask in zip((tick.pursuer, tick.evader), masks):
            assert not mask[grid.world_to_cell(pose.x, pose.y)]
    assert ticks[-1].evader.distance_to(ticks[0].evader) > 0.0


@pytest.mark.parametrize("role", ["pursuer", "evader"])
def test_an_unknown_model_names_its_key(role):
    with pytest.raises(ConfigError, match=rf"{role}\.model"):
        Game(compose([*RANDOM, f"{role}.model=brownian"]))
