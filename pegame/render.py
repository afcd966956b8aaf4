"""Frames of a game as RGB arrays, drawn with Pillow: no display, no GPU, no matplotlib.

One :class:`FrameRenderer` per map draws a :class:`FrameState` (what is on the map at one
tick) over the map's image: each pursuer's visibility region (its recorded or computed
outline, filled; the plain FOV wedge when there is none), the belief's particles and
mean, every body as a disc with its heading, and the time. A pursuer that detects its
evader has a green region, one that does not a yellow one. The Gymnasium and PettingZoo
environments render with it (``render_mode="rgb_array"``) and ``python -m pegame.replay
--video`` draws a recording's ticks with it.

The image is the map's own cell frame (rows of the grid bottom-up, a rotated origin's yaw
undone), its longer side ``size`` pixels, the map drawn by blocks of cells on large maps
(:data:`pegame.figures.MAX_DRAWN_CELLS`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike
from PIL import Image, ImageDraw

from pegame.figures import drawn_shades
from pegame.grid import OccupancyGrid

PURSUER = (220, 40, 40)
EVADER = (30, 160, 60)
SEEN = (60, 200, 90, 90)  # RGBA fill of a region whose pursuer detects its evader
UNSEEN = (240, 200, 40, 90)
PARTICLE = (110, 0, 170)
ESTIMATE = (20, 90, 220)


@dataclass
class FrameState:
    """What is drawn at one tick. pursuers, evaders: (N, 3) and (M, 3) poses (x, y, theta)
    in the map frame (m, rad); detected: per pursuer, whether it detects its evader;
    outlines: per pursuer its visibility region's (K, 2) polygons (m), None to draw the
    FOV wedge; particles: (P, 2) positions (m); mean: the belief's mean (m) or None;
    time: simulated time (s)."""

    pursuers: np.ndarray
    evaders: np.ndarray
    detected: Sequence[bool]
    outlines: Sequence[Sequence[np.ndarray] | None] | None = None
    particles: np.ndarray = field(default_factory=lambda: np.empty((0, 2)))
    mean: np.ndarray | None = None
    time: float = 0.0


class FrameRenderer:
    """Draws :class:`FrameState` on ``grid``: the longer side about ``size`` px. fov, near,
    far: the camera's field of view (rad) and range (m), for the wedge of a pursuer whose
    outline is not given; pursuer_radius, evader_radius: body radii (m)."""

    def __init__(
        self,
        grid: OccupancyGrid,
        *,
        fov: float,
        near: float,
        far: float,
        pursuer_radius: float,
        evader_radius: float,
        size: int = 480,
    ) -> None:
        shades, block = drawn_shades(grid)
        pixels = size / max(shades.shape)  # per drawn cell
        self.scale = pixels / (block * grid.resolution)  # px per m
        grey = Image.fromarray(np.uint8(np.round(255 * np.flipud(shades))))
        width, height = (max(1, round(n * pixels)) for n in (shades.shape[1], shades.shape[0]))
        self.base = grey.resize((width, height), Image.Resampling.NEAREST).convert("RGB")
        self.height = self.base.height
        self.origin = grid.origin
        self.fov, self.near, self.far = fov, near, far
        self.radii = (pursuer_radius, evader_radius)

    def pixel(self, x: ArrayLike, y: ArrayLike) -> np.ndarray:
        """Map-frame points (m) -> (n, 2) pixel coordinates (column, row from the top)."""
        ox, oy, yaw = self.origin
        dx, dy = np.asarray(x, dtype=float) - ox, np.asarray(y, dtype=float) - oy
        c, s = math.cos(yaw), math.sin(yaw)
        u, v = c * dx + s * dy, -s * dx + c * dy
        return np.column_stack((u * self.scale, self.height - v * self.scale))

    def wedge(self, pose: np.ndarray, arc: int = 16) -> np.ndarray:
        """The FOV wedge of a pursuer at ``pose`` (x, y, theta), a (K, 2) polygon (m)."""
        angles = pose[2] + np.linspace(-self.fov / 2, self.fov / 2, arc)
        near = np.column_stack((np.cos(angles[::-1]), np.sin(angles[::-1]))) * self.near
        far = np.column_stack((np.cos(angles), np.sin(angles))) * self.far
        return pose[:2] + np.vstack((far, near))

    def frame(self, state: FrameState) -> np.ndarray:
        """The (H, W, 3) uint8 image of ``state``."""
        image = self.base.copy()
        overlay = Image.new("RGBA", image.size, (0, 0, 0, 0))
        shade = ImageDraw.Draw(overlay)
        for i, pose in enumerate(np.asarray(state.pursuers, dtype=float)):
            if not np.all(np.isfinite(pose)):
                continue
            given = state.outlines[i] if state.outlines is not None else None
            polygons = given if given is not None else [self.wedge(pose)]
            fill = SEEN if i < len(state.detected) and state.detected[i] else UNSEEN
            for polygon in polygons:
                if len(polygon) >= 3:
                    points = self.pixel(polygon[:, 0], polygon[:, 1])
                    shade.polygon([tuple(p) for p in points], fill=fill)
        image = Image.alpha_composite(image.convert("RGBA"), overlay).convert("RGB")
        draw = ImageDraw.Draw(image)
        particles = np.asarray(state.particles, dtype=float).reshape(-1, 2)
        for px, py in self.pixel(particles[:, 0], particles[:, 1]):
            draw.point((px, py), fill=PARTICLE)
        if state.mean is not None and np.all(np.isfinite(state.mean)):
            (mx, my), r = self.pixel([state.mean[0]], [state.mean[1]])[0], 4
            draw.line((mx - r, my - r, mx + r, my + r), fill=ESTIMATE, width=2)
            draw.line((mx - r, my + r, mx + r, my - r), fill=ESTIMATE, width=2)
        for poses, color, radius in (
            (state.pursuers, PURSUER, self.radii[0]),
            (state.evaders, EVADER, self.radii[1]),
        ):
            for x, y, theta in np.asarray(poses, dtype=float).reshape(-1, 3):
                if not math.isfinite(x + y + theta):
                    continue
                (cx, cy), r = self.pixel([x], [y])[0], max(2.0, radius * self.scale)
                draw.ellipse((cx - r, cy - r, cx + r, cy + r), fill=color)
                tip = self.pixel(
                    [x + 2 * radius * math.cos(theta)], [y + 2 * radius * math.sin(theta)]
                )
                draw.line((cx, cy, *tip[0]), fill=(0, 0, 0), width=2)
        draw.text((4, 2), f"t = {state.time:5.1f} s", fill=(0, 0, 0))
        return np.asarray(image)
