"""The visibility region on demand: the whole mask once asked, or only the part asked about.

:class:`VisibilityRegion` is the region V^p_k of Algorithm 1 (:mod:`pegame.visibility.region`)
for the camera at one pose. Most consumers need only part of it: the particle filter asks
whether its particles' cells are in the region, and they usually lie in a small block of
the grid. For a block of cells the kernels here march only the rays that can reach it
(:func:`rays_reaching`), only as far as the block, and skip cells that cannot meet the
field of view's wedge (:func:`_near_wedge`). On the block this gives exactly the cells of
the whole mask: the same rays are sampled at the same points (:mod:`pegame.visibility.rays`)
and stop at the same blocked sample, and no other sample can land in the block.

Units and frames: metres and radians in the map frame of :mod:`pegame.grid`; cells are
flat row-major indices row * width + col, or (row, col). The kernels take the grid, the
camera's pose and its rays as :class:`Sight`, :class:`Eye` and :class:`Rays`, and a block
of cells as (row0, row1, col0, col1), unpacked once at entry.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from pegame.grid import OccupancyGrid
from pegame.grid.occupancy import OX, OY, RESOLUTION
from pegame.numerics import wrap_angle_kernel
from pegame.types import Camera, Pose
from pegame.visibility.rays import directions, ray_tables
from pegame.visibility.region import MaskRegion, lookup, march, whole_region

#: a block of cells: (first row, last row, first column, last column), inclusive
Block = tuple[int, int, int, int]


class Sight(NamedTuple):
    """The grid as the ray kernels see it."""

    blocked: np.ndarray  # bool (H, W), the cells that stop a ray
    frame: tuple  # OccupancyGrid.kernel_frame
    yaw: float  # rad, the grid's rotation in the map frame


class Eye(NamedTuple):
    """The camera's pose (map frame)."""

    x: float  # m
    y: float  # m
    theta: float  # rad, the heading


class Rays(NamedTuple):
    """The camera's rays and their samples (:func:`pegame.visibility.rays.ray_tables`)."""

    angles: np.ndarray  # rad from the heading, increasing
    distances: np.ndarray  # m along a ray of each sample
    first: int  # the first sample that counts (at the near plane)
    angle_step: float  # rad between rays
    distance_step: float  # m between samples
    fov: float  # rad, the field of view
    far: float  # m, the range


class VisibilityRegion:
    """The visibility region V^p_k of the camera at one pose, computed on demand (a
    :class:`pegame.types.Region`).

    :attr:`mask` is the whole region of :func:`pegame.visibility.visibility_region`,
    computed at the first read, and :attr:`bounds` the block of cells that holds it.
    :meth:`holds` answers for a few cells without computing the whole region, by
    :meth:`mask_over` their block (module docstring); once the whole region is computed,
    both read it.
    """

    def __init__(self, grid: OccupancyGrid, pose: Pose, camera: Camera) -> None:
        self.grid, self.pose, self.camera = grid, pose, camera
        self._whole: MaskRegion | None = None

    @property
    def shape(self) -> tuple[int, ...]:
        """(H, W) of the mask: the grid's."""
        return self.grid.blocked.shape

    @property
    def mask(self) -> np.ndarray:
        """The whole region: bool (H, W) over the grid, read-only."""
        return self._computed().mask

    @property
    def bounds(self) -> tuple[int, int, int, int]:
        """(r0, r1, c0, c1): rows [r0, r1) and columns [c0, c1) hold every cell of
        :attr:`mask` (r1 <= r0 when it is empty); found while the mask is computed."""
        return self._computed().bounds

    def _computed(self) -> MaskRegion:
        """The whole region with its bounds, computed once."""
        if self._whole is None:
            self._whole = MaskRegion(*whole_region(self.grid, self.pose, self.camera))
        return self._whole

    def mask_over(self, rows: tuple[int, int], cols: tuple[int, int]) -> np.ndarray:
        """A bool (H, W) mask equal to :attr:`mask` on the cells with rows[0] <= row <=
        rows[1] and cols[0] <= col <= cols[1], and False or equal to it elsewhere."""
        if self._whole is not None:
            return self._whole.mask
        return _mask_over(*self._kernel_arguments(), (rows[0], rows[1], cols[0], cols[1]))

    def holds(self, cells: np.ndarray) -> np.ndarray:
        """Bool (N,): whether the region holds each of the flat cell indices ``cells`` (N,)
        (row * width + col; negative: no cell, False).

        Cells that cannot meet the field of view (their centres farther than half a cell
        diagonal from its wedge) are not in the region; the rays are cast only towards the
        block of the others (:meth:`mask_over`), all in one kernel.
        """
        if self._whole is not None:
            return self._whole.holds(cells)
        return _holds(np.asarray(cells, dtype=np.int64), *self._kernel_arguments())

    def _kernel_arguments(self) -> tuple[tuple, tuple, tuple]:
        """The grid, pose and camera as :func:`_mask_over` and :func:`_holds` take them:
        :class:`Sight`, :class:`Eye` and :class:`Rays` as plain tuples (numba dispatches
        a NamedTuple argument in about 0.6 us, a plain tuple in 0.05-0.13 us; the particle
        filter asks once per tick)."""
        pose = self.pose
        sight, rays = sight_and_rays(self.grid, self.camera)
        return sight, tuple(Eye(float(pose.x), float(pose.y), float(pose.theta))), rays


