"""Plugin interfaces: what a plugin is given and what it must implement.

Every plugin kind is an abstract base class here: :class:`Simulator`, :class:`Detector`,
:class:`Estimator`, :class:`Pursuer`, :class:`Evader` and :class:`Recorder`. A plugin is
a subclass registered under an entry-point group (see :mod:`pegame.registry`); it declares
its parameters as a dataclass ``Config`` (fields with defaults, validated in
``__post_init__``) and is constructed as ``Plugin(config, context, rng)``. The value types
they exchange live in :mod:`pegame.types` and are re-exported here, so a plugin author
imports everything from ``pegame.api``.

The information each role sees follows the paper's problem statement: the pursuer knows
the map and its own pose and learns about the evader only through its detector; the smart
evader is told the pursuer's pose; the estimator never sees the true evader pose.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any, ClassVar, Generic, NamedTuple, TypeVar

import numpy as np

from pegame.errors import require
from pegame.losses import Loss
from pegame.types import (
    EMPTY_BELIEF,
    STOP,
    Belief,
    Body,
    BoundingBox,
    Camera,
    Detection,
    Plan,
    Pose,
    Region,
    SensorFrame,
    Velocity,
    clamp,
    value_type,
    wrap_angle,
)

if TYPE_CHECKING:  # pragma: no cover - typing only
    from pegame.grid import OccupancyGrid

__all__ = [
    "EMPTY_BELIEF",
    "STOP",
    "Belief",
    "Body",
    "BoundingBox",
    "Camera",
    "Context",
    "Detection",
    "Detector",
    "Estimator",
    "Evader",
    "FirstMembers",
    "EvaderObservation",
    "INTERFACES",
    "PLUGIN_KINDS",
    "Plan",
    "Plugin",
    "PluginKind",
    "Pose",
    "Pursuer",
    "PursuerObservation",
    "PursuerTeam",
    "Recorder",
    "Region",
    "SensorFrame",
    "OneOnOneEstimator",
    "OneOnOneSimulator",
    "Simulator",
    "Strategy",
    "Tick",
    "Velocity",
    "clamp",
    "fuse_detections",
    "wrap_angle",
]


@value_type(eq=False)
class PursuerTeam:
    """What a pursuer knows of its team at one tick (a team game's; None in a 1v1 game).

    member: this pursuer's index i among the N pursuers; target: the index of the evader
    its observation's own fields describe (i mod M); pursuers: the N pursuers' true poses;
    detections: detections[i][j] is pursuer i's detection of evader j this tick, or None;
    beliefs: the team's belief about each of the M evaders (one estimator per evader,
    fed by every pursuer's detections and the union of their regions); regions: the N
    pursuers' visibility regions; union: the cells at least one of them sees.
    """

    member: int
    target: int
    pursuers: tuple[Pose, ...]
    detections: tuple[tuple[Detection | None, ...], ...]
    beliefs: tuple[Belief, ...]
    regions: tuple[Region, ...]
    union: Region


@value_type(eq=False)
class PursuerObservation:
    """What the pursuer strategy is given at each tick.

    time (s); pose: its own true pose (the paper assumes a localised robot); detection of
    the evader this tick, or None; belief: the estimator's current belief; region: the
    pursuer's own visibility region this tick (``region.mask`` is a bool (H, W) mask over
    the grid, computed when first read).

    In a team game these fields are the pursuer's own (its pose, its region) about its
    target evader (its own detection of it, the team's belief about it), so a 1v1
    strategy plays as one of N independent copies; team: the whole team's view
    (:class:`PursuerTeam`), for strategies that cooperate (None in a 1v1 game).
    """

    time: float
    pose: Pose
    detection: Detection | None
    belief: Belief
    region: Region
    team: PursuerTeam | None = None


@value_type
class EvaderObservation:
    """What the evader strategy is given: time (s), its own pose and the pursuer's pose.

    pursuer_region: the pursuer's visibility region at this tick, as the game computed it
    from the pursuer's pose, the map and the camera (which the evader knows too, so this
    only saves it the work); None when the game did not compute it.

    Against a team: pursuer is the pursuer nearest to this evader and pursuer_region the
    union of every pursuer's region (:class:`pegame.visibility.UnionRegion`), so a 1v1
    strategy hides from the whole team; pursuers: every pursuer's pose (one in 1v1);
    member: this evader's index j among the M evaders.
    """

    time: float
    pose: Pose
    pursuer: Pose
    pursuer_region: Region | None = None
    pursuers: tuple[Pose, ...] = ()
    member: int = 0


@value_type
class Context:
    """What every plugin is built with, fixed for one game.

    grid: the occupancy map; pursuer and evader: the agents' bodies; camera: the pursuer's
    camera; control_dt and decision_dt: the control and decision periods (s).
    """

    grid: OccupancyGrid
    pursuer: Body
    evader: Body
    camera: Camera
    control_dt: float
    decision_dt: float


class FirstMembers:
    """Member 0's values under the 1v1 game's names, for a record that holds one value
    per member (``pursuers``, ``evaders``, ``frames``, ``detections[i][j]``, ``beliefs``,
    ``regions``, ``in_views[i][j]``, ``pursuer_plans``, ``evader_plans``): a
    :class:`Tick`, and the :class:`pegame.loop.TickLoop` at its current tick."""

    __slots__ = ()
    pursuers: tuple[Pose, ...]
    evaders: tuple[Pose, ...]
    frames: tuple[SensorFrame, ...]
    detections: tuple[tuple[Detection | None, ...], ...]
    beliefs: tuple[Belief, ...]
    regions: tuple[Region | None, ...]
    in_views: tuple[tuple[bool, ...], ...]
    pursuer_plans: tuple[Plan, ...]
    evader_plans: tuple[Plan, ...]

    @property
    def pursuer(self) -> Pose:
        """Pursuer 0's true pose."""
        return self.pursuers[0]

    @property
    def evader(self) -> Pose:
        """Evader 0's true pose."""
        return self.evaders[0]

    @property
    def frame(self) -> SensorFrame:
        """Pursuer 0's sensor frame."""
        return self.frames[0]

    @property
    def detection(self) -> Detection | None:
        """Pursuer 0's detection of evader 0, or None."""
        return self.detections[0][0]

    @property
    def belief(self) -> Belief:
        """The belief about evader 0."""
        return self.beliefs[0]

    @property
    def region(self) -> Region | None:
        """Pursuer 0's visibility region (None when not computed)."""
        return self.regions[0]

    @property
    def in_view(self) -> bool:
        """Ground truth: evader 0's body in the view of some pursuer."""
        rows = self.in_views
        return rows[0][0] if len(rows) == 1 else any(row[0] for row in rows)

    @property
    def plans(self) -> tuple[Plan, Plan]:
        """(pursuer 0's, evader 0's) latest plans."""
        return self.pursuer_plans[0], self.evader_plans[0]


