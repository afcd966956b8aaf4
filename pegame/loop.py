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

Roles listed as ``external`` take their commands from the caller (a learner in the
environments) instead of their strategy. When no strategy pursuer needs the belief, the
estimator and the region can be skipped (``estimate=False``: they are the most expensive
part of a tick); the belief is then empty and the game has no estimation error.

:class:`pegame.game.Game` (the CLI and sweeps) and the Gymnasium/PettingZoo environments
(:mod:`pegame.envs`) both drive this loop.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from pegame.api import Context, EvaderObservation, Plugin, PursuerObservation, Tick
from pegame.metrics import TrackingMetrics
from pegame.types import EMPTY_BELIEF, Belief, Detection, Plan, Pose, SensorFrame, Velocity
from pegame.visibility import VisibilityRegion, body_in_view

ROLES = ("pursuer", "evader")


class TickLoop:
    """Plays the ticks of one game in the order of the module docstring.

    plugins: the game's plugins by kind (``sim``, ``detector``, ...); context: its context;
    ticks: control ticks in the game; decide_every: control ticks per decision; external:
    the roles commanded by the caller; estimate: run the estimator and build the region
    (forced on when the pursuer is a strategy, which needs them).
    """

    def __init__(
        self,
        plugins: Mapping[str, Plugin],
        context: Context,
        ticks: int,
        decide_every: int,
        external: Sequence[str] = (),
        estimate: bool = True,
    ) -> None:
        unknown = sorted(set(external) - set(ROLES))
        if unknown:
            raise ValueError(f"external roles must be among {ROLES}, got {unknown}.")
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

    def start(self, pursuer: Pose, evader: Pose) -> None:
        """Place both agents, reset every plugin and sense tick 0."""
        self.sim.reset(pursuer, evader)
        self.detector.reset()
        self.pursuer_strategy.reset(pursuer)
        self.evader_strategy.reset(evader)
        self._sense()

    def _sense(self) -> None:
        """The current tick's poses, frame, detection, region, belief and in_view."""
        grid, camera = self.context.grid, self.context.camera
        self.pursuer, self.evader = self.sim.poses
        self.frame: SensorFrame = self.sim.sense(self.time)
        self.detection: Detection | None = self.detector.detect(self.frame)
        self.region: VisibilityRegion | None = None
        self.belief: Belief = EMPTY_BELIEF
        if self.estimate:
            self.region = VisibilityRegion(grid, self.pursuer, camera)
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
        e_plan, p_plan = self.plans[1], self.plans[0]
        e_obs = self.evader_observation() if "evader" not in self.external else None
        p_obs = self.pursuer_observation() if "pursuer" not in self.external else None
        if self.step % self.decide_every == 0:  # the evader first, then the pursuer (paper)
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
        self.sim.step(velocities[0], velocities[1], self.context.control_dt)
        self.step += 1
        self._sense()  # also after the last tick: the environments observe the final state
        return tick
