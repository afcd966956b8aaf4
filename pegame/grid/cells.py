"""Numba helpers that find the cell of a map point and test it, for every grid kernel,
and the centres of many cells at once.

They take a grid's map-to-cell transform as its :class:`pegame.grid.GridFrame`
(``OccupancyGrid.frame``) and reproduce :meth:`OccupancyGrid.world_to_cell` operation for
operation, so a kernel picks exactly the cells that the numpy code picks. Inlined into the
caller's loop (line of sight, the grid simulator's collision sweep, the smart pursuer's
straight-line check), they cost no call.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from pegame.grid.occupancy import COS_YAW, OX, OY, RESOLUTION, ROTATED, SIN_YAW


@njit(cache=True, inline="always")
def point_cell(x: float, y: float, frame: tuple | np.ndarray) -> tuple[int, int]:
    """(row, col) of the cell containing map point (x, y) (m); may lie off the grid."""
    dx = x - frame[OX]
    dy = y - frame[OY]
    if frame[ROTATED]:
        c, s = frame[COS_YAW], frame[SIN_YAW]
        dx, dy = c * dx + s * dy, -s * dx + c * dy
    return math.floor(dy / frame[RESOLUTION]), math.floor(dx / frame[RESOLUTION])


@njit(cache=True, inline="always")
def cell_blocked(blocked: np.ndarray, row: int, col: int) -> bool:
    """True when (row, col) is off the grid or True in the bool (H, W) mask ``blocked``."""
    height, width = blocked.shape
    return row < 0 or row >= height or col < 0 or col >= width or blocked[row, col]


@njit(cache=True)
def cell_centres(cells: np.ndarray, width: int, frame: tuple) -> np.ndarray:
    """Float (N, 2): the map-frame centres (x, y) (m) of the flat row-major indices
    ``cells`` (int (N,), row * ``width`` + col), by the operations of
    :meth:`OccupancyGrid.cell_to_world` in its order (the same floats), in one pass instead
    of its several numpy passes."""
    out = np.empty((cells.size, 2))
    for k in range(cells.size):
        row = cells[k] // width
        out[k, 0], out[k, 1] = cell_centre(row, cells[k] - row * width, frame)
    return out


@njit(cache=True, inline="always")
def cell_centre(row: int, col: int, frame: tuple) -> tuple[float, float]:
    """Map-frame centre (x, y) (m) of cell (row, col), by the operations of
    :meth:`OccupancyGrid.cell_to_world` (so the same floats)."""
    u = (float(col) + 0.5) * frame[RESOLUTION]
    v = (float(row) + 0.5) * frame[RESOLUTION]
    if frame[ROTATED]:
        c, s = frame[COS_YAW], frame[SIN_YAW]
        u, v = c * u - s * v, s * u + c * v
    return u + frame[OX], v + frame[OY]
