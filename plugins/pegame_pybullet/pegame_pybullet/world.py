"""The static 3D world of a map: the occupancy grid's blocked cells extruded into walls.

Occupied and unknown cells (``OccupancyGrid.blocked``) and a one-cell ring around the grid
(the grid simulator treats the outside as blocked too) are covered by axis-aligned
rectangles of cells, merged greedily so that a map of ~10^5 cells becomes tens to a few
hundred boxes (the paper maps: 10 to 42), each a static body, on a floor box whose top face
is z = 0. Frames: the PyBullet world frame is the map frame with z up, in metres.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import pybullet

from pegame.grid import OccupancyGrid
from pegame_pybullet.client import Client

WALL_RGBA = (0.72, 0.72, 0.70, 1.0)  # neutral grey: nothing in the scenery has a clothing hue
FLOOR_RGBA = (0.45, 0.45, 0.45, 1.0)
FLOOR_THICKNESS = 0.05  # m
VISUAL_OVERLAP = 0.001  # m by which a wall's visual box exceeds its collision box


def merge_rectangles(mask: np.ndarray) -> list[tuple[int, int, int, int]]:
    """Cover the True cells of ``mask`` (H, W) exactly with disjoint rectangles.

    Greedy: take the first uncovered True cell in row-major order, extend it along the
    row as far as the cells are True and uncovered, then grow it row by row while the
    whole span stays so. Returns (row, col, height, width) in cells.
    """
    todo = np.array(mask, dtype=bool)
    height, width = todo.shape
    flat = todo.ravel()  # a view: covering cells in ``todo`` updates it
    rects: list[tuple[int, int, int, int]] = []
    start = 0
    while True:
        # Every cell before ``start`` is covered, so the scans add up to one pass; argmax
        # of a bool array stops at the first True.
        start += int(np.argmax(flat[start:]))
        if not flat[start]:
            return rects
        row, col = divmod(start, width)
        span = todo[row, col:]
        w = span.size if span.all() else int(np.argmin(span))
        h = 1
        while row + h < height and todo[row + h, col : col + w].all():
            h += 1
        todo[row : row + h, col : col + w] = False
        rects.append((row, col, h, w))


@lru_cache(maxsize=8)
def wall_rectangles(grid: OccupancyGrid) -> tuple[tuple[int, int, int, int], ...]:
    """Rectangles (row, col, height, width) of grid cells covering the blocked cells and a
    one-cell ring outside the grid (rows and cols -1 and H or W). Cached per grid."""
    padded = np.pad(grid.blocked, 1, constant_values=True)
    return tuple((r - 1, c - 1, h, w) for r, c, h, w in merge_rectangles(padded))


def _quaternion_z(yaw: float) -> list[float]:
    return [0.0, 0.0, math.sin(0.5 * yaw), math.cos(0.5 * yaw)]


@dataclass(frozen=True)
class World:
    """Body ids of the static world: one per wall box, and the floor."""

    walls: tuple[int, ...]
    floor: int


def build_world(client: Client, grid: OccupancyGrid, wall_height: float) -> World:
    """Add the floor and the walls of ``grid`` (``wall_height`` m tall) to ``client``.

    Each wall box is a body of its own: PyBullet's compound shapes hold at most 16 children,
    and separate bodies let collision queries find the few boxes near an agent through the
    broadphase.
    """
    res, yaw = grid.resolution, grid.origin[2]
    cos, sin = math.cos(yaw), math.sin(yaw)
    turn = _quaternion_z(yaw)

    def to_map(u: float, v: float) -> tuple[float, float]:
        """Grid-frame point (m from the corner of cell (0, 0)) -> map frame."""
        return grid.origin[0] + cos * u - sin * v, grid.origin[1] + sin * u + cos * v

    walls = []
    for row, col, h, w in wall_rectangles(grid):
        half = [0.5 * w * res, 0.5 * h * res, 0.5 * wall_height]
        collision = client.createCollisionShape(pybullet.GEOM_BOX, halfExtents=half)
        # Visual boxes overlap their neighbours a little: TinyRenderer leaves one-pixel
        # cracks along the shared edge of two touching boxes, and the evader shows through.
        grown = [half[0] + VISUAL_OVERLAP, half[1] + VISUAL_OVERLAP, half[2]]
        visual = client.createVisualShape(pybullet.GEOM_BOX, halfExtents=grown, rgbaColor=WALL_RGBA)
        centre = to_map((col + 0.5 * w) * res, (row + 0.5 * h) * res)
        walls.append(
            client.createMultiBody(0, collision, visual, [*centre, 0.5 * wall_height], turn)
        )

    # The floor spans the grid and its ring; it has no collision shape (agents move in 2D).
    half = [0.5 * (grid.width + 2) * res, 0.5 * (grid.height + 2) * res, 0.5 * FLOOR_THICKNESS]
    visual = client.createVisualShape(pybullet.GEOM_BOX, halfExtents=half, rgbaColor=FLOOR_RGBA)
    centre = to_map(0.5 * grid.width * res, 0.5 * grid.height * res)
    floor = client.createMultiBody(0, -1, visual, [*centre, -0.5 * FLOOR_THICKNESS], turn)
    return World(walls=tuple(walls), floor=floor)
