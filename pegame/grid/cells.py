"""Numba helpers that find the cell of a map point and test it, for every grid kernel.

They take a grid's map-to-cell transform as its :class:`pegame.grid.GridFrame`
(``OccupancyGrid.frame``) and reproduce :meth:`OccupancyGrid.world_to_cell` operation for
operation, so a kernel picks exactly the cells that the numpy code picks. Inlined into the
caller's loop (line of sight, the grid simulator's collision sweep, the smart pursuer's
straight-line check), they cost no call.
"""

from __future__ import annotations

import math

from numba import njit

from pegame.grid.occupancy import COS_YAW, OX, OY, RESOLUTION, ROTATED, SIN_YAW


@njit(cache=True, inline="always")
def point_cell(x, y, frame):
    """(row, col) of the cell containing map point (x, y) (m); may lie off the grid."""
    dx = x - frame[OX]
    dy = y - frame[OY]
    if frame[ROTATED]:
        c, s = frame[COS_YAW], frame[SIN_YAW]
        dx, dy = c * dx + s * dy, -s * dx + c * dy
    return math.floor(dy / frame[RESOLUTION]), math.floor(dx / frame[RESOLUTION])


@njit(cache=True, inline="always")
def cell_blocked(blocked, row, col):
    """True when (row, col) is off the grid or True in the bool (H, W) mask ``blocked``."""
    height, width = blocked.shape
    return row < 0 or row >= height or col < 0 or col >= width or blocked[row, col]
