"""The tick loop: the order of one control tick, written once (paper, Sec. "Simulation
based validation").

Every tick (period ``context.control_dt``): the simulator gives the true poses and the
pursuer camera's frame; the detector looks for the evader; the pursuer's visibility region
is built (lazily: :class:`pegame.visibility.VisibilityRegion`) and the estimator updates its
belief from the detection and the region; ground truth ``in_view`` is whether any part of
the evader's body is in the pursuer's view. At every decision tick (every
``decide_every`` ticks, the paper's 1 Hz nodes) the evader decides first, then the
pursuer; then both strategies give their velocity commands, the tick is measured and
handed to the recorder, and the simulator integrates the commands for one period.

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

Roles listed as ``external`` take their commands from the caller (a learner in the
environments) instead of their strategy. When no strategy pursuer needs the belief, the
estimator and the region can be skipped (``estimate=False``: they are the most expensive
part of a tick); the belief is then empty and the game has no estimation error.

:class:`pegame.game.Game` (the CLI and sweeps) and the Gymnasium/PettingZoo environments
(:mod:`pegame.envs`) both drive this loop.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from pegame.api import (
    Context,
    EvaderObservation,
    Plugin,
    PursuerObservation,
    Simulator,
    Tick,
)
from pegame.config import TURN_ORDERS
from pegame.errors import ConfigError
from pegame.metrics import TrackingMetrics
from pegame.types import EMPTY_BELIEF, Belief, Detection, Plan, Pose, SensorFrame, Velocity
from pegame.visibility import VisibilityRegion, body_in_view

ROLES = ("pursuer", "evader")


class TickLoop:
    """Plays the ticks of one game in the order of the module docstring.

    plugins: the game's plugins by kind (``sim``, ``detector``, ...); context: its context;
    ticks: control ticks in the game; decide_every: control ticks per decision; external:
    the roles commanded by the caller; estimate: run the estimator and build the region
    (forced on when the pursuer is a strategy, which needs them); substeps: simulator
    steps per control tick; turn_order: one of :data:`pegame.config.TURN_ORDERS`.
    """

    def __init__(
        self,
        plugins: Mapping[str, Plugin],
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
        if turn_order == "evader_first" and type(plugins["sim"]).step_one is Simulator.step_one:
            raise ConfigError(
                f"game.turn_order=evader_first needs a simulator that moves one agent at a "
                f"time (Simulator.step_one); {type(plugins['sim']).__name__} does not. Use "
                "game.turn_order=simultaneous, or the grid simulator (sim=grid)."
            )
        if substeps < 1:
            raise ValueError(f"substeps must be a whole number >= 1, got {substeps}.")
        self.sim, self.detector, self.estimator = (
            plugins["sim"],
            plugins["detector"],
            plugins["estimator"],
        )
        self.pursuer_strategy, self.evader_strategy = plugins["pursuer"], plugins["evader"]
        self.recorder = plugins["recorder"]
        self.context = context
        self.ticks = ticks
        self.decide_every = decide_every
        self.external = tuple(external)
        self.estimate = estimate or "pursuer" not in self.external
        self.substeps = substeps
        self.turn_order = turn_order
        self.metrics = TrackingMetrics(context.control_dt)
        self.step = 0
        self.plans = (Plan(), Plan())

    @property
    def time(self) -> float:
        """Simulation time of the current tick (s)."""
        return self.step * self.context.control_dt

    @property
    def done(self) -> bool:
        """True once every tick of the game has been played."""
        return self.step >= self.ticks

    @property
    def evader_first(self) -> bool:
        return self.turn_order == "evader_first"

    def start(self, pursuer: Pose, evader: Pose) -> None:
        """Place both agents, reset every plugin and sense tick 0 (with ``evader_first``,
        tick 0 is sensed after the evader's first move, in :meth:`advance`)."""
        self.sim.reset(pursuer, evader)
        self.detector.reset()
        self.pursuer_strategy.reset(pursuer)
        self.evader_strategy.reset(evader)
        if self.evader_first:
            self.pursuer, self.evader = pursuer, evader
        else:
            self._sense()

    def _sense(self, region: VisibilityRegion | None = None) -> None:
        """The current tick's poses, frame, detection, region, belief and in_view;
        ``region``: the pursuer's region already built for its current pose, if any."""
        grid, camera = self.context.grid, self.context.camera
        self.pursuer, self.evader = self.sim.poses
        self.frame: SensorFrame = self.sim.sense(self.time)
        self.detection: Detection | None = self.detector.detect(self.frame)
        self.region: VisibilityRegion | None = None
        self.belief: Belief = EMPTY_BELIEF
        if self.estimate:
            self.region = region or VisibilityRegion(grid, self.pursuer, camera)
            if self.step == 0:
                self.belief = self.estimator.reset(self.pursuer, self.detection, self.region)
            else:
                self.belief = self.estimator.update(
                    self.context.control_dt, self.pursuer, self.detection, self.region
                )
        self.in_view = body_in_view(
            grid, camera, self.pursuer, (self.evader.x, self.evader.y), self.context.evader.radius
        )

    def pursuer_observation(self) -> PursuerObservation:
        """What a pursuer strategy is given at this tick (needs ``estimate``)."""
        return PursuerObservation(self.time, self.pursuer, self.detection, self.belief, self.region)

    def evader_observation(self) -> EvaderObservation:
        """What an evader strategy is given at this tick."""
        return EvaderObservation(self.time, self.evader, self.pursuer, self.region)

    def advance(self, commands: Mapping[str, Velocity] | None = None) -> Tick:
        """Play the current tick with the external roles' ``commands`` (role -> velocity),
        step the simulator and sense the next tick. Returns the tick that was played."""
        if self.done:
            raise RuntimeError("The game is over: every tick has been played.")
        commanded = dict(commands or {})
        missing = [role for role in self.external if role not in commanded]
        if missing:
            raise ValueError(f"No command for the external role(s) {missing}.")
        deciding = self.step % self.decide_every == 0
        e_plan, p_plan = self.plans[1], self.plans[0]
        if self.evader_first:
            # The evader's turn, on the world after the pursuer's last move: its own pose,
            # the pursuer's, and the pursuer's region (kept for the sensing that follows,
            # since the pursuer does not move in the evader's turn).
            self.pursuer, self.evader = self.sim.poses
            self.region = VisibilityRegion(self.context.grid, self.pursuer, self.context.camera)
            e_obs = self.evader_observation()
            if deciding:
                e_plan = self.evader_strategy.decide(e_obs)
            commanded["evader"] = self.evader_strategy.control(e_obs)
            self._integrate(evader=commanded["evader"])
            self._sense(self.region)
            e_obs = None
        else:
            e_obs = self.evader_observation() if "evader" not in self.external else None
        p_obs = self.pursuer_observation() if "pursuer" not in self.external else None
        if deciding:  # the evader first, then the pursuer (paper)
            if e_obs is not None:
                e_plan = self.evader_strategy.decide(e_obs)
            if p_obs is not None:
                p_plan = self.pursuer_strategy.decide(p_obs)
            self.plans = (p_plan, e_plan)
        if p_obs is not None:
            commanded["pursuer"] = self.pursuer_strategy.control(p_obs)
        if e_obs is not None:
            commanded["evader"] = self.evader_strategy.control(e_obs)
        velocities = (commanded["pursuer"], commanded["evader"])
        self.metrics.add(
            self.pursuer, self.evader, self.detection is not None, self.in_view, self.belief
        )
        tick = Tick(
            self.step,
            self.time,
            self.pursuer,
            self.evader,
            self.frame,
            self.detection,
            self.belief,
            self.region,
            self.in_view,
            velocities,
            self.plans,
        )
        self.recorder.log(tick)
        if self.evader_first:
            self._integrate(pursuer=velocities[0])
            self.step += 1
        else:
            self._integrate(*velocities)
            self.step += 1
            self._sense()  # also after the last tick: the environments observe the final state
        return tick

    def _integrate(self, pursuer: Velocity | None = None, evader: Velocity | None = None) -> None:
        """Hold the commands for one control period, in ``substeps`` simulator steps; a
        role without a command is paused (``evader_first``'s turns)."""
        dt = self.context.control_dt / self.substeps
        for _ in range(self.substeps):
            if pursuer is not None and evader is not None:
                self.sim.step(pursuer, evader, dt)
            elif pursuer is not None:
                self.sim.step_one("pursuer", pursuer, dt)
            elif evader is not None:
                self.sim.step_one("evader", evader, dt)