def sight_and_rays(grid: OccupancyGrid, camera: Camera) -> tuple[tuple, tuple]:
    """``grid`` and ``camera``'s rays as the ray kernels take them: :class:`Sight` and
    :class:`Rays` as plain tuples."""
    angles, distances, first = ray_tables(camera)
    sight = Sight(grid.blocked, grid.kernel_frame, float(grid.origin[2]))
    rays = Rays(
        angles, distances, first, camera.angle_step, camera.distance_step, camera.fov, camera.far
    )
    return tuple(sight), tuple(rays)


@njit(cache=True)
def _mask_over(sight: tuple, eye: tuple, rays: tuple, block: Block) -> np.ndarray:
    """Kernel of :meth:`VisibilityRegion.mask_over`: march the rays reaching the block
    (row0, row1, col0, col1) of cells."""
    blocked, frame, yaw = sight
    px, py, theta = eye
    angles, distances, first, _, _, _, _ = rays
    i0, i1, samples = rays_reaching(rays, eye, frame, yaw, block)
    mask = np.zeros(blocked.shape, dtype=np.bool_)
    if i1 > i0 and samples > first:
        cos_a, sin_a = directions(theta, angles, i0, i1)
        march(blocked, cos_a, sin_a, distances[:samples], first, px, py, frame, mask)
    return mask


@njit(cache=True)
def _holds(cells: np.ndarray, sight: tuple, eye: tuple, rays: tuple) -> np.ndarray:
    """Kernel of :meth:`VisibilityRegion.holds` for a region not yet computed whole."""
    blocked, frame, yaw = sight
    _, _, _, _, _, fov, far = rays
    near, block = _near_wedge(cells, blocked.shape[1], eye, frame, yaw, fov, far)
    if block[1] < block[0]:
        return near  # all False
    mask = _mask_over(sight, eye, rays, block)
    return lookup(mask.ravel(), cells, near)


@njit(cache=True, inline="always")
def _in_cells(
    x: float, y: float, ox: float, oy: float, yaw: float, resolution: float
) -> tuple[float, float]:
    """(u, v): the map point (x, y) (m) in continuous cell coordinates, u along columns and
    v along rows, from the grid origin (ox, oy, yaw) (m, m, rad); not floored."""
    du, dv = (x - ox) / resolution, (y - oy) / resolution
    return math.cos(yaw) * du + math.sin(yaw) * dv, -math.sin(yaw) * du + math.cos(yaw) * dv


