"""Algorithm 1 of the paper: the whole visibility region of the pursuer's camera.

:func:`visibility_region` implements the paper's Algorithm 1 ("Algorithm to compute
visibility region"): rays leave the camera at angles theta + a for a from -fov/2 to +fov/2
in steps of ``angle_step``, and each ray is sampled at distances 0, distance_step, ...,
far; the cell of every sample at distance >= near joins the region V^p_k. (The printed
outer loop bound repeats theta_min; it is read as theta_max = +fov/2, and both the last
ray at +fov/2 and the last sample at far are included; :mod:`pegame.visibility.rays`.)

Occlusion extension. Algorithm 1 as printed ignores obstacles, so a camera would see
through walls. Here a ray stops at its first sample whose cell is blocked (occupied or
unknown, ``OccupancyGrid.blocked``) or off the grid. That blocked cell is not marked
visible: the mask holds the free space the camera sees, and an obstacle is seen as an
obstacle, not as a place where the evader could be seen. Samples closer than ``near``
are not marked but still occlude. A camera in a blocked cell sees nothing.

Units and frames: positions in metres and angles in radians, all in the map frame of
:mod:`pegame.grid` (x right, y up); poses are :class:`pegame.types.Pose`. Map-frame points
go to cells exactly as :meth:`OccupancyGrid.world_to_cell` does, origin yaw included.

Two implementations give identical masks: :func:`visibility_region_reference`, plain
vectorised numpy over all rays and samples, and the numba ray march :func:`march` behind
:func:`visibility_region`, which stops each ray at its first blocked sample.
:class:`MaskRegion` is a region known by its mask (:class:`pegame.types.Region`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from pegame.grid import OccupancyGrid
from pegame.grid.occupancy import COS_YAW, OX, OY, RESOLUTION, ROTATED, SIN_YAW
from pegame.types import Camera, Pose
from pegame.visibility.rays import ray_directions, ray_tables


def visibility_region_reference(grid: OccupancyGrid, pose: Pose, camera: Camera) -> np.ndarray:
    """Bool (H, W) mask of the cells the camera at ``pose`` (map frame) sees.

    Plain numpy reference of :func:`visibility_region`: every sample of every ray is
    computed, and cumulative OR along each ray removes the samples at and beyond the
    first blocked or off-grid one.
    """
    _, distances, first = ray_tables(camera)
    cos_a, sin_a = ray_directions(pose, camera)
    x = pose.x + distances[None, :] * cos_a[:, None]
    y = pose.y + distances[None, :] * sin_a[:, None]
    rows, cols = grid.world_to_cell(x, y)
    inside = grid.contains(rows, cols)
    stop = ~inside
    stop[inside] = grid.blocked[rows[inside], cols[inside]]
    seen = ~np.logical_or.accumulate(stop, axis=1)
    seen[:, :first] = False
    mask = np.zeros(grid.blocked.shape, dtype=bool)
    mask[rows[seen], cols[seen]] = True
    return mask


#: cells; a sample whose cell coordinate is closer than this to a cell edge is recomputed
#: with a division (the product with 1 / resolution may round to the other side)
_EDGE = 1e-9


@njit(cache=True, inline="always")
def _ray_cells(
    px: float,
    py: float,
    ray: tuple[float, float],
    distances: np.ndarray,
    frame: tuple,
    shape: tuple[int, int],
    divide: bool,
    cells: np.ndarray,
) -> bool:
    """Flat row-major cell index (row * width + col) of every sample of one ray, -1 off the grid.

    The ray starts at (px, py) (map frame, m) along ``ray`` = (cos, sin); sample j is at
    range ``distances[j]`` m; ``shape`` is the grid's (height, width). With ``divide`` the
    cell coordinates are the quotients by the resolution, as in
    :func:`pegame.grid.point_cell`. Without it they are products with 1 / resolution, a
    few times cheaper; a product floors to the
    same integer as the quotient unless both lie within rounding error of an integer, so
    the function returns False when any sample came within _EDGE cells of a cell edge (the
    caller then redoes the ray with ``divide``) and True otherwise.
    """
    ox, oy, res, rotate = frame[OX], frame[OY], frame[RESOLUTION], frame[ROTATED]
    c, s = frame[COS_YAW], frame[SIN_YAW]
    cos_i, sin_i = ray
    height, width = shape
    inv = 1.0 / res
    clear = True
    for j in range(distances.size):
        dx = px + distances[j] * cos_i - ox
        dy = py + distances[j] * sin_i - oy
        if rotate:
            dx, dy = c * dx + s * dy, -s * dx + c * dy
        if divide:
            u = np.floor(dx / res)
            v = np.floor(dy / res)
        else:
            qu = dx * inv
            qv = dy * inv
            u = np.floor(qu)
            v = np.floor(qv)
            # Bitwise & (no short circuit) keeps the loop free of branches, so it vectorises.
            clear &= (qu - u >= _EDGE) & (u + 1.0 - qu >= _EDGE)
            clear &= (qv - v >= _EDGE) & (v + 1.0 - qv >= _EDGE)
        col = np.int64(u)
        row = np.int64(v)
        inside = (row >= 0) & (row < height) & (col >= 0) & (col < width)
        cells[j] = row * width + col if inside else -1
    return clear


@njit(cache=True)
def march(
    blocked: np.ndarray,
    cos_a: np.ndarray,
    sin_a: np.ndarray,
    distances: np.ndarray,
    first: int,
    px: float,
    py: float,
    frame: tuple,
    mask: np.ndarray,
) -> tuple[int, int, int, int]:
    """Mark in ``mask`` the cells seen along each ray, stopping at the first blocked one,
    and return the bounds (r0, r1, c0, c1) of the marked cells: rows [r0, r1) and columns
    [c0, c1) (r1 <= r0 when none).

    Ray directions come from :func:`pegame.visibility.rays.directions` and cells follow
    ``OccupancyGrid.world_to_cell`` exactly (:func:`_ray_cells`), so the result matches
    :func:`visibility_region_reference` bit for bit. Each ray's cells are computed in one
    branch-free pass before the walk along it, which is faster than stopping the
    computation at the first blocked sample. A ray's cells move monotonically in row and
    column, so its first and last marked cells bound all of its marked cells.
    """
    shape, flat = blocked.shape, (blocked.ravel(), mask.ravel())
    bounds = (shape[0], 0, shape[1], 0)
    cells = np.empty(distances.size, dtype=np.int64)
    for i in range(cos_a.size):
        ray = (cos_a[i], sin_a[i])
        bounds = march_ray(flat, shape, ray, distances, first, px, py, frame, cells, bounds)[1]
    return bounds


@njit(cache=True, inline="always")
def march_ray(
    flat: tuple[np.ndarray, np.ndarray],
    shape: tuple[int, int],
    ray: tuple[float, float],
    distances: np.ndarray,
    first: int,
    px: float,
    py: float,
    frame: tuple,
    cells: np.ndarray,
    bounds: tuple[int, int, int, int],
) -> tuple[int, tuple[int, int, int, int]]:
    """One ray of :func:`march`: mark in the mask the cells of its samples ``distances``
    (ranges in m, from index ``first`` on) before the first blocked or off-grid one;
    return that sample's index (distances.size when none) and ``bounds`` (r0, r1, c0,
    c1) grown to hold the marks. flat: the blocked cells and the mask, flattened once by
    the caller (a ravel per ray costs about a fifth of the march); shape: the grid's (H,
    W); ``cells``: scratch of at least distances.size entries. A sample's cell depends
    on its range alone, so a ray may be marched in pieces of consecutive ranges, and it
    marks the same cells whichever other rays are marched."""
    blocked_flat, mask_flat = flat
    width = shape[1]
    if not _ray_cells(px, py, ray, distances, frame, shape, False, cells):
        _ray_cells(px, py, ray, distances, frame, shape, True, cells)
    stop = distances.size
    for j in range(distances.size):
        cell = cells[j]
        if cell < 0 or blocked_flat[cell]:
            stop = j
            break
        if j >= first:
            mask_flat[cell] = True
    r0, r1, c0, c1 = bounds
    if stop > first:
        for end in (cells[first], cells[stop - 1]):
            row, col = end // width, end % width
            r0, r1, c0, c1 = min(r0, row), max(r1, row + 1), min(c0, col), max(c1, col + 1)
    return stop, (r0, r1, c0, c1)


def visibility_region(grid: OccupancyGrid, pose: Pose, camera: Camera) -> np.ndarray:
    """Bool (H, W) mask of the cells the camera at ``pose`` (map frame) sees.

    Algorithm 1 of the paper with occlusion (see the module docstring): rays every
    ``camera.angle_step`` rad across the field of view, samples every
    ``camera.distance_step`` m up to ``camera.far``; cells of samples at range >=
    ``camera.near`` m before the first blocked or off-grid sample are True. Blocked cells
    are never True; a camera in a blocked cell gives an all-False mask.
    """
    return whole_region(grid, pose, camera)[0]


def whole_region(
    grid: OccupancyGrid, pose: Pose, camera: Camera
) -> tuple[np.ndarray, tuple[int, int, int, int]]:
    """:func:`visibility_region`'s mask and the bounds (r0, r1, c0, c1) of its True
    cells, rows [r0, r1) and columns [c0, c1) (r1 <= r0 when there is none)."""
    _, distances, first = ray_tables(camera)
    cos_a, sin_a = ray_directions(pose, camera)
    mask = np.zeros(grid.blocked.shape, dtype=bool)
    px, py = float(pose.x), float(pose.y)
    bounds = march(grid.blocked, cos_a, sin_a, distances, first, px, py, grid.kernel_frame, mask)
    return mask, bounds


class MaskRegion:
    """A region known by its bool (H, W) mask over the grid, for sensors that see otherwise
    and for tests (a :class:`pegame.types.Region`, as :class:`VisibilityRegion` is).

    ``bounds``, when the caller already knows them, are (r0, r1, c0, c1) as in
    :attr:`bounds`; otherwise they are found at the first read. The mask is shared, not
    copied, and flagged read-only.
    """

    def __init__(self, mask: np.ndarray, bounds: tuple[int, int, int, int] | None = None) -> None:
        self._mask = np.asarray(mask, dtype=bool).view()
        self._mask.setflags(write=False)
        self._bounds = bounds

    @property
    def shape(self) -> tuple[int, ...]:
        """(H, W) of the mask."""
        return self._mask.shape

    @property
    def mask(self) -> np.ndarray:
        """The region: bool (H, W) over the grid, read-only."""
        return self._mask

    @property
    def bounds(self) -> tuple[int, int, int, int]:
        """(r0, r1, c0, c1): rows [r0, r1) and columns [c0, c1) hold every cell of
        :attr:`mask` (r1 <= r0 when it is empty)."""
        if self._bounds is None:
            rows = np.flatnonzero(self._mask.any(axis=1))
            cols = np.flatnonzero(self._mask.any(axis=0))
            empty = rows.size == 0
            self._bounds = (0, 0, 0, 0) if empty else (rows[0], rows[-1] + 1, cols[0], cols[-1] + 1)
        return self._bounds

    def holds(self, cells: np.ndarray) -> np.ndarray:
        """Bool (N,): whether the region holds each of the flat cell indices ``cells`` (N,)
        (row * width + col; negative: no cell, False)."""
        cells = np.asarray(cells, dtype=np.int64)
        return lookup(self._mask.ravel(), cells, np.ones(cells.size, dtype=np.bool_))


@njit(cache=True)
def lookup(flat_mask: np.ndarray, cells: np.ndarray, candidates: np.ndarray) -> np.ndarray:
    """flat_mask[cells[i]] where candidates[i] and cells[i] >= 0, else False (N,)."""
    out = np.zeros(cells.size, dtype=np.bool_)
    for i in range(cells.size):
        if candidates[i] and cells[i] >= 0:
            out[i] = flat_mask[cells[i]]
    return out
