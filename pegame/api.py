"""Plugin interfaces and the value types they exchange.

Every plugin kind is an abstract base class here: :class:`Simulator`, :class:`Detector`,
:class:`Estimator`, :class:`Pursuer`, :class:`Evader` and :class:`Recorder`. A plugin is
a subclass registered under an entry-point group (see :mod:`pegame.registry`); it declares
its parameters as a dataclass ``Config`` (fields with defaults, validated in
``__post_init__``) and is constructed as ``Plugin(config, context, rng)``.

Conventions (see DESIGN.md): SI units (m, s, rad); angles wrapped to (-pi, pi]; the map
frame is ROS's (x right, y up, origin at the lower-left corner of cell (row 0, col 0));
value types are frozen dataclasses; arrays are numpy with documented shapes.

The information each role sees follows the paper's problem statement: the pursuer knows
the map and its own pose and learns about the evader only through its detector; the smart
evader is told the pursuer's pose; the estimator never sees the true evader pose.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from pegame.errors import require

if TYPE_CHECKING:  # pragma: no cover - typing only
    from pegame.geometry import VisibilityRegion
    from pegame.maps import OccupancyGrid


def wrap_angle(angle: float) -> float:
    """Wrap an angle in radians to (-pi, pi]."""
    wrapped = math.remainder(angle, 2.0 * math.pi)
    return math.pi if wrapped == -math.pi else wrapped


# --------------------------------------------------------------------------- values


@dataclass(frozen=True)
class Pose:
    """A planar pose in the map frame: position (m) and heading theta (rad, from +x, CCW)."""

    x: float
    y: float
    theta: float = 0.0

    @property
    def xy(self) -> np.ndarray:
        """Position as a float array of shape (2,), metres."""
        return np.array([self.x, self.y])

    def distance_to(self, other: Pose) -> float:
        """Euclidean distance between the two positions, metres."""
        return math.hypot(other.x - self.x, other.y - self.y)


@dataclass(frozen=True)
class Velocity:
    """A unicycle command: forward speed v (m/s) and turn rate w (rad/s, CCW positive)."""

    v: float = 0.0
    w: float = 0.0


STOP = Velocity(0.0, 0.0)


@dataclass(frozen=True)
class Body:
    """An agent's physical limits: disc radius (m), max speed (m/s), max turn rate (rad/s)."""

    radius: float
    v_max: float
    w_max: float


@dataclass(frozen=True)
class Camera:
    """The pursuer's forward-facing camera, a pinhole looking along the robot's heading.

    fov: horizontal field of view (rad); near/far: sensing range (m); image_width and
    image_height in pixels; angle_step (rad) and distance_step (m) are the ray-casting
    resolution of the paper's Algorithm 1.
    """

    fov: float = math.pi / 3
    near: float = 0.3
    far: float = 5.0
    image_width: int = 640
    image_height: int = 480
    angle_step: float = 0.0016
    distance_step: float = 0.05

    def __post_init__(self) -> None:
        require(0 < self.fov <= 2 * math.pi, "camera.fov", "(0, 2*pi] radians", self.fov)
        require(self.near >= 0, "camera.near", "a range >= 0 m", self.near)
        require(self.far > self.near, "camera.far", f"a range > camera.near ({self.near} m)", self.far)
        for key in ("image_width", "image_height", "angle_step", "distance_step"):
            value = getattr(self, key)
            require(value > 0, f"camera.{key}", "a positive number", value)

    @property
    def focal_px(self) -> float:
        """Horizontal focal length in pixels: (image_width / 2) / tan(fov / 2)."""
        return 0.5 * self.image_width / math.tan(0.5 * self.fov)

    def column_of(self, bearing: float) -> float:
        """Image column (px, 0 = left edge) of a ray at ``bearing`` rad left of the optical axis."""
        return 0.5 * self.image_width - self.focal_px * math.tan(bearing)

    def bearing_of(self, column: float) -> float:
        """Bearing (rad, left positive) of image column ``column`` (px); inverse of column_of."""
        return math.atan2(0.5 * self.image_width - column, self.focal_px)


@dataclass(frozen=True)
class BoundingBox:
    """An axis-aligned image box: top-left corner (x, y) and size (w, h), all in pixels."""

    x: float
    y: float
    w: float
    h: float

    @property
    def center_x(self) -> float:
        return self.x + 0.5 * self.w


