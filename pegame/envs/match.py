"""One game of the framework driven one control tick at a time, for the environments.

:class:`Match` builds a :class:`pegame.game.Game` from a composed config (so the map,
simulator, detector, estimator, bodies and strategies are exactly the app's) and then
drives its plugins tick by tick in the game loop's order: sense, detect, (estimate),
then at decision ticks the strategies decide (evader first), then commands, metrics
and the simulator step. Roles listed as ``learners`` get their commands from outside;
the other role is played by its configured strategy.

Seeding follows the game: :meth:`Match.start` with seed s gives every component the
generator that ``Game`` with ``game.seed = s`` gives it (one SeedSequence stream per
component, in ``pegame.game.STREAMS`` order), so an episode and a game with the same
seed and the same pursuer and evader commands have the same trajectory. Plugins are
built once and reset per episode: their generators are re-seeded in place, so a plugin
must keep drawing from the Generator it was built with and clear its state in reset().

The estimator and the pursuer's visibility region run only when needed (a strategy
pursuer, or ``belief=True``): they are the most expensive part of a tick. Without them
``belief`` is empty and the game metrics have no estimation error.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from omegaconf import DictConfig

from pegame.api import EvaderObservation, PursuerObservation
from pegame.types import EMPTY_BELIEF, Belief, Velocity
from pegame.game import STREAMS, Game, spawn
from pegame.visibility import VisibilityRegion, body_in_view
from pegame.metrics import TrackingMetrics

ROLES = ("pursuer", "evader")


class Match:
    """A game driven tick by tick (see the module docstring).

    cfg: a composed run config (:func:`pegame.envs.settings.env_config`). learners: the roles commanded from
    outside. belief: run the estimator even when no strategy pursuer needs it.
    """

    def __init__(self, cfg: DictConfig, learners: Sequence[str], belief: bool = False) -> None:
        self.game = Game(cfg)
        self.context = self.game.context
        settings = self.game.settings
        self.dt = self.context.control_dt
        self.ticks = int(round(settings.t_max * settings.control_hz))
        self.decide_every = max(1, int(round(settings.control_hz / settings.decision_hz)))
        self.learners = tuple(learners)
        # The evader decides first, as in the game loop.
        self.strategies = [(role, self.game.plugins[role]) for role in ("evader", "pursuer") if role not in learners]
        self.estimating = belief or "pursuer" not in self.learners
        self.step = 0

    @property
    def time(self) -> float:
        """Simulation time of the current tick (s)."""
        return self.step * self.dt

    @property
    def done(self) -> bool:
        """True once every tick of the game has been played."""
        return self.step >= self.ticks

    def start(self, seed: int) -> None:
        """Begin a game with master seed ``seed``: spawn, reset every plugin, sense tick 0."""
        plugins = self.game.plugins
        streams = np.random.SeedSequence(seed).spawn(len(STREAMS))
        generators = {"spawn": self.game.spawn_rng, **{group: plugin.rng for group, plugin in plugins.items()}}
        for name, stream in zip(STREAMS, streams):
            generators[name].bit_generator.state = np.random.default_rng(stream).bit_generator.state
        start_p, start_e = spawn(self.context, self.game.spawn_rng)
        plugins["sim"].reset(start_p, start_e)
        plugins["detector"].reset()
        plugins["pursuer"].reset(start_p)
        plugins["evader"].reset(start_e)
        self.metrics = TrackingMetrics(self.dt)
        self.detected_ticks = 0
        self.step = 0
        self._sense()

    def _sense(self) -> None:
        """The current tick's poses, detection, visibility and belief."""
        plugins, grid, camera = self.game.plugins, self.context.grid, self.context.camera
        self.pursuer, self.evader = plugins["sim"].poses
        p = self.pursuer
        self.detection = plugins["detector"].detect(plugins["sim"].sense(self.time))
        self.visible: VisibilityRegion | None = None
        self.belief: Belief = EMPTY_BELIEF
        if self.estimating:
            self.visible = VisibilityRegion(grid, p, camera)
            estimator = plugins["estimator"]
            if self.step == 0:
                self.belief = estimator.reset(p, self.detection, self.visible)
            else:
                self.belief = estimator.update(self.dt, p, self.detection, self.visible)
        radius = self.context.evader.radius
        self.in_view = body_in_view(grid, camera, p, (self.evader.x, self.evader.y), radius)

    def pursuer_observation(self) -> PursuerObservation:
        """What a pursuer strategy is given at this tick (needs the visibility region)."""
        return PursuerObservation(self.time, self.pursuer, self.detection, self.belief, self.visible)

    def evader_observation(self) -> EvaderObservation:
        """What an evader strategy is given at this tick."""
        return EvaderObservation(self.time, self.evader, self.pursuer)

    def advance(self, pursuer_cmd: Velocity | None = None, evader_cmd: Velocity | None = None) -> bool:
        """Play the current tick with the learners' commands (None for a strategy's role),
        then sense the next tick. Returns whether the evader is detected at the new tick."""
        commands = {"pursuer": pursuer_cmd, "evader": evader_cmd}
        if self.strategies:
            observations = {"pursuer": self.pursuer_observation, "evader": self.evader_observation}
            for role, strategy in self.strategies:
                observation = observations[role]()
                if self.step % self.decide_every == 0:
                    strategy.decide(observation)
                commands[role] = strategy.control(observation)
        detected = self.detection is not None
        self.detected_ticks += detected
        self.metrics.add(self.pursuer, self.evader, detected, self.in_view, self.belief)
        self.game.plugins["sim"].step(commands["pursuer"], commands["evader"], self.dt)
        self.step += 1
        self._sense()
        return self.detection is not None

    @property
    def tracking_rate(self) -> float:
        """Fraction of the ticks played so far with the evader detected (the game's measure)."""
        return self.detected_ticks / self.step if self.step else 0.0

    def close(self) -> None:
        """Release the simulator's resources."""
        self.game.plugins["sim"].close()

