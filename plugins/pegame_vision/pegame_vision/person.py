"""``detector=person``: a person detector (HOG), Lucas-Kanade tracking between detections,
placement by depth (paper, Sec. IV-A "Object tracking from static camera": OpenPose, then
pyramidal Lucas-Kanade, then the depth of the box's points).

Detection is Dalal & Triggs' histograms of oriented gradients with a linear SVM trained on
people (CVPR 2005), as OpenCV ships it: ``cv2.HOGDescriptor`` with its built-in
coefficients, ``getDefaultPeopleDetector`` (INRIA, 64 x 128 px window) or
``getDaimlerPeopleDetector`` (Daimler, 48 x 96 px, Munder & Gavrila 2006) by ``model``. The
coefficients are compiled into OpenCV, so nothing is downloaded; OpenCV 5 moved HOG from
the main modules to contrib's ``xobjdetect``, hence the ``opencv-contrib-python-headless``
dependency (4.x builds have it in ``objdetect``). A person must stand about as tall in the
image as the window's person (~96 px for INRIA, ~72 px for Daimler) or taller; the image
is searched at scales ``scale``, ``scale``^2, ... and the window with the highest SVM
score above ``hit_threshold`` is the person. A camera 0.4 m above the floor cuts a close
person's head off at the image's top; ``top_margin`` rows repeating the top row are added
above the image, so that a window may reach past it.

A HOG window is larger than the person in it (the training windows have a margin), so the
person's pixels are taken from the depth image: the median depth of the window's core
(its middle third across, rows 20-80 % down) is the person's; the window's pixels within
``depth_tolerance`` m of it and more than ``min_height`` m above the floor (through the
calibration: not the floor around the feet) are the person, their box the detection's
box, and Lucas-Kanade features are taken on them (:class:`pegame_vision.detector.
TrackingDetector`). A tracked feature still shows the person while its depth is within
``depth_tolerance`` of the person's last depth and it is above the floor.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pegame.api import Context
from pegame.errors import require
from pegame_vision.detector import RGBD, Box, TrackingDetector, back_project
from pegame_vision.opencv import cv2

#: model -> (window (w, h) px, SVM coefficients)
MODELS = {
    "inria": ((64, 128), cv2.HOGDescriptor.getDefaultPeopleDetector),
    "daimler": ((48, 96), cv2.HOGDescriptor.getDaimlerPeopleDetector),
}


class PersonDetector(TrackingDetector):
    """HOG person detection, Lucas-Kanade tracking and depth placement on RGB-D frames."""

    description = "OpenCV on RGB-D: HOG person detector, Lucas-Kanade tracking, depth placement."
    entry = "person"

    @dataclass
    class Config(TrackingDetector.Config):
        model: str = "inria"  # HOG people model: inria (64 x 128 px window) or daimler (48 x 96)
        hit_threshold: float = -0.5  # SVM score a window needs to be a person (README)
        scale: float = 1.05  # step between the scales the image is searched at
        win_stride: int = 8  # px between the windows tried
        depth_tolerance: float = 0.4  # m: the person's pixels are this close to its depth
        min_height: float = 0.05  # m above the floor below which a pixel is floor
        min_pixels: int = 12  # person pixels a detection needs
        top_margin: int = 64  # px of the top row repeated above the image (module docstring)

        def __post_init__(self) -> None:
            super().__post_init__()
            require(self.model in MODELS, "model", " or ".join(MODELS), self.model)
            require(self.scale > 1, "scale", "a factor > 1", self.scale)
            require(
                self.win_stride >= 1, "win_stride", "a whole number of px >= 1", self.win_stride
            )
            for key in ("depth_tolerance", "min_height"):
                require(getattr(self, key) > 0, key, "a distance > 0 m", getattr(self, key))
            require(self.min_pixels >= 1, "min_pixels", "a whole number >= 1", self.min_pixels)
            require(
                self.top_margin >= 0, "top_margin", "a whole number of px >= 0", self.top_margin
            )

    def __init__(self, config: Config, context: Context, rng: np.random.Generator) -> None:
        window, coefficients = MODELS[config.model]
        # block 16 px, block stride 8 px, cell 8 px, 9 orientation bins: both models' layout
        self.hog = cv2.HOGDescriptor(window, (16, 16), (8, 8), (8, 8), 9)
        self.hog.setSVMDetector(np.asarray(coefficients(), dtype=np.float32))
        super().__init__(config, context, rng)

    def reset(self) -> None:
        super().reset()
        self._depth = float("nan")  # m: the person's depth at the last detection or tracking

    def windows(self, gray: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """HOG windows (N, 4) (x, y, w, h) px scoring above ``hit_threshold`` in ``gray``
        (H, W) uint8, and their scores (N,)."""
        cfg = self.config
        stride = (cfg.win_stride, cfg.win_stride)
        padded = cv2.copyMakeBorder(gray, cfg.top_margin, 0, 0, 0, cv2.BORDER_REPLICATE)
        rects, scores = self.hog.detectMultiScale(
            padded, hitThreshold=cfg.hit_threshold, winStride=stride, scale=cfg.scale
        )
        rects = np.reshape(rects, (-1, 4)) - [0, cfg.top_margin, 0, 0]
        return rects, np.ravel(scores)

    def _find(self, images: RGBD, gray: np.ndarray) -> tuple[Box, np.ndarray] | None:
        rects, scores = self.windows(gray)
        if len(rects) == 0:
            return None
        x, y, w, h = (int(v) for v in rects[int(np.argmax(scores))])
        height, width = gray.shape
        x0, y0, x1, y1 = max(0, x), max(0, y), min(width, x + w), min(height, y + h)
        core = images.depth[
            max(y0, y + h // 5) : min(y1, y + 4 * h // 5),
            max(x0, x + w // 3) : min(x1, x + 2 * w // 3),
        ]
        core = core[np.isfinite(core)]
        if core.size == 0:
            return None
        self._depth = float(np.median(core))
        rows, cols = np.mgrid[y0:y1, x0:x1]
        rows, cols = rows.ravel(), cols.ravel()
        person = self._accept_pixels(images, rows, cols)
        if np.count_nonzero(person) < self.config.min_pixels:
            return None
        rows, cols = rows[person], cols[person]
        mask = np.zeros(gray.shape, dtype=bool)
        mask[rows, cols] = True
        return (
            float(cols.min()),
            float(rows.min()),
            float(cols.max() + 1),
            float(rows.max() + 1),
        ), mask

    def _accept_pixels(self, images: RGBD, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """Bool (N,): pixels at the person's depth and above the floor."""
        depth = images.depth[rows, cols]
        with np.errstate(invalid="ignore"):
            near = np.abs(depth - self._depth) <= self.config.depth_tolerance
            above = back_project(images, rows, cols)[2] > self.config.min_height
        return near & above

    def _accept(self, images: RGBD, points: np.ndarray) -> np.ndarray:
        height, width = images.depth.shape
        cols = np.clip(points[:, 0].astype(int), 0, width - 1)
        rows = np.clip(points[:, 1].astype(int), 0, height - 1)
        good = self._accept_pixels(images, rows, cols)
        if good.any():
            self._depth = float(np.median(images.depth[rows[good], cols[good]]))
        return good
