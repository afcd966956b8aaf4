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
the other parts from their own generators, only when they are on.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pegame.api import Context, Detector
from pegame.detectors.perception import Perception, PerceptionConfig, hidden_fraction, pinhole_box
from pegame.errors import require
from pegame.types import Detection, SensorFrame, wrap_angle
from pegame.visibility import in_view


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

    def reset(self) -> None:
        self.perception.reset()

    def detect(self, frame: SensorFrame) -> Detection | None:
        if self.perception.passthrough:  # each frame's own capture (no closure to build)
            return self._capture(frame)
        return self.perception.deliver(frame.time, frame.camera_pose, lambda: self._capture(frame))

    def _capture(self, frame: SensorFrame) -> Detection | None:
        """The detection of this frame, before the pipeline (rate, latency, bursts, false
        positives)."""
        cam, evader = frame.camera_pose, frame.evader_truth
        camera, cfg, perception = self.context.camera, self.config, self.perception
        if evader is None or not in_view(self.context.grid, camera, cam, (evader.x, evader.y)):
            return None
        distance = cam.distance_to(evader)
        if not perception.in_range(distance):
            return None
        # Draw both numbers every time so the random stream does not depend on outcomes.
        miss, noise = self.rng.random(), self.rng.normal(0.0, 1.0)
        if miss < cfg.miss_probability:
            return None
        if perception.misses_by_range_or_occlusion:
            hidden = 0.0
            if cfg.occlusion_miss > 0:
                grid, radius = self.context.grid, self.context.evader.radius
                hidden = hidden_fraction(grid, camera, cam, (evader.x, evader.y), radius)
            if perception.missed_by_range(distance, hidden):
                return None
        bearing = math.atan2(evader.y - cam.y, evader.x - cam.x) - cam.theta
        bearing = wrap_angle(bearing)
        if cfg.bearing_noise > 0:
            bearing += perception.bearing_error()
        depth = max(
            camera.near, distance * math.cos(bearing) + perception.depth_std(distance) * noise
        )
        radius = self.context.evader.radius
        box = pinhole_box(
            camera, bearing, distance, depth, radius, cfg.evader_height, cfg.camera_height
        )
        seen_bearing = camera.bearing_of(box.center_x)
        seen_range = depth / math.cos(seen_bearing)
        heading = cam.theta + seen_bearing
        position = (cam.x + seen_range * math.cos(heading), cam.y + seen_range * math.sin(heading))
        return Detection(box=box, depth=depth, position=position)