@value_type(eq=False)
class Tick(FirstMembers):
    """Everything that happened at one control tick of a game of N pursuers and M evaders
    (1v1: N = M = 1), as the recorder receives it; every field is per member, in member
    order; member 0's values, for a 1v1 recorder, are properties (:class:`FirstMembers`,
    and ``commands``).

    step: control tick index; time (s); pursuers (N) and evaders (M): true poses; frames:
    each pursuer's sensor frame; detections[i][j]: pursuer i's detection of evader j or
    None; beliefs: one per evader; regions: each pursuer's visibility region (None when not
    computed); in_views[i][j]: ground truth, evader j's body in pursuer i's view;
    pursuer_commands, evader_commands: the velocities applied after this tick (with
    ``game.turn_order=evader_first`` the evaders' were applied just before it, see
    :mod:`pegame.loop`); pursuer_plans, evader_plans: the latest plans; losses: the losses
    of track begun at this tick, every pair's, each with its cause (:mod:`pegame.losses`).
    """

    step: int
    time: float
    pursuers: tuple[Pose, ...]
    evaders: tuple[Pose, ...]
    frames: tuple[SensorFrame, ...]
    detections: tuple[tuple[Detection | None, ...], ...]
    beliefs: tuple[Belief, ...]
    regions: tuple[Region | None, ...]
    in_views: tuple[tuple[bool, ...], ...]
    pursuer_commands: tuple[Velocity, ...]
    evader_commands: tuple[Velocity, ...]
    pursuer_plans: tuple[Plan, ...]
    evader_plans: tuple[Plan, ...]
    losses: tuple[Loss, ...] = ()

    @classmethod
    def one_on_one(
        cls,
        step: int,
        time: float,
        pursuer: Pose,
        evader: Pose,
        frame: SensorFrame,
        detection: Detection | None,
        belief: Belief,
        region: Region | None,
        in_view: bool,
        commands: tuple[Velocity, Velocity],
        plans: tuple[Plan, Plan],
        losses: tuple[Loss, ...] = (),
    ) -> Tick:
        """The tick of a 1v1 game from its members' values (commands and plans as
        (pursuer, evader) pairs)."""
        return cls(
            step,
            time,
            (pursuer,),
            (evader,),
            (frame,),
            ((detection,),),
            (belief,),
            (region,),
            ((in_view,),),
            (commands[0],),
            (commands[1],),
            (plans[0],),
            (plans[1],),
            losses,
        )

    @property
    def commands(self) -> tuple[Velocity, Velocity]:
        """(pursuer 0's, evader 0's) velocities applied after this tick."""
        return self.pursuer_commands[0], self.evader_commands[0]

    @property
    def solo(self) -> bool:
        """Whether this is a 1v1 game's tick (N = M = 1)."""
        return len(self.pursuers) == 1 and len(self.evaders) == 1


