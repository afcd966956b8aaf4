"""The environments' shared core: observations, actions, rewards and infos of one or two
learning roles in games played by the one tick loop (:class:`pegame.loop.TickLoop`).

A step applies the learners' actions for ``ticks_per_action`` control ticks (the
decision period) while the other role, if any, plays its strategy. Reward: the pursuer
gets +1 for every control tick reached during the step at which its detector reports the
evader, the evader the negative (zero-sum). The game ends after ``game.t_max`` s: the
last step is a truncation (there is no terminal state); a last step may be shorter when
t_max is not a whole number of decision periods.

Teams (``team.pursuers``, ``team.evaders``): one agent per member (:class:`EnvGame`); the
pursuers share the team's reward, +1 per control tick for every evader some pursuer
detects, and each evader gets -1 per tick that it is detected.

Infos: ``seed`` (the game's master seed; ``python -m pegame game.seed=<seed>`` with
the same strategies replays it) after reset; ``time`` (s) and ``tracking_rate`` (the
fraction of the ticks played so far with the evader detected, as in the game's result)
after every step; and at the end ``metrics``, the game's
:meth:`pegame.metrics.TrackingMetrics.summary`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, overload

import numpy as np
from omegaconf import DictConfig

from pegame.errors import ConfigError
from pegame.game import Scenario
from pegame.loop import TickLoop, nearest
from pegame.observe.actions import to_velocity
from pegame.observe.observations import EvaderFeatures, PursuerFeatures
from pegame.observe.settings import EnvSettings

if TYPE_CHECKING:  # pragma: no cover - typing only
    from pegame.render import FrameRenderer

#: the render modes of the environments: ``rgb_array``, a frame from above (EnvGame.frame)
RENDER_MODES = ("rgb_array",)


def check_render_mode(mode: str | None) -> str | None:
    """``mode`` if it is None or one of :data:`RENDER_MODES`, else a ConfigError."""
    if mode is not None and mode not in RENDER_MODES:
        raise ConfigError(
            f"Invalid value for 'render_mode': {mode!r}. Allowed: None or "
            f"{', '.join(repr(m) for m in RENDER_MODES)} (a frame from above as an RGB array)."
        )
    return mode


@overload
def check_seed(seed: int) -> int: ...
@overload
def check_seed(seed: None) -> None: ...
@overload
def check_seed(seed: int | None) -> int | None: ...
def check_seed(seed: int | None) -> int | None:
    """``seed`` if it is None or a non-negative integer, else ValueError."""
    if seed is not None and (
        isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0
    ):
        raise ValueError(f"seed must be a non-negative integer or None, got {seed!r}.")
    return seed


def game_seed(seed: int | None, rng: np.random.Generator) -> int:
    """``seed`` itself when given (checked), else a fresh one drawn from ``rng``."""
    checked = check_seed(seed)
    return int(rng.integers(2**63 - 1)) if checked is None else int(checked)


class EnvGame:
    """The learning ``roles`` (a subset of ('pursuer', 'evader')) in games of ``cfg``, one
    game at a time: ``reset(seed)`` builds the scenario's game with that master seed (the
    game ``python -m pegame game.seed=<seed>`` plays) and ``step`` drives its tick loop,
    the learners' roles commanded from outside.

    Agents: a learning role is one agent named by the role in a 1v1 game, and one agent
    per member, ``pursuer_0``, ``pursuer_1``, ... (``evader_0``, ...), in a team game
    (``team.pursuers``, ``team.evaders``). Pursuer i observes its own pose and the team's
    belief about its target evader (i mod M); evader j its pose and its nearest pursuer.
    """

    def __init__(self, cfg: DictConfig, settings: EnvSettings, roles: Sequence[str]) -> None:
        self.settings = settings
        self.roles = tuple(roles)
        self.scenario = Scenario(cfg)
        context = self.scenario.context
        self.ticks_per_action = settings.ticks_per_action(context.control_dt)
        pursuer_features = PursuerFeatures(context, settings.observation)
        evader_features = EvaderFeatures(context, settings.observation)
        self.features: dict[str, PursuerFeatures | EvaderFeatures] = {
            "pursuer": pursuer_features,
            "evader": evader_features,
        }
        self.bodies = {"pursuer": context.pursuer, "evader": context.evader}
        sizes = dict(zip(("pursuer", "evader"), self.scenario.team_size))
        solo = self.scenario.team_size == (1, 1)
        #: the learning agents per role, in member order
        self.members = {
            role: [role] if solo else [f"{role}_{k}" for k in range(sizes[role])]
            for role in self.roles
        }
        self.agents = [agent for role in self.roles for agent in self.members[role]]
        #: (agent, pursuer index i, its target evader i mod M, features) per learning pursuer
        self._pursuer_agents = [
            (
                agent,
                i,
                i % sizes["evader"],
                pursuer_features if solo else PursuerFeatures(context, settings.observation),
            )
            for i, agent in enumerate(self.members.get("pursuer", ()))
        ]
        #: (agent, evader index j, features) per learning evader
        self._evader_agents = [
            (agent, j, evader_features if solo else EvaderFeatures(context, settings.observation))
            for j, agent in enumerate(self.members.get("evader", ()))
        ]
        self.member_features: dict[str, PursuerFeatures | EvaderFeatures] = {
            **{agent: features for agent, _, _, features in self._pursuer_agents},
            **{agent: features for agent, _, features in self._evader_agents},
        }
        #: (role, body, [(agent, name in errors)]) per learning role; a 1v1 game's roles
        #: are commanded with one velocity each, a team's with one per member
        self._actors = [
            (role, self.bodies[role], [(agent, f"{agent} action") for agent in self.members[role]])
            for role in self.roles
        ]
        self._agent_set = frozenset(self.agents)
        self.evader_detections = [0] * sizes["evader"]  # in the last step, per evader
        self.seed: int | None = None
        self.loop: TickLoop | None = None
        self._renderer: tuple[int, FrameRenderer] | None = None  # (size, renderer) of frame()

    @property
    def step_period(self) -> float:
        """Simulated time of one env step (s): the ticks of one action."""
        return self.ticks_per_action * self.scenario.context.control_dt

    @property
    def steps(self) -> int:
        """Steps in one game."""
        return -(-self.scenario.settings.ticks // self.ticks_per_action)

    def reset(self, seed: int) -> dict[str, np.ndarray]:
        """Start a game with master seed ``seed``; the learners' first observations."""
        self.close()
        self.seed = seed
        self.loop = self.scenario.game(seed).start(self.roles, estimate=self.settings.belief)
        for features in self.member_features.values():
            features.reset()
        self._remember()
        return self.observations()

    def step(self, actions: Mapping[str, object]) -> tuple[dict[str, np.ndarray], float, bool]:
        """Apply the learners' ``actions`` (agent -> scaled (v, w)) for one decision period.

        Returns the new observations, the pursuers' reward (the evaders' together is its
        negative: the ticks at which each evader is detected by some pursuer, summed over
        the evaders; per evader in ``evader_detections``) and whether the game is over.
        Every action is checked before anything moves.
        """
        loop = self.loop
        if loop is None or loop.done:
            raise RuntimeError("No game in progress: call reset() before step().")
        commands = self._commands(actions)
        detections = [0] * len(self.evader_detections)
        evaders = range(len(detections))
        for _ in range(self.ticks_per_action):
            loop.advance(commands)
            rows = loop.detections
            for j in evaders:  # loops, not generators: once per tick
                for row in rows:
                    if row[j] is not None:
                        detections[j] += 1
                        break
            self._remember()
            if loop.done:
                break
        self.evader_detections = detections
        return self.observations(), float(sum(detections)), loop.done

    def observations(self) -> dict[str, np.ndarray]:
        """Each learning agent's observation at the current tick (new arrays)."""
        loop, out = self.loop, {}
        if loop is None:
            raise RuntimeError("No game in progress: call reset() first.")
        time, pursuers = loop.time, loop.pursuers
        for agent, i, j, features in self._pursuer_agents:
            out[agent] = features.build(time, pursuers[i], loop.beliefs[j])
        for agent, j, evader_features in self._evader_agents:
            evader = loop.evaders[j]
            out[agent] = evader_features.build(evader, pursuers[nearest(pursuers, evader)])
        return out

    def info(self) -> dict[str, object]:
        """The step's info (see the module docstring); a new dict each call."""
        loop = self.loop
        if loop is None:
            raise RuntimeError("No game in progress: call reset() first.")
        info: dict[str, object] = {"time": loop.time, "tracking_rate": loop.metrics.tracking_rate}
        if loop.done:
            info["metrics"] = loop.metrics.summary()
        return info

    def _remember(self) -> None:
        loop = self.loop
        if loop is None:
            raise RuntimeError("No game in progress: call reset() first.")
        for _, i, j, features in self._pursuer_agents:
            features.remember(loop.time, loop.detections[i][j])

    def _commands(self, actions: Mapping[str, object]) -> dict:
        """The learners' ``actions`` as the tick loop's commands: role -> velocity in a 1v1
        game, role -> one velocity per member in a team game."""
        if not isinstance(actions, Mapping):
            raise ValueError(
                f"actions must map each agent in {self.agents} to its action, got {actions!r}."
            )
        if actions.keys() != self._agent_set:
            unknown = sorted(set(actions) - self._agent_set)
            missing = [agent for agent in self.agents if agent not in actions]
            raise ValueError(
                f"actions must have exactly the agents {self.agents}; "
                f"missing {missing}, unexpected {unknown}."
            )
        commands, clip = {}, self.settings.clip_actions
        for role, body, members in self._actors:  # loops, not comprehensions: once per step
            velocities = []
            for agent, who in members:
                velocities.append(to_velocity(actions[agent], body, clip, who))
            commands[role] = velocities[0] if len(velocities) == 1 else velocities
        return commands

    def frame(self, size: int = 480) -> np.ndarray:
        """The current tick drawn from above (:mod:`pegame.render`): the map, every
        pursuer's visibility region (green while it detects its target evader), the belief
        about evader 0 (its particles, at most 500, and its mean), every body; (H, W, 3)
        uint8, the longer side ``size`` px. A blank map before the first reset."""
        from pegame.recorders.rerun import RerunRecorder
        from pegame.render import FrameRenderer, FrameState
        from pegame.visibility.outlines import visibility_outlines

        context = self.scenario.context
        if self._renderer is None or self._renderer[0] != size:
            camera = context.camera
            self._renderer = (
                size,
                FrameRenderer(
                    context.grid,
                    fov=camera.fov,
                    near=camera.near,
                    far=camera.far,
                    pursuer_radius=context.pursuer.radius,
                    evader_radius=context.evader.radius,
                    size=size,
                ),
            )
        renderer, loop = self._renderer[1], self.loop
        if loop is None:
            return renderer.frame(FrameState(np.empty((0, 3)), np.empty((0, 3)), []))
        pursuers = np.array([(p.x, p.y, p.theta) for p in loop.pursuers])
        outlines = visibility_outlines(
            context.grid,
            pursuers[:, 0],
            pursuers[:, 1],
            pursuers[:, 2],
            context.camera,
            RerunRecorder.Config.outline_rays,
        )
        n_evaders = len(loop.evaders)
        belief = loop.beliefs[0]
        particles = belief.particles[:500, :2] if belief.particles is not None else np.empty((0, 2))
        state = FrameState(
            pursuers,
            np.array([(e.x, e.y, e.theta) for e in loop.evaders]),
            [loop.detections[i][i % n_evaders] is not None for i in range(len(pursuers))],
            [[outline[:, :2].astype(float)] for outline in outlines],
            particles,
            np.asarray(belief.mean, dtype=float) if belief.mean is not None else None,
            loop.time,
        )
        return renderer.frame(state)

    def close(self) -> None:
        """Release the current game's simulator."""
        if self.loop is not None:
            self.loop.sim.close()
            self.loop = None
