"""The perception model a detector's raw detections go through: rate, latency, misses,
noise, false positives and a detection range, every rate per second (s, m, rad; map frame).

A real person detector is not a perfect oracle at the control rate: the paper's pursuer
detected the evader with OpenPose, tracked it with Lucas-Kanade and placed it with a
TurtleBot's RGB-D camera, its nodes running at 1 Hz (paper, Secs. "Object tracking from
static camera" and "Simulation based validation"). Every part below is off by
default, and a part that is off draws no random number, so today's games are unchanged.
Each part draws from its own generator, spawned from the detector's (``Generator.spawn``
leaves the detector's own stream as it was), so turning one part on does not change
another's draws.

- Pipeline (:meth:`Perception.deliver`): a frame is captured every 1/``rate`` s (every
  control tick when ``rate`` is null) and its result is delivered ``latency`` s later, so a
  result shows the world as it was ``latency`` s before; between deliveries the latest
  result (a detection or None) is held.
- Independent misses: each captured detection is lost with ``miss_probability``.
- Bursty misses, the two-state Markov chain of Gilbert (1960) and Elliott (1963): a
  detector state G (detects) or B (misses), stepped at each capture with the time
  dt (s) since the last one by P(G->B) = dt f / (L (1 - f)) and P(B->G) = dt / L, where f is
  ``burst_miss_fraction`` and L is ``burst_length``. Its stationary miss fraction is
  P(G->B) / (P(G->B) + P(B->G)) = f and a burst lasts 1 / P(B->G) frames, L s on average,
  at any control or capture rate. The first frame draws its state from the stationary law.
- Range and occlusion misses: a detection at range r (m) is lost with
  p = 1 - (1 - p_r)(1 - p_o), p_r = ``miss_at_range`` * clip((r - r0) / (R - r0), 0, 1) from
  r0 = ``miss_range_start`` to the detection range R, and p_o = ``occlusion_miss`` * h, h the
  fraction of the evader's silhouette points (:data:`pegame.visibility.SILHOUETTE`) not in
  view (:func:`hidden_fraction`; simulator-side detectors with the true evader only).
- Depth noise, the structured-light (Kinect) model of Khoshelham & Elberink (2012,
  "Accuracy and resolution of Kinect depth data for indoor mapping applications",
  Sensors 12(2)), whose random depth error grows with the square of the range:
  std = ``range_noise`` + ``range_noise_growth`` * r^2 (m); bearing noise of std
  ``bearing_noise`` (rad).
- False positives: a Poisson process of ``false_positive_rate`` false detections per
  second; a frame whose evader is not detected holds one when at least one arrived since
  the last frame (chance 1 - exp(-rate * dt)), placed uniformly over the field-of-view
  wedge between the camera's near range and the detection range (occlusion ignored), with
  the pinhole box of a person there (:func:`pinhole_box`). A frame where the evader is
  detected reports the evader (a single-target detector reports its best candidate).
- Detection range: nothing beyond ``detection_range`` m (null: the camera's ``far``) is
  detected.
- Identified profile: ``profile`` names a detection profile measured on the 3D pipeline
  (:mod:`pegame.detectors.profile`): a seen evader is detected with the chance the profile
  gives its range, bearing, visible fraction and lateral speed (naive Bayes over the
  profile's marginal tables), and its position carries the profile's error; drawn from a
  generator spawned after the parts', only when a profile is on.

Only the detector knows what its raw detection is; it calls :meth:`Perception.deliver`
with a function that captures one (applying the per-detection parts: range, misses,
noise, through :meth:`Perception.degrade` or the building blocks), and the pipeline adds
rate, latency, bursts and false positives.

The pipeline's schedule (:func:`frame_due`, :func:`deliver_frame`, on the pipelines of a
batch of detectors, :func:`new_pipeline`), the range and occlusion miss chance
(:func:`miss_chance`), the hidden fraction (:func:`silhouette_hidden`, the points of
:func:`pegame.visibility.sight.silhouette_in_view`) and the pinhole box
(:func:`pinhole`) are numba kernels: a :class:`Perception` and the detectors run them on a
batch of one or for one pose, the batched game (:mod:`pegame.vector`) on its games, so
the two are one model.
The results in flight are the caller's (a slot index per result: Python objects here,
rows of arrays in the batched game).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar

import numpy as np
from numba import njit

from pegame.detectors.profile import DetectionProfile, resolve
from pegame.errors import ConfigError, require
from pegame.types import XY, BoundingBox, Camera, Detection, Pose, wrap_angle
from pegame.visibility.sight import SILHOUETTE, across, point_in_view, sight_tables

if TYPE_CHECKING:  # pragma: no cover - typing only
    from pegame.api import Context
    from pegame.grid import OccupancyGrid

#: s; times this close count as equal (capture and delivery schedules)
TIME_TOLERANCE = 1e-9
#: m, height of the person a false positive is drawn as when the detector has no evader model
PERSON_HEIGHT = 1.7
#: the generators the parts draw from, one each, spawned from the detector's in this order
PARTS = ("burst", "range", "bearing", "false_positive", "independent", "noise")
#: columns of a pipeline's row (:func:`new_pipeline`): the first capture's time (s; NaN
#: before it), the frames counted from it, the last capture's time (s; NaN before it), the
#: ring's first slot and its length, and the first slot's delivery time (s)
FIRST, CAPTURES, LAST, HEAD, SIZE, DUE = range(6)


@dataclass
class PerceptionConfig:
    """Config mixin of the perception model's fields (module docstring), for a detector's
    ``Config`` to inherit; every part is off by default. The checks that need the camera
    and the control period are :meth:`check_context`, which the scenario calls once."""

    # Whether the detector knows the evader's hidden fraction (a simulator-side geometric
    # detector); a rendering detector sets it False, its pixels already showing occlusion.
    occlusion: ClassVar[bool] = True

    rate: float | None = None  # Hz, results delivered per second (null: every control tick)
    latency: float = 0.0  # s, a result shows the world this long before its delivery
    detection_range: float | None = None  # m, farthest detection (null: the camera's far)
    miss_probability: float = 0.0  # chance that a detection is missed, independently per frame
    burst_miss_fraction: float = 0.0  # long-run fraction of frames missed in bursts, in [0, 1)
    burst_length: float = 1.0  # s, mean length of a burst of misses
    miss_range_start: float | None = None  # m, range where misses start to grow (null: off)
    miss_at_range: float = 1.0  # miss chance at the detection range, with miss_range_start
    occlusion_miss: float = 0.0  # miss chance per hidden fraction of the silhouette, in [0, 1]
    range_noise: float = 0.0  # m, depth noise std at range 0 (a in a + b * range^2)
    range_noise_growth: float = 0.0  # 1/m, depth noise std growth (b in a + b * range^2)
    bearing_noise: float = 0.0  # rad, std of the bearing noise
    false_positive_rate: float = 0.0  # 1/s, false detections per second (Poisson)
    profile: str | None = None  # a detection profile's name or CSV path (null: off)

    def __post_init__(self) -> None:
        if self.profile is not None:
            resolve(self.profile)  # a ConfigError naming the profiles
        if self.rate is not None:
            ok = math.isfinite(self.rate) and self.rate > 0
            require(ok, "rate", "a rate > 0 Hz, or null for every control tick", self.rate)
        ok = math.isfinite(self.latency) and self.latency >= 0
        require(ok, "latency", "a delay >= 0 s", self.latency)
        if self.detection_range is not None:
            ok = math.isfinite(self.detection_range) and self.detection_range > 0
            allowed = "a range > 0 m, or null for the camera's far"
            require(ok, "detection_range", allowed, self.detection_range)
        for name in ("miss_probability", "miss_at_range", "occlusion_miss"):
            require(0 <= getattr(self, name) <= 1, name, "[0, 1]", getattr(self, name))
        fraction = self.burst_miss_fraction
        require(0 <= fraction < 1, "burst_miss_fraction", "[0, 1)", fraction)
        ok = math.isfinite(self.burst_length) and self.burst_length > 0
        require(ok, "burst_length", "a duration > 0 s", self.burst_length)
        if self.miss_range_start is not None:
            ok = math.isfinite(self.miss_range_start) and self.miss_range_start >= 0
            allowed = "a range >= 0 m, or null for no range misses"
            require(ok, "miss_range_start", allowed, self.miss_range_start)
        for name, unit in (
            ("range_noise", "m"),
            ("range_noise_growth", "1/m"),
            ("bearing_noise", "rad"),
            ("false_positive_rate", "1/s"),
        ):
            value = getattr(self, name)
            require(math.isfinite(value) and value >= 0, name, f"a number >= 0 {unit}", value)

    def check_context(self, context: Context) -> None:
        """The checks that need the game's camera and control period (``context``): a
        ConfigError naming the key."""
        near, reach = context.camera.near, detection_range(self, context.camera)
        if reach <= near:
            raise ConfigError(
                f"Invalid value for 'detector.detection_range': {self.detection_range!r}. "
                f"Allowed: a range > camera.near ({near} m)."
            )
        start = self.miss_range_start
        if start is not None and start >= reach:
            raise ConfigError(
                f"Invalid value for 'detector.miss_range_start': {start!r}. Allowed: a range "
                f"below the detection range ({reach} m), or null for no range misses."
            )
        f, length = self.burst_miss_fraction, self.burst_length
        step = max(context.control_dt, 0.0 if self.rate is None else 1.0 / self.rate)
        if f > 0 and (length < step or length * (1 - f) / f < step):
            raise ConfigError(
                f"Invalid value for 'detector.burst_length': {length!r}. Allowed: bursts and "
                f"the runs between them (burst_length * (1 - f) / f with f = "
                f"detector.burst_miss_fraction = {f}) of at least one frame, {step:g} s."
            )
        noisy = self.range_noise > 0 or self.range_noise_growth > 0 or self.bearing_noise > 0
        if self.profile is not None and (not self.occlusion or self.occlusion_miss > 0 or noisy):
            allowed = (
                "null for this detector, which measures its own detections (a profile is the "
                "oracle's, detector=oracle)"
                if not self.occlusion
                else "null, or a profile with detector.occlusion_miss, range_noise, "
                "range_noise_growth and bearing_noise at 0 (the profile's visible-fraction "
                "factor is its occlusion miss, its position error its noise)"
            )
            raise ConfigError(
                f"Invalid value for 'detector.profile': {self.profile!r}. Allowed: {allowed}."
            )
        if not self.occlusion and self.occlusion_miss > 0:
            raise ConfigError(
                f"Invalid value for 'detector.occlusion_miss': {self.occlusion_miss!r}. "
                "Allowed: 0 for this detector, whose pixels already show what is hidden "
                "(the occlusion miss is the oracle's, detector=oracle)."
            )


def capture_period(config: PerceptionConfig, control_dt: float) -> float:
    """The time (s) between captures: 1 / ``rate``, or the control period ``control_dt``."""
    return control_dt if config.rate is None else 1.0 / config.rate


def runs_pipeline(config: PerceptionConfig) -> bool:
    """Whether any pipeline part is on (rate, latency, bursts, false positives); else
    each tick delivers its own capture."""
    return not (
        config.rate is None
        and config.latency == 0
        and config.burst_miss_fraction == 0
        and config.false_positive_rate == 0
    )


def misses_by_range_or_occlusion(config: PerceptionConfig) -> bool:
    """Whether the range or the occlusion miss is on (they draw from the 'range' part)."""
    return config.miss_range_start is not None or config.occlusion_miss > 0


def part_generators(rng: np.random.Generator) -> dict[str, np.random.Generator]:
    """The parts' generators (:data:`PARTS`), spawned from the detector's ``rng``."""
    return dict(zip(PARTS, rng.spawn(len(PARTS))))


def detection_range(config: PerceptionConfig, camera: Camera) -> float:
    """The detection range (m): ``detection_range``, or the camera's ``far`` when null."""
    return camera.far if config.detection_range is None else config.detection_range


