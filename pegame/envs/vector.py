"""Batched environments: ``num_envs`` games stepped in one call by numba kernels
(:mod:`pegame.vector`).

- :class:`PursuitVectorEnv` and :class:`EvasionVectorEnv`: ``gymnasium.vector.VectorEnv``
  for a learning pursuer (evader) against a scripted opponent, the batched
  ``pegame/Pursuit-v0`` (``pegame/Evasion-v0``);
- :class:`SelfPlayVectorEnv`: both roles learning, the batched PettingZoo env
  (:mod:`pegame.envs.parallel`), with dicts of batched arrays per agent;
- :func:`vector_env` builds any of them.

Every sub-env is the single env: the spaces are its spaces batched (``single_*_space``
are the single env's), and the rewards, the end of a game (a truncation after
``game.t_max`` s), the observations and the infos (``seed`` at a reset; ``time`` and
``tracking_rate`` after a step; ``metrics`` at the end of a game) are the ones
``gymnasium.vector.SyncVectorEnv`` of the single envs gives with the same seeds
(``reset(seed=s)`` seeds game i with s + i; later games draw their seeds from each
game's generator, as the single env does). Autoreset is Gymnasium's default
``AutoresetMode.NEXT_STEP``: the step after a game's last returns the first observation
of its next game (reward 0, actions ignored). All games have the same length, so they
end and restart together when started together.

What differs from the single env: the batched game plays the configurations that
:func:`pegame.vector.game.check_playable` allows, its means and path lengths are
summed tick by tick (:mod:`pegame.vector.metrics`), and its measures keep no loss causes
(``loss_causes`` None).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any, Literal, overload

import numpy as np
from gymnasium import spaces
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space
from numpy.typing import ArrayLike
from omegaconf import DictConfig

from pegame.envs.config import env_config, env_settings
from pegame.envs.core import check_seed
from pegame.errors import ConfigError
from pegame.loop import ROLES
from pegame.vector import BatchedGame

#: the seeds a batched env's reset takes: one for game 0 (the others follow), one per game
Seeds = int | Sequence[int | None] | None

#: the ``role`` values of :func:`vector_env`: one learner, or both (self-play)
VECTOR_ROLES = ("pursuer", "evader", "both")


class _Batch:
    """What the batched envs share: the batched game of ``roles``, seeding, actions,
    autoreset and infos."""

    #: gymnasium's VectorEnv._add_info, which each batched env has
    _add_info: Callable[[dict[str, Any], dict[str, Any], int], dict[str, Any]]

    def _setup(
        self,
        num_envs: int,
        config: DictConfig | None,
        overrides: Sequence[str],
        opponents: dict[str, str] | None,
        roles: Sequence[str],
        settings: dict[str, Any],
    ) -> None:
        self.settings = env_settings(**settings)
        cfg = env_config(config, overrides, opponents)
        self.game = BatchedGame(cfg, self.settings, roles, num_envs)
        self.num_envs = self.game.num_games
        self.roles = tuple(roles)
        self.layouts = {role: self.game.features[role].layout for role in self.roles}
        self._rngs: list[np.random.Generator | None] = [None] * self.num_envs
        self._autoreset = np.zeros(self.num_envs, np.bool_)
        self._all = np.arange(self.num_envs)
        self._started = False

    def _observation_space(self, role: str) -> spaces.Box:
        features = self.game.features[role]
        return spaces.Box(features.low, features.high, dtype=np.float32)

    def _seeds(self, seed: Seeds) -> list[int | None]:
        """Per-game seeds as SyncVectorEnv.reset takes them."""
        if seed is None:
            return [None] * self.num_envs
        if isinstance(seed, bool):
            raise ValueError(f"seed must be None, an integer or a list of seeds, got {seed!r}.")
        if isinstance(seed, (int, np.integer)):
            return [check_seed(int(seed)) + i for i in range(self.num_envs)]
        seeds = list(seed)
        if len(seeds) != self.num_envs:
            raise ValueError(
                f"seed must be None, an integer or a list of {self.num_envs} seeds "
                f"(one per env), got {len(seeds)}."
            )
        return [check_seed(s) for s in seeds]

    def _game_seeds(self, games: np.ndarray, seeds: Sequence[int | None]) -> list[int]:
        """The master seed of each game: its seed, else one drawn from its generator
        (the single env's ``reset``: ``game_seed``)."""
        out = []
        for game, seed in zip(games.tolist(), seeds):
            if seed is not None or self._rngs[game] is None:
                self._rngs[game] = seeding.np_random(seed)[0]
            out.append(int(self._rngs[game].integers(2**63 - 1)) if seed is None else int(seed))
        return out

    def _reset(self, seed: Seeds, options: dict[str, Any] | None) -> None:
        seeds = self._seeds(seed)
        self.game.reset_games(self._all, self._game_seeds(self._all, seeds))
        self._autoreset[:] = False
        self._started = True

    def _commands(
        self, actions: Mapping[str, ArrayLike], playing: np.ndarray
    ) -> dict[str, np.ndarray]:
        """role -> (N, members, 2) (v, w) of the learners' batched ``actions`` (agent ->
        (N, 2) in [-1, 1]); ValueError for a bad one among the games playing."""
        out = {}
        for role, members in self.game.members.items():
            body = self.game.context.pursuer if role == "pursuer" else self.game.context.evader
            scale = np.array([body.v_max, body.w_max])
            commands = out[role] = np.empty((self.num_envs, len(members), 2))
            for k, agent in enumerate(members):
                commands[:, k] = scale * self._action(agent, actions[agent], playing)
        return out

    def _action(self, agent: str, action: ArrayLike, playing: np.ndarray) -> np.ndarray:
        """``agent``'s (N, 2) scaled actions as float64, clipped when the settings say so;
        ValueError for a bad one among the games playing."""
        a = np.asarray(action)
        if a.shape != (self.num_envs, 2):
            raise ValueError(
                f"{agent} actions must have shape ({self.num_envs}, 2) (v, w) in [-1, 1] "
                f"per env, got shape {a.shape}."
            )
        a = a.astype(np.float64)
        live = a if playing.all() else a[playing]  # no copy in the common case
        if not np.isfinite(live).all():
            raise ValueError(
                f"{agent} actions must be finite, got {a[playing][~np.isfinite(live).all(1)][0]!r}."
            )
        if np.abs(live).max(initial=0.0) > 1.0:
            if not self.settings.clip_actions:
                bad = live[(np.abs(live) > 1.0).any(axis=1)][0]
                raise ValueError(
                    f"{agent} actions must lie in [-1, 1] (scaled v, w), got {bad!r}; "
                    "pass clip_actions=True to clip instead."
                )
            a = np.clip(a, -1.0, 1.0)
        return a

    def _advance(
        self, actions: Mapping[str, ArrayLike]
    ) -> tuple[np.ndarray, np.ndarray, dict[str, Any]]:
        """Step the playing games, reset the ones that ended last step (NEXT_STEP).
        Returns the rewards, the games that ended and the infos."""
        if not self._started:
            raise RuntimeError("No games in progress: call reset() before step().")
        resetting = self._autoreset.copy()
        playing = ~resetting
        rewards = self.game.step(playing, self._commands(actions, playing))
        infos: dict = {}
        if resetting.any():
            games = np.flatnonzero(resetting)
            self.game.reset_games(games, self._game_seeds(games, [None] * games.size))
        if playing.any():
            infos["time"] = np.where(playing, self.game.time(), 0.0)
            infos["_time"] = playing.copy()
            infos["tracking_rate"] = np.where(playing, self.game.tracking_rate(), 0.0)
            infos["_tracking_rate"] = playing.copy()
        ended = playing & self.game.done
        for game in np.flatnonzero(ended).tolist():
            self._add_info(infos, {"metrics": self.game.summary(game)}, game)
        if resetting.any():
            self._seed_info(infos, resetting)
        self._autoreset = ended.copy()  # the caller may keep or change what it is given
        return rewards, ended, infos

    def _seed_info(self, infos: dict, games: np.ndarray) -> dict:
        infos["seed"] = np.where(games, self.game.seeds, 0)
        infos["_seed"] = games.copy()
        return infos


class _LearnerVectorEnv(_Batch, VectorEnv):
    """One learner, ``role``, against the opponent strategy ``opponent``.

    num_envs: games stepped together; config / overrides / opponent: as the single env
    (:class:`pegame.envs.single.PursuitEnv`); settings: :class:`EnvSettings` fields.
    """

    role: str
    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(
        self,
        num_envs: int,
        config: DictConfig | None = None,
        overrides: Sequence[str] = (),
        opponent: str | None = None,
        **settings: Any,
    ) -> None:
        other = "evader" if self.role == "pursuer" else "pursuer"
        opponents = {other: opponent} if opponent is not None else None
        self._setup(num_envs, config, overrides, opponents, (self.role,), settings)
        self.opponent = str(self.game.scenario.names[other])
        self.layout = self.layouts[self.role]
        self.single_observation_space = self._observation_space(self.role)
        self.single_action_space = spaces.Box(-1.0, 1.0, (2,), np.float32)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self._sign = 1.0 if self.role == "pursuer" else -1.0

    def reset(
        self, *, seed: Seeds = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Start a game in every env; ``seed`` as ``SyncVectorEnv.reset`` takes it."""
        self._reset(seed, options)
        infos = self._seed_info({}, np.ones(self.num_envs, np.bool_))
        return self.game.observations(self.role), infos

    def step(
        self, actions: ArrayLike
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """One decision period of every game ((N, 2) actions; ValueError for a bad one)."""
        rewards, ended, infos = self._advance({self.role: actions})
        return (
            self.game.observations(self.role),
            self._sign * rewards,
            np.zeros(self.num_envs, np.bool_),
            ended,
            infos,
        )

    def close_extras(self, **kwargs: Any) -> None:
        """Stop the opponent's threads, if any (the games hold no simulator processes)."""
        self.game.close()


class PursuitVectorEnv(_LearnerVectorEnv):
    """The batched ``pegame/Pursuit-v0``: the learners are the pursuers."""

    role = "pursuer"


class EvasionVectorEnv(_LearnerVectorEnv):
    """The batched ``pegame/Evasion-v0``: the learners are the evaders. A pursuer
    strategy opponent runs with its estimator per game in Python; the random pursuer
    with ``model=action`` runs batched and without one, so that its games' estimation
    measures are None (see :mod:`pegame.vector.opponents`)."""

    role = "evader"


class SelfPlayVectorEnv(_Batch):
    """Both roles learning in ``num_envs`` games: the batched PettingZoo env
    (:mod:`pegame.envs.parallel`), 1v1 or teams.

    ``reset`` and ``step`` take and return dicts keyed by agent of batched arrays:
    observations (N, size), actions (N, 2), rewards (N,), terminations and truncations
    (N,); infos is one dict for all games (as the vector envs'). The agents are
    'pursuer' and 'evader' in a 1v1 game, and ``pursuer_0`` .. ``pursuer_{P-1}``,
    ``evader_0`` .. ``evader_{E-1}`` in a team game (``team.pursuers``, ``team.evaders``),
    the pursuers with the team's reward and each evader with its own (the evader's is the
    pursuer's negative in a 1v1 game). Autoreset as the vector envs.
    """

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}
    _add_info = VectorEnv._add_info

    def __init__(
        self,
        num_envs: int,
        config: DictConfig | None = None,
        overrides: Sequence[str] = (),
        **settings: Any,
    ) -> None:
        self._setup(num_envs, config, overrides, None, ROLES, settings)
        members = self.game.members
        self.possible_agents = [agent for role in ROLES for agent in members[role]]
        #: (agent, role, member index) per agent
        self._agents = [(agent, role, k) for role in ROLES for k, agent in enumerate(members[role])]
        self.layouts = {agent: self.game.features[role].layout for agent, role, _ in self._agents}
        self.single_observation_spaces = {
            agent: self._observation_space(role) for agent, role, _ in self._agents
        }
        self.single_action_spaces = {
            agent: spaces.Box(-1.0, 1.0, (2,), np.float32) for agent in self.possible_agents
        }
        self.observation_spaces = {
            agent: batch_space(space, self.num_envs)
            for agent, space in self.single_observation_spaces.items()
        }
        self.action_spaces = {
            agent: batch_space(space, self.num_envs)
            for agent, space in self.single_action_spaces.items()
        }

    def _observations(self) -> dict[str, np.ndarray]:
        return {agent: self.game.observations(role, k) for agent, role, k in self._agents}

    def reset(
        self, *, seed: Seeds = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        """Start a game in every env; ``seed`` as the vector envs take it."""
        self._reset(seed, options)
        return self._observations(), self._seed_info({}, np.ones(self.num_envs, np.bool_))

    def step(
        self, actions: dict[str, np.ndarray]
    ) -> tuple[
        dict[str, np.ndarray],
        dict[str, np.ndarray],
        dict[str, np.ndarray],
        dict[str, np.ndarray],
        dict[str, Any],
    ]:
        """One decision period of every game with every agent's (N, 2) actions."""
        if not isinstance(actions, dict) or sorted(actions) != sorted(self.possible_agents):
            raise ValueError(
                f"actions must map each agent in {self.possible_agents} to its (N, 2) actions."
            )
        detections, ended, infos = self._advance(actions)
        if detections.ndim == 1:  # a 1v1 game
            rewards = {"pursuer": detections, "evader": -detections}
        else:
            team = detections.sum(axis=1)
            rewards = {agent: team.copy() for agent in self.game.members["pursuer"]}
            for j, agent in enumerate(self.game.members["evader"]):
                rewards[agent] = -detections[:, j]
        never = np.zeros(self.num_envs, np.bool_)
        agents = self.possible_agents
        return (
            self._observations(),
            rewards,
            dict.fromkeys(agents, never),
            dict.fromkeys(agents, ended),
            infos,
        )

    def close(self) -> None:
        """Nothing to release: self-play has no opponent."""


@overload
def vector_env(
    num_envs: int,
    config: DictConfig | None = None,
    overrides: Sequence[str] = (),
    opponent: str | None = None,
    role: Literal["pursuer", "evader"] = "pursuer",
    **settings: Any,
) -> PursuitVectorEnv | EvasionVectorEnv: ...
@overload
def vector_env(
    num_envs: int,
    config: DictConfig | None = None,
    overrides: Sequence[str] = (),
    opponent: None = None,
    *,
    role: Literal["both"],
    **settings: Any,
) -> SelfPlayVectorEnv: ...
@overload
def vector_env(
    num_envs: int,
    config: DictConfig | None = None,
    overrides: Sequence[str] = (),
    opponent: str | None = None,
    role: str = "pursuer",
    **settings: Any,
) -> PursuitVectorEnv | EvasionVectorEnv | SelfPlayVectorEnv: ...
def vector_env(
    num_envs: int,
    config: DictConfig | None = None,
    overrides: Sequence[str] = (),
    opponent: str | None = None,
    role: str = "pursuer",
    **settings: Any,
) -> PursuitVectorEnv | EvasionVectorEnv | SelfPlayVectorEnv:
    """``num_envs`` games stepped together for a learning ``role``: 'pursuer'
    (:class:`PursuitVectorEnv`), 'evader' (:class:`EvasionVectorEnv`), both against
    ``opponent`` (a strategy name, as the single envs take it), or 'both'
    (:class:`SelfPlayVectorEnv`, no opponent). config / overrides / settings: as the
    single envs (:mod:`pegame.envs.single`)."""
    if role not in VECTOR_ROLES:
        raise ConfigError(
            f"Invalid value for 'role': {role!r}. Allowed: {', '.join(VECTOR_ROLES)}."
        )
    if role == "both":
        if opponent is not None:
            raise ConfigError(
                "role='both' has no opponent: both agents learn; leave opponent unset."
            )
        return SelfPlayVectorEnv(num_envs, config, overrides, **settings)
    cls = PursuitVectorEnv if role == "pursuer" else EvasionVectorEnv
    return cls(num_envs, config, overrides, opponent, **settings)


__all__ = [
    "EvasionVectorEnv",
    "PursuitVectorEnv",
    "SelfPlayVectorEnv",
    "VECTOR_ROLES",
    "vector_env",
]
