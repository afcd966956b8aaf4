"""The tick loop: the order of one control tick, written once (paper, Sec. "Simulation
based validation").

Every tick (period ``context.control_dt``): the simulator gives the true poses and the
pursuer camera's frame; the detector looks for the evader; the pursuer's visibility region
is built (lazily: :class:`pegame.visibility.VisibilityRegion`) and the estimator updates its
belief from the detection and the region; ground truth ``in_view`` is whether any part of
the evader's body is in the pursuer's view. At every decision tick (every
``decide_every`` ticks, the paper's 1 Hz nodes) the evader decides first, then the
pursuer; then both strategies give their velocity commands, the tick is measured and
handed to the recorder, and the simulator integrates the commands for one period. The
measures include every loss of track and its cause (:mod:`pegame.losses`), which the tick
hands to the recorder (``Tick.losses``).

Timing (``game.physics_hz``, ``game.turn_order``; every default keeps the order above):

- The simulator integrates a tick's commands in ``substeps`` steps of
  ``control_dt / substeps`` (``game.physics_hz / game.control_hz``), each command held the
  whole tick: the paper's agents are ROS nodes "with a rate of 1Hz" that hold a command
  while Gazebo moves the world continuously. Sensing, estimation, ground truth and metrics
  stay once per control tick.
- ``turn_order="evader_first"`` plays the paper's "each player take turns to progress in
  the game. First the evader moves and then pursuer moves": a move is one step of the game,
  the paper's "discrete intervals of 1 unit each" (tau = 0, 1, ..., k, its states x_k and
  observations z_k), which is pegame's control tick (at ``control_hz = decision_hz = 1``
  tick, decision and the paper's step coincide). In each tick the evader observes, decides
  (at decision ticks), commands and moves for ``control_dt`` with the pursuer paused; then
  the tick is sensed (so the pursuer's detection, belief and the measured ground truth are
  of the world after the evader's move), the pursuer decides, commands and moves for
  ``control_dt`` with the evader paused. No role may be ``external`` then (an external
  pursuer would have to command before it could see the evader's move).

Teams (``team.pursuers`` = N, ``team.evaders`` = M; a 1v1 game is N = M = 1 and plays as
it always has): the simulator holds every agent and gives each pursuer's camera frame;
one detector per (pursuer i, evader j) pair looks for evader j in pursuer i's frame; one
estimator per evader is fed by every pursuer's detection of it and by the union of the
pursuers' regions (:class:`pegame.visibility.UnionRegion`, the team's negative
information); all evaders decide, then all pursuers, in member order; each pursuer's
observation carries its own pose, region and detection of its target evader (i mod M)
with the team's belief about it, plus the whole team's view
(:class:`pegame.api.PursuerTeam`); each evader's carries the nearest pursuer and the union
region. Member 0 of each role, and detector (0, 0), use the generators a 1v1 game gives
its plugins (:mod:`pegame.game`).

Roles listed as ``external`` take their commands from the caller (a learner in the
environments) instead of their strategy. When no strategy pursuer needs the belief, the
estimator and the region can be skipped (``estimate=False``: they are the most expensive
part of a tick); the belief is then empty and the game has no estimation error.

:class:`pegame.game.Game` (the CLI and sweeps) and the Gymnasium/PettingZoo environments
(:mod:`pegame.envs`) both drive this loop; a 1v1 game plays the same :meth:`TickLoop.advance`
as a team's, with one member per role (the plugins' interfaces are team-shaped,
:mod:`pegame.api`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TypeGuard

from pegame.api import (
    Context,
    Detector,
    Estimator,
    Evader,
    EvaderObservation,
    FirstMembers,
    OneOnOneSimulator,
    Pursuer,
    PursuerObservation,
    PursuerTeam,
    Recorder,
    Simulator,
    Tick,
)
from pegame.config import TURN_ORDERS
from pegame.errors import ConfigError
from pegame.losses import LossCauses
from pegame.metrics import TeamMetrics, TrackingMetrics
from pegame.types import (
    EMPTY_BELIEF,
    Detection,
    Plan,
    Pose,
    Region,
    Velocity,
)
from pegame.visibility import UnionRegion, VisibilityRegion, body_in_view

ROLES = ("pursuer", "evader")


@dataclass(frozen=True)
class GamePlugins:
    """A game's plugins, one typed field per role: the simulator; ``detectors[i][j]``,
    pursuer i's detector of evader j; ``estimators[j]``, evader j's; the N ``pursuers``
    and M ``evaders`` strategies in member order; the recorder. A 1v1 game has one of
    each (:meth:`one_on_one`); member 0 of each role is also named by its 1v1 property."""

    sim: Simulator
    detectors: tuple[tuple[Detector, ...], ...]
    estimators: tuple[Estimator, ...]
    pursuers: tuple[Pursuer, ...]
    evaders: tuple[Evader, ...]
    recorder: Recorder

    @classmethod
    def one_on_one(
        cls,
        sim: Simulator,
        detector: Detector,
        estimator: Estimator,
        pursuer: Pursuer,
        evader: Evader,
        recorder: Recorder,
    ) -> GamePlugins:
        """The plugins of a game of one pursuer against one evader."""
        return cls(sim, ((detector,),), (estimator,), (pursuer,), (evader,), recorder)

    @property
    def detector(self) -> Detector:
        """Pursuer 0's detector of evader 0."""
        return self.detectors[0][0]

    @property
    def estimator(self) -> Estimator:
        """Evader 0's estimator."""
        return self.estimators[0]

    @property
    def pursuer(self) -> Pursuer:
        """Pursuer 0's strategy."""
        return self.pursuers[0]

    @property
    def evader(self) -> Evader:
        """Evader 0's strategy."""
        return self.evaders[0]


