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
and the numba kernels behind :class:`LocalCrop`, which write into a caller's buffer: the
crop's cells from its lattice (:func:`lattice_crop`, a row term plus a column term per
cell, whose error bound proves the same cells) and, for a pose whose lattice comes too
near a cell edge, :func:`_crop`'s division; :func:`crop_kernel` picks the route, for
the single game and the batched environments alike.
The kernels take what they read grouped by meaning (:class:`CropLattice`,
:class:`CropSamples`, :class:`CropScratch`, and the agent's pose as (x, y, cos, sin) of
its heading), unpacked once at entry.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from functools import lru_cache
from typing import NamedTuple

import numpy as np
from numba import njit
from scipy.ndimage import maximum_filter

from pegame.grid import OccupancyGrid
from pegame.grid.occupancy import COS_YAW, OX, OY, RESOLUTION, ROTATED, SIN_YAW

#: an agent's pose as the crop kernels take it: (x m, y m, cos, sin of the heading)
Heading = tuple[float, float, float, float]


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


class CropSamples(NamedTuple):
    """The crop as the division route samples it (:func:`_crop`)."""

    pooled: np.ndarray  # bool (H, W), the max-pooled map (pooled_blocked)
    off_x: np.ndarray  # m, robot-frame x of every crop cell centre (crop_offsets)
    off_y: np.ndarray  # m, their robot-frame y


class CropLattice(NamedTuple):
    """The map and the crop as the lattice route reads them (:func:`lattice_crop`)."""

    table: np.ndarray  # uint8, the pooled map inside a blocked border (bordered_table)
    centres: np.ndarray  # m, the crop's cell centres along one axis
    frame: np.ndarray  # float64 (6,), the map's OccupancyGrid.kernel_frame
    width: int  # the map's width in cells


class CropScratch(NamedTuple):
    """The lattice route's scratch (:func:`lattice_crop`)."""

    cells: np.ndarray  # int32 (crop cells,), each crop cell's flat index into the table
    columns: np.ndarray  # float64 (2, cells per side), the lattice's column terms


@njit(cache=True)
def _crop(samples: tuple, frame: Sequence[float], pose: Heading, out: np.ndarray) -> None:
    """Write into ``out`` (flat float32) the pooled value at each offset of ``samples``
    rotated by the ``pose`` (x, y, cos, sin of the heading; map frame, m).

    Reproduces ``OccupancyGrid.world_to_cell`` operation for operation (``frame`` the
    grid's ``kernel_frame``) so that the result matches :func:`local_crop_reference`
    exactly.
    """
    pooled, off_x, off_y = samples
    x, y, c, s = pose
    gx, gy, gc, gs, res = frame[OX], frame[OY], frame[COS_YAW], frame[SIN_YAW], frame[RESOLUTION]
    rotate = frame[ROTATED] != 0.0
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


#: a lattice point within this many cells of a cell edge is not decided by the lattice
_EDGE = 2.0**-20
#: |u - floor(u) - 1/2| below which a lattice coordinate u is decided
_DECIDED = 0.5 - _EDGE
#: the largest size L (cells, see :func:`_lattice_crop`) for which the lattice decides
_SIZE_LIMIT = 2.0**21
#: tables of at least this many cells are not looked up by the lattice: its flat cell
#: indices are int32 (AVX2 converts four float64 to int32 at once, but int64 one at a time)
_TABLE_LIMIT = 2**31


