"""``detector=segmentation``: the reference detector, reading the renderer's segmentation.

The evader's pixels are exactly those labelled ``evader`` in ``frame.segmentation``,
kept when their back-projected point lies within the camera's sensing range [near, far]
(m, horizontal distance from the camera, as :func:`pegame.visibility.in_view` measures it).
With fewer than ``min_pixels`` of them there is no detection. Otherwise (paper, Sec.
"Object tracking from static camera"):

- box: the pixels' bounding box, scaled from the rendered resolution to the pursuer's
  ``camera.image_width`` x ``camera.image_height`` pixel frame that strategies use;
- depth: the median of the pixels' depth (m, along the optical axis);
- position: every pixel is back-projected through the intrinsics and the camera pose
  (``frame.intrinsics``, ``frame.camera_to_map``); the median of their map (x, y) lies on
  the evader's visible surface, so it is moved ``surface_offset`` m further along the
  horizontal ray from the camera, to the evader's axis.

The perception model (:mod:`pegame.detectors.perception`) applies to these detections:
rate and latency, the detection range, independent, bursty and range misses, depth noise
growing with range (Khoshelham & Elberink 2012), bearing noise and false positives, all
off by default; not the occlusion miss (``occlusion_miss`` must stay 0), since the
rendered pixels already show what is hidden.

Needs a simulator that renders segmentation (``sim=pybullet``); imports no pybullet.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, NamedTuple

import numpy as np

from pegame.api import Context, Detector
from pegame.detectors.perception import Perception, PerceptionConfig
from pegame.errors import ConfigError, require
from pegame.types import BoundingBox, Camera, Detection, SensorFrame


class Rendered(NamedTuple):
    """What the detector reads of a rendered frame: the segmentation mask and the depth
    image (m) (H, W), the intrinsics K (3, 3), the camera-to-map transform (4, 4) and the
    evader's label in the mask."""

    segmentation: np.ndarray
    depth: np.ndarray
    intrinsics: np.ndarray
    camera_to_map: np.ndarray
    evader: int


def rendered(frame: SensorFrame) -> Rendered:
    """The images of ``frame``; ConfigError when the simulator does not render them."""
    seg, depth, k, to_map = frame.segmentation, frame.depth, frame.intrinsics, frame.camera_to_map
    labels = frame.labels or {}
    if seg is None or depth is None or k is None or to_map is None or "evader" not in labels:
        raise ConfigError(
            "detector=segmentation needs a simulator that renders a segmentation mask with an "
            "'evader' label (sim=pybullet); use detector=oracle with sim=grid."
        )
    return Rendered(seg, depth, k, to_map, labels["evader"])


def backproject(images: Rendered, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """(3, N) map-frame points (m) of the pixels (rows, cols) at their depth."""
    k = images.intrinsics
    z = images.depth[rows, cols]
    optical = np.stack(
        [(cols + 0.5 - k[0, 2]) * (z / k[0, 0]), (rows + 0.5 - k[1, 2]) * (z / k[1, 1]), z]
    )
    return images.camera_to_map[:3, :3] @ optical + images.camera_to_map[:3, 3:]


def box_in_camera_frame(
    images: Rendered, camera: Camera, left: float, top: float, right: float, bottom: float
) -> BoundingBox:
    """A box given by pixel edges (px of the rendered image) in the pursuer camera's
    ``image_width`` x ``image_height`` frame."""
    height, width = images.depth.shape
    sx, sy = camera.image_width / width, camera.image_height / height
    return BoundingBox(
        float(left * sx), float(top * sy), float((right - left) * sx), float((bottom - top) * sy)
    )


class SegmentationDetector(Detector):
    """The evader's exact pixels from the segmentation mask."""

    description = (
        "Reference detector: the evader's pixels in the rendered segmentation (sim=pybullet)."
    )

    @dataclass
    class Config(PerceptionConfig):
        # The rendered pixels already show occlusion: no occlusion miss here.
        occlusion: ClassVar[bool] = False
        min_pixels: int = 5  # fewer evader pixels than this: not detected
        surface_offset: float = 0.12  # m from the evader's visible surface to its axis

        def __post_init__(self) -> None:
            super().__post_init__()
            require(self.min_pixels >= 1, "min_pixels", "a whole number >= 1", self.min_pixels)
            require(
                self.surface_offset >= 0,
                "surface_offset",
                "a distance >= 0 m",
                self.surface_offset,
            )

    def __init__(self, config: Config, context: Context, rng: np.random.Generator) -> None:
        super().__init__(config, context, rng)
        self.perception = Perception(config, context, rng)

    def reset(self) -> None:
        self.perception.reset()

    def detect(self, frame: SensorFrame) -> Detection | None:
        pose = frame.camera_pose
        return self.perception.deliver(
            frame.time,
            pose,
            lambda: self.perception.degrade(self._see(frame), pose),
            camera_height=None if frame.camera_to_map is None else float(frame.camera_to_map[2, 3]),
        )

    def _see(self, frame: SensorFrame) -> Detection | None:
        """The evader's detection in this frame's segmentation, before the perception model."""
        images = rendered(frame)
        camera = self.context.camera
        rows, cols = np.nonzero(images.segmentation == images.evader)
        if rows.size < self.config.min_pixels:
            return None
        x, y, _ = backproject(images, rows, cols)
        origin = images.camera_to_map[:2, 3]
        ranges = np.hypot(x - origin[0], y - origin[1])
        keep = (ranges >= camera.near) & (ranges <= camera.far)
        kept = int(np.count_nonzero(keep))
        if kept < self.config.min_pixels:
            return None
        if kept < rows.size:
            rows, cols, x, y = rows[keep], cols[keep], x[keep], y[keep]
        box = box_in_camera_frame(
            images, camera, cols.min(), rows.min(), cols.max() + 1, rows.max() + 1
        )
        surface = np.array([np.median(x), np.median(y)])
        ray = surface - origin
        position = surface + self.config.surface_offset * ray / max(float(np.hypot(*ray)), 1e-9)
        depth = float(np.median(images.depth[rows, cols]))
        return Detection(box=box, depth=depth, position=(float(position[0]), float(position[1])))