def nearest(poses: Sequence[Pose], to: Pose) -> int:
    """The index of the pose in ``poses`` nearest to ``to`` (the lowest among ties)."""
    if len(poses) == 1:
        return 0
    distances = [(p.x - to.x) ** 2 + (p.y - to.y) ** 2 for p in poses]
    return distances.index(min(distances))


class TickLoop(FirstMembers):
    """Plays the ticks of one game in the order of the module docstring.

    plugins: the game's plugins (:class:`GamePlugins`, one per member of each role);
    context: its context; ticks: control ticks in the game; decide_every: control ticks
    per decision; external: the roles commanded by the caller (with one velocity per
    member); estimate: run the estimator and build the region (forced on when the
    pursuer is a strategy, which needs them); substeps: simulator steps per control
    tick; turn_order: one of :data:`pegame.config.TURN_ORDERS`.
    """

    def __init__(
        self,
        plugins: GamePlugins,
        context: Context,
        ticks: int,
        decide_every: int,
        external: Sequence[str] = (),
        estimate: bool = True,
        substeps: int = 1,
        turn_order: str = "simultaneous",
    ) -> None:
        unknown = sorted(set(external) - set(ROLES))
        if unknown:
            raise ValueError(f"external roles must be among {ROLES}, got {unknown}.")
        if turn_order not in TURN_ORDERS:
            raise ValueError(f"turn_order must be one of {TURN_ORDERS}, got {turn_order!r}.")
        if turn_order == "evader_first" and external:
            raise ConfigError(
                f"game.turn_order=evader_first cannot have external roles {list(external)}: "
                "the pursuer commands after seeing the evader's move, inside one tick. Use "
                "game.turn_order=simultaneous with the environments."
            )
        if turn_order == "evader_first" and not moves_one_role(type(plugins.sim)):
            raise ConfigError(
                f"game.turn_order=evader_first needs a simulator that moves one role at a "
                f"time (Simulator.step_one); {type(plugins.sim).__name__} does not. Use "
                "game.turn_order=simultaneous, or the grid simulator (sim=grid)."
            )
        if substeps < 1:
            raise ValueError(f"substeps must be a whole number >= 1, got {substeps}.")
        # the plugins as attributes of the loop, one lookup away in the ticks
        self.sim, self.recorder = plugins.sim, plugins.recorder
        self.pursuer_strategies, self.evader_strategies = plugins.pursuers, plugins.evaders
        self.detectors, self.estimators = plugins.detectors, plugins.estimators
        self.n_pursuers, self.n_evaders = len(self.pursuer_strategies), len(self.evader_strategies)
        self.solo = self.n_pursuers == 1 and self.n_evaders == 1
        check_team(type(self.sim), type(self.detectors[0][0]), self.n_pursuers, self.n_evaders)
        self.context = context
        self.ticks = ticks
        self.decide_every = decide_every
        self.external = tuple(external)
        self.estimate = estimate or "pursuer" not in self.external
        self.substeps = substeps
        self.turn_order = turn_order
        # the game's measures; a 1v1 game's ticks add to them as ``tracking``, a team's
        # as ``team_metrics`` (each defined only in its kind of game); every pair's
        # losses of track and their causes (``losses``) are part of them
        self.losses = LossCauses(context, self.n_pursuers, self.n_evaders)
        self.metrics: TrackingMetrics | TeamMetrics
        if self.solo:
            self.tracking = self.metrics = TrackingMetrics(context.control_dt, self.losses)
        else:
            self.team_metrics = self.metrics = TeamMetrics(
                context, self.n_pursuers, self.n_evaders, self.losses
            )
        self.step = 0
        self.time = 0.0  # s, simulation time of the current tick: step * control_dt
        self.evader_first = turn_order == "evader_first"
        self.pursuer_plans: tuple[Plan, ...] = (Plan(),) * self.n_pursuers
        self.evader_plans: tuple[Plan, ...] = (Plan(),) * self.n_evaders
        # per-tick constants of the member loops
        self._pursuer_ids, self._evader_ids = range(self.n_pursuers), range(self.n_evaders)
        self._no_regions: tuple[None, ...] = (None,) * self.n_pursuers
        self._no_beliefs = (EMPTY_BELIEF,) * self.n_evaders

    @property
    def done(self) -> bool:
        """True once every tick of the game has been played."""
        return self.step >= self.ticks

    def start(self, pursuer: Pose | Sequence[Pose], evader: Pose | Sequence[Pose]) -> None:
        """Place the agents (a pose per role in 1v1, a sequence of poses per role for a
        team), reset every plugin and sense tick 0 (with ``evader_first``, tick 0 is sensed
        after the evaders' first move, in :meth:`advance`)."""
        pursuers = (pursuer,) if isinstance(pursuer, Pose) else tuple(pursuer)
        evaders = (evader,) if isinstance(evader, Pose) else tuple(evader)
        if (len(pursuers), len(evaders)) != (self.n_pursuers, self.n_evaders):
            raise ValueError(
                f"start needs {self.n_pursuers} pursuer and {self.n_evaders} evader poses, "
                f"got {len(pursuers)} and {len(evaders)}."
            )
        self.sim.reset(pursuers, evaders)
        for row in self.detectors:
            for detector in row:
                detector.reset()
        for pursuer_strategy, pose in zip(self.pursuer_strategies, pursuers):
            pursuer_strategy.reset(pose)
        for evader_strategy, pose in zip(self.evader_strategies, evaders):
            evader_strategy.reset(pose)
        if self.evader_first:
            self.pursuers, self.evaders = pursuers, evaders
            self.regions: tuple[VisibilityRegion | None, ...] = (None,) * self.n_pursuers
            self.union: Region | None = None
        else:
            self._sense()

    def _sense(self, regions: tuple[VisibilityRegion, ...] | None = None) -> None:
        """The current tick's poses, frames, detections, regions, beliefs and in_view;
        ``regions``: the pursuers' regions already built for their current poses, if any.
        (Loops, not comprehensions, here and in :meth:`advance`: each comprehension is a
        function call in Python 3.11, and these run every tick.)"""
        context = self.context
        grid, camera, radius = context.grid, context.camera, context.evader.radius
        pursuers, evaders = self.pursuers, self.evaders = self.sim.poses
        frames = self.frames = self.sim.sense(self.time)
        detections: list[tuple[Detection | None, ...]] = []
        for frame, pair_detectors in zip(frames, self.detectors):
            if self.n_evaders == 1:  # one evader: nobody to tell apart
                detections.append((pair_detectors[0].detect(frame),))
                continue
            seen = []
            for j, detector in enumerate(pair_detectors):
                seen.append(_identified(detector.detect(frame.about(j)), j))
            detections.append(tuple(seen))
        self.detections = tuple(detections)
        if self.estimate:
            if regions is None:
                built = []
                for pose in pursuers:
                    built.append(VisibilityRegion(grid, pose, camera))
                regions = tuple(built)
            union = regions[0] if self.n_pursuers == 1 else UnionRegion(regions)
            self.regions, self.union = regions, union
            beliefs = []
            # each evader's estimator, with every pursuer's detection of it
            for estimator, seen_by in zip(self.estimators, zip(*self.detections)):
                if self.step == 0:
                    beliefs.append(estimator.reset(pursuers, seen_by, union))
                else:
                    beliefs.append(estimator.update(context.control_dt, pursuers, seen_by, union))
            self.beliefs = tuple(beliefs)
        else:
            self.regions, self.union, self.beliefs = self._no_regions, None, self._no_beliefs
        in_views = []
        for pursuer in pursuers:
            sees = []
            for evader in evaders:
                sees.append(body_in_view(grid, camera, pursuer, (evader.x, evader.y), radius))
            in_views.append(tuple(sees))
        self.in_views = tuple(in_views)

    def pursuer_observation(self, i: int = 0) -> PursuerObservation:
        """What pursuer ``i`` is given at this tick (needs ``estimate``)."""
        j = i % self.n_evaders
        regions, union = self.regions, self.union
        if union is None or not _built(regions):
            raise RuntimeError("A pursuer's observation needs its region: estimate=True.")
        team = None
        if not self.solo:
            team = PursuerTeam(i, j, self.pursuers, self.detections, self.beliefs, regions, union)
        return PursuerObservation(
            self.time,
            self.pursuers[i],
            self.detections[i][j],
            self.beliefs[j],
            regions[i],
            team,
        )

    def evader_observation(self, j: int = 0) -> EvaderObservation:
        """What evader ``j`` is given at this tick: the pursuer nearest to it and the
        union of the pursuers' regions."""
        me, pursuers = self.evaders[j], self.pursuers
        near = pursuers[0] if self.n_pursuers == 1 else pursuers[nearest(pursuers, me)]
        return EvaderObservation(self.time, me, near, self.union, pursuers, j)

    def advance(self, commands: Mapping[str, Velocity | Sequence[Velocity]] | None = None) -> Tick:
        """Play the current tick with the external roles' ``commands`` (role -> velocity,
        or one velocity per member in a team game), step the simulator and sense the next
        tick. Returns the tick that was played."""
        if self.step >= self.ticks:
            raise RuntimeError("The game is over: every tick has been played.")
        commanded = self._commanded(commands) if commands or self.external else {}
        deciding = self.step % self.decide_every == 0
        evaders, pursuers = self.evader_strategies, self.pursuer_strategies
        if self.evader_first:
            self._evaders_turn(deciding, commanded)
        e_obs: list[EvaderObservation] | None = None
        if not self.evader_first and "evader" not in self.external:
            e_obs = []
            for j in self._evader_ids:
                e_obs.append(self.evader_observation(j))
        p_obs: list[PursuerObservation] | None = None
        if "pursuer" not in self.external:
            p_obs = []
            for i in self._pursuer_ids:
                p_obs.append(self.pursuer_observation(i))
        if deciding:  # the evaders first, then the pursuers (paper)
            if e_obs is not None:
                self.evader_plans = tuple([s.decide(o) for s, o in zip(evaders, e_obs)])
            if p_obs is not None:
                self.pursuer_plans = tuple([s.decide(o) for s, o in zip(pursuers, p_obs)])
        if p_obs is not None:
            controlled = commanded["pursuer"] = []
            for pursuer, p_ob in zip(pursuers, p_obs):
                controlled.append(pursuer.control(p_ob))
        if e_obs is not None:
            controlled = commanded["evader"] = []
            for evader, e_ob in zip(evaders, e_obs):
                controlled.append(evader.control(e_ob))
        p_cmds, e_cmds = commanded["pursuer"], commanded["evader"]
        tick = self._measure(deciding, p_cmds, e_cmds)
        self.recorder.log(tick)
        if self.evader_first:
            self._integrate(pursuers=p_cmds)
            self._next_tick()
        else:
            self._integrate(p_cmds, e_cmds)
            self._next_tick()
            self._sense()  # also after the last tick: the environments observe the final state
        return tick

    def _evaders_turn(self, deciding: bool, commanded: dict[str, Sequence[Velocity]]) -> None:
        """``evader_first``: the evaders observe, decide (at a decision tick), command and
        move on the world after the pursuers' last move, then the tick is sensed. The
        pursuers' regions are built first and kept for the sensing, since the pursuers do
        not move in the evaders' turn."""
        evaders = self.evader_strategies
        self.pursuers, self.evaders = self.sim.poses
        grid, camera = self.context.grid, self.context.camera
        regions = tuple(VisibilityRegion(grid, pose, camera) for pose in self.pursuers)
        self.regions = regions
        self.union = regions[0] if self.n_pursuers == 1 else UnionRegion(regions)
        observations = [self.evader_observation(j) for j in self._evader_ids]
        if deciding:
            self.evader_plans = tuple([s.decide(o) for s, o in zip(evaders, observations)])
        commanded["evader"] = [s.control(o) for s, o in zip(evaders, observations)]
        self._integrate(evaders=commanded["evader"])
        self._sense(regions)

    def _measure(
        self, deciding: bool, p_cmds: Sequence[Velocity], e_cmds: Sequence[Velocity]
    ) -> Tick:
        """Add the tick to the game's measures and losses of track; the tick."""
        pursuers, evaders, detections = self.pursuers, self.evaders, self.detections
        if self.solo:
            in_view, detected = self.in_views[0][0], detections[0][0] is not None
            self.tracking.add(pursuers[0], evaders[0], detected, in_view, self.beliefs[0])
            losses = self.losses.add_one(pursuers[0], evaders[0], detected, p_cmds[0])
        else:
            self.team_metrics.add(
                pursuers,
                evaders,
                detections,
                self.in_views,
                self.beliefs,
                self.union if deciding else None,
            )
            losses = self.losses.add(pursuers, evaders, detections, p_cmds)
        return Tick(
            self.step,
            self.time,
            pursuers,
            evaders,
            self.frames,
            detections,
            self.beliefs,
            self.regions,
            self.in_views,
            tuple(p_cmds),
            tuple(e_cmds),
            self.pursuer_plans,
            self.evader_plans,
            losses,
        )

    def _next_tick(self) -> None:
        self.step += 1
        self.time = self.step * self.context.control_dt

    def _commanded(
        self, commands: Mapping[str, Velocity | Sequence[Velocity]] | None
    ) -> dict[str, Sequence[Velocity]]:
        """The external roles' commands as one sequence of velocities per role;
        ValueError when an external role has none."""
        commanded: dict[str, Sequence[Velocity]] = {}
        for role, command in (commands or {}).items():  # loops, not comprehensions: per tick
            commanded[role] = (command,) if isinstance(command, Velocity) else command
        for role in self.external:
            if role not in commanded:
                missing = [role for role in self.external if role not in commanded]
                raise ValueError(f"No command for the external role(s) {missing}.")
        return commanded

    def _integrate(
        self, pursuers: Sequence[Velocity] | None = None, evaders: Sequence[Velocity] | None = None
    ) -> None:
        """Hold the commands for one control period, in ``substeps`` simulator steps; a
        role without commands is paused (``evader_first``'s turns)."""
        dt = self.context.control_dt / self.substeps
        sim = self.sim
        for _ in range(self.substeps):
            if pursuers is not None and evaders is not None:
                sim.step(pursuers, evaders, dt)
            elif pursuers is not None:
                sim.step_one("pursuer", pursuers, dt)
            elif evaders is not None:
                sim.step_one("evader", evaders, dt)


