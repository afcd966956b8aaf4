"""The grid simulator's camera: a geometric detector with a synthetic bounding box.

The evader is detected when its centre is in view of the pursuer's camera (inside the FOV
wedge, within [near, far] and in line of sight on the grid, :func:`pegame.visibility.in_view`),
unless a configured miss happens. The game's ground truth is wider: any part of the body
in view (:func:`pegame.visibility.body_in_view`), so a shoulder past a corner is visible but
not detected. The evader is modelled as an upright cylinder (its body
radius, ``evader_height``) projected through a pinhole camera of the configured FOV and
image size (square pixels) mounted ``camera_height`` above the floor. Depth is the range
along the optical axis to the evader's axis, optionally with Gaussian noise; the map
position is back-projected from the box centre's bearing and that depth, as a depth
camera would (paper, Sec. "Object tracking from static camera").

Every part of the perception model (:mod:`pegame.detectors.perception`) applies: rate and
latency, the detection range, independent misses, bursty (Gilbert-Elliott) misses, misses
growing with range and with the hidden fraction of the evader's silhouette, depth noise
growing with range (Khoshelham & Elberink 2012) and bearing noise, both entering before
the box is drawn, and false positives. The independent miss and the depth noise draw from
the detector's own generator, two numbers for every evader in view, as they always have;
the other parts from their own generators, only when they are on. With a profile
(``detector.profile``, :mod:`pegame.detectors.profile`) an evader any part of whose body
is in view (:func:`pegame.visibility.body_in_view`, the frames the profile's reference
sees: a 3D detector finds a body whose centre has left the image's edge) and in range is
detected with the profile's chance for its range, bearing, visible fraction and lateral
speed relative to the camera (from the previous call's poses), and its position is the
evader's centre moved by the profile's error (measured from the centre), its box and
depth those of a body there; one uniform and two normal draws from the profile's
generator per such frame (the depth and bearing noise are the profile's error, and
refused beside it).

The capture's geometry is the numba kernel :func:`image` (bearing, depth, the pinhole box
of :func:`pegame.detectors.perception.pinhole`, the back-projection), on the camera's
numbers (:func:`camera_numbers`, entries FOV..CAMERA_HEIGHT): the detector calls it for
its one pose, the batched game (:func:`pegame.vector.camera.detect`) inlines it into its
loop over games, so the two compute the same floats; the tests before it are
:func:`pegame.visibility.in_view` and the perception model's (their kernels likewise).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from pegame import numerics
from pegame.api import Context, Detector
from pegame.detectors.perception import (
    Perception,
    PerceptionConfig,
    detection_range,
    hidden_fraction,
    pinhole,
    pinhole_box,
)
from pegame.detectors.profile import DetectionProfile
from pegame.errors import require
from pegame.types import BoundingBox, Camera, Detection, Pose, SensorFrame, wrap_angle
from pegame.visibility import in_view

#: entries of the camera's numbers (:func:`camera_numbers`): fov (rad), near and far (m),
#: the image's width and height (px), the focal length (px), the detection range (m), the
#: evader's height and the camera's above the floor (m)
FOV, NEAR, FAR, IMAGE_WIDTH, IMAGE_HEIGHT, FOCAL, DETECTION_RANGE, BODY_HEIGHT, CAMERA_HEIGHT = (
    range(9)
)


def camera_numbers(camera: Camera, config: OracleDetector.Config) -> np.ndarray:
    """float64 (9,): the numbers of ``camera`` and the detector's ``config`` that
    :func:`image` reads, entries FOV..CAMERA_HEIGHT."""
    return np.array(
        [
            camera.fov,
            camera.near,
            camera.far,
            float(camera.image_width),
            float(camera.image_height),
            camera.focal_px,
            detection_range(config, camera),
            config.evader_height,
            config.camera_height,
        ],
        dtype=np.float64,
    )


@njit(cache=True, inline="always")
def body_box(
    camera: np.ndarray, bearing: float, distance: float, depth: float, radius: float
) -> tuple[float, float, float, float]:
    """The pinhole box (x, y, w, h) (px) of the evader's body (``radius`` m, the camera
    numbers' body height) at ``bearing`` rad, ``distance`` m and ``depth`` m, seen by the
    camera of ``camera`` (:func:`camera_numbers`)."""
    return pinhole(
        camera[IMAGE_WIDTH],
        camera[IMAGE_HEIGHT],
        camera[FOCAL],
        bearing,
        distance,
        depth,
        radius,
        camera[BODY_HEIGHT],
        camera[CAMERA_HEIGHT],
    )


@njit(cache=True, inline="always")
def image(
    camera: np.ndarray,
    cx: float,
    cy: float,
    ctheta: float,
    ex: float,
    ey: float,
    distance: float,
    bearing_error: float,
    depth_error: float,
    radius: float,
) -> tuple[float, float, float, float, float, float, float]:
    """The detection of an evader (a cylinder of ``radius`` m) at (ex, ey), ``distance`` m
    from the camera at (cx, cy, ctheta) (m, m, rad; ``camera``: :func:`camera_numbers`):
    its bearing (rad, plus ``bearing_error``), its depth along the optical axis (m, plus
    ``depth_error``, at least near), the pinhole box (x, y, w, h) (px) of the body there,
    and the map position (m) back-projected from the box centre's bearing and the depth.
    Returns (x, y, w, h, depth, position x, position y). (:func:`pegame.numerics.wrap_angle`
    is :func:`pegame.types.wrap_angle` in numba code.)"""
    bearing = numerics.wrap_angle(math.atan2(ey - cy, ex - cx) - ctheta) + bearing_error
    depth = distance * math.cos(bearing) + depth_error
    depth = depth if depth > camera[NEAR] else camera[NEAR]
    width, focal = camera[IMAGE_WIDTH], camera[FOCAL]
    left, top, box_w, box_h = body_box(camera, bearing, distance, depth, radius)
    seen_bearing = math.atan2(0.5 * width - (left + 0.5 * box_w), focal)
    seen_range = depth / math.cos(seen_bearing)
    heading = ctheta + seen_bearing
    seen_x = cx + seen_range * math.cos(heading)
    seen_y = cy + seen_range * math.sin(heading)
    return left, top, box_w, box_h, depth, seen_x, seen_y


class OracleDetector(Detector):
    """Ground-truth visibility with a synthetic pinhole bounding box."""

    description = "Geometric detection (FOV, range, line of sight) with a synthetic pinhole box."
    identifies = True  # it looks for frame.evader_truth only: in a team it names its evader

    @dataclass
    class Config(PerceptionConfig):
        evader_height: float = 1.7  # m, height of the evader's cylinder
        camera_height: float = 0.4  # m, camera height above the floor

        def __post_init__(self) -> None:
            super().__post_init__()
            for key in ("evader_height", "camera_height"):
                require(
                    getattr(self, key) > 0,
                    key,
                    "a positive height in m",
                    getattr(self, key),
                )

    def __init__(self, config: Config, context: Context, rng: np.random.Generator) -> None:
        super().__init__(config, context, rng)
        self.perception = Perception(
            config, context, rng, config.evader_height, config.camera_height
        )
        self._camera = camera_numbers(context.camera, config)
        self.reset()

    def reset(self) -> None:
        self.perception.reset()
        self._lateral = math.nan  # m/s, see _lateral_speed
        self._last: tuple[float, Pose, Pose] | None = None

    def detect(self, frame: SensorFrame) -> Detection | None:
        if self.perception.profile is not None:
            self._lateral_speed(frame)
        if self.perception.passthrough:  # each frame's own capture (no closure to build)
            return self._capture(frame)
        return self.perception.deliver(frame.time, frame.camera_pose, lambda: self._capture(frame))

    def _lateral_speed(self, frame: SensorFrame) -> None:
        """The evader's speed (m/s) across the line of sight relative to the camera, from
        this frame's and the previous call's poses, as the profile measures it (NaN when
        unknown)."""
        cam, evader = frame.camera_pose, frame.evader_truth
        self._lateral = math.nan
        if evader is None:
            self._last = None
            return
        dx, dy = evader.x - cam.x, evader.y - cam.y
        distance = math.hypot(dx, dy)
        if self._last is not None and distance > 1e-9 and frame.time > self._last[0]:
            before, was_cam, was = self._last
            rvx = (dx - (was.x - was_cam.x)) / (frame.time - before)
            rvy = (dy - (was.y - was_cam.y)) / (frame.time - before)
            self._lateral = abs(rvx * dy - rvy * dx) / distance
        self._last = (frame.time, cam, evader)

    def _capture(self, frame: SensorFrame) -> Detection | None:
        """The detection of this frame, before the pipeline (rate, latency, bursts, false
        positives)."""
        cam, evader = frame.camera_pose, frame.evader_truth
        camera, cfg, perception = self.context.camera, self.config, self.perception
        if evader is None:
            return None
        grid, profile = self.context.grid, perception.profile
        if profile is None:
            if not in_view(grid, camera, cam, (evader.x, evader.y)):
                return None
        else:  # any part of the body in view, as the profile's reference sees it
            radius = self.context.evader.radius
            visible = 1.0 - hidden_fraction(grid, camera, cam, (evader.x, evader.y), radius)
            if visible == 0.0:
                return None
        distance = cam.distance_to(evader)
        if not perception.in_range(distance):
            return None
        # Draw both numbers every time so the random stream does not depend on outcomes.
        miss, noise = self.rng.random(), self.rng.normal(0.0, 1.0)
        if miss < cfg.miss_probability:
            return None
        if profile is not None:
            bearing = abs(wrap_angle(math.atan2(evader.y - cam.y, evader.x - cam.x) - cam.theta))
            chance = profile.probability(distance, bearing, visible, self._lateral)
            if perception.profile_rng.random() >= chance:
                return None
        if perception.misses_by_range_or_occlusion:
            hidden = 0.0
            if cfg.occlusion_miss > 0:
                grid, radius = self.context.grid, self.context.evader.radius
                hidden = hidden_fraction(grid, camera, cam, (evader.x, evader.y), radius)
            if perception.missed_by_range(distance, hidden):
                return None
        if profile is not None:
            return self._profiled(cam, evader, profile)
        x, y, w, h, depth, seen_x, seen_y = image(
            self._camera,
            cam.x,
            cam.y,
            cam.theta,
            evader.x,
            evader.y,
            distance,
            perception.bearing_error(),
            perception.depth_std(distance) * noise,
            self.context.evader.radius,
        )
        return Detection(box=BoundingBox(x, y, w, h), depth=depth, position=(seen_x, seen_y))

    def _profiled(self, cam: Pose, evader: Pose, profile: DetectionProfile) -> Detection:
        """A detected evader under a profile: its centre moved by the profile's error (in
        the line of sight's frame, measured from the centre), and the box and depth of a
        body there, so that a pursuer servoing on the box sees the error the 3D detector's
        box has (its box and position come from the same pixels)."""
        camera = self.context.camera
        along, across = profile.position_error(self.perception.profile_rng)
        sight = math.atan2(evader.y - cam.y, evader.x - cam.x)
        c, s = math.cos(sight), math.sin(sight)
        x, y = evader.x + along * c - across * s, evader.y + along * s + across * c
        distance = max(camera.near, math.hypot(x - cam.x, y - cam.y))
        bearing = wrap_angle(math.atan2(y - cam.y, x - cam.x) - cam.theta)
        depth = max(camera.near, distance * math.cos(bearing))
        cfg, radius = self.config, self.context.evader.radius
        box = pinhole_box(
            camera, bearing, distance, depth, radius, cfg.evader_height, cfg.camera_height
        )
        return Detection(box=box, depth=depth, position=(x, y))
