"""Value types that plugins exchange, and the small helpers shared by every module.

Conventions (see DESIGN.md): SI units (m, s, rad); angles wrapped to (-pi, pi]; the map
frame is ROS's (x right, y up, origin at the lower-left corner of cell (row 0, col 0));
value types are frozen dataclasses (:func:`value_type`); arrays are numpy with documented shapes. Nothing here
imports another pegame module but :mod:`pegame.errors`, so every module can import it.
"""

from __future__ import annotations

import dataclasses
import math
import sys
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any, Protocol, TypeVar, overload

import numpy as np

from pegame.errors import require

if sys.version_info >= (3, 11):
    from typing import dataclass_transform
else:  # pragma: no cover - Python 3.10
    from typing_extensions import dataclass_transform

#: a map-frame point (x, y), m: a pair of floats or a numpy array of two
XY = tuple[float, float] | np.ndarray


def wrap_angle(angle: float) -> float:
    """Wrap an angle in radians to (-pi, pi]."""
    wrapped = math.remainder(angle, 2.0 * math.pi)
    return math.pi if wrapped == -math.pi else wrapped


def clamp(value: float, limit: float) -> float:
    """``value`` limited to [-limit, limit] (limit >= 0), as a float; like np.clip, NaN
    stays NaN."""
    return float(min(max(value, -limit), limit))


_T = TypeVar("_T")


def _slot(cls: type, name: str) -> Any:
    """The slot descriptor of field ``name`` of the slotted class ``cls`` (or a base's)."""
    return next(vars(k)[name] for k in cls.__mro__ if name in vars(k))


@overload
def value_type(cls: type[_T], /) -> type[_T]: ...
@overload
def value_type(*, eq: bool = True) -> Callable[[type[_T]], type[_T]]: ...
@dataclass_transform(frozen_default=True)
def value_type(cls: type[_T] | None = None, /, *, eq: bool = True) -> Any:
    """``dataclass(frozen=True, eq=eq, slots=True)``, whose ``__init__`` stores each field
    through its slot's descriptor.

    The ``__init__`` a frozen dataclass generates sets each field through
    ``object.__setattr__``, about 0.2 us a field on CPython 3.11; a game tick builds some
    ten value objects (poses, commands, the camera frame, observations, the tick record),
    so those calls alone were several percent of a game. Slots also make every field read
    CPython 3.11's specialised slot load: an instance ``__dict__`` filled by hand (the
    previous form of this ``__init__``) left 3.11's attribute caches missing on every read
    (a split dict, which its ``LOAD_ATTR_WITH_HINT`` cannot read), and cost a dict per
    object. The instances are the same: frozen (assignment raises
    ``FrozenInstanceError``), with the same fields, defaults, ``__post_init__``, equality,
    hash, pickling and repr (``tests/test_value_types.py`` compares them with plain
    frozen dataclasses), but no ``__dict__``: a value type holds its fields only. Classes
    with ``default_factory`` fields, fields left out of ``__init__`` or keyword-only fields
    keep the dataclass's own ``__init__``.
    """

    def wrap(cls: type[_T]) -> type[_T]:
        cls = dataclass(frozen=True, eq=eq, slots=True)(cls)
        fields = dataclasses.fields(cls)  # type: ignore[arg-type]  # a dataclass now
        if any(
            f.default_factory is not dataclasses.MISSING or not f.init or f.kw_only for f in fields
        ):
            return cls
        names: dict[str, Any] = {f"_default_{f.name}": f.default for f in fields}
        names |= {f"_set_{f.name}": _slot(cls, f.name).__set__ for f in fields}
        params = ", ".join(
            f.name if f.default is dataclasses.MISSING else f"{f.name}=_default_{f.name}"
            for f in fields
        )
        body = [f"    _set_{f.name}(self, {f.name})" for f in fields]
        if hasattr(cls, "__post_init__"):
            body.append("    self.__post_init__()")
        namespace: dict[str, Any] = {}
        exec(f"def __init__(self, {params}):\n" + "\n".join(body), names, namespace)
        init = namespace["__init__"]
        init.__qualname__ = f"{cls.__qualname__}.__init__"
        init.__doc__ = cls.__init__.__doc__
        init.__annotations__ = {**{f.name: f.type for f in fields}, "return": None}
        cls.__init__ = init  # type: ignore[method-assign]
        return cls

    return wrap if cls is None else wrap(cls)


@value_type
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


@value_type
class Velocity:
    """A unicycle command: forward speed v (m/s) and turn rate w (rad/s, CCW positive)."""

    v: float = 0.0
    w: float = 0.0