@njit(cache=True)
def burst_next(chain: int, draw: float, fraction: float, length: float, dt: float) -> bool:
    """The Gilbert-Elliott chain's next state (True: in a burst, the frame missed) after
    ``dt`` s from ``chain`` (-1 not yet drawn, 0 between bursts, 1 in one) on the uniform
    ``draw``, for bursts of mean ``length`` s and the long-run missed ``fraction``: the
    stationary law at the first frame, else the exit and entry chances over dt."""
    if chain < 0:
        return draw < fraction
    if chain == 1:
        return draw >= min(1.0, dt / length)
    return draw < min(1.0, dt * fraction / (length * (1 - fraction)))


@njit(cache=True, inline="always")
def pinhole(
    width: float,
    height: float,
    focal: float,
    bearing: float,
    distance: float,
    depth: float,
    radius: float,
    body_height: float,
    camera_height: float,
) -> tuple[float, float, float, float]:
    """Kernel of :func:`pinhole_box`: the box (x, y, w, h) (px) of that body seen by a
    pinhole camera of an image ``width`` x ``height`` px and horizontal focal length
    ``focal`` px (``Camera.focal_px``; a column is ``Camera.column_of`` its bearing)."""
    ratio = radius / distance
    half = math.asin(ratio if ratio < 1.0 else 1.0)
    left = 0.5 * width - focal * math.tan(bearing + half)
    left = left if left > 0.0 else 0.0
    right = 0.5 * width - focal * math.tan(bearing - half)
    right = right if right < width else width
    middle = 0.5 * height
    top = middle - focal * (body_height - camera_height) / depth
    top = top if top > 0.0 else 0.0
    bottom = middle + focal * camera_height / depth
    bottom = bottom if bottom < height else height
    return left, top, right - left, bottom - top


