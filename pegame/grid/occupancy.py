"""The occupancy grid: a frozen nav_msgs/OccupancyGrid and its map-to-cell transform.

An :class:`OccupancyGrid` follows nav_msgs/OccupancyGrid: ``data`` is int8 of shape
(height, width) with 0 (FREE) free, 100 (OCCUPIED) occupied and -1 (UNKNOWN) unknown; row
0 is the lowest y. ``origin`` is the map-frame pose (x m, y m, yaw rad) of the lower-left
corner of cell (0, 0). Unknown cells are neither traversable nor transparent. A grid and
its arrays never change after construction, so whatever is derived from it stays valid
(:func:`pegame.grid.per_grid`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import NamedTuple, overload

import numpy as np
from numpy.typing import ArrayLike

FREE = 0
OCCUPIED = 100
UNKNOWN = -1


class GridFrame(NamedTuple):
    """The map-to-cell transform of a grid (``OccupancyGrid.frame``).

    Numba kernels take it as the plain tuple ``OccupancyGrid.kernel_frame`` (the same
    fields in the same order) and read it by field name through the index constants below
    (``frame[RESOLUTION]``): a NamedTuple argument costs numba about 1.4 us more per call
    to unbox, and the kernels are called several times per control tick.

    (ox, oy): the map-frame position of cell (0, 0)'s lower-left corner (m); cos_yaw and
    sin_yaw of the origin's yaw; rotated: whether that yaw is nonzero (the kernels skip the
    rotation otherwise, as :meth:`OccupancyGrid.world_to_cell` does); resolution: cell edge
    length (m). A point (x, y) lies in row floor(v / resolution), column floor(u /
    resolution) with (u, v) = R(-yaw) (x - ox, y - oy).
    """

    ox: float
    oy: float
    cos_yaw: float
    sin_yaw: float
    rotated: bool
    resolution: float


#: the index of each GridFrame field in ``OccupancyGrid.kernel_frame``, for the kernels
OX, OY, COS_YAW, SIN_YAW, ROTATED, RESOLUTION = (
    GridFrame._fields.index(name)
    for name in ("ox", "oy", "cos_yaw", "sin_yaw", "rotated", "resolution")
)


@dataclass(frozen=True, eq=False)
class OccupancyGrid:
    """A 2D occupancy grid.

    data: int8 (height, width), values FREE, OCCUPIED or UNKNOWN, row 0 = lowest y.
    resolution: cell edge length (m). origin: (x, y, yaw) of cell (0, 0)'s lower-left
    corner in the map frame (m, m, rad). name: a label for logs and results.
    """

    data: np.ndarray
    resolution: float
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0)
    name: str = "map"
    blocked: np.ndarray = field(init=False, repr=False)
    frame: GridFrame = field(init=False, repr=False)
    kernel_frame: tuple = field(init=False, repr=False)  # the frame as kernels take it

    def __post_init__(self) -> None:
        data = np.ascontiguousarray(self.data, dtype=np.int8)
        data.setflags(write=False)
        object.__setattr__(self, "data", data)
        blocked = data != FREE
        blocked.setflags(write=False)
        object.__setattr__(self, "blocked", blocked)
        object.__setattr__(self, "origin", tuple(float(v) for v in self.origin))
        ox, oy, yaw = self.origin
        frame = GridFrame(ox, oy, math.cos(yaw), math.sin(yaw), yaw != 0.0, float(self.resolution))
        object.__setattr__(self, "frame", frame)
        object.__setattr__(self, "kernel_frame", tuple(frame))

    @property
    def height(self) -> int:
        """Number of rows (cells along y)."""
        return int(self.data.shape[0])

    @property
    def width(self) -> int:
        """Number of columns (cells along x)."""
        return int(self.data.shape[1])

    @property
    def free(self) -> np.ndarray:
        """Bool (height, width): True where the cell is known free."""
        return ~self.blocked

    @overload
    def world_to_cell(self, x: float, y: float) -> tuple[int, int]: ...
    @overload
    def world_to_cell(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]: ...
    def world_to_cell(
        self, x: float | np.ndarray, y: float | np.ndarray
    ) -> tuple[int, int] | tuple[np.ndarray, np.ndarray]:
        """Map-frame (x, y) in metres -> integer (row, col) of the containing cell.

        Works on scalars or arrays; results may lie outside the grid (see ``contains``).
        """
        ox, oy, yaw = self.origin
        if isinstance(x, (float, int)) and isinstance(y, (float, int)) and math.isfinite(x + y):
            # The same float operations as below, without numpy's per-call overhead.
            dx, dy = float(x) - ox, float(y) - oy
            if yaw:
                c, s = math.cos(yaw), math.sin(yaw)
                dx, dy = c * dx + s * dy, -s * dx + c * dy
            return math.floor(dy / self.resolution), math.floor(dx / self.resolution)
        ux = np.asarray(x, dtype=float) - ox
        uy = np.asarray(y, dtype=float) - oy
        if yaw:
            c, s = math.cos(yaw), math.sin(yaw)
            ux, uy = c * ux + s * uy, -s * ux + c * uy
        col = np.floor(ux / self.resolution).astype(np.int64)
        row = np.floor(uy / self.resolution).astype(np.int64)
        if row.ndim == 0:
            return int(row), int(col)
        return row, col

    @overload
    def cell_to_world(
        self, row: int | np.integer, col: int | np.integer
    ) -> tuple[float, float]: ...
    @overload
    def cell_to_world(self, row: np.ndarray, col: np.ndarray) -> tuple[np.ndarray, np.ndarray]: ...
    def cell_to_world(
        self, row: int | np.integer | np.ndarray, col: int | np.integer | np.ndarray
    ) -> tuple[float, float] | tuple[np.ndarray, np.ndarray]:
        """Integer (row, col) -> map-frame (x, y) of the cell centre, metres."""
        ox, oy, yaw = self.origin
        u = (np.asarray(col, dtype=float) + 0.5) * self.resolution
        v = (np.asarray(row, dtype=float) + 0.5) * self.resolution
        if yaw:
            c, s = math.cos(yaw), math.sin(yaw)
            u, v = c * u - s * v, s * u + c * v
        x, y = u + ox, v + oy
        if x.ndim == 0:
            return float(x), float(y)
        return x, y

    @overload
    def contains(self, row: np.ndarray, col: np.ndarray) -> np.ndarray: ...
    @overload
    def contains(self, row: int | np.integer, col: int | np.integer) -> np.bool_: ...
    def contains(self, row: ArrayLike, col: ArrayLike) -> np.ndarray | np.bool_:
        """True where (row, col) indexes a cell of the grid."""
        row, col = np.asarray(row), np.asarray(col)
        return (row >= 0) & (row < self.height) & (col >= 0) & (col < self.width)

    def is_free(self, x: float, y: float) -> bool:
        """True when the map-frame point (x, y) (m) lies in a known-free cell."""
        row, col = self.world_to_cell(x, y)
        return bool(self.contains(row, col)) and not self.blocked[row, col]

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """(x_min, x_max, y_min, y_max) of the grid in the map frame, for yaw = 0 (m)."""
        ox, oy, _ = self.origin
        return (ox, ox + self.width * self.resolution, oy, oy + self.height * self.resolution)
