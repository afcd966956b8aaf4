"""The scripted role of a batched game: the opponent of a learner.

- :class:`ActionTable`: the random agent with ``model=action``
  (:class:`pegame.wander.RandomActions`), batched: at a game's reset every decision's
  (v, w) is drawn at once from the strategy's own generator, the same numbers the
  strategy would draw one decision at a time, and the tick kernel reads them;
- :class:`SmartEvaderOpponent`: the smart evader (Euclidean distances, its default),
  decided and commanded for every game of a tick in one kernel call
  (:class:`pegame.evaders.smart_batch.SmartEvaderBatch`), the strategy's commands bit
  for bit;
- :class:`StrategyOpponent`: any other evader strategy (``smart``, ``random`` with
  ``model=waypoint``, any plugin): one instance per game, built exactly as
  :class:`pegame.game.Game` builds it and asked, game by game in Python, for its decision
  and its command at every tick. It costs what the strategy costs in a single game.
- :class:`PursuerStrategyOpponent`: any other pursuer strategy, with what a pursuer
  strategy is given: its detection, the visibility region and the belief of the game's
  estimator (:class:`pegame.vector.estimation.Estimation`: one per game, updated every
  tick in Python as the loop does, and the game's measures with the estimator's). It
  costs the strategy and the estimator per game.

The action table ignores what it sees, so no estimator runs with it: its games' measures
have no estimation error, n_eff or resamplings (None and 0).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from pegame.api import Context, Evader, EvaderObservation, Pursuer, PursuerObservation
from pegame.evaders.random import RandomEvader
from pegame.evaders.smart import SmartEvader
from pegame.evaders.smart_batch import SmartEvaderBatch, batchable
from pegame.game import Scenario
from pegame.pursuers.random import RandomPursuer
from pegame.types import Pose
from pegame.vector.estimation import Estimation
from pegame.vector.state import EVADER, PURSUER, V_MAX, W_MAX, BatchState


class ActionTable:
    """The random (v, w) actions of ``role`` (0 pursuer, 1 evader) for ``num_games`` games
    of ``decisions`` decisions each, drawn per game at its reset; ``body``: the role's
    (radius, v_max, w_max, ...) row of the kernels' bodies."""

    def __init__(self, role: int, body: np.ndarray, num_games: int, decisions: int) -> None:
        self.role = role
        self.v_max, self.w_max = float(body[V_MAX]), float(body[W_MAX])
        self.table = np.zeros((num_games, decisions, 2))
        self.name = "pursuer" if role == PURSUER else "evader"

    def reset(self, game: int, streams: dict, pose: Pose) -> None:
        """Draw game ``game``'s actions from the role's stream (of the game's ``streams``,
        :data:`pegame.game.STREAMS`): uniform(0, v_max) and uniform(-w_max, w_max) per
        decision, in the order RandomActions.decide draws them (numpy's uniform is
        low + (high - low) * next_double, computed the same way here)."""
        rng = np.random.default_rng(streams[self.name])
        u = rng.random(2 * self.table.shape[1]).reshape(-1, 2)
        self.table[game, :, 0] = 0.0 + (self.v_max - 0.0) * u[:, 0]
        self.table[game, :, 1] = -self.w_max + (self.w_max - -self.w_max) * u[:, 1]

    def command(
        self, state: BatchState, games: np.ndarray, time: np.ndarray, deciding: np.ndarray
    ) -> None:
        """Nothing: the tick kernel reads the table."""


class StrategyOpponent:
    """The evader strategy ``cls`` with ``config`` in ``context``, one per game."""

    role = EVADER
    table = None

    def __init__(self, cls: type[Evader], config: Any, context: Context, num_games: int) -> None:
        self.cls, self.config, self.context = cls, config, context
        self.strategies: list = [None] * num_games

    def reset(self, game: int, streams: dict, pose: Pose) -> None:
        """A new strategy for ``game`` with the evader's stream of ``streams``, reset at
        ``pose``."""
        strategy = self.cls(self.config, self.context, np.random.default_rng(streams["evader"]))
        strategy.reset(pose)
        self.strategies[game] = strategy

    def command(
        self, state: BatchState, games: np.ndarray, time: np.ndarray, deciding: np.ndarray
    ) -> None:
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