def pinhole_box(
    camera: Camera,
    bearing: float,
    distance: float,
    depth: float,
    radius: float,
    height: float,
    camera_height: float,
) -> BoundingBox:
    """The image box (px) of an upright cylinder of ``radius`` and ``height`` m standing at
    ``distance`` m (horizontal, to its axis) and ``bearing`` rad (left of the optical axis),
    ``depth`` m along the axis, seen by the pinhole ``camera`` mounted ``camera_height`` m
    above the floor; clipped to the image (:func:`pinhole`)."""
    width, image_height = float(camera.image_width), float(camera.image_height)
    return BoundingBox(
        *pinhole(
            width,
            image_height,
            camera.focal_px,
            bearing,
            distance,
            depth,
            radius,
            height,
            camera_height,
        )
    )


@njit(cache=True, inline="always")
def silhouette_hidden(
    frame: np.ndarray,
    blocked: np.ndarray,
    values: np.ndarray,
    near: float,
    far: float,
    fov: float,
    px: float,
    py: float,
    ptheta: float,
    x: float,
    y: float,
    radius: float,
) -> float:
    """Kernel of :func:`hidden_fraction`: the fraction of the SILHOUETTE points of the body
    of ``radius`` m at (x, y) (m) not in view of the camera at (px, py, ptheta), each
    point tested by :func:`pegame.visibility.sight.point_in_view` (the grid and camera
    numbers as it takes them)."""
    ax, ay = across(px, py, x, y)
    hidden = 0
    for k in SILHOUETTE:
        if not point_in_view(
            frame,
            blocked,
            values,
            near,
            far,
            fov,
            px,
            py,
            ptheta,
            x + k * radius * ax,
            y + k * radius * ay,
        ):
            hidden += 1
    return hidden / len(SILHOUETTE)