def _built(regions: tuple[VisibilityRegion | None, ...]) -> TypeGuard[tuple[VisibilityRegion, ...]]:
    """Whether every pursuer's region was built this tick (``estimate``)."""
    return None not in regions


def _identified(detection: Detection | None, evader: int) -> Detection | None:
    """``detection`` naming evader ``evader`` (a team detector pair knows whom it saw)."""
    if detection is None or detection.evader == evader:
        return detection
    return replace(detection, evader=evader)


def moves_one_role(sim: type[Simulator]) -> bool:
    """Whether the simulator class can move one role with the other paused
    (:meth:`Simulator.step_one`, or :meth:`OneOnOneSimulator.step_one_1v1`)."""
    if issubclass(sim, OneOnOneSimulator):
        return sim.step_one_1v1 is not OneOnOneSimulator.step_one_1v1
    return sim.step_one is not Simulator.step_one


def check_team(sim: type[Simulator], detector: type[Detector], pursuers: int, evaders: int) -> None:
    """ConfigError unless the simulator and detector classes can play N ``pursuers``
    against M ``evaders``: a simulator that holds teams, and, against several evaders, a
    detector that tells them apart."""
    team = f"{pursuers} pursuer(s) against {evaders} evader(s)"
    if (pursuers > 1 or evaders > 1) and not sim.teams:
        raise ConfigError(
            f"Invalid value for 'team': {team}, but the simulator {sim.__name__} plays "
            "one pursuer and one evader. Allowed: team.pursuers=1 team.evaders=1, or a "
            "simulator that plays teams (sim=grid)."
        )
    if evaders > 1 and not detector.identifies:
        raise ConfigError(
            f"Invalid value for 'team.evaders': {evaders}, but the detector "
            f"{detector.__name__} cannot tell evaders apart. Allowed: team.evaders=1, "
            "or a detector that identifies the evader it saw (detector=oracle)."
        )