class SmartEvaderOpponent:
    """The smart evader with ``config`` in ``context``, batched over ``num_games`` games."""

    role = EVADER
    table = None

    def __init__(self, config: Any, context: Context, num_games: int) -> None:
        self.batch = SmartEvaderBatch(config, context, num_games)

    def reset(self, game: int, streams: dict, pose: Pose) -> None:
        """Game ``game`` starts (the smart evader draws nothing from its stream)."""
        self.batch.reset(game)

    def command(
        self, state: BatchState, games: np.ndarray, time: np.ndarray, deciding: np.ndarray
    ) -> None:
        """The evaders' commands for ``games`` into state.commands, deciding first where
        ``deciding[k]`` (the smart evader does not read the time)."""
        self.batch.command(state.poses, state.commands, games, deciding)

    def close(self) -> None:
        """Stop the batch's threads."""
        self.batch.close()


class PursuerStrategyOpponent:
    """The pursuer strategy ``cls`` with ``config`` in ``context``, one per game, given
    each game's detection, region and belief by the game's ``estimation``."""

    role = PURSUER
    table = None

    def __init__(
        self,
        cls: type[Pursuer],
        config: Any,
        estimation: Estimation,
        context: Context,
        num_games: int,
    ) -> None:
        self.cls, self.config, self.context = cls, config, context
        self.estimation = estimation
        self.strategies: list = [None] * num_games

    def reset(self, game: int, streams: dict, pose: Pose) -> None:
        """A new strategy for ``game`` from ``streams``, reset at ``pose``."""
        strategy = self.cls(self.config, self.context, np.random.default_rng(streams["pursuer"]))
        strategy.reset(pose)
        self.strategies[game] = strategy

    def command(
        self, state: BatchState, games: np.ndarray, time: np.ndarray, deciding: np.ndarray
    ) -> None:
        """The strategies' commands for ``games`` at ``time[k]`` s (deciding first where
        ``deciding[k]``) into state.commands."""
        poses, commands, seen = state.poses, state.commands, self.estimation.seen
        for k, game in enumerate(games.tolist()):
            pursuer = Pose(*poses[game, PURSUER].tolist())
            detection, region, belief = seen[game]
            observation = PursuerObservation(float(time[k]), pursuer, detection, belief, region)
            strategy = self.strategies[game]
            if deciding[k]:
                strategy.decide(observation)
            cmd = strategy.control(observation)
            commands[game, PURSUER, 0], commands[game, PURSUER, 1] = cmd.v, cmd.w


def opponent_for(
    scenario: Scenario,
    learner: str,
    bodies: np.ndarray,
    num_games: int,
    estimation: Estimation | None = None,
) -> ActionTable | SmartEvaderOpponent | StrategyOpponent | PursuerStrategyOpponent:
    """The opponent of ``learner`` ('pursuer' or 'evader') in ``scenario``'s games; a
    pursuer strategy takes its beliefs from ``estimation`` (see :func:`needs_estimation`)."""
    role = "evader" if learner == "pursuer" else "pursuer"
    cls, config = scenario.classes[role], scenario.configs[role]
    settings = scenario.settings
    decisions = -(-settings.ticks // settings.decide_every)
    index = EVADER if role == "evader" else PURSUER
    if _plays_a_table(cls, config):
        return ActionTable(index, bodies[index], num_games, decisions)
    if cls is SmartEvader and batchable(config):
        return SmartEvaderOpponent(config, scenario.context, num_games)
    if role == "evader":
        assert issubclass(cls, Evader)  # the scenario's classes implement their kinds
        return StrategyOpponent(cls, config, scenario.context, num_games)
    assert issubclass(cls, Pursuer) and estimation is not None
    return PursuerStrategyOpponent(cls, config, estimation, scenario.context, num_games)


def needs_estimation(scenario: Scenario, learner: str) -> bool:
    """Whether the opponent of ``learner`` is a pursuer strategy (which needs the game's
    estimation), not the batched random pursuer."""
    if learner != "evader":
        return False
    cls, config = scenario.classes["pursuer"], scenario.configs["pursuer"]
    return not _plays_a_table(cls, config)


def _plays_a_table(cls: type, config: Any) -> bool:
    """Whether the strategy ``cls`` with ``config`` is the random agent with
    ``model=action``, which the kernels play from an action table."""
    return cls in (RandomEvader, RandomPursuer) and config.model == "action"