def hidden_fraction(
    grid: OccupancyGrid, camera: Camera, pose: Pose, centre_xy: XY, radius: float
) -> float:
    """The fraction in [0, 1] of the silhouette points of a body (an upright cylinder of
    ``radius`` m at the map-frame point ``centre_xy``) that the camera at ``pose`` does not
    see: the same points, across the line of sight, as :func:`pegame.visibility.body_in_view`
    (:func:`silhouette_hidden`)."""
    frame, values = sight_tables(grid)
    return silhouette_hidden(
        frame,
        grid.blocked,
        values,
        camera.near,
        camera.far,
        camera.fov,
        pose.x,
        pose.y,
        pose.theta,
        float(centre_xy[0]),
        float(centre_xy[1]),
        float(radius),
    )


def pipeline_slots(latency: float, period: float) -> int:
    """Slots enough for the results in flight: at most one capture per ``period`` s, each
    held ``latency`` s."""
    return int(math.floor(latency / period + TIME_TOLERANCE)) + 2


def new_pipeline(detectors: int, slots: int) -> np.ndarray:
    """Empty pipelines (:func:`reset_pipeline`) of ``detectors`` detectors: float64
    (detectors, DUE + ``slots``), one row per detector: its clock (FIRST, CAPTURES, LAST),
    the ring of results in flight (HEAD, the first one's slot, and SIZE, how many) and
    from column DUE the delivery times (s) of the slots. One array, so that a scalar
    detector's call of the kernels checks one argument's type."""
    pipeline = np.zeros((detectors, DUE + slots))
    reset_pipeline(pipeline, np.arange(detectors))
    return pipeline