# ----------------------------------------------------------------------- interfaces

PluginT = TypeVar("PluginT", bound="Plugin")


class Plugin(ABC):  # noqa: B024 - an abstract base for the interfaces, which add the methods
    """Base of every plugin: holds its validated config, the game context and its RNG.

    Subclasses set ``Config`` to a dataclass of their parameters and ``description`` to a
    one-line summary shown by ``python -m pegame.catalog``.
    """

    @dataclass
    class Config:
        """No parameters."""

    description: ClassVar[str] = ""

    def __init__(self, config: Any, context: Context, rng: np.random.Generator) -> None:
        self.config = config
        self.context = context
        self.rng = rng

    @classmethod
    def narrow(cls: type[PluginT], plugin: Plugin) -> PluginT:
        """``plugin`` as an instance of this class (an interface: ``Pursuer.narrow(p)``);
        TypeError for a plugin of another kind."""
        if not isinstance(plugin, cls):
            raise TypeError(f"{type(plugin).__name__} is not an instance of {cls.__name__}.")
        return plugin


class Simulator(Plugin):
    """Holds the true state of N pursuers and M evaders and renders each pursuer's sensor
    (a 1v1 game is N = M = 1). Poses are in the map frame (m, m, rad); commands and poses
    go in member order.

    A simulator that plays one pursuer against one evader only subclasses
    :class:`OneOnOneSimulator` and writes its scalar methods instead.
    """

    #: whether the simulator holds more than one pursuer or evader
    teams: ClassVar[bool] = True

    @abstractmethod
    def reset(self, pursuers: Sequence[Pose], evaders: Sequence[Pose]) -> None:
        """Place the N pursuers and M evaders at the given map-frame poses.

        :param pursuers: each pursuer's pose (m, m, rad), in member order.
        :param evaders: each evader's pose (m, m, rad), in member order.
        """

    @abstractmethod
    def step(
        self, pursuer_cmds: Sequence[Velocity], evader_cmds: Sequence[Velocity], dt: float
    ) -> None:
        """Advance dt seconds with every command held; commands beyond an agent's limits
        are saturated (speed, turn rate and, when finite, the bodies' ``a_max`` and
        ``alpha_max``), and an agent never enters an obstacle (it stops at the wall).

        :param pursuer_cmds: each pursuer's (v m/s, w rad/s), held for ``dt``.
        :param evader_cmds: each evader's (v m/s, w rad/s), held for ``dt``.
        :param dt: the period (s), ``context.control_dt`` divided by the physics substeps.
        """

    def step_one(self, role: str, cmds: Sequence[Velocity], dt: float) -> None:
        """Advance only the agents of ``role`` ('pursuer' or 'evader') dt seconds with
        ``cmds`` held, the other role paused (poses and velocities kept): the turns of
        ``game.turn_order=evader_first``. Optional: the tick loop refuses that turn order
        for a simulator that keeps this default."""
        raise NotImplementedError(f"{type(self).__name__} cannot move one role at a time.")

    @property
    @abstractmethod
    def poses(self) -> tuple[tuple[Pose, ...], tuple[Pose, ...]]:
        """The true (pursuers, evaders) poses in the map frame, in member order."""

    @abstractmethod
    def sense(self, time: float) -> tuple[SensorFrame, ...]:
        """Each pursuer camera's frame at simulation time ``time`` (s), in member order.

        :param time: the simulated time of the frames (s), the tick's.
        :returns: per pursuer, the camera's pose and whatever the simulator renders
            (ground-truth evader poses for the oracle; RGB, depth and segmentation for a
            3D simulator).
        """

    def close(self) -> None:
        """Release resources (connections, windows). Called once per game."""


