"""The PettingZoo environment: learning pursuers against learning evaders.

Agents ``pursuer`` and ``evader`` act simultaneously (PettingZoo's Parallel API); in a
team game (``team.pursuers=N``, ``team.evaders=M`` in the overrides or config) the agents
are ``pursuer_0`` .. ``pursuer_{N-1}`` and ``evader_0`` .. ``evader_{M-1}``, every pursuer
with the team's reward and every evader with its own (:mod:`pegame.envs.core`).
Spaces, per agent: ``Box(-1, 1, (2,), float32)`` actions (v, w) scaled to the agent's
limits (:mod:`pegame.observe.actions`) and a flat float32 ``Box`` observation
(:mod:`pegame.observe.observations`; ``env.layouts[agent]`` names its parts). Rewards,
infos and episode length: :mod:`pegame.envs.core`. Both agents are truncated together
when the game's ``t_max`` is reached.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from gymnasium import spaces
from omegaconf import DictConfig
from pettingzoo import ParallelEnv

from pegame.envs.config import env_config, env_settings
from pegame.envs.core import RENDER_MODES, EnvGame, check_render_mode, check_seed, game_seed
from pegame.loop import ROLES


class PursuitEvasionParallelEnv(ParallelEnv):
    """Pursuer vs evader, both learning, on any map and config of the app.

    config: a composed run config (``pegame.config.compose`` or a Hydra app's), or None to
    compose one from ``overrides`` (the app's command-line overrides, e.g.
    ``["env=hall", "game.t_max=30"]``). The ``pursuer`` and ``evader`` nodes give the
    bodies only; the config's ``game.seed`` is not used: seed with ``reset(seed=...)``.
    settings: :class:`pegame.observe.settings.EnvSettings` fields (decision_period,
    crop_cells, crop_resolution, belief, clip_actions). render_mode: None or
    ``"rgb_array"`` (``render()`` draws the game from above, :meth:`EnvGame.frame`).
    """

    metadata: dict[str, Any] = {
        "name": "pegame_pursuit_evasion_v0",
        "render_modes": list(RENDER_MODES),
    }

    def __init__(
        self,
        config: DictConfig | None = None,
        overrides: Sequence[str] = (),
        render_mode: str | None = None,
        **settings: Any,
    ) -> None:
        self.settings = env_settings(**settings)
        self.render_mode = check_render_mode(render_mode)
        self.game = EnvGame(env_config(config, overrides), self.settings, ROLES)
        self.metadata = {**self.metadata, "render_fps": 1.0 / self.game.step_period}
        self.possible_agents = list(self.game.agents)
        self.agents: list[str] = []
        features = self.game.features
        self.roles = {agent: role for role in ROLES for agent in self.game.members[role]}
        self.layouts = {agent: features[role].layout for agent, role in self.roles.items()}
        self.observation_spaces = {
            agent: spaces.Box(features[role].low, features[role].high, dtype=np.float32)
            for agent, role in self.roles.items()
        }
        self.action_spaces = {
            agent: spaces.Box(-1.0, 1.0, (2,), np.float32) for agent in self.possible_agents
        }
        self._np_random: np.random.Generator | None = None

    def observation_space(self, agent: str) -> spaces.Box:
        return self.observation_spaces[agent]

    def action_space(self, agent: str) -> spaces.Box:
        return self.action_spaces[agent]

    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, dict[str, Any]]]:
        """Start a game. ``seed`` re-seeds the env: the game with master seed ``seed``, and
        later seedless resets draw their seeds from it; never seeded, seeds are random."""
        if seed is not None or self._np_random is None:
            self._np_random = np.random.default_rng(check_seed(seed))
        obs = self.game.reset(game_seed(seed, self._np_random))
        self.agents = list(self.possible_agents)
        return obs, {agent: {"seed": self.game.seed} for agent in self.agents}

    def step(
        self, actions: dict[str, np.ndarray]
    ) -> tuple[
        dict[str, np.ndarray],
        dict[str, float],
        dict[str, bool],
        dict[str, bool],
        dict[str, dict[str, object]],
    ]:
        """One decision period with every agent's action (ValueError for a bad one)."""
        obs, reward, done = self.game.step(actions)
        rewards = dict.fromkeys(self.game.members["pursuer"], reward)
        for j, agent in enumerate(self.game.members["evader"]):
            rewards[agent] = -float(self.game.evader_detections[j])
        agents = self.possible_agents
        infos = {agent: self.game.info() for agent in agents}
        if done:
            self.agents = []
        return obs, rewards, dict.fromkeys(agents, False), dict.fromkeys(agents, done), infos

    def render(self) -> np.ndarray | None:
        """The current tick as an (H, W, 3) uint8 image in ``rgb_array`` mode, else None."""
        return self.game.frame() if self.render_mode == "rgb_array" else None

    def close(self) -> None:
        self.game.close()


def parallel_env(
    config: DictConfig | None = None,
    overrides: Sequence[str] = (),
    render_mode: str | None = None,
    **settings: Any,
) -> PursuitEvasionParallelEnv:
    """The PettingZoo Parallel environment (see :class:`PursuitEvasionParallelEnv`)."""
    return PursuitEvasionParallelEnv(config, overrides, render_mode, **settings)