STOP = Velocity(0.0, 0.0)


@value_type
class Body:
    """An agent's physical limits: disc radius (m), max speed (m/s), max turn rate (rad/s),
    and the simulator's acceleration limits on its speed (m/s^2) and turn rate (rad/s^2);
    infinite acceleration (the default) means a command takes effect at once."""

    radius: float
    v_max: float
    w_max: float
    a_max: float = math.inf
    alpha_max: float = math.inf


#: the most rays, and samples along a ray, of the visibility region (Algorithm 1): the
#: default camera casts 655 rays of 100 samples; 10**5 samples at 0.05 m reach 5 km
MAX_RAY_STEPS = 100_000


@value_type
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
        require(
            self.far > self.near, "camera.far", f"a range > camera.near ({self.near} m)", self.far
        )
        for key in ("image_width", "image_height", "angle_step", "distance_step"):
            value = getattr(self, key)
            require(value > 0, f"camera.{key}", "a positive number", value)
        # Algorithm 1 casts fov / angle_step rays of far / distance_step samples each.
        for count, key, value in (
            (self.fov / self.angle_step, "camera.angle_step", self.angle_step),
            (self.far / self.distance_step, "camera.far", self.far),
        ):
            require(
                count <= MAX_RAY_STEPS,
                key,
                f"at most {MAX_RAY_STEPS} rays per view (camera.fov / camera.angle_step) and "
                f"samples per ray (camera.far / camera.distance_step)",
                value,
            )

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


@value_type
class BoundingBox:
    """An axis-aligned image box: top-left corner (x, y) and size (w, h), all in pixels."""

    x: float
    y: float
    w: float
    h: float

    @property
    def center_x(self) -> float:
        return self.x + 0.5 * self.w


@value_type(eq=False)
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

    In a team game every pursuer's camera delivers its own frame: evaders_truth holds
    every evader's true pose (evader_truth is the one a detector is asked about, evader 0
    unless the tick loop asked about another, :meth:`about`).
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
    evaders_truth: tuple[Pose, ...] | None = None

    def about(self, evader: int) -> SensorFrame:
        """This frame with ``evader_truth`` set to evader ``evader``'s true pose (a team
        frame; the frame itself for evader 0 of a frame without ``evaders_truth``)."""
        if self.evaders_truth is None:
            if evader != 0:
                raise ValueError(f"This frame holds one evader; evader {evader} is not in it.")
            return self
        return replace(self, evader_truth=self.evaders_truth[evader])


@value_type
class Detection:
    """The evader as seen by the pursuer's detector.

    box: image bounding box (px); depth: range along the optical axis to the evader (m);
    position: the evader's estimated (x, y) in the map frame (m); confidence in [0, 1].
    evader: the index of the evader seen, when the detector can tell (a team game's
    simulator-side detectors can; None: unknown, or the only evader of a 1v1 game).
    """

    box: BoundingBox
    depth: float
    position: tuple[float, float]
    confidence: float = 1.0
    evader: int | None = None


@value_type(eq=False)
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


@value_type(eq=False)
class Plan:
    """A strategy's decision: a goal (x, y) in the map frame (m) or None, the path to it as
    (K, 2) waypoints in metres (empty when there is none), and free-form ``info`` that the
    recorder shows (for example the smart evader's candidate set). A plan is not changed
    once returned: recorders keep it by reference until they send it."""

    goal: tuple[float, float] | None = None
    path: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    info: dict[str, Any] = field(default_factory=dict)


class Region(Protocol):
    """A set of grid cells: the pursuer's visibility region V^p_k as observations carry it.

    shape: (H, W) of the grid. mask: bool (H, W), True on the cells of the region,
    read-only (possibly computed at the first read). bounds: (r0, r1, c0, c1), rows
    [r0, r1) and columns [c0, c1) hold every cell of the region (r1 <= r0 when it is
    empty). holds(cells): bool (N,), whether the region holds each flat cell index of the
    int (N,) array ``cells`` (row * width + col; negative: no cell, False), possibly
    without computing the whole mask. Implemented by :class:`pegame.visibility.
    VisibilityRegion` (Algorithm 1, on demand) and :class:`pegame.visibility.MaskRegion`
    (a given mask, for sensors that see otherwise and for tests).
    """

    @property
    def shape(self) -> tuple[int, ...]: ...

    @property
    def mask(self) -> np.ndarray: ...

    @property
    def bounds(self) -> tuple[int, int, int, int]: ...

    def holds(self, cells: np.ndarray) -> np.ndarray: ...