@dataclass(frozen=True, eq=False)
class SensorFrame:
    """What the pursuer's camera delivers at one control tick.

    time: simulation time (s). camera_pose: the camera's pose in the map frame.
    rgb (H, W, 3) uint8, depth (H, W) float32 metres, segmentation (H, W) int: present only
    when the simulator renders images. evader_truth: the simulator's ground-truth evader
    pose, for simulator-side detectors (oracle, segmentation) only; strategies and
    estimators never receive a SensorFrame.

    With rendered images, a camera's calibration as a depth camera driver gives it:
    intrinsics, the (3, 3) pinhole matrix K of rgb and depth in their own pixels (pixel
    (row i, col j) spans [j, j+1] x [i, i+1], so its centre is at (j + 0.5, i + 0.5));
    depth is the distance along the optical axis (m), inf where nothing is within range;
    camera_to_map, the (4, 4) homogeneous transform from the optical frame (x right, y
    down, z forward; m) to the map frame with z up and the floor at z = 0 (it holds the
    camera's height and tilt); labels, segmentation values by name (e.g. ``"evader"``),
    for simulator-side detectors only.
    """

    time: float
    camera_pose: Pose
    evader_truth: Pose | None = None
    rgb: np.ndarray | None = None
    depth: np.ndarray | None = None
    segmentation: np.ndarray | None = None
    intrinsics: np.ndarray | None = None
    camera_to_map: np.ndarray | None = None
    labels: dict[str, int] | None = None


@dataclass(frozen=True)
class Detection:
    """The evader as seen by the pursuer's detector.

    box: image bounding box (px); depth: range along the optical axis to the evader (m);
    position: the evader's estimated (x, y) in the map frame (m); confidence in [0, 1].
    """

    box: BoundingBox
    depth: float
    position: tuple[float, float]
    confidence: float = 1.0


@dataclass(frozen=True, eq=False)
class Belief:
    """An estimator's belief about the evader's position.

    mean: estimated (x, y) in the map frame (m), or None when the estimator has nothing
    yet. covariance: (2, 2) m^2 or None. particles: (N, 3) states (x m, y m, theta rad)
    and weights: (N,) summing to 1, for particle estimators. n_eff: effective sample
    size 1 / sum(w^2). resampled: whether this update resampled.
    """

    mean: tuple[float, float] | None
    covariance: np.ndarray | None = None
    particles: np.ndarray | None = None
    weights: np.ndarray | None = None
    n_eff: float | None = None
    resampled: bool = False


EMPTY_BELIEF = Belief(mean=None)


@dataclass(frozen=True, eq=False)
class PursuerObservation:
    """What the pursuer strategy is given at each tick.

    time (s); pose: its own true pose (the paper assumes a localised robot); detection of
    the evader this tick, or None; belief: the estimator's current belief; visible: the
    pursuer's own visibility region this tick (``visible.mask`` is a bool (H, W) mask over
    the grid, computed when first read).
    """

    time: float
    pose: Pose
    detection: Detection | None
    belief: Belief
    visible: VisibilityRegion


@dataclass(frozen=True)
class EvaderObservation:
    """What the evader strategy is given: time (s), its own pose and the pursuer's pose."""

    time: float
    pose: Pose
    pursuer: Pose


@dataclass(frozen=True, eq=False)
class Plan:
    """A strategy's decision: a goal (x, y) in the map frame (m) or None, the path to it as
    (K, 2) waypoints in metres (empty when there is none), and free-form ``info`` that the
    recorder shows (for example the smart evader's candidate set)."""

    goal: tuple[float, float] | None = None
    path: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    info: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
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


@dataclass(frozen=True, eq=False)
class Tick:
    """Everything that happened at one control tick, as the recorder receives it.

    step: control tick index; time (s); pursuer, evader: true poses; frame: the sensor
    frame; detection or None; belief; visible: the pursuer's visibility region;
    in_view: ground-truth visibility of the evader; commands: (pursuer, evader) velocities
    applied after this tick; plans: the latest (pursuer, evader) plans.
    """

    step: int
    time: float
    pursuer: Pose
    evader: Pose
    frame: SensorFrame
    detection: Detection | None
    belief: Belief
    visible: VisibilityRegion
    in_view: bool
    commands: tuple[Velocity, Velocity]
    plans: tuple[Plan, Plan]


# ----------------------------------------------------------------------- interfaces


class Plugin(ABC):
    """Base of every plugin: holds its validated config, the game context and its RNG.

    Subclasses set ``Config`` to a dataclass of their parameters and ``description`` to a
    one-line summary shown by ``python -m pegame.plugins``.
    """

    @dataclass
    class Config:
        """No parameters."""

    description: ClassVar[str] = ""

    def __init__(self, config: Any, context: Context, rng: np.random.Generator) -> None:
        self.config = config
        self.context = context
        self.rng = rng


