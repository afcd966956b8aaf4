"""Many games of one scenario stepped together: the batched counterpart of
:class:`pegame.envs.core.EnvGame` on the tick loop (:class:`pegame.loop.TickLoop`).

A :class:`BatchedGame` holds ``num_games`` games of one :class:`pegame.game.Scenario`
with the learning ``roles`` commanded from outside. Each game is the game the single env
plays with the same master seed: the same SeedSequence streams (:data:`pegame.game.STREAMS`),
the same spawn (:func:`pegame.game.spawn`), the opponent strategy built from its own
stream, and the same tick.

The order of a tick is the loop's, for the loop's case of external learners and no
estimator (``TickLoop.advance`` with ``estimate=False``), one step of each below per
step of ``advance``:

=====================================  =====================================================
TickLoop.advance                       BatchedGame.step (per control tick)
=====================================  =====================================================
opponent observes; decides at a        opponent.command (the smart evader's batch kernel,
decision tick; gives its command       or a strategy per game in Python), or the tick
                                       kernel reads the opponent's action table
_measure: metrics.add (current tick)   kernels._measure: kernels.tally per evader (and the
                                       team's handoffs and per-pursuer measures)
_integrate: substeps, the pursuers     sims.grid.move per agent, pursuers then evaders, per
then the evaders (GridSimulator.step)  substep (the simulator's own kernel)
step += 1; _sense(): poses, detector   steps += 1; camera.sense: per pair camera.detect,
per pair, in_view per pair             then sight.silhouette_in_view
EnvGame: reward += detections,         camera.sense (memory), state.rewards per evader
features.remember
=====================================  =====================================================

and ``TickLoop.start`` (spawn, plugin resets, sense tick 0) is :meth:`reset_games`. The
kernels play every game's tick in one call (:func:`pegame.vector.kernels.play`, parallel
over games from ``PARALLEL_GAMES`` games on: below, starting numba's threads costs more
than it saves). ``tests/envs/test_vector.py`` plays the batched and the single env side
by side, through autoresets and with each opponent, which keeps the two orders the same.

Why a mirror and not the loop itself: ``TickLoop.advance`` drives one game's plugin
objects with Python values (poses, detections, velocities), and its cost per game is
what the batch exists to remove; a loop generic over batched plugins would need a
batched version of every plugin interface. The kernels keep the loop's order instead,
and the side-by-side test is the contract.

What the batched game plays (anything else is a ConfigError at construction): the grid
simulator; the oracle detector with the perception model's rate, latency, detection
range, range and occlusion misses, independent and bursty misses, depth and bearing
noise (every setting of ``+experiment=paper_conditions`` but its turn order; the pipeline
and the miss chance are the scalar detector's own kernels,
:mod:`pegame.detectors.perception`, and each detector pair's random numbers the
oracle's, drawn ahead at a game's reset, :meth:`BatchedGame._draw_ahead`), and its false
positives, but not a detection profile; ``game.turn_order=simultaneous``; the belief
in a 1v1 pursuer's observation (``belief=True``: the estimator runs per game in Python,
:mod:`pegame.vector.estimation`, at a single game's cost); teams (``team.pursuers``,
``team.evaders``) when both roles learn, as the PettingZoo env plays them: every member
moves (the pursuers, then the evaders), every detector pair (i, j) detects with its own
miss stream and pipeline, and the measures are ``TeamMetrics``' (coverage None, as in an
env game, which builds no regions). A pursuer strategy as the opponent adds the loop's
estimation per game in Python
(:class:`pegame.vector.opponents.PursuerStrategyOpponent`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from omegaconf import DictConfig

from pegame.api import Context
from pegame.detectors.oracle import OracleDetector, camera_numbers
from pegame.detectors.perception import (
    PerceptionConfig,
    capture_period,
    misses_by_range_or_occlusion,
    part_generators,
    pipeline_slots,
    reset_pipeline,
    runs_pipeline,
)
from pegame.errors import ConfigError
from pegame.game import STREAMS, Scenario, member_stream, spawn_team
from pegame.grid import OccupancyGrid
from pegame.navigation import shared_inflation
from pegame.observe.crop import LocalCrop
from pegame.observe.features import extent_numbers
from pegame.observe.observations import EvaderFeatures, PursuerFeatures
from pegame.observe.settings import EnvSettings
from pegame.sims.grid import GridSimulator, body_rows
from pegame.types import Pose
from pegame.vector import kernels
from pegame.vector.estimation import Estimation
from pegame.vector.features import features as kernel_features
from pegame.vector.metrics import new_tally, summary, team_summary
from pegame.vector.opponents import needs_estimation, opponent_for
from pegame.vector.state import (
    BEARING_DRAW,
    BURST_DRAW,
    DEPTH_DRAW,
    DETECTED,
    EVADER,
    FALSE_POSITIVE_DRAW,
    MISS_DRAW,
    PURSUER,
    TICKS,
    BatchState,
    Rules,
    World,
    new_state,
)
from pegame.visibility.sight import sight_tables

#: the oracle detector's perception fields the kernels play only off, and that value
PERCEPTION_OFF = {"profile": None}


def check_playable(scenario: Scenario, settings: EnvSettings, roles: Sequence[str]) -> None:
    """ConfigError naming every key whose value the batched game of the learners
    ``roles`` does not play, each with the values it plays (one paragraph: a config
    such as ``+experiment=paper_conditions`` that sets several learns them all at once)."""
    refused: list[tuple[str, object, str]] = []
    if scenario.classes["sim"] is not GridSimulator:
        refused.append(("sim", scenario.names["sim"], "grid"))
    if scenario.classes["detector"] is not OracleDetector:
        refused.append(("detector", scenario.names["detector"], "oracle"))
    else:
        for key, off in PERCEPTION_OFF.items():
            value = getattr(scenario.configs["detector"], key)
            if value != off:
                refused.append((f"detector.{key}", value, repr(off)))
    if scenario.team_size != (1, 1) and len(roles) != 2:
        for key, size in zip(("team.pursuers", "team.evaders"), scenario.team_size):
            if size != 1:
                refused.append((key, size, "1 against an opponent (a team plays in self-play)"))
    if scenario.settings.turn_order != "simultaneous":
        allowed = "'simultaneous' (a learner commands before it sees the other's move)"
        refused.append(("game.turn_order", scenario.settings.turn_order, allowed))
    if settings.belief and scenario.team_size != (1, 1):
        refused.append(("belief", settings.belief, "False in a team game"))
    if not refused:
        return
    tail = "the batched kernels play only these; use the single env for the rest"
    if len(refused) == 1:
        key, value, allowed = refused[0]
        raise ConfigError(
            f"Invalid value for '{key}' in a batched env: {value!r}. Allowed: {allowed} ({tail})."
        )
    listed = "; ".join(
        f"'{key}': {value!r} (allowed: {allowed})" for key, value, allowed in refused
    )
    raise ConfigError(f"Invalid values in a batched env: {listed} ({tail}).")


class BatchedGame:
    """``num_games`` games of ``cfg`` (a composed run config) with the learners ``roles``
    (a subset of ('pursuer', 'evader')); the other role, if any, is the config's strategy.
    settings: the env's :class:`EnvSettings`."""

    def __init__(
        self, cfg: DictConfig, settings: EnvSettings, roles: Sequence[str], num_games: int
    ) -> None:
        if not (isinstance(num_games, (int, np.integer)) and num_games >= 1):
            raise ConfigError(
                f"Invalid value for 'num_envs': {num_games!r}. Allowed: a whole number >= 1."
            )
        self.settings = settings
        self.roles = tuple(roles)
        self.num_games = int(num_games)
        self.scenario = scenario = Scenario(cfg)
        check_playable(scenario, settings, roles)
        self.team_size = scenario.team_size
        solo = self.team_size == (1, 1)
        #: the learning agents per role, in member order (as :class:`pegame.envs.core.EnvGame`'s)
        self.members = {
            role: [role] if solo else [f"{role}_{k}" for k in range(size)]
            for role, size in zip(("pursuer", "evader"), self.team_size)
            if role in self.roles
        }
        detector = _detector(scenario)
        self._misses = misses_by_range_or_occlusion(detector)
        self._noisy = _noisy(detector)
        #: whether a detector pair takes random numbers (drawn ahead at a reset)
        self._draws_ahead = self._misses or self._noisy or _errs(detector)
        context = scenario.context
        self.context = context
        self.ticks_per_action = settings.ticks_per_action(context.control_dt)
        self.features = {
            "pursuer": PursuerFeatures(context, settings.observation),
            "evader": EvaderFeatures(context, settings.observation),
        }
        self.world = _world(context.grid, context, settings)
        self.rules = _rules(scenario)
        self.state: BatchState = new_state(
            self.num_games,
            _slots(scenario),
            _draws(scenario) if self._misses else 1,
            *self.team_size,
            _draws(scenario) if self._noisy or _errs(detector) else 1,
        )
        self.state.tally[:] = new_tally()
        #: the loop's estimation per game, for a pursuer strategy or a belief observation
        self.estimation = (
            Estimation(scenario, self.num_games)
            if (settings.belief and "pursuer" in self.roles)
            or (len(self.roles) == 1 and needs_estimation(scenario, self.roles[0]))
            else None
        )
        self.opponent = (
            opponent_for(
                scenario, self.roles[0], self.rules.bodies, self.num_games, self.estimation
            )
            if len(self.roles) == 1
            else None
        )
        self.seeds = np.zeros(self.num_games, np.int64)

    @property
    def steps(self) -> int:
        """Env steps in one game."""
        return -(-self.rules.ticks // self.ticks_per_action)

    @property
    def done(self) -> np.ndarray:
        """Bool (N,): the games whose every tick has been played."""
        return self.state.steps >= self.rules.ticks

    def reset_games(self, games: np.ndarray, seeds: Sequence[int]) -> None:
        """Start a new game in each slot of ``games`` with the master seed of the same
        position in ``seeds`` (TickLoop.start: spawn, resets, tick 0 sensed)."""
        state, context = self.state, self.context
        games = np.asarray(games, dtype=np.int64)
        opponent = self.opponent
        n_p, n_e = self.team_size
        pairs = n_p * n_e
        for game, seed in zip(games.tolist(), seeds):
            streams = dict(zip(STREAMS, np.random.SeedSequence(seed).spawn(len(STREAMS))))
            pursuers, evaders = spawn_team(
                context, np.random.default_rng(streams["spawn"]), n_p, n_e
            )
            self.seeds[game] = seed
            state.poses[game] = [(pose.x, pose.y, pose.theta) for pose in (*pursuers, *evaders)]
            if opponent is not None:
                first = pursuers[0] if opponent.role == PURSUER else evaders[0]
                opponent.reset(game, streams, first)
            if self.estimation is not None:
                self.estimation.reset(game, streams)
            if self._draws_ahead:
                for q, seeded in enumerate(_detector_streams(seed, streams, n_p, n_e)):
                    self._draw_ahead(game * pairs + q, np.random.default_rng(seeded))
        rows = {k: (games[:, None] * k + np.arange(k)).ravel() for k in (n_p, n_e, pairs)}
        state.velocities[games] = 0.0
        state.commands[games] = 0.0
        state.steps[games] = 0
        state.has_seen[rows[n_p]] = False
        state.tally[rows[n_e]] = new_tally()
        state.crew[rows[n_p]] = 0.0
        state.trackers[rows[n_e]] = -1
        state.handoffs[games] = 0.0
        state.detected[rows[pairs]] = False  # nothing delivered yet
        reset_pipeline(state.pipeline, rows[pairs])
        state.drawn[rows[pairs]] = 0
        state.noise_drawn[rows[pairs]] = 0
        state.bursting[rows[pairs]] = -1
        kernels.sense_games(self.world, self.rules, state, games)
        if self.estimation is not None:
            self.estimation.sensed(state, games)

    def _draw_ahead(self, pair: int, rng: np.random.Generator) -> None:
        """The random numbers detector pair row ``pair`` (its generator ``rng``, as the
        oracle's) will take, drawn ahead in the oracle's order: its 'range' part's
        uniforms; its own (uniform, normal) per in-range capture, the independent miss
        and the depth noise, drawn together one capture after the other; its 'bearing'
        part's errors; its 'burst' part's uniforms, one per captured frame; its
        'false_positive' part's uniforms, one per frame without a detection and two more
        per false positive."""
        state, config = self.state, _detector(self.scenario)
        parts = part_generators(rng)
        if self._misses:
            state.draws[pair] = parts["range"].random(state.draws.shape[1])
        count = state.noise.shape[1]
        if self._noisy:
            pairs = [(rng.random(), rng.normal(0.0, 1.0)) for _ in range(count)]
            state.noise[pair, :, MISS_DRAW : DEPTH_DRAW + 1] = pairs
        if config.bearing_noise > 0:
            state.noise[pair, :, BEARING_DRAW] = parts["bearing"].normal(
                0.0, config.bearing_noise, count
            )
        if config.burst_miss_fraction > 0:
            state.noise[pair, :, BURST_DRAW] = parts["burst"].random(count)
        if config.false_positive_rate > 0:
            uniforms = parts["false_positive"].random(3 * count).reshape(count, 3)
            state.noise[pair, :, FALSE_POSITIVE_DRAW:] = uniforms

    def step(self, playing: np.ndarray, commands: dict[str, np.ndarray]) -> np.ndarray:
        """One env step (``ticks_per_action`` control ticks) of the games where ``playing``
        (bool (N,)) is set, with the learners' ``commands`` (role -> (N, 2) (v, w) in m/s
        and rad/s, or (N, members, 2) in a team game; rows of other games ignored).
        Returns the detections counted at the ticks reached, (N,) in a 1v1 game and
        (N, E) per evader in a team game (0 for games not playing)."""
        state, rules = self.state, self.rules
        state.rewards[:] = 0.0
        n_p = rules.pursuers
        for role, command in commands.items():
            agents = slice(0, n_p) if role == "pursuer" else slice(n_p, None)
            shaped = np.reshape(command, state.commands[:, agents].shape)
            np.copyto(state.commands[:, agents], shaped, where=playing[:, None, None])
        opponent, estimation = self.opponent, self.estimation
        table = _NO_TABLE if opponent is None or opponent.table is None else opponent.table
        played = -1 if opponent is None or opponent.table is None else opponent.role
        if estimation is None and (opponent is None or opponent.table is not None):
            kernels.play(self.world, rules, state, playing, self.ticks_per_action, table, played)
        else:  # tick by tick: Python's part of a tick around the kernels'
            for _ in range(self.ticks_per_action):
                live = playing & (state.steps < rules.ticks)
                games = np.flatnonzero(live)
                steps = state.steps[games]
                if opponent is not None:
                    time, deciding = steps * rules.control_dt, steps % rules.decide_every == 0
                    opponent.command(state, games, time, deciding)
                if estimation is not None:
                    estimation.measure(state, games)
                kernels.play(self.world, rules, state, live, 1, table, played)
                if estimation is not None:
                    estimation.sensed(state, games)
        rewards = state.rewards.reshape(self.num_games, rules.evaders)
        return rewards[:, 0].copy() if self.team_size == (1, 1) else rewards.copy()

    def observations(self, role: str, member: int = 0) -> np.ndarray:
        """Float32 (N, size): the observation of member ``member`` of ``role`` in every
        game (a new array); a pursuer's belief part, with ``belief``, from each game's
        estimation."""
        features = self.features[role]
        out = np.empty((self.num_games, features.size), dtype=np.float32)
        index = PURSUER if role == "pursuer" else EVADER
        crop = features.layout["crop"].start
        kernel_features(self.world, self.rules, self.state, out, index, member, crop)
        belief = features.layout.get("belief")
        if belief is not None and self.estimation is not None:
            assert isinstance(features, PursuerFeatures)  # only a pursuer's has a belief
            poses = self.state.poses
            for game in range(self.num_games):
                pose = Pose(*poses[game, PURSUER].tolist())
                features.belief_part(out[game, belief], pose, self.estimation.belief(game))
        return out

    def close(self) -> None:
        """Release what the games hold beyond their arrays: the opponent's threads."""
        close = getattr(self.opponent, "close", None)
        if close is not None:
            close()

    def time(self) -> np.ndarray:
        """Float64 (N,): every game's simulation time (s), as ``TickLoop.time``."""
        return self.state.steps * self.context.control_dt

    def tracking_rate(self) -> np.ndarray:
        """Float64 (N,): the fraction of the ticks played with the evader detected (in a
        team game its mean over the evaders, ``TeamMetrics.tracking_rate``)."""
        tally = self.state.tally.reshape(self.num_games, self.rules.evaders, -1)
        ticks = tally[:, :, TICKS]
        rates = np.divide(tally[:, :, DETECTED], ticks, out=np.zeros(ticks.shape), where=ticks > 0)
        return rates[:, 0] if self.team_size == (1, 1) else rates.mean(axis=1)

    def summary(self, game: int) -> dict:
        """Game ``game``'s measures (``TrackingMetrics.summary``, or ``TeamMetrics``'s in a
        team game): a pursuer strategy's opponent keeps them itself (with the
        estimator's), else the kernels' tally. The batched game keeps no loss causes
        (:mod:`pegame.losses`): ``loss_causes`` is None."""
        if self.estimation is not None:
            metrics = self.estimation.metrics[game]
            assert metrics is not None  # the game was reset
            return {**metrics.summary(), "loss_causes": None}
        dt, (n_p, n_e) = self.context.control_dt, self.team_size
        state = self.state
        if (n_p, n_e) == (1, 1):
            return {**summary(state.tally[game], dt), "loss_causes": None}
        rows = state.tally[game * n_e : (game + 1) * n_e]
        crew = state.crew[game * n_p : (game + 1) * n_p]
        handoffs = int(state.handoffs[game])
        return {**team_summary(rows, crew, handoffs, dt), "loss_causes": None}


_NO_TABLE = np.zeros((1, 1, 2))


def _world(grid: OccupancyGrid, context: Context, settings: EnvSettings) -> World:
    crop = LocalCrop(grid, settings.crop_cells, settings.crop_resolution)
    masks = np.stack(
        [
            shared_inflation(grid, context.pursuer.radius),
            shared_inflation(grid, context.evader.radius),
        ]
    )
    frame, sight_values = sight_tables(grid)
    return World(
        grid.blocked,
        frame,
        masks,
        *crop._samples,
        crop._lattice.frame,
        crop._lattice.table,
        crop._lattice.centres,
        sight_values,
        extent_numbers(grid),
    )


def _detector(scenario: Scenario) -> PerceptionConfig:
    config = scenario.configs["detector"]
    assert isinstance(config, PerceptionConfig)  # check_playable: the oracle's
    return config


def _slots(scenario: Scenario) -> int:
    """The results in flight a game's pipeline holds at most."""
    config = _detector(scenario)
    return pipeline_slots(config.latency, capture_period(config, scenario.context.control_dt))


def _draws(scenario: Scenario) -> int:
    """The most range-stream draws of a game: one per capture, at most one per tick (and
    tick 0) and one per capture period."""
    config, ticks = _detector(scenario), scenario.settings.ticks
    period = capture_period(config, scenario.context.control_dt)
    frames = math.floor(ticks * scenario.context.control_dt / period) + 2
    return min(ticks + 1, frames)


def _perception(config: PerceptionConfig, control_dt: float) -> np.ndarray:
    """rules.perception (PERIOD..FALSE_POSITIVE_RATE) of the detector's ``config``."""
    start = math.nan if config.miss_range_start is None else config.miss_range_start
    return np.array(
        [
            capture_period(config, control_dt),
            float(config.rate is not None),
            config.latency,
            float(runs_pipeline(config)),
            float(misses_by_range_or_occlusion(config)),
            start,
            config.miss_at_range,
            config.occlusion_miss,
            float(_noisy(config)),
            config.miss_probability,
            config.range_noise,
            config.range_noise_growth,
            config.bearing_noise,
            config.burst_miss_fraction,
            config.burst_length,
            config.false_positive_rate,
        ],
        dtype=np.float64,
    )


def _errs(config: PerceptionConfig) -> bool:
    """Whether the bearing noise, the bursts or the false positives take draws."""
    return (
        config.bearing_noise > 0 or config.burst_miss_fraction > 0 or config.false_positive_rate > 0
    )


def _noisy(config: PerceptionConfig) -> bool:
    """Whether an in-range capture's independent-miss and depth-noise draws matter (the
    oracle draws them always; the batched game draws them ahead only when they do)."""
    return config.miss_probability > 0 or config.range_noise > 0 or config.range_noise_growth > 0


def _rules(scenario: Scenario) -> Rules:
    context, settings = scenario.context, scenario.settings
    detector = scenario.configs["detector"]
    assert isinstance(detector, OracleDetector.Config)  # check_playable: the oracle's
    n_p, n_e = scenario.team_size
    bodies = body_rows(*[context.pursuer] * n_p, *[context.evader] * n_e)
    return Rules(
        bodies,
        camera_numbers(context.camera, detector),
        _perception(detector, float(context.control_dt)),
        float(context.control_dt),
        int(settings.substeps),
        int(settings.decide_every),
        int(settings.ticks),
        int(n_p),
        int(n_e),
    )


def _detector_streams(
    seed: int, streams: dict, pursuers: int, evaders: int
) -> list[np.random.SeedSequence]:
    """The seed sequence of each detector pair's generator in pair order (the one
    :class:`pegame.game.Game` builds it with: pair (0, 0) the 1v1 detector's stream, the
    others a team member's, ``Game._member``)."""
    return [
        streams["detector"] if (i, j) == (0, 0) else member_stream(seed, "detector", i, j)
        for i in range(pursuers)
        for j in range(evaders)
    ]
