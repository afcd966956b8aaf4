"""Pyramidal Lucas-Kanade tracking of a bounding box (Bouguet 2000, the paper's tracker).

Corner features (``cv2.goodFeaturesToTrack``, Shi-Tomasi) are taken on the evader's pixels;
each new frame they are tracked forward and back again (``cv2.calcOpticalFlowPyrLK``), and a
feature survives when both passes converge, it returns within ``max_error`` px of where it
started (forward-backward check), and the caller's appearance test still accepts it. The
box moves by the survivors' median displacement and scales by the median change of their
spread. Boxes and points are in pixels of the tracked images, (x, y) = (column, row).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from pegame_vision.opencv import cv2

LK_PARAMS: dict[str, Any] = {
    "winSize": (9, 9),
    "maxLevel": 2,
    "criteria": (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 20, 0.03),
}


class BoxTracker:
    """Tracks one box with Lucas-Kanade features; see the module docstring."""

    def __init__(self, max_features: int, max_error: float = 1.0) -> None:
        self.max_features = max_features
        self.max_error = max_error
        self.points: np.ndarray = np.zeros((0, 2), dtype=np.float32)
        self.box = np.zeros(4)  # left, top, right, bottom (px)
        self._gray: np.ndarray | None = None

    def start(self, gray: np.ndarray, box: np.ndarray, mask: np.ndarray) -> int:
        """Track ``box`` from ``gray`` (H, W) uint8, with features on ``mask`` (H, W) bool;
        returns the number of features found."""
        corners = cv2.goodFeaturesToTrack(
            gray, self.max_features, 0.01, 2, mask=mask.astype(np.uint8)
        )
        self.points = np.zeros((0, 2), np.float32) if corners is None else corners.reshape(-1, 2)
        self.box = np.asarray(box, dtype=float)
        self._gray = gray
        return len(self.points)

    def step(self, gray: np.ndarray, accept: Callable[[np.ndarray], np.ndarray]) -> int:
        """Track into ``gray``; ``accept(points) -> bool (N,)`` is the appearance test.
        Updates the box and the surviving features; returns how many survived."""
        if self._gray is None or len(self.points) == 0:
            return 0
        old: np.ndarray = self.points.reshape(-1, 1, 2)
        new, found, _ = cv2.calcOpticalFlowPyrLK(self._gray, gray, old, None, **LK_PARAMS)
        back, found_back, _ = cv2.calcOpticalFlowPyrLK(gray, self._gray, new, None, **LK_PARAMS)
        old, new, back = old.reshape(-1, 2), new.reshape(-1, 2), back.reshape(-1, 2)
        height, width = gray.shape
        good = (found.ravel() == 1) & (found_back.ravel() == 1)
        good &= np.hypot(*(old - back).T) < self.max_error
        good &= (new[:, 0] >= 0) & (new[:, 0] < width) & (new[:, 1] >= 0) & (new[:, 1] < height)
        if good.any():
            good[good] = accept(new[good])
        self._gray = gray
        old, new = old[good], new[good]
        self.points = new
        if len(new) == 0:
            return 0
        shift = np.median(new - old, axis=0)
        scale = 1.0
        if len(new) >= 2:
            before = np.median(np.hypot(*(old - old.mean(axis=0)).T))
            after = np.median(np.hypot(*(new - new.mean(axis=0)).T))
            if before > 1e-3:
                scale = float(np.clip(after / before, 0.8, 1.25))
        centre = 0.5 * (self.box[:2] + self.box[2:]) + shift
        half = 0.5 * (self.box[2:] - self.box[:2]) * scale
        self.box = np.concatenate([centre - half, centre + half])
        return len(new)
