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
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from pegame.api import Detector
from pegame.errors import require
from pegame.types import BoundingBox, Detection, SensorFrame, wrap_angle
from pegame.visibility import in_view


class OracleDetector(Detector):
    """Ground-truth visibility with a synthetic pinhole bounding box."""

    description = "Geometric detection (FOV, range, line of sight) with a synthetic pinhole box."

    @dataclass
    class Config:
        evader_height: float = 1.7  # m, height of the evader's cylinder
        camera_height: float = 0.4  # m, camera height above the floor
        range_noise: float = 0.0  # m, std of the depth noise
        miss_probability: float = 0.0  # chance that a visible evader goes undetected

        def __post_init__(self) -> None:
            for key in ("evader_height", "camera_height"):
                require(
                    getattr(self, key) > 0,
                    f"detector.{key}",
                    "a positive height in m",
                    getattr(self, key),
                )
            require(self.range_noise >= 0, "detector.range_noise", "a std >= 0 m", self.range_noise)
            require(
                0 <= self.miss_probability <= 1,
                "detector.miss_probability",
                "[0, 1]",
                self.miss_probability,
            )

    def detect(self, frame: SensorFrame) -> Detection | None:
        cam, evader = frame.camera_pose, frame.evader_truth
        camera, cfg = self.context.camera, self.config
        if evader is None or not in_view(self.context.grid, camera, cam, (evader.x, evader.y)):
            return None
        # Draw both numbers every time so the random stream does not depend on outcomes.
        miss, noise = self.rng.random(), self.rng.normal(0.0, 1.0)
        if miss < cfg.miss_probability:
            return None
        distance = cam.distance_to(evader)
        bearing = math.atan2(evader.y - cam.y, evader.x - cam.x) - cam.theta
        bearing = wrap_angle(bearing)
        half = math.asin(min(1.0, self.context.evader.radius / distance))
        left = max(0.0, camera.column_of(bearing + half))
        right = min(float(camera.image_width), camera.column_of(bearing - half))
        depth = max(camera.near, distance * math.cos(bearing) + cfg.range_noise * noise)
        focal, cy = camera.focal_px, 0.5 * camera.image_height
        top = max(0.0, cy - focal * (cfg.evader_height - cfg.camera_height) / depth)
        bottom = min(float(camera.image_height), cy + focal * cfg.camera_height / depth)
        box = BoundingBox(left, top, right - left, bottom - top)
        seen_bearing = camera.bearing_of(box.center_x)
        seen_range = depth / math.cos(seen_bearing)
        heading = cam.theta + seen_bearing
        position = (cam.x + seen_range * math.cos(heading), cam.y + seen_range * math.sin(heading))
        return Detection(box=box, depth=depth, position=position)