@njit(cache=True, inline="always")
def lattice_crop(lattice: tuple, pose: Heading, out: np.ndarray, at: int, scratch: tuple) -> bool:
    """The crop's cells around the ``pose`` (x, y, cos, sin of the heading theta; map
    frame, m) from the crop's lattice, into out[at:]; returns whether every cell is
    decided (else out is to be redone by :func:`_crop`'s division, as
    :func:`crop_kernel` does).

    Crop cell (i, j) lies at the grid-frame point (in cells) P + o_j A + o_i B, with
    o = ``centres`` (m, the crop's cell centres along one axis), P = R(-yaw) (x - gx, y - gy) / res and A, B = R(-yaw)
    R(theta) (e_x, e_y) / res the crop's axes; its coordinates are the row term
    P + o_i B (once per row) plus the column term o_j A (once per game, into
    ``scratch.columns``): a sum per coordinate and cell instead of the reference's
    rotation and division.

    Why it picks the reference's cells. Let u = 2**-53 and L = (|x| + |y| + |gx| + |gy|
    + 4 max|o|) / res, a bound (cells) on every quantity either route forms. A rounding
    errs by at most u times its quantity, and reaches a final coordinate through sums,
    products by cos/sin (at most 1) and the scaling to cells, so it moves the coordinate
    by at most u L (1 + u)^k. Per coordinate the reference (:func:`pegame.observe.crop._crop`)
    rounds 14 times (5 for each of dx and dy, the grid rotation's 3, the division) and
    this route 18 times (fl(1 / res) in the three scaled terms, the axes' 3 + 3, the
    position's 2 + 3, the lattice's two products and two sums), so the two are within
    34 u L (1 + u)^18 < 2**-26 cells of each other for L <= 2**21 (checked per game). A
    coordinate q of this route with |q - floor(q) - 1/2| < 1/2 - 2**-20 (q - floor(q)
    is exact) is more than 2**-20 > 2**-26 from every whole number, so the reference's
    quotient has the same floor: the same cell. A game with a coordinate that close to a
    cell edge (under one game in 100 on random poses), with L too large, or whose
    lattice leaves the table's border is redone by the division.

    The crop's bounding box (its centre P plus the reach of its corners, |A| + |B| times
    max|o|, and 2 cells for rounding) is checked inside the ``lattice``'s table
    (:func:`bordered_table`), the pooled map with a border of blocked cells, so that no
    cell needs a test against the map's edges; the coordinates' cells are found in one
    vectorised pass (flat int32 indices into ``scratch.cells``: a table of 2**31 cells or
    more is left to the division) and looked up in a second, a gather that does not
    vectorise (an unsigned index: no test for negative ones).
    """
    table, centres, frame, width = lattice
    x, y, c, s = pose
    cells, columns = scratch
    gx, gy, gc, gs, res = frame[OX], frame[OY], frame[COS_YAW], frame[SIN_YAW], frame[RESOLUTION]
    padded_height, padded_width = table.shape
    pad = (padded_width - width) // 2
    inverse = 1.0 / res
    ax, ay = (gc * c + gs * s) * inverse, (gc * s - gs * c) * inverse
    bx, by = (gs * c - gc * s) * inverse, (gc * c + gs * s) * inverse
    px, py = x - gx, y - gy
    u0, v0 = (gc * px + gs * py) * inverse, (gc * py - gs * px) * inverse
    n = centres.size
    top = max(abs(centres[0]), abs(centres[n - 1]))
    reach_u = (abs(ax) + abs(bx)) * top + 2.0
    reach_v = (abs(ay) + abs(by)) * top + 2.0
    size = (abs(x) + abs(y) + abs(gx) + abs(gy) + 4.0 * top) * inverse
    if not (
        size <= _SIZE_LIMIT
        and table.size < _TABLE_LIMIT
        and u0 - reach_u > -pad
        and u0 + reach_u < padded_width - pad
        and v0 - reach_v > -pad
        and v0 + reach_v < padded_height - pad
    ):
        return False  # also NaN
    origin, stride = float(pad * padded_width + pad), float(padded_width)
    for j in range(n):
        columns[0, j] = centres[j] * ax
        columns[1, j] = centres[j] * ay
    bad = False
    for i in range(n):
        row_u = u0 + centres[i] * bx
        row_v = v0 + centres[i] * by
        for j in range(n):
            u = row_u + columns[0, j]
            v = row_v + columns[1, j]
            col, row = np.floor(u), np.floor(v)
            bad |= (abs(u - col - 0.5) >= _DECIDED) | (abs(v - row - 0.5) >= _DECIDED)
            cells[i * n + j] = np.int32(row * stride + col + origin)
    flat = table.reshape(-1)
    for k in range(n * n):
        out[at + k] = flat[np.uint32(cells[k])]
    return not bad


