"""``detector=vision``: detect the evader by colour, track it with Lucas-Kanade, place it
with the depth image (paper, Sec. "Object tracking from static camera").

:class:`TrackingDetector` holds what it shares with ``detector=person``
(:mod:`pegame_vision.person`): the tracking, the placement and the perception model;
:class:`VisionDetector` adds the colour model. Reads only what an RGB-D camera driver
gives: ``frame.rgb``, ``frame.depth`` and the calibration (``frame.intrinsics``,
``frame.camera_to_map``); never the simulator's segmentation, labels or ``evader_truth``.
Each frame either

- detects: the pixels that match the colour model (:class:`pegame_vision.colour.
  ColourModel`), in components of at least ``min_component`` px, at least ``min_pixels``
  of them; their bounding box is the evader's, and Lucas-Kanade features are taken on
  them; this happens every ``redetect_every``-th frame, and at once when tracking fails;
- or tracks: the features follow the evader (:class:`pegame_vision.tracker.BoxTracker`),
  and the frame counts as tracked while at least ``min_features`` of them survive the
  forward-backward check and still show the evader's colours (the quality bar).

The evader's samples (the matching pixels, or the surviving features) are back-projected
with their depth; those with no depth or outside the camera's range [near, far] (m,
horizontal) are dropped. The depth is the samples' median depth (m along the optical
axis), the position their median map (x, y) moved ``surface_offset`` m further from the
camera, from the body's visible surface to its axis. Boxes are reported in the pursuer
camera's ``image_width`` x ``image_height`` frame.

The perception model (:mod:`pegame.detectors.perception`) applies to these detections:
rate (the colour model and the tracker then see only the frames the pipeline captures)
and latency, the detection range, independent, bursty and range misses, depth noise
growing with range (Khoshelham & Elberink 2012), bearing noise and false positives, all
off by default; not the occlusion miss (``occlusion_miss`` must stay 0), since the image
already shows what is hidden.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar, NamedTuple

import numpy as np

from pegame.api import Context, Detector
from pegame.detectors.perception import Perception, PerceptionConfig
from pegame.errors import ConfigError, require
from pegame.types import BoundingBox, Detection, SensorFrame
from pegame_vision.colour import ColourModel, find_blobs, parse_hex
from pegame_vision.opencv import cv2
from pegame_vision.tracker import BoxTracker

#: the clothing and skin of sim=pybullet's evader: shirt, trousers, skin
EVADER_COLOURS = ["#cc1f1a", "#1f38a6", "#dead8c"]
MIN_SAMPLES = 3  # back-projected samples needed to place the evader

#: a box (left, top, right, bottom) in pixels of the rendered image
Box = tuple[float, float, float, float]
#: a box and the (rows, cols) of the evader's sample pixels in it
Samples = tuple[Box, np.ndarray, np.ndarray]


class RGBD(NamedTuple):
    """What the detector reads of a frame: the RGB (H, W, 3) and depth (H, W, m) images,
    the intrinsics K (3, 3) and the camera-to-map transform (4, 4)."""

    rgb: np.ndarray
    depth: np.ndarray
    intrinsics: np.ndarray
    camera_to_map: np.ndarray


def back_project(images: RGBD, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """(3, N) map-frame points (m, z up from the floor) of the pixels at ``rows``, ``cols``
    through their depth; nan where a pixel has no depth (inf: no return)."""
    k, transform = images.intrinsics, images.camera_to_map
    z = images.depth[rows, cols].astype(float)
    optical = np.stack(
        [(cols + 0.5 - k[0, 2]) * z / k[0, 0], (rows + 0.5 - k[1, 2]) * z / k[1, 1], z]
    )
    with np.errstate(invalid="ignore"):  # inf depth gives nan
        points: np.ndarray = transform[:3, :3] @ optical + transform[:3, 3:]
    return points


class TrackingDetector(Detector):
    """What the RGB-D detectors share: a detection on some frames (:meth:`_find`, the
    subclass's), Lucas-Kanade tracking in between with the subclass's appearance test
    (:meth:`_accept`), placement by depth back-projection, then the perception model."""

    #: the detector's name in a config (``detector=...``), for messages
    entry: ClassVar[str] = ""

    @dataclass
    class Config(PerceptionConfig):
        # The rendered pixels already show occlusion: no occlusion miss here.
        occlusion: ClassVar[bool] = False
        redetect_every: int = 5  # detect on every K-th frame while tracking (1: every frame)
        min_features: int = 4  # fewer tracked features than this: re-detect at once
        max_features: int = 40  # features tracked at most
        surface_offset: float = 0.12  # m from the evader's visible surface to its axis

        def __post_init__(self) -> None:
            super().__post_init__()
            for key in ("redetect_every", "min_features", "max_features"):
                require(getattr(self, key) >= 1, key, "a whole number >= 1", getattr(self, key))
            require(
                self.surface_offset >= 0,
                "surface_offset",
                "a distance >= 0 m",
                self.surface_offset,
            )

    def _find(self, images: RGBD, gray: np.ndarray) -> tuple[Box, np.ndarray] | None:
        """The evader's box (px) and its pixels (bool (H, W)) in a fresh detection, or None."""
        raise NotImplementedError

    def _accept(self, images: RGBD, points: np.ndarray) -> np.ndarray:
        """Bool (N,): whether the tracked ``points`` (N, 2) (x, y) px still show the evader."""
        raise NotImplementedError

    def __init__(self, config: Config, context: Context, rng: np.random.Generator) -> None:
        super().__init__(config, context, rng)
        self.tracker = BoxTracker(config.max_features)
        self.perception = Perception(config, context, rng)
        self.reset()

    def reset(self) -> None:
        self._tracking = False
        self._since_detection = 0
        self._frame: SensorFrame | None = None
        self._last: Detection | None = None
        self._delivered: Detection | None = None
        self.source: str | None = None  # how the last detection was made: "detect" or "track"
        self.perception.reset()

    def detect(self, frame: SensorFrame) -> Detection | None:
        if frame is self._frame:  # the simulator reused its last frame: nothing new to see
            return self._delivered
        self._frame, pose = frame, frame.camera_pose
        self._delivered = self.perception.deliver(
            frame.time,
            pose,
            lambda: self.perception.degrade(self._see(frame), pose),
            camera_height=None if frame.camera_to_map is None else float(frame.camera_to_map[2, 3]),
        )
        return self._delivered

    def _see(self, frame: SensorFrame) -> Detection | None:
        """This frame's detection (:meth:`_find`) or tracking, before the perception model."""
        rgb, depth, k, to_map = frame.rgb, frame.depth, frame.intrinsics, frame.camera_to_map
        if rgb is None or depth is None or k is None or to_map is None:
            raise ConfigError(
                f"detector={self.entry} needs RGB-D frames with the camera calibration (sim=pybullet); "
                "use detector=oracle with sim=grid."
            )
        images = RGBD(rgb, depth, k, to_map)
        gray = cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY)
        samples, source = (self._track(images, gray) if self._tracking else None), "track"
        if samples is None:
            samples, source = self._detect(images, gray), "detect"
        self._last = None if samples is None else self._place(images, *samples)
        self.source = None if self._last is None else source
        return self._last

    def _track(self, images: RGBD, gray: np.ndarray) -> Samples | None:
        """(box, rows, cols) from Lucas-Kanade, or None when it is time or necessary to
        detect again."""
        if self._since_detection >= self.config.redetect_every:
            return None
        survivors = self.tracker.step(gray, lambda points: self._accept(images, points))
        if survivors < self.config.min_features:
            self._tracking = False
            return None
        self._since_detection += 1
        height, width = gray.shape
        left, top, right, bottom = self.tracker.box
        box = (max(0.0, left), max(0.0, top), min(float(width), right), min(float(height), bottom))
        points = self.tracker.points
        return box, points[:, 1].astype(int), points[:, 0].astype(int)

    def _detect(self, images: RGBD, gray: np.ndarray) -> Samples | None:
        """(box, rows, cols) of a fresh detection (:meth:`_find`), or None."""
        self._tracking = False
        found = self._find(images, gray)
        if found is None:
            return None
        box, mask = found
        rows, cols = np.nonzero(mask)
        self._tracking = self.tracker.start(gray, np.array(box), mask) >= self.config.min_features
        self._since_detection = 1  # frames since (and including) this detection
        return box, rows, cols

    def _place(
        self, images: RGBD, box: Box, rows: np.ndarray, cols: np.ndarray
    ) -> Detection | None:
        """The detection from the box (px) and the evader's sample pixels, or None when too
        few samples have a depth within range."""
        z = images.depth[rows, cols].astype(float)
        x, y, _ = back_project(images, rows, cols)
        origin = images.camera_to_map[:2, 3]
        ranges = np.hypot(x - origin[0], y - origin[1])
        camera = self.context.camera
        valid = np.isfinite(z) & (ranges >= camera.near) & (ranges <= camera.far)
        if np.count_nonzero(valid) < MIN_SAMPLES:
            return None
        surface = np.array([np.median(x[valid]), np.median(y[valid])])
        ray = surface - origin
        position = surface + self.config.surface_offset * ray / max(float(np.hypot(*ray)), 1e-9)
        height, width = images.depth.shape
        sx, sy = camera.image_width / width, camera.image_height / height
        left, top, right, bottom = box
        return Detection(
            box=BoundingBox(left * sx, top * sy, (right - left) * sx, (bottom - top) * sy),
            depth=float(np.median(z[valid])),
            position=(float(position[0]), float(position[1])),
        )


