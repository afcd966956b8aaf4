"""The scripted role of a batched game: the opponent of a learner.

- :class:`ActionTable`: the random agent with ``model=action``
  (:class:`pegame.wander.RandomActions`), batched: at a game's reset every decision's
  (v, w) is drawn at once from the strategy's own generator, the same numbers the
  strategy would draw one decision at a time, and the tick kernel reads them;
- :class:`StrategyOpponent`: any other strategy (``smart``, ``random`` with
  ``model=waypoint``, any plugin): one instance per game, built exactly as
  :class:`pegame.game.Game` builds it and asked, game by game in Python, for its decision
  and its command at every tick. It costs what the strategy costs in a single game.

The learner's role gives the opponent's observation: a pursuer opponent would need the
estimator's belief and the visibility region, which the batched game does not compute,
so only evader strategies (and the random pursuer's action table, which ignores what it
sees) are opponents here (:func:`opponent_for`).
"""

from __future__ import annotations

import numpy as np

from pegame.api import EvaderObservation
from pegame.errors import ConfigError
from pegame.evaders.random import RandomEvader
from pegame.pursuers.random import RandomPursuer
from pegame.types import Pose
from pegame.vector.state import EVADER, PURSUER, V_MAX, W_MAX


class ActionTable:
    """The random (v, w) actions of ``role`` (0 pursuer, 1 evader) for ``num_games`` games
    of ``decisions`` decisions each, drawn per game at its reset; ``body``: the role's
    (radius, v_max, w_max, ...) row of the kernels' bodies."""

    def __init__(self, role: int, body: np.ndarray, num_games: int, decisions: int) -> None:
        self.role = role
        self.v_max, self.w_max = float(body[V_MAX]), float(body[W_MAX])
        self.table = np.zeros((num_games, decisions, 2))

    def reset(self, game: int, rng: np.random.Generator, pose: Pose) -> None:
        """Draw game ``game``'s actions: uniform(0, v_max) and uniform(-w_max, w_max) per
        decision, in the order RandomActions.decide draws them (numpy's uniform is
        low + (high - low) * next_double, computed the same way here)."""
        u = rng.random(2 * self.table.shape[1]).reshape(-1, 2)
        self.table[game, :, 0] = 0.0 + (self.v_max - 0.0) * u[:, 0]
        self.table[game, :, 1] = -self.w_max + (self.w_max - -self.w_max) * u[:, 1]

    def command(self, state, games: np.ndarray, time: np.ndarray, deciding: np.ndarray) -> None:
        """Nothing: the tick kernel reads the table."""


class StrategyOpponent:
    """The evader strategy ``cls`` with ``config`` in ``context``, one per game."""

    role = EVADER
    table = None

    def __init__(self, cls, config, context, num_games: int) -> None:
        self.cls, self.config, self.context = cls, config, context
        self.strategies: list = [None] * num_games

    def reset(self, game: int, rng: np.random.Generator, pose: Pose) -> None:
        """A new strategy for ``game`` with its generator, reset at ``pose``."""
        strategy = self.cls(self.config, self.context, rng)
        strategy.reset(pose)
        self.strategies[game] = strategy

    def command(self, state, games: np.ndarray, time: np.ndarray, deciding: np.ndarray) -> None:
        """Write the strategies' commands for ``games`` into state.commands: each is given
        its observation at ``time[k]`` s and decides first where ``deciding[k]`` (the
        loop's order)."""
        poses, commands = state.poses, state.commands
        for k, game in enumerate(games.tolist()):
            p, e = poses[game, PURSUER].tolist(), poses[game, EVADER].tolist()
            observation = EvaderObservation(float(time[k]), Pose(*e), Pose(*p), None)
            strategy = self.strategies[game]
            if deciding[k]:
                strategy.decide(observation)
            cmd = strategy.control(observation)
            commands[game, EVADER, 0], commands[game, EVADER, 1] = cmd.v, cmd.w


def opponent_for(scenario, learner: str, bodies: np.ndarray, num_games: int):
    """The opponent of ``learner`` ('pursuer' or 'evader') in ``scenario``'s games, or a
    ConfigError when the batched game cannot play it."""
    role = "evader" if learner == "pursuer" else "pursuer"
    cls, config = scenario.classes[role], scenario.configs[role]
    settings = scenario.settings
    decisions = -(-settings.ticks // settings.decide_every)
    index = EVADER if role == "evader" else PURSUER
    if cls in (RandomEvader, RandomPursuer) and config.model == "action":
        return ActionTable(index, bodies[index], num_games, decisions)
    if role == "evader":
        return StrategyOpponent(cls, config, scenario.context, num_games)
    raise ConfigError(
        f"Invalid value for 'pursuer': {scenario.names['pursuer']!r} as the opponent of a "
        "batched evader. Allowed: pursuer=random pursuer.model=action (a pursuer strategy "
        "reads the estimator's belief, which the batched game does not compute); play "
        "other pursuers with the single env pegame/Evasion-v0."
    )