def bordered_table(pooled: np.ndarray, offsets: np.ndarray, resolution: float) -> np.ndarray:
    """Uint8: ``pooled`` (1 blocked, 0 free) inside a border of blocked cells wider than
    the crop's reach from any point of the map (its corner's distance, max |offset|
    times sqrt 2 m, and 3 cells), :func:`lattice_crop`'s look-up table (a quarter of
    float32's cache lines: the look-up is the crop's larger part)."""
    pad = math.ceil(math.sqrt(2.0) * np.abs(offsets).max() / resolution) + 3
    return np.pad(pooled.astype(np.uint8), pad, constant_values=1)


@njit(cache=True, inline="always")
def crop_kernel(
    lattice: tuple, samples: tuple, scratch: tuple, pose: Heading, out: np.ndarray, at: int
) -> bool:
    """:func:`_crop`'s cells around the ``pose`` into out[at:]: from the crop's lattice
    (:func:`lattice_crop`) when it decides every cell, else by :func:`_crop`'s division;
    returns whether the division was needed. The one crop of both the single game
    (:class:`LocalCrop`, :mod:`pegame.observe.features`) and the batched one."""
    if lattice_crop(lattice, pose, out, at, scratch):
        return False
    _, _, frame, _ = lattice
    _crop(samples, frame, pose, out[at:])
    return True


@njit(cache=True)
def _crop_fast(
    lattice: tuple, samples: tuple, scratch: tuple, pose: Heading, out: np.ndarray
) -> None:
    """:func:`crop_kernel` into ``out``, for :class:`LocalCrop` (the structures as plain
    tuples)."""
    crop_kernel(lattice, samples, scratch, pose, out, 0)


class LocalCrop:
    """The crop of ``cells`` x ``cells`` at ``resolution`` m on ``grid``, ready to sample
    (the pooled map and the offsets are prepared once)."""

    def __init__(self, grid: OccupancyGrid, cells: int, resolution: float) -> None:
        self.grid = grid
        self.size = cells * cells
        self._samples = CropSamples(
            pooled_blocked(grid, resolution), *crop_offsets(cells, resolution)
        )
        pooled, off_x = self._samples.pooled, self._samples.off_x
        self._lattice = CropLattice(
            bordered_table(pooled, off_x, grid.resolution),
            np.ascontiguousarray(off_x[:cells]),
            np.array(grid.kernel_frame, dtype=np.float64),
            pooled.shape[1],
        )
        self._scratch = CropScratch(np.empty(self.size, dtype=np.int32), np.empty((2, cells)))
        #: (lattice, samples, scratch) as plain tuples for the kernels (crop_kernel): numba
        #: dispatches a NamedTuple argument in about 0.6 us, a plain tuple in 0.05-0.13
        #: us, and a crop takes 2 us.
        self.structures = (tuple(self._lattice), tuple(self._samples), tuple(self._scratch))

    def __call__(
        self, x: float, y: float, theta: float, out: np.ndarray | None = None
    ) -> np.ndarray:
        """Flat float32 (cells * cells,) crop around the map-frame pose (x m, y m, theta
        rad), row-major as in the module docstring; written into ``out`` when given (a
        float32 array of that size, e.g. a slice of an observation vector)."""
        if out is None:
            out = np.empty(self.size, dtype=np.float32)
        pose = (float(x), float(y), math.cos(theta), math.sin(theta))
        _crop_fast(*self.structures, pose, out)
        return out