class OneOnOneSimulator(Simulator):
    """The small adapter for a simulator of one pursuer against one evader: write the
    scalar methods below (``*_1v1``); the team-shaped :class:`Simulator` methods call them
    with the one member of each role (and refuse more)."""

    teams: ClassVar[bool] = False

    @abstractmethod
    def reset_1v1(self, pursuer: Pose, evader: Pose) -> None:
        """Place both agents at the given map-frame poses (m, m, rad)."""

    @abstractmethod
    def step_1v1(self, pursuer_cmd: Velocity, evader_cmd: Velocity, dt: float) -> None:
        """:meth:`Simulator.step` for the pursuer's and the evader's command."""

    def step_one_1v1(self, role: str, cmd: Velocity, dt: float) -> None:
        """:meth:`Simulator.step_one` for the one agent of ``role``. Optional."""
        raise NotImplementedError(f"{type(self).__name__} cannot move one agent at a time.")

    @property
    @abstractmethod
    def poses_1v1(self) -> tuple[Pose, Pose]:
        """The true (pursuer, evader) poses in the map frame."""

    @abstractmethod
    def sense_1v1(self, time: float) -> SensorFrame:
        """The pursuer camera's frame at simulation time ``time`` (s)."""

    def reset(self, pursuers: Sequence[Pose], evaders: Sequence[Pose]) -> None:
        if len(pursuers) != 1 or len(evaders) != 1:
            raise NotImplementedError(f"{type(self).__name__} plays one pursuer and one evader.")
        self.reset_1v1(pursuers[0], evaders[0])

    def step(
        self, pursuer_cmds: Sequence[Velocity], evader_cmds: Sequence[Velocity], dt: float
    ) -> None:
        self.step_1v1(pursuer_cmds[0], evader_cmds[0], dt)

    def step_one(self, role: str, cmds: Sequence[Velocity], dt: float) -> None:
        self.step_one_1v1(role, cmds[0], dt)

    @property
    def poses(self) -> tuple[tuple[Pose, ...], tuple[Pose, ...]]:
        pursuer, evader = self.poses_1v1
        return (pursuer,), (evader,)

    def sense(self, time: float) -> tuple[SensorFrame, ...]:
        return (self.sense_1v1(time),)


class Detector(Plugin):
    """Turns a sensor frame into a detection of the evader, or None.

    In a team game the loop holds one detector per (pursuer, evader) pair and asks the
    one of pair (i, j) about pursuer i's frame with ``frame.evader_truth`` = evader j.
    ``identifies``: whether a detection then is of evader j only (a simulator-side
    detector reading ``evader_truth``); a detector that finds whoever is in its images
    cannot tell evaders apart and plays only against one evader.
    """

    #: whether detect() reports only the evader of ``frame.evader_truth``
    identifies: ClassVar[bool] = False

    @abstractmethod
    def detect(self, frame: SensorFrame) -> Detection | None:
        """Detect the evader in ``frame``; None when it is not seen.

        :param frame: the pursuer camera's frame of this tick (``Simulator.sense``).
        :returns: the detection (image box in px, map-frame position in m, depth in m,
            confidence), or None.
        """

    def reset(self) -> None:
        """Forget any tracking state; called at the start of each game."""