class Simulator(Plugin):
    """Holds the true state of both agents and renders the pursuer's sensor."""

    @abstractmethod
    def reset(self, pursuer: Pose, evader: Pose) -> None:
        """Place both agents at the given map-frame poses."""

    @abstractmethod
    def step(self, pursuer_cmd: Velocity, evader_cmd: Velocity, dt: float) -> None:
        """Advance dt seconds with both commands held; commands beyond an agent's limits
        are saturated, and an agent never enters an obstacle (it stops at the wall)."""

    @property
    @abstractmethod
    def poses(self) -> tuple[Pose, Pose]:
        """The true (pursuer, evader) poses in the map frame."""

    @abstractmethod
    def sense(self, time: float) -> SensorFrame:
        """The pursuer camera's frame at simulation time ``time`` (s)."""

    def close(self) -> None:
        """Release resources (connections, windows). Called once per game."""


class Detector(Plugin):
    """Turns a sensor frame into a detection of the evader, or None."""

    @abstractmethod
    def detect(self, frame: SensorFrame) -> Detection | None:
        """Detect the evader in ``frame``; None when it is not seen."""

    def reset(self) -> None:
        """Forget any tracking state; called at the start of each game."""


class Estimator(Plugin):
    """Estimates the evader's position from the pursuer's detections and what it sees.

    It is given the map (``context.grid``) and the evader's max speed
    (``context.evader.v_max``), never the true evader pose.
    """

    @abstractmethod
    def reset(self, pursuer: Pose, detection: Detection | None, visible: VisibilityRegion) -> Belief:
        """Start a new game; the evader is in view at the start (the paper's protocol)."""

    @abstractmethod
    def update(
        self, dt: float, pursuer: Pose, detection: Detection | None, visible: VisibilityRegion
    ) -> Belief:
        """Predict dt seconds (s) ahead and correct with this tick's detection (or its
        absence) and the pursuer's visibility region (``visible.mask`` is a bool (H, W) mask
        over the grid; ``visible.holds(cells)`` answers for a few cells, at a fraction of
        the cost)."""


class Strategy(Plugin):
    """A pursuer or evader policy: a plan at each decision tick, a command at each control
    tick. The game calls ``reset`` once, then ``decide`` every decision period and
    ``control`` every control period (both with the latest observation)."""

    @abstractmethod
    def reset(self, pose: Pose) -> None:
        """Start a new game at ``pose``."""

    @abstractmethod
    def decide(self, observation: Any) -> Plan:
        """Choose what to do until the next decision (called at decision_hz)."""

    @abstractmethod
    def control(self, observation: Any) -> Velocity:
        """The velocity command for the next control period (called at control_hz)."""


class Pursuer(Strategy):
    """A pursuer strategy; observations are :class:`PursuerObservation`.

    Its body: ``Config.radius`` and ``Config.w_max``; its max speed is not a parameter but
    ``game.speed_ratio`` times the evader's ``v_max`` (read it from ``context.pursuer``).
    Subclasses extend ``Pursuer.Config`` with their own parameters.
    """

    @dataclass
    class Config:
        radius: float = 0.2  # body radius (m), a TurtleBot 2
        w_max: float = 1.8  # max turn rate (rad/s)

        def __post_init__(self) -> None:
            for key in ("radius", "w_max"):
                value = getattr(self, key)
                require(value > 0, f"pursuer.{key}", "a positive number", value)


class Evader(Strategy):
    """An evader strategy; observations are :class:`EvaderObservation`.

    Its body: ``Config.radius``, ``Config.v_max`` and ``Config.w_max`` (also in
    ``context.evader``). Subclasses extend ``Evader.Config`` with their own parameters.
    """

    @dataclass
    class Config:
        radius: float = 0.25  # body radius (m), a person
        v_max: float = 0.5  # max speed (m/s); the pursuer's is game.speed_ratio times this
        w_max: float = 1.8  # max turn rate (rad/s)

        def __post_init__(self) -> None:
            for key in ("radius", "v_max", "w_max"):
                value = getattr(self, key)
                require(value > 0, f"evader.{key}", "a positive number", value)


class Recorder(Plugin):
    """Logs every tick of a game (for example to a Rerun recording)."""

    @abstractmethod
    def start(self, out_dir: str, game_id: str, properties: dict[str, Any]) -> None:
        """Begin a recording for one game in ``out_dir``; ``properties`` is the run config."""

    @abstractmethod
    def log(self, tick: Tick) -> None:
        """Log one control tick."""

    @abstractmethod
    def finish(self, result: dict[str, Any]) -> None:
        """Close the recording; ``result`` is the game's result dict."""


#: entry-point group suffix and interface, per config group
INTERFACES: dict[str, type[Plugin]] = {
    "sim": Simulator,
    "detector": Detector,
    "estimator": Estimator,
    "pursuer": Pursuer,
    "evader": Evader,
    "recorder": Recorder,
}