class VisionDetector(TrackingDetector):
    """Colour-model detection and Lucas-Kanade tracking on RGB-D frames."""

    description = "OpenCV on RGB-D: colour model of the evader's clothing, Lucas-Kanade tracking."
    entry = "vision"

    @dataclass
    class Config(TrackingDetector.Config):
        colours: list[str] = field(
            default_factory=lambda: list(EVADER_COLOURS)
        )  # '#rrggbb', the evader's
        hue_tolerance: float = 12.0  # degrees of hue around each colour
        min_saturation: float = (
            0.25  # HSV saturation in [0, 1] below which a pixel has no reliable hue
        )
        min_value: float = 0.08  # HSV value in [0, 1] below which a pixel is too dark to judge
        min_pixels: int = 12  # matching pixels needed for a detection
        min_component: int = 3  # px; smaller matching specks are noise

        def __post_init__(self) -> None:
            super().__post_init__()
            require(
                len(self.colours) > 0,
                "colours",
                "a non-empty list of '#rrggbb'",
                self.colours,
            )
            for colour in self.colours:
                try:
                    parse_hex(colour)
                except ValueError:
                    require(False, "colours", "colours written '#rrggbb'", colour)
            require(
                0 < self.hue_tolerance <= 90,
                "hue_tolerance",
                "(0, 90] degrees",
                self.hue_tolerance,
            )
            for key in ("min_saturation", "min_value"):
                require(0 <= getattr(self, key) <= 1, key, "[0, 1]", getattr(self, key))
            for key in ("min_pixels", "min_component"):
                require(getattr(self, key) >= 1, key, "a whole number >= 1", getattr(self, key))

    def __init__(self, config: Config, context: Context, rng: np.random.Generator) -> None:
        self.model = ColourModel(
            config.colours, config.hue_tolerance, config.min_saturation, config.min_value
        )
        super().__init__(config, context, rng)

    def _find(self, images: RGBD, gray: np.ndarray) -> tuple[Box, np.ndarray] | None:
        """The pixels matching the colour model, in components of at least
        ``min_component`` px and at least ``min_pixels`` of them, and their box."""
        mask = find_blobs(self.model.mask(images.rgb), self.config.min_component)
        rows, cols = np.nonzero(mask)
        if rows.size < self.config.min_pixels:
            return None
        return (
            float(cols.min()),
            float(rows.min()),
            float(cols.max() + 1),
            float(rows.max() + 1),
        ), mask

    def _accept(self, images: RGBD, points: np.ndarray) -> np.ndarray:
        return self.model.matches_at(images.rgb, points)