class Estimator(Plugin):
    """Estimates one evader's position from every pursuer's detection of it and what the
    pursuers see (a 1v1 game has one pursuer).

    It is given the map (``context.grid``) and the evader's max speed
    (``context.evader.v_max``), never the true evader pose. An estimator that takes one
    pursuer's detection at a time subclasses :class:`OneOnOneEstimator` instead.
    """

    @abstractmethod
    def reset(
        self, pursuers: Sequence[Pose], detections: Sequence[Detection | None], region: Region
    ) -> Belief:
        """Start a new game; the evader is in view at the start (the paper's protocol).

        :param pursuers: every pursuer's pose (map frame), in member order.
        :param detections: each pursuer's detection of this evader at the first tick, or
            None where its detector missed.
        :param region: the cells the pursuers see (the union of their visibility regions).
        :returns: the initial belief about the evader's position.
        """

    @abstractmethod
    def update(
        self,
        dt: float,
        pursuers: Sequence[Pose],
        detections: Sequence[Detection | None],
        region: Region,
    ) -> Belief:
        """Predict dt seconds (s) ahead and correct with this tick's detections (or their
        absence) and the pursuers' visibility region (``region.mask`` is a bool (H, W) mask
        over the grid; ``region.holds(cells)`` answers for a few cells, at a fraction of
        the cost).

        :param dt: the time since the last update (s), one control period.
        :param pursuers: every pursuer's pose at this tick (map frame).
        :param detections: each pursuer's detection of this evader, or None (negative
            information: the evader is not in ``region``, unless the detectors missed it).
        :param region: the cells the pursuers see (the union of their regions).
        :returns: the belief about the evader's position after this tick.
        """


class OneOnOneEstimator(Estimator):
    """The small adapter for an estimator fed by one detection at a time: write
    :meth:`reset_1v1` and :meth:`update_1v1`; against a team the pursuers' detections
    are fused first (:func:`fuse_detections`), with the union of their regions, so the
    negative information is every pursuer's."""

    @abstractmethod
    def reset_1v1(self, pursuer: Pose, detection: Detection | None, region: Region) -> Belief:
        """:meth:`Estimator.reset` for one pursuer's pose and detection (or None)."""

    @abstractmethod
    def update_1v1(
        self, dt: float, pursuer: Pose, detection: Detection | None, region: Region
    ) -> Belief:
        """:meth:`Estimator.update` for one pursuer's pose and detection (or None)."""

    def reset(
        self, pursuers: Sequence[Pose], detections: Sequence[Detection | None], region: Region
    ) -> Belief:
        pursuer, detection = fuse_detections(pursuers, detections)
        return self.reset_1v1(pursuer, detection, region)

    def update(
        self,
        dt: float,
        pursuers: Sequence[Pose],
        detections: Sequence[Detection | None],
        region: Region,
    ) -> Belief:
        pursuer, detection = fuse_detections(pursuers, detections)
        return self.update_1v1(dt, pursuer, detection, region)


def fuse_detections(
    pursuers: Sequence[Pose], detections: Sequence[Detection | None]
) -> tuple[Pose, Detection | None]:
    """One detection from several pursuers' detections of the same evader, and the pose
    of the pursuer it is credited to: the nearest detection (smallest depth, the least
    noisy) placed at the mean of all the detected positions (m, map frame), the fusion
    of equally trusted measurements of one point. (pursuers[0], None) when none detects."""
    if len(detections) == 1:  # one pursuer: its own
        return pursuers[0], detections[0]
    seen = [(d.depth, i, d) for i, d in enumerate(detections) if d is not None]
    if not seen:
        return pursuers[0], None
    _, nearest, best = min(seen, key=lambda s: s[:2])
    if len(seen) == 1:
        return pursuers[nearest], best
    xs = [d.position[0] for _, _, d in seen]
    ys = [d.position[1] for _, _, d in seen]
    return pursuers[nearest], replace(best, position=(sum(xs) / len(xs), sum(ys) / len(ys)))


#: the observation type a :class:`Strategy` is given
ObservationT = TypeVar("ObservationT", contravariant=True)


class Strategy(Plugin, Generic[ObservationT]):
    """A pursuer or evader policy: a plan at each decision tick, a command at each control
    tick. The game calls ``reset`` once, then ``decide`` every decision period and
    ``control`` every control period (both with the latest observation).

    Generic over its observation type: :class:`Pursuer` is a
    ``Strategy[PursuerObservation]``, :class:`Evader` a ``Strategy[EvaderObservation]``;
    a behaviour written once for either role is a
    ``Strategy[PursuerObservation | EvaderObservation]``."""

    @abstractmethod
    def reset(self, pose: Pose) -> None:
        """Start a new game at ``pose``.

        :param pose: this agent's starting pose (m, m, rad), in the map frame.
        """

    @abstractmethod
    def decide(self, observation: ObservationT) -> Plan:
        """Choose what to do until the next decision (called at decision_hz).

        :param observation: what the role may know at this tick
            (:class:`PursuerObservation` or :class:`EvaderObservation`).
        :returns: the plan: a goal (m) and a path to it, and ``info`` for the recording.
        """

    @abstractmethod
    def control(self, observation: ObservationT) -> Velocity:
        """The velocity command for the next control period (called at control_hz).

        :param observation: what the role may know at this tick.
        :returns: (v m/s, w rad/s); the simulator saturates it to the body's limits.
        """


