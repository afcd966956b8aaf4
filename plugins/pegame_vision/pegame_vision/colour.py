"""A colour model of the evader's appearance: the hues of its clothing and skin.

A pixel belongs to the evader when its hue is within ``hue_tolerance`` degrees of one of
the model's colours and it is saturated and bright enough to have a hue at all. Shading
changes a surface's value and barely its hue, so the model holds under the renderer's
light; grey scenery (walls, floor, the robot) never matches.
"""

from __future__ import annotations

import colorsys

import numpy as np

from pegame_vision.opencv import cv2


def parse_hex(colour: str) -> tuple[float, float, float]:
    """'#rrggbb' -> (r, g, b) in [0, 1]; ValueError for anything else."""
    text = colour.strip().lstrip("#")
    if len(text) != 6:
        raise ValueError(colour)
    red, green, blue = (int(text[i : i + 2], 16) / 255 for i in (0, 2, 4))
    return red, green, blue


class ColourModel:
    """Evader pixels by hue. colours: '#rrggbb' strings; hue_tolerance in degrees;
    min_saturation and min_value in [0, 1] (HSV)."""

    def __init__(
        self, colours: list[str], hue_tolerance: float, min_saturation: float, min_value: float
    ) -> None:
        # OpenCV's 8-bit HSV has hue in [0, 180) (2 degrees per unit), S and V in [0, 255].
        self.hues = np.array([colorsys.rgb_to_hsv(*parse_hex(c))[0] * 180.0 for c in colours])
        self.tolerance = hue_tolerance / 2.0
        self.min_saturation = round(255 * min_saturation)
        self.min_value = round(255 * min_value)

    def _matches(self, hsv: np.ndarray) -> np.ndarray:
        """Bool mask over the leading dimensions of ``hsv`` (..., 3) uint8."""
        hue = hsv[..., 0].astype(np.int16)[..., None]
        distance = np.abs(hue - self.hues)
        distance = np.minimum(distance, 180.0 - distance)  # hue is circular
        tinted = (hsv[..., 1] >= self.min_saturation) & (hsv[..., 2] >= self.min_value)
        return tinted & np.any(distance <= self.tolerance, axis=-1)

    def mask(self, rgb: np.ndarray) -> np.ndarray:
        """Bool (H, W): the pixels of ``rgb`` (H, W, 3) uint8 that match the model."""
        return self._matches(cv2.cvtColor(rgb, cv2.COLOR_RGB2HSV))

    def matches_at(self, rgb: np.ndarray, points: np.ndarray) -> np.ndarray:
        """Bool (N,): whether the pixels under ``points`` (N, 2) (x, y) px match."""
        cols = np.clip(points[:, 0].astype(int), 0, rgb.shape[1] - 1)
        rows = np.clip(points[:, 1].astype(int), 0, rgb.shape[0] - 1)
        pixels = np.ascontiguousarray(rgb[rows, cols][None])  # (1, N, 3) for cvtColor
        return self._matches(cv2.cvtColor(pixels, cv2.COLOR_RGB2HSV))[0]


def find_blobs(mask: np.ndarray, min_component: int) -> np.ndarray:
    """Bool (H, W): the 8-connected components of ``mask`` with at least ``min_component``
    pixels (smaller specks are noise at colour edges)."""
    count, labels, stats, _ = cv2.connectedComponentsWithStats(
        mask.astype(np.uint8), connectivity=8
    )
    keep = np.zeros(count, dtype=bool)
    keep[1:] = stats[1:, cv2.CC_STAT_AREA] >= min_component
    return keep[labels]