def reset_pipeline(pipeline: np.ndarray, detectors: np.ndarray | int) -> None:
    """Start a new game in the pipelines ``detectors`` (row indices): nothing captured,
    nothing in flight."""
    pipeline[detectors, :DUE] = (math.nan, 0.0, math.nan, 0.0, 0.0)


@njit(cache=True)
def frame_due(
    pipeline: np.ndarray, k: int, time: float, period: float, rated: bool
) -> tuple[bool, float]:
    """Whether detector ``k`` (a row of ``pipeline``) captures a frame at ``time`` (s):
    every call without a rate (``rated`` False), else at whole capture periods ``period``
    (s) from its first capture (counted, not summed, so the schedule does not drift); and
    the time (s) since its last capture (``period`` before the first)."""
    if math.isnan(pipeline[k, FIRST]):
        pipeline[k, FIRST] = time
    next_frame = pipeline[k, FIRST] + pipeline[k, CAPTURES] * period
    due = not rated or time >= next_frame - TIME_TOLERANCE
    last = pipeline[k, LAST]
    return due, period if math.isnan(last) else time - last


@njit(cache=True)
def deliver_frame(
    pipeline: np.ndarray,
    k: int,
    time: float,
    period: float,
    rated: bool,
    latency: float,
    captured: bool,
) -> tuple[int, int, float]:
    """Detector ``k``'s pipeline (a row of ``pipeline``) at ``time`` (s) after
    :func:`frame_due`: a frame ``captured`` goes in flight for ``latency`` s in the slot
    returned first (-1 when none was captured), and the frames a rate skips are counted;
    the second slot returned is that of the last result delivered by ``time`` (-1: none,
    the held result stays). The caller stores the captured result in its slot before it
    reads the delivered one (with no latency they are the same). Third: a time (s) before
    which the pipeline certainly does nothing (no frame due, no result delivered; -inf
    without a rate), two tolerances before its next event, so that a caller may skip the
    kernels until then and play the same."""
    row = pipeline[k]
    slots = row.size - DUE
    head, size = int(row[HEAD]), int(row[SIZE])
    slot_in = -1
    if captured:
        slot_in = (head + size) % slots
        row[DUE + slot_in] = time + latency
        size += 1
        row[LAST] = time
        while rated and row[FIRST] + row[CAPTURES] * period <= time + TIME_TOLERANCE:
            row[CAPTURES] += 1.0  # past this frame, and past the frames a high rate skips
    slot_out = -1
    while size > 0 and row[DUE + head] <= time + TIME_TOLERANCE:
        slot_out = head
        head = (head + 1) % slots
        size -= 1
    row[HEAD], row[SIZE] = head, size
    quiet = row[FIRST] + row[CAPTURES] * period if rated else -math.inf
    if size > 0:
        quiet = min(quiet, row[DUE + head])
    return slot_in, slot_out, quiet - 2.0 * TIME_TOLERANCE


