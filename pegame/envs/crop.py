"""The egocentric local occupancy crop: the map around an agent, rotated into its frame.

A crop of ``cells`` x ``cells`` at ``resolution`` m per cell is centred on the agent and
laid out like the map (row = y, column = x, row 0 = lowest y) but in the agent's frame:
x forward along its heading, y to its left. Cell (r, c) samples the robot-frame point
((c + 0.5 - cells/2) * resolution, (r + 0.5 - cells/2) * resolution). Values are 0 (free)
or 1 (blocked: occupied, unknown or off the map).

Crop cells are usually coarser than map cells (0.2 m vs 0.05 m), and a point sample
would skip thin walls. Each crop cell therefore samples a max-pooled map: a map cell is
blocked in it when any cell of the smallest odd square window at least ``resolution``
wide around it is blocked, so a wall crossing a crop cell near its centre is never
missed (the window is along the map axes, so at 45 degrees it reaches a little less far
than the rotated crop cell's corners).

Two implementations give identical crops: :func:`local_crop_reference` in plain numpy
and the numba kernel behind :class:`LocalCrop`, which writes into a caller's buffer.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from numba import njit
from scipy.ndimage import maximum_filter

from pegame.grid import OccupancyGrid


@lru_cache(maxsize=16)
def pooled_blocked(grid: OccupancyGrid, resolution: float) -> np.ndarray:
    """Bool (H, W): ``grid.blocked`` max-pooled over the smallest odd square window of
    cells at least ``resolution`` m wide; cells near the border see the outside as blocked.

    Cached per grid (grids are immutable and compare by identity) and resolution.
    """
    ratio = resolution / grid.resolution
    half = max(0, math.ceil((ratio - 1.0) / 2.0 - 1e-9))
    pooled = maximum_filter(grid.blocked, size=2 * half + 1, mode="constant", cval=True)
    pooled.setflags(write=False)
    return pooled


@lru_cache(maxsize=16)
def crop_offsets(cells: int, resolution: float) -> tuple[np.ndarray, np.ndarray]:
    """Robot-frame (x, y) of every crop cell centre, each float64 (cells * cells,), m,
    row-major."""
    centres = (np.arange(cells) + 0.5 - 0.5 * cells) * resolution
    y, x = np.meshgrid(centres, centres, indexing="ij")
    x, y = x.ravel(), y.ravel()
    x.setflags(write=False)
    y.setflags(write=False)
    return x, y


def local_crop_reference(
    grid: OccupancyGrid, x: float, y: float, theta: float, cells: int, resolution: float
) -> np.ndarray:
    """Float32 (cells, cells) crop around the map-frame pose (x m, y m, theta rad).

    Plain numpy reference of :class:`LocalCrop`.
    """
    ox, oy = crop_offsets(cells, resolution)
    c, s = math.cos(theta), math.sin(theta)
    rows, cols = grid.world_to_cell(x + (c * ox - s * oy), y + (s * ox + c * oy))
    inside = grid.contains(rows, cols)
    values = np.ones(rows.shape, dtype=np.float32)
    values[inside] = pooled_blocked(grid, resolution)[rows[inside], cols[inside]]
    return values.reshape(cells, cells)


@njit(cache=True)
def _crop(pooled, off_x, off_y, x, y, c, s, gx, gy, gc, gs, rotate, res, out):
    """Write into ``out`` (flat float32) the pooled value at each rotated offset.

    Reproduces ``OccupancyGrid.world_to_cell`` operation for operation (gx, gy: grid
    origin; gc, gs: cos and sin of its yaw, applied when ``rotate``) so that the result
    matches :func:`local_crop_reference` exactly.
    """
    height, width = pooled.shape
    for k in range(off_x.size):
        dx = x + (c * off_x[k] - s * off_y[k]) - gx
        dy = y + (s * off_x[k] + c * off_y[k]) - gy
        if rotate:
            dx, dy = gc * dx + gs * dy, -gs * dx + gc * dy
        col = math.floor(dx / res)
        row = math.floor(dy / res)
        if row < 0 or row >= height or col < 0 or col >= width or pooled[row, col]:
            out[k] = 1.0
        else:
            out[k] = 0.0


class LocalCrop:
    """The crop of ``cells`` x ``cells`` at ``resolution`` m on ``grid``, ready to sample
    (the pooled map and the offsets are prepared once)."""

    def __init__(self, grid: OccupancyGrid, cells: int, resolution: float) -> None:
        self.grid = grid
        self.size = cells * cells
        self._pooled = pooled_blocked(grid, resolution)
        self._off_x, self._off_y = crop_offsets(cells, resolution)
        gx, gy, yaw = grid.origin
        self._origin = (gx, gy, math.cos(yaw), math.sin(yaw), yaw != 0.0, float(grid.resolution))

    def __call__(
        self, x: float, y: float, theta: float, out: np.ndarray | None = None
    ) -> np.ndarray:
        """Flat float32 (cells * cells,) crop around the map-frame pose (x m, y m, theta
        rad), row-major as in the module docstring; written into ``out`` when given (a
        float32 array of that size, e.g. a slice of an observation vector)."""
        if out is None:
            out = np.empty(self.size, dtype=np.float32)
        _crop(
            self._pooled,
            self._off_x,
            self._off_y,
            float(x),
            float(y),
            math.cos(theta),
            math.sin(theta),
            *self._origin,
            out,
        )
        return out
