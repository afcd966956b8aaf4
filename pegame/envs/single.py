"""Single-agent Gymnasium environments: ``pegame/Pursuit-v0`` (the learner pursues) and
``pegame/Evasion-v0`` (the learner evades) against a pegame strategy.

Spaces: ``Box(-1, 1, (2,), float32)`` actions (v, w) scaled to the learner's limits
(:mod:`pegame.observe.actions`) and a flat float32 ``Box`` observation
(:mod:`pegame.observe.observations`; ``env.unwrapped.layout`` names its parts). Rewards,
infos and episode length: :mod:`pegame.envs.core`; the end of the game is a truncation.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, ClassVar

import gymnasium
import numpy as np
from gymnasium import spaces
from omegaconf import DictConfig

from pegame.envs.config import env_config, env_settings
from pegame.envs.core import RENDER_MODES, EnvGame, check_render_mode, check_seed, game_seed
from pegame.errors import ConfigError

PURSUIT_ID = "pegame/Pursuit-v0"
EVASION_ID = "pegame/Evasion-v0"


class _SingleAgentEnv(gymnasium.Env):
    """The learner plays ``role``; the other role is the strategy ``opponent``.

    config: a composed run config, or None to compose one from ``overrides`` (the app's
    command-line overrides, e.g. ``["env=hall", "estimator=kalman"]``). opponent: the
    registry name of the other role's strategy (``smart``, ``random`` or any registered
    plugin); None keeps the config's choice (``smart`` by default); with overrides it
    adds ``<role>=<opponent>``, with a config it must match it. The config's ``game.seed``
    is not used: seed with ``reset(seed=...)``. render_mode: None or ``"rgb_array"``
    (``render()`` draws the game from above, :meth:`EnvGame.frame`). settings:
    :class:`EnvSettings` fields.
    """

    role: ClassVar[str]
    env_id: ClassVar[str]
    metadata: dict[str, Any] = {"render_modes": list(RENDER_MODES)}

    def __init__(
        self,
        config: DictConfig | None = None,
        overrides: Sequence[str] = (),
        opponent: str | None = None,
        render_mode: str | None = None,
        **settings: Any,
    ) -> None:
        self.settings = env_settings(**settings)
        self.render_mode = check_render_mode(render_mode)
        other = "evader" if self.role == "pursuer" else "pursuer"
        cfg = env_config(config, overrides, {other: opponent} if opponent is not None else None)
        self.game = EnvGame(cfg, self.settings, (self.role,))
        self.metadata = {**self.metadata, "render_fps": 1.0 / self.game.step_period}
        for key, size in zip(("team.pursuers", "team.evaders"), self.game.scenario.team_size):
            if size != 1:
                raise ConfigError(
                    f"Invalid value for '{key}' in {self.env_id}: {size}. Allowed: 1 (the "
                    "single-agent envs play one pursuer against one evader; a team game is "
                    "the PettingZoo env's, pegame.envs.parallel)."
                )
        self.opponent = str(cfg[other].name)
        features = self.game.features[self.role]
        self.layout = features.layout
        self.observation_space = spaces.Box(features.low, features.high, dtype=np.float32)
        self.action_space = spaces.Box(-1.0, 1.0, (2,), np.float32)
        self._sign = 1.0 if self.role == "pursuer" else -1.0

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Start a game; ``seed`` is the game's master seed (later seedless resets draw
        theirs from it); never seeded, seeds are random."""
        super().reset(seed=check_seed(seed))
        obs = self.game.reset(game_seed(seed, self.np_random))
        return obs[self.role], {"seed": self.game.seed}

    def step(self, action: object) -> tuple[np.ndarray, float, bool, bool, dict[str, object]]:
        """One decision period (ValueError for a bad action)."""
        obs, reward, done = self.game.step({self.role: action})
        return obs[self.role], self._sign * reward, False, done, self.game.info()

    def render(self) -> np.ndarray | None:
        """The current tick as an (H, W, 3) uint8 image in ``rgb_array`` mode, else None."""
        return self.game.frame() if self.render_mode == "rgb_array" else None

    def close(self) -> None:
        self.game.close()


class PursuitEnv(_SingleAgentEnv):
    """``pegame/Pursuit-v0``: the learner is the pursuer."""

    role = "pursuer"
    env_id = PURSUIT_ID


class EvasionEnv(_SingleAgentEnv):
    """``pegame/Evasion-v0``: the learner is the evader."""

    role = "evader"
    env_id = EVASION_ID


def register_envs() -> None:
    """Register ``pegame/Pursuit-v0`` and ``pegame/Evasion-v0`` with Gymnasium (idempotent;
    importing :mod:`pegame.envs` does it), with the batched envs of
    :mod:`pegame.envs.vector` as their ``vector_entry_point`` (``gymnasium.make_vec``)."""
    for env_id, cls, batched in (
        (PURSUIT_ID, PursuitEnv, "PursuitVectorEnv"),
        (EVASION_ID, EvasionEnv, "EvasionVectorEnv"),
    ):
        if env_id not in gymnasium.registry:
            gymnasium.register(
                id=env_id,
                entry_point=f"{cls.__module__}:{cls.__name__}",
                vector_entry_point=f"pegame.envs.vector:{batched}",
            )