@njit(cache=True)
def _near_wedge(
    cells: np.ndarray, width: int, eye: tuple, frame: tuple, yaw: float, fov: float, far: float
) -> tuple[np.ndarray, Block]:
    """(near (N,) bool, (row min, row max, col min, col max) of the near cells): which flat
    cell indices (negative: none) of a grid ``width`` cells wide (``frame``, rotated by
    ``yaw``) have their centre within half a cell diagonal (plus a rounding margin) of the
    field of view's wedge, apex and heading the ``eye``'s, opening fov, radius far (m). A
    cell farther away cannot hold a ray sample of Algorithm 1. For fov > pi every cell
    within range is near. The bounds are (0, -1, 0, -1) when no cell is near."""
    px, py, theta = eye
    ox, oy, resolution = frame[OX], frame[OY], frame[RESOLUTION]
    u, v = _in_cells(px, py, ox, oy, yaw, resolution)
    heading = theta - yaw  # in the grid frame
    left_u, left_v = math.cos(heading + 0.5 * fov), math.sin(heading + 0.5 * fov)
    right_u, right_v = math.cos(heading - 0.5 * fov), math.sin(heading - 0.5 * fov)
    slack = 0.5 * math.sqrt(2.0) + 1e-6  # cells
    reach = far / resolution + slack
    wedge = fov <= math.pi
    near = np.zeros(cells.size, dtype=np.bool_)
    r0, r1, c0, c1 = np.iinfo(np.int64).max, -1, np.iinfo(np.int64).max, -1
    per_row = 1.0 / width
    for i in range(cells.size):
        if cells[i] < 0:
            continue
        # cells[i] // width without an integer division (several times slower): the
        # quotient's fraction, (col + 0.5) / width, is far from 0 and 1 next to float
        # round-off for any grid that fits in memory.
        row = np.int64((cells[i] + 0.5) * per_row)
        col = cells[i] - row * width
        x, y = col + 0.5 - u, row + 0.5 - v
        if x * x + y * y > reach * reach:
            continue
        # Signed distances (cells) inside the right and left edges of the wedge.
        if wedge and (right_u * y - right_v * x < -slack or x * left_v - y * left_u < -slack):
            continue
        near[i] = True
        r0, r1, c0, c1 = min(r0, row), max(r1, row), min(c0, col), max(c1, col)
    if r1 < 0:
        return near, (0, -1, 0, -1)
    return near, (r0, r1, c0, c1)


#: cells; how far :func:`rays_reaching` grows a block to absorb rounding at cell edges
_REACH_MARGIN = 0.5


@njit(cache=True)
def rays_reaching(
    rays: tuple, eye: tuple, frame: tuple, yaw: float, block: Block
) -> tuple[int, int, int]:
    """(first ray, stop ray, samples): the ``rays`` angles[first:stop] (rad from the
    ``eye``'s heading theta) and the number of samples along each (from the first) that
    can land in the block of cells row0..row1 x col0..col1 (inclusive) of a grid
    (``frame``, rotated by ``yaw``), seen from the eye. The block is grown by
    _REACH_MARGIN cells, and one ray and one sample more are taken on every side, so
    rounding at cell edges cannot hide a sample.
    """
    angles, distances, _, angle_step, distance_step, _, _ = rays
    n_distances = distances.size
    px, py, theta = eye
    ox, oy, resolution = frame[OX], frame[OY], frame[RESOLUTION]
    row0, row1, col0, col1 = block
    u, v = _in_cells(px, py, ox, oy, yaw, resolution)
    us = (col0 - _REACH_MARGIN - u, col1 + 1 + _REACH_MARGIN - u)
    vs = (row0 - _REACH_MARGIN - v, row1 + 1 + _REACH_MARGIN - v)
    reach = 0.0
    for a in us:
        for b in vs:
            reach = max(reach, math.hypot(a, b))
    samples = min(n_distances, math.ceil(reach * resolution / distance_step) + 2)
    if us[0] <= 0.0 <= us[1] and vs[0] <= 0.0 <= vs[1]:
        return 0, angles.size, samples
    # The camera is outside the convex block, so the bearings of its corners span less
    # than pi about the bearing of its centre.
    centre = math.atan2(vs[0] + vs[1], us[0] + us[1])
    low, high = math.inf, -math.inf
    for a in us:
        for b in vs:
            offset = wrap_angle_kernel(math.atan2(b, a) - centre)
            low, high = min(low, offset), max(high, offset)
    # The turns below also try the heading 2 pi lower and higher, so which end of the
    # circle the wrap maps +-pi to does not matter; the offsets lie strictly inside it.
    heading = wrap_angle_kernel(centre + yaw - theta)
    first, last = angles.size, -1
    for turn in (-1.0, 0.0, 1.0):
        lo = heading + low + turn * 2.0 * math.pi
        hi = heading + high + turn * 2.0 * math.pi
        if hi < angles[0] - angle_step or lo > angles[-1] + angle_step:
            continue  # this turn of the bearings misses the field of view
        i0 = np.searchsorted(angles, lo, side="left") - 1
        i1 = np.searchsorted(angles, hi, side="right")
        first, last = min(first, max(i0, 0)), max(last, min(i1, angles.size - 1))
    if last < first:
        return 0, 0, samples
    return first, last + 1, samples