class Pursuer(Strategy[PursuerObservation]):
    """A pursuer strategy; observations are :class:`PursuerObservation`.

    Its body: ``Config.radius`` and ``Config.w_max``; its max speed is not a parameter but
    ``game.speed_ratio`` times the evader's ``v_max`` (read it from ``context.pursuer``).
    Subclasses extend ``Pursuer.Config`` with their own parameters.
    """

    @dataclass
    class Config:
        radius: float = 0.2  # body radius (m), a TurtleBot 2
        w_max: float = 1.8  # max turn rate (rad/s)
        a_max: float = math.inf  # max change of speed (m/s^2) the simulator applies; .inf: at once
        alpha_max: float = math.inf  # max change of turn rate (rad/s^2); .inf: at once

        def __post_init__(self) -> None:
            for key in ("radius", "w_max", "a_max", "alpha_max"):
                value = getattr(self, key)
                require(value > 0, key, "a positive number", value)


class Evader(Strategy[EvaderObservation]):
    """An evader strategy; observations are :class:`EvaderObservation`.

    Its body: ``Config.radius``, ``Config.v_max`` and ``Config.w_max`` (also in
    ``context.evader``). Subclasses extend ``Evader.Config`` with their own parameters.
    """

    @dataclass
    class Config:
        radius: float = 0.25  # body radius (m), a person
        v_max: float = 0.5  # max speed (m/s); the pursuer's is game.speed_ratio times this
        w_max: float = 1.8  # max turn rate (rad/s)
        a_max: float = math.inf  # max change of speed (m/s^2) the simulator applies; .inf: at once
        alpha_max: float = math.inf  # max change of turn rate (rad/s^2); .inf: at once

        def __post_init__(self) -> None:
            for key in ("radius", "v_max", "w_max", "a_max", "alpha_max"):
                value = getattr(self, key)
                require(value > 0, key, "a positive number", value)


class Recorder(Plugin):
    """Logs every tick of a game (for example to a Rerun recording)."""

    @abstractmethod
    def start(self, out_dir: str, game_id: str, properties: dict[str, Any]) -> None:
        """Begin a recording for one game in ``out_dir``; ``properties`` is the run config.

        :param out_dir: the job's directory, where the recording is written.
        :param game_id: the game's name in it (``game``, or ``game_<seed>`` in a job of
            several games).
        :param properties: the run's config, flattened to dotted keys.
        """

    @abstractmethod
    def log(self, tick: Tick) -> None:
        """Log one control tick.

        :param tick: the tick's true poses, frame, detection, belief, region and plans.
        """

    @abstractmethod
    def finish(self, result: dict[str, Any]) -> None:
        """Close the recording of a game that ended; ``result`` is the game's result dict."""

    def abort(self, error: BaseException) -> None:
        """Close the recording of a game that raised ``error`` (the game loop calls this
        instead of :meth:`finish`); the recording should say that the game failed."""


class PluginKind(NamedTuple):
    """A kind of plugin: the interface its classes implement and the entry-point group
    they register under."""

    interface: type[Plugin]
    entry_point_group: str


#: the one list of plugin kinds, in the order a game builds them; the config group of a
#: kind is its key (``pursuer=smart`` picks the ``smart`` entry point of ``pegame.pursuers``)
PLUGIN_KINDS: dict[str, PluginKind] = {
    "sim": PluginKind(Simulator, "pegame.simulators"),
    "detector": PluginKind(Detector, "pegame.detectors"),
    "estimator": PluginKind(Estimator, "pegame.estimators"),
    "pursuer": PluginKind(Pursuer, "pegame.pursuers"),
    "evader": PluginKind(Evader, "pegame.evaders"),
    "recorder": PluginKind(Recorder, "pegame.recorders"),
}

#: kind -> interface, derived from :data:`PLUGIN_KINDS`
INTERFACES: dict[str, type[Plugin]] = {kind: spec.interface for kind, spec in PLUGIN_KINDS.items()}