@njit(cache=True)
def miss_chance(
    distance: float,
    hidden: float,
    reach: float,
    start: float,
    at_range: float,
    occlusion: float,
) -> float:
    """The range and occlusion miss chance 1 - (1 - p_r)(1 - p_o) (module docstring) of a
    body ``distance`` m away with a ``hidden`` fraction of its silhouette out of view:
    ``reach`` the detection range (m), ``start`` miss_range_start (m; NaN: no range
    misses), ``at_range`` miss_at_range, ``occlusion`` occlusion_miss."""
    p_range = 0.0
    if not math.isnan(start):
        ramp = (distance - start) / (reach - start)
        p_range = at_range * min(1.0, max(0.0, ramp))
    return 1.0 - (1.0 - p_range) * (1.0 - occlusion * hidden)


class Perception:
    """One detector's perception model (module docstring) for one game at a time.

    config: a :class:`PerceptionConfig`; context: the game's context (camera, control_dt,
    evader body); rng: the detector's generator, from which one generator per part is
    spawned; body_height and camera_height (m): the box of a false positive.
    """

    def __init__(
        self,
        config: PerceptionConfig,
        context: Context,
        rng: np.random.Generator,
        body_height: float = PERSON_HEIGHT,
        camera_height: float = 0.4,
    ) -> None:
        config.check_context(context)
        self.config, self.context = config, context
        self.camera = context.camera
        self.body_height, self.camera_height = body_height, camera_height
        self.range = detection_range(config, context.camera)
        self.rngs = part_generators(rng)
        self.period = capture_period(config, context.control_dt)
        self.rated = config.rate is not None
        self.miss_start = math.nan if config.miss_range_start is None else config.miss_range_start
        self.pipeline = new_pipeline(1, pipeline_slots(config.latency, self.period))
        self.misses_by_range_or_occlusion = misses_by_range_or_occlusion(config)
        self.profile: DetectionProfile | None = None
        if config.profile is not None:
            self.profile = DetectionProfile.read(resolve(config.profile))
            self.profile_rng = rng.spawn(1)[0]
        # Every pipeline part off: each tick delivers its own capture, nothing to hold.
        self.passthrough = not runs_pipeline(config)
        self.reset()

    def reset(self) -> None:
        """Start a new game: empty pipeline, nothing held, the burst chain undrawn."""
        reset_pipeline(self.pipeline, 0)
        self._quiet_until = -math.inf  # s, see deliver_frame
        self._in_flight: list[Detection | None] = [None] * (self.pipeline.shape[1] - DUE)
        self._held: Detection | None = None
        self._bursting: bool | None = None

    # ---------------------------------------------------------------- the pipeline

    def deliver(
        self,
        time: float,
        pose: Pose,
        capture: Callable[[], Detection | None],
        camera_height: float | None = None,
    ) -> Detection | None:
        """The detection delivered at ``time`` (s) by a camera at ``pose``: ``capture()``
        (the detector's detection for the current frame) is called only when a frame is
        due; bursts and false positives are applied to it, and it is delivered ``latency``
        s later; until then the previous result is held. ``camera_height`` (m) overrides
        the one given at construction for this frame's false positive (a rendering
        simulator's calibration knows it)."""
        if self.passthrough:
            return capture()
        if time < self._quiet_until:  # between events: the kernels would do nothing
            return self._held
        pipeline = self.pipeline
        due, dt = frame_due(pipeline, 0, time, self.period, self.rated)
        result = None
        if due:
            result = capture()
            if self._burst_step(dt):
                result = None
            if result is None:
                height = self.camera_height if camera_height is None else camera_height
                result = self._false_positive(dt, pose, height)
        slot_in, slot_out, self._quiet_until = deliver_frame(
            pipeline, 0, time, self.period, self.rated, self.config.latency, due
        )
        if slot_in >= 0:
            self._in_flight[slot_in] = result
        if slot_out >= 0:
            self._held = self._in_flight[slot_out]
        return self._held

    def _burst_step(self, dt: float) -> bool:
        """Step the Gilbert-Elliott chain over ``dt`` s; True when this frame is missed."""
        f, length = self.config.burst_miss_fraction, self.config.burst_length
        if f == 0:
            return False
        draw = self.rngs["burst"].random()
        chain = -1 if self._bursting is None else int(self._bursting)
        self._bursting = bool(burst_next(chain, draw, f, length, dt))
        return self._bursting

    def _false_positive(self, dt: float, pose: Pose, camera_height: float) -> Detection | None:
        """A false detection when one arrived in the last ``dt`` s, else None."""
        rate = self.config.false_positive_rate
        if rate == 0:
            return None
        rng = self.rngs["false_positive"]
        if rng.random() >= -math.expm1(-rate * dt):
            return None
        camera = self.camera
        bearing = rng.uniform(-0.5 * camera.fov, 0.5 * camera.fov)
        distance = math.sqrt(rng.uniform(camera.near**2, self.range**2))  # uniform over the area
        depth = max(camera.near, distance * math.cos(bearing))
        radius = self.context.evader.radius
        box = pinhole_box(camera, bearing, distance, depth, radius, self.body_height, camera_height)
        heading = pose.theta + bearing
        position = (pose.x + distance * math.cos(heading), pose.y + distance * math.sin(heading))
        return Detection(box=box, depth=depth, position=position)

    # ---------------------------------------------------- per-detection building blocks

    def in_range(self, distance: float) -> bool:
        """Whether a body ``distance`` m away (horizontal) is within the detection range."""
        return distance <= self.range

    def depth_std(self, distance: float) -> float:
        """Std (m) of the depth noise at ``distance`` m: range_noise + range_noise_growth * r^2."""
        return self.config.range_noise + self.config.range_noise_growth * distance**2

    def miss_chance(self, distance: float, hidden: float = 0.0) -> float:
        """The range and occlusion miss chance at ``distance`` m with a ``hidden`` fraction of
        the silhouette out of view: 1 - (1 - p_r)(1 - p_o) (:func:`miss_chance`)."""
        cfg = self.config
        return miss_chance(
            distance, hidden, self.range, self.miss_start, cfg.miss_at_range, cfg.occlusion_miss
        )

    def missed_by_range(self, distance: float, hidden: float = 0.0) -> bool:
        """Draw the range and occlusion miss (no draw when both are off)."""
        if not self.misses_by_range_or_occlusion:
            return False
        return bool(self.rngs["range"].random() < self.miss_chance(distance, hidden))

    def bearing_error(self) -> float:
        """A bearing error (rad), 0.0 without a draw when bearing noise is off."""
        if self.config.bearing_noise == 0:
            return 0.0
        return float(self.rngs["bearing"].normal(0.0, self.config.bearing_noise))

    def degrade(self, detection: Detection | None, pose: Pose) -> Detection | None:
        """A detector's own detection through the per-detection parts, for detectors that
        measure rather than simulate (segmentation, vision): the detection range, the
        independent and range misses, depth noise (the range from the camera at ``pose``
        scaled by the noisy depth over the measured one) and bearing noise (the position
        turned about the camera, the box shifted to the new bearing's column)."""
        if detection is None:
            return None
        cfg = self.config
        dx, dy = detection.position[0] - pose.x, detection.position[1] - pose.y
        distance = math.hypot(dx, dy)
        if not self.in_range(distance):
            return None
        if cfg.miss_probability > 0 and self.rngs["independent"].random() < cfg.miss_probability:
            return None
        if self.missed_by_range(distance):
            return None
        std, error = self.depth_std(distance), self.bearing_error()
        if std == 0 and error == 0:
            return detection
        depth = detection.depth
        if std > 0:
            depth = max(self.camera.near, depth + std * float(self.rngs["noise"].normal()))
        scale = depth / detection.depth if detection.depth > 0 else 1.0
        heading = math.atan2(dy, dx) + error
        position = (
            pose.x + scale * distance * math.cos(heading),
            pose.y + scale * distance * math.sin(heading),
        )
        bearing = wrap_angle(heading - error - pose.theta)
        shift = self.camera.column_of(bearing + error) - self.camera.column_of(bearing)
        box = detection.box
        box = BoundingBox(box.x + shift, box.y, box.w, box.h)
        return Detection(box=box, depth=depth, position=position, confidence=detection.confidence)
