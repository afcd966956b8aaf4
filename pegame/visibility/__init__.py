"""The pursuer camera's visibility region and line-of-sight tests on an occupancy grid.

:func:`visibility_region` implements the paper's Algorithm 1 ("Algorithm to compute
visibility region"): rays leave the camera at angles theta + a for a from -fov/2 to +fov/2
in steps of ``angle_step``, and each ray is sampled at distances 0, distance_step, ...,
far; the cell of every sample at distance >= near joins the region V^p_k. (The printed
outer loop bound repeats theta_min; it is read as theta_max = +fov/2, and both the last
ray at +fov/2 and the last sample at far are included.)

Occlusion extension. Algorithm 1 as printed ignores obstacles, so a camera would see
through walls. Here a ray stops at its first sample whose cell is blocked (occupied or
unknown, ``OccupancyGrid.blocked``) or off the grid. That blocked cell is not marked
visible: the mask holds the free space the camera sees, and an obstacle is seen as an
obstacle, not as a place where the evader could be seen. Samples closer than ``near``
are not marked but still occlude. A camera in a blocked cell sees nothing.

Units and frames: positions in metres and angles in radians, all in the map frame of
:mod:`pegame.grid` (x right, y up); poses are :class:`pegame.api.Pose`. Map-frame points
go to cells exactly as :meth:`OccupancyGrid.world_to_cell` does, origin yaw included.

Two implementations give identical masks: :func:`visibility_region_reference`, plain
vectorised numpy over all rays and samples, and the numba ray march behind
:func:`visibility_region`, which stops each ray at its first blocked sample. Likewise
:func:`line_of_sight` is a numba kernel with the numpy reference
``_line_of_sight_reference``. The small numba helpers :func:`point_cell`
and :func:`cell_blocked` (on a grid's :class:`pegame.grid.GridFrame`) serve other modules'
kernels too.
:class:`VisibilityRegion` computes the same mask on demand, or only the part of it that
a caller asks about; :func:`body_in_view` extends :func:`in_view` from a point to a body.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from numba import njit

from pegame.types import Camera, Pose, wrap_angle
from pegame.grid import OccupancyGrid
from pegame.trig import MAX_ANGLE, sin_cos


def _inclusive_range(stop: float, step: float) -> np.ndarray:
    """0, step, 2 step, ... below ``stop``, then ``stop`` itself exactly (float64)."""
    count = math.ceil(stop / step - 1e-9)
    return np.append(np.arange(max(count, 0)) * step, stop)


@lru_cache(maxsize=64)
def _ray_tables(camera: Camera) -> tuple[np.ndarray, np.ndarray, int]:
    """Per-camera tables of Algorithm 1, computed once per camera.

    Returns (angles, distances, first): ray angles relative to the heading (rad, from
    -fov/2 to +fov/2 inclusive), sample distances along a ray (m, from 0 to far
    inclusive), and the index of the first distance >= near. Arrays are read-only. The
    camera validates its own fields (positive steps, 0 <= near < far, 0 < fov <= 2 pi).
    """
    angles = _inclusive_range(camera.fov, camera.angle_step) - 0.5 * camera.fov
    distances = _inclusive_range(camera.far, camera.distance_step)
    first = int(np.searchsorted(distances, camera.near, side="left"))
    angles.setflags(write=False)
    distances.setflags(write=False)
    return angles, distances, first


def _ray_directions(pose: Pose, camera: Camera) -> tuple[np.ndarray, np.ndarray]:
    """Unit direction (cos, sin) of every ray of ``camera`` at ``pose``, map frame."""
    angles = _ray_tables(camera)[0]
    return _directions(float(pose.theta), angles, 0, angles.size)


@njit(cache=True)
def _directions(theta, angles, first, stop):
    """Unit directions (cos, sin) (each (stop - first,)) of the rays at angles[first:stop]
    (rad) from the heading theta (rad), by the vectorised :func:`pegame.trig.sin_cos`.
    Every path takes its directions from here, so they all sample the same points."""
    count = stop - first
    cos_a, sin_a = np.empty(count), np.empty(count)
    for i in range(count):
        sin_a[i], cos_a[i] = sin_cos(theta + angles[first + i])
    if not abs(theta) <= MAX_ANGLE - math.pi:  # beyond sin_cos's range: libm's
        for i in range(count):
            towards = theta + angles[first + i]
            cos_a[i], sin_a[i] = math.cos(towards), math.sin(towards)
    return cos_a, sin_a


def visibility_region_reference(grid: OccupancyGrid, pose: Pose, camera: Camera) -> np.ndarray:
    """Bool (H, W) mask of the cells the camera at ``pose`` (map frame) sees.

    Plain numpy reference of :func:`visibility_region`: every sample of every ray is
    computed, and cumulative OR along each ray removes the samples at and beyond the
    first blocked or off-grid one.
    """
    _, distances, first = _ray_tables(camera)
    cos_a, sin_a = _ray_directions(pose, camera)
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


# ------------------------------------------------------------------ numba helpers
# The kernels take the map-to-cell transform as a GridFrame (OccupancyGrid.frame) and
# reproduce OccupancyGrid.world_to_cell operation for operation, so they pick exactly the
# cells that the numpy code picks.


@njit(cache=True, inline="always")
def point_cell(x, y, frame):
    """(row, col) of the cell containing map point (x, y) (m); may lie off the grid."""
    dx = x - frame.ox
    dy = y - frame.oy
    if frame.rotated:
        c, s = frame.cos_yaw, frame.sin_yaw
        dx, dy = c * dx + s * dy, -s * dx + c * dy
    return math.floor(dy / frame.resolution), math.floor(dx / frame.resolution)


@njit(cache=True, inline="always")
def cell_blocked(blocked, row, col):
    """True when (row, col) is off the grid or True in the bool (H, W) mask ``blocked``."""
    height, width = blocked.shape
    return row < 0 or row >= height or col < 0 or col >= width or blocked[row, col]


#: cells; a sample whose cell coordinate is closer than this to a cell edge is recomputed
#: with a division (the product with 1 / resolution may round to the other side)
_EDGE = 1e-9


@njit(cache=True, inline="always")
def _ray_cells(px, py, ray, distances, frame, shape, divide, cells):
    """Flat row-major cell index (row * width + col) of every sample of one ray, -1 off the grid.

    The ray starts at (px, py) (map frame, m) along ``ray`` = (cos, sin); sample j is at
    range ``distances[j]`` m; ``shape`` is the grid's (height, width). With ``divide`` the
    cell coordinates are the quotients by the resolution, as in :func:`point_cell`. Without
    it they are products with 1 / resolution, a few times cheaper; a product floors to the
    same integer as the quotient unless both lie within rounding error of an integer, so
    the function returns False when any sample came within _EDGE cells of a cell edge (the
    caller then redoes the ray with ``divide``) and True otherwise.
    """
    ox, oy, res, rotate = frame.ox, frame.oy, frame.resolution, frame.rotated
    c, s = frame.cos_yaw, frame.sin_yaw
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
def _march(blocked, cos_a, sin_a, distances, first, px, py, frame, mask):
    """Mark in ``mask`` the cells seen along each ray, stopping at the first blocked one,
    and return the bounds (r0, r1, c0, c1) of the marked cells: rows [r0, r1) and columns
    [c0, c1) (r1 <= r0 when none).

    Ray directions come from :func:`_directions` and cells follow
    ``OccupancyGrid.world_to_cell`` exactly (:func:`_ray_cells`), so the result matches
    :func:`visibility_region_reference` bit for bit. Each ray's cells are computed in one
    branch-free pass before the walk along it, which is faster than stopping the
    computation at the first blocked sample. A ray's cells move monotonically in row and
    column, so its first and last marked cells bound all of its marked cells.
    """
    blocked_flat, mask_flat = blocked.ravel(), mask.ravel()
    width = blocked.shape[1]
    r0, r1, c0, c1 = blocked.shape[0], 0, width, 0
    cells = np.empty(distances.size, dtype=np.int64)
    for i in range(cos_a.size):
        ray = (cos_a[i], sin_a[i])
        if not _ray_cells(px, py, ray, distances, frame, blocked.shape, False, cells):
            _ray_cells(px, py, ray, distances, frame, blocked.shape, True, cells)
        stop = distances.size
        for j in range(distances.size):
            cell = cells[j]
            if cell < 0 or blocked_flat[cell]:
                stop = j
                break
            if j >= first:
                mask_flat[cell] = True
        if stop > first:
            for end in (cells[first], cells[stop - 1]):
                row, col = end // width, end % width
                r0, r1, c0, c1 = min(r0, row), max(r1, row + 1), min(c0, col), max(c1, col + 1)
    return r0, r1, c0, c1


@njit(cache=True)
def _segment_clear(blocked, ax, ay, bx, by, step, frame):
    """Kernel of :func:`line_of_sight`: the same samples as the numpy reference, where
    ``np.linspace(0, 1, count + 1)`` gives t = k * (1 / count) and exactly 1 at the end."""
    count = max(1, math.ceil(math.hypot(bx - ax, by - ay) / step))
    dx, dy = bx - ax, by - ay
    dt = 1.0 / count
    for k in range(count + 1):
        t = 1.0 if k == count else k * dt
        row, col = point_cell(ax + t * dx, ay + t * dy, frame)
        if cell_blocked(blocked, row, col):
            return False
    return True


# ----------------------------------------------------------------- visibility region


def visibility_region(grid: OccupancyGrid, pose: Pose, camera: Camera) -> np.ndarray:
    """Bool (H, W) mask of the cells the camera at ``pose`` (map frame) sees.

    Algorithm 1 of the paper with occlusion (see the module docstring): rays every
    ``camera.angle_step`` rad across the field of view, samples every
    ``camera.distance_step`` m up to ``camera.far``; cells of samples at range >=
    ``camera.near`` m before the first blocked or off-grid sample are True. Blocked cells
    are never True; a camera in a blocked cell gives an all-False mask.
    """
    return _whole_region(grid, pose, camera)[0]


def _whole_region(grid: OccupancyGrid, pose: Pose, camera: Camera):
    """:func:`visibility_region`'s mask and the bounds (r0, r1, c0, c1) of its True
    cells, rows [r0, r1) and columns [c0, c1) (r1 <= r0 when there is none)."""
    _, distances, first = _ray_tables(camera)
    cos_a, sin_a = _ray_directions(pose, camera)
    mask = np.zeros(grid.blocked.shape, dtype=bool)
    px, py = float(pose.x), float(pose.y)
    bounds = _march(grid.blocked, cos_a, sin_a, distances, first, px, py, grid.frame, mask)
    return mask, bounds


class VisibilityRegion:
    """The visibility region V^p_k of the camera at one pose, computed on demand.

    :attr:`mask` is the whole region of :func:`visibility_region`, computed once, and
    :attr:`bounds` the block of cells that holds it. Most
    consumers need only part of it: the particle filter asks about its particles' cells
    (:meth:`holds`), which usually lie in a small block of the grid. :meth:`mask_over`
    marches only the rays that can reach a given block of cells, and only as far as the
    block. On the block this gives exactly the cells of the whole mask: the same rays are
    sampled at the same points and stop at the same blocked sample, and no other sample
    can land in the block.
    """

    def __init__(self, grid: OccupancyGrid, pose: Pose, camera: Camera) -> None:
        self.grid, self.pose, self.camera = grid, pose, camera
        self._mask: np.ndarray | None = None
        self._bounds: tuple[int, int, int, int] | None = None

    @classmethod
    def given(cls, mask: np.ndarray) -> VisibilityRegion:
        """A region known by its bool (H, W) mask, for sensors that see otherwise and for
        tests; :meth:`mask_over` returns the mask itself."""
        region = cls.__new__(cls)
        region.grid = region.pose = region.camera = None
        region._mask = np.asarray(mask, dtype=bool).view()
        region._mask.setflags(write=False)
        region._bounds = None  # found on demand
        return region

    @property
    def shape(self) -> tuple[int, ...]:
        """(H, W) of the mask."""
        return self.grid.blocked.shape if self._mask is None else self._mask.shape

    @property
    def mask(self) -> np.ndarray:
        """The whole region: bool (H, W) over the grid, read-only."""
        self._compute_whole()
        return self._mask

    @property
    def bounds(self) -> tuple[int, int, int, int]:
        """(r0, r1, c0, c1): rows [r0, r1) and columns [c0, c1) hold every cell of
        :attr:`mask` (r1 <= r0 when it is empty); found while the mask is computed."""
        self._compute_whole()
        if self._bounds is None:  # a given mask
            rows, cols = np.flatnonzero(self._mask.any(axis=1)), np.flatnonzero(self._mask.any(axis=0))
            self._bounds = (rows[0], rows[-1] + 1, cols[0], cols[-1] + 1) if rows.size else (0, 0, 0, 0)
        return self._bounds

    def _compute_whole(self) -> None:
        """Compute :attr:`mask` and :attr:`bounds`, once."""
        if self._mask is None:
            self._mask, self._bounds = _whole_region(self.grid, self.pose, self.camera)
            self._mask.setflags(write=False)

    def mask_over(self, rows: tuple[int, int], cols: tuple[int, int]) -> np.ndarray:
        """A bool (H, W) mask equal to :attr:`mask` on the cells with rows[0] <= row <=
        rows[1] and cols[0] <= col <= cols[1], and False or equal to it elsewhere."""
        if self._mask is not None:
            return self._mask
        return _mask_over(*self._kernel_arguments(), rows[0], rows[1], cols[0], cols[1])

    def holds(self, cells: np.ndarray) -> np.ndarray:
        """Bool (N,): whether the region holds each of the flat cell indices ``cells`` (N,)
        (row * width + col; negative: no cell, False).

        Cells that cannot meet the field of view (their centres farther than half a cell
        diagonal from its wedge) are not in the region; the rays are cast only towards the
        block of the others (:meth:`mask_over`), all in one kernel.
        """
        cells = np.asarray(cells, dtype=np.int64)
        if self._mask is not None:
            return _lookup(self._mask.ravel(), cells, np.ones(cells.size, dtype=np.bool_))
        return _holds(cells, *self._kernel_arguments())

    def _kernel_arguments(self) -> tuple:
        """The grid, pose and camera as :func:`_mask_over` and :func:`_holds` take them."""
        grid, pose, camera = self.grid, self.pose, self.camera
        angles, distances, first = _ray_tables(camera)
        return (
            grid.blocked, grid.frame, float(grid.origin[2]), float(pose.x), float(pose.y),
            float(pose.theta), angles, distances, first, camera.angle_step, camera.distance_step,
            camera.fov, camera.far,
        )


@njit(cache=True)
def _mask_over(blocked, frame, yaw, px, py, theta, angles, distances, first, angle_step,
               distance_step, fov, far, row0, row1, col0, col1):
    """Kernel of :meth:`VisibilityRegion.mask_over`: march the rays reaching the block."""
    ox, oy, resolution = frame.ox, frame.oy, frame.resolution
    i0, i1, samples = _rays_reaching(
        angles, angle_step, distance_step, distances.size, px, py, theta, ox, oy, yaw,
        resolution, row0, row1, col0, col1,
    )
    mask = np.zeros(blocked.shape, dtype=np.bool_)
    if i1 > i0 and samples > first:
        cos_a, sin_a = _directions(theta, angles, i0, i1)
        _march(blocked, cos_a, sin_a, distances[:samples], first, px, py, frame, mask)
    return mask


@njit(cache=True)
def _holds(cells, blocked, frame, yaw, px, py, theta, angles, distances, first, angle_step,
           distance_step, fov, far):
    """Kernel of :meth:`VisibilityRegion.holds` for a region not yet computed whole."""
    ox, oy, resolution = frame.ox, frame.oy, frame.resolution
    near, (r0, r1, c0, c1) = _near_wedge(
        cells, blocked.shape[1], px, py, theta, ox, oy, yaw, resolution, fov, far
    )
    if r1 < r0:
        return near  # all False
    mask = _mask_over(blocked, frame, yaw, px, py, theta, angles, distances, first,
                      angle_step, distance_step, fov, far, r0, r1, c0, c1)
    return _lookup(mask.ravel(), cells, near)


@njit(cache=True, inline="always")
def _in_cells(x, y, ox, oy, yaw, resolution):
    """(u, v): the map point (x, y) (m) in continuous cell coordinates, u along columns and
    v along rows, from the grid origin (ox, oy, yaw) (m, m, rad); not floored."""
    du, dv = (x - ox) / resolution, (y - oy) / resolution
    return math.cos(yaw) * du + math.sin(yaw) * dv, -math.sin(yaw) * du + math.cos(yaw) * dv


@njit(cache=True)
def _lookup(flat_mask, cells, candidates):
    """flat_mask[cells[i]] where candidates[i] and cells[i] >= 0, else False (N,)."""
    out = np.zeros(cells.size, dtype=np.bool_)
    for i in range(cells.size):
        if candidates[i] and cells[i] >= 0:
            out[i] = flat_mask[cells[i]]
    return out


@njit(cache=True)
def _near_wedge(cells, width, px, py, theta, ox, oy, yaw, resolution, fov, far):
    """(near (N,) bool, (row min, row max, col min, col max) of the near cells): which flat
    cell indices (negative: none) have their centre within half a cell diagonal (plus a
    rounding margin) of the field of view's wedge, apex (px, py) (map frame, m), heading
    theta, opening fov, radius far (m). A cell farther away cannot hold a ray sample of
    Algorithm 1. For fov > pi every cell within range is near. The bounds are (0, -1,
    0, -1) when no cell is near."""
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


#: cells; how far :func:`_rays_reaching` grows a block to absorb rounding at cell edges
_REACH_MARGIN = 0.5


@njit(cache=True, inline="always")
def _wrapped(angle):
    """``angle`` (rad) wrapped to [-pi, pi)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


@njit(cache=True)
def _rays_reaching(angles, angle_step, distance_step, n_distances, px, py, theta, ox, oy, yaw,
                   resolution, row0, row1, col0, col1):
    """(first ray, stop ray, samples): the camera's rays angles[first:stop] (rad from the
    heading theta) and the number of samples along each (from the first) that can land in
    the block of cells row0..row1 x col0..col1 (inclusive), seen from (px, py) (map frame,
    m). The block is grown by _REACH_MARGIN cells, and one ray and one sample more are
    taken on every side, so rounding at cell edges cannot hide a sample.
    """
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
            offset = _wrapped(math.atan2(b, a) - centre)
            low, high = min(low, offset), max(high, offset)
    heading = _wrapped(centre + yaw - theta)
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


# --------------------------------------------------------------------- line of sight


def _line_of_sight_reference(grid: OccupancyGrid, a_xy, b_xy, step: float) -> bool:
    """Plain numpy reference of :func:`line_of_sight` (``step`` given, > 0)."""
    a = np.asarray(a_xy, dtype=float)
    b = np.asarray(b_xy, dtype=float)
    count = max(1, math.ceil(float(np.hypot(*(b - a))) / step))
    t = np.linspace(0.0, 1.0, count + 1)[:, None]
    points = a + t * (b - a)
    rows, cols = grid.world_to_cell(points[:, 0], points[:, 1])
    if not np.all(grid.contains(rows, cols)):
        return False
    return not bool(np.any(grid.blocked[rows, cols]))


def line_of_sight(grid: OccupancyGrid, a_xy, b_xy, step: float | None = None) -> bool:
    """True when the segment from ``a_xy`` to ``b_xy`` (map frame, m) crosses no blocked cell.

    The segment is sampled at most ``step`` m apart (default: half the grid resolution),
    both endpoints included; a sample off the grid or in a blocked (occupied or unknown)
    cell breaks the line of sight, so an endpoint in a blocked cell gives False. Like the
    visibility mask this is a sampled test: it may miss a cell whose corner the segment
    only grazes over less than ``step``.
    """
    step = 0.5 * grid.resolution if step is None else float(step)
    if step <= 0.0:
        raise ValueError(f"step must be positive, got {step}")
    ax, ay = float(a_xy[0]), float(a_xy[1])
    bx, by = float(b_xy[0]), float(b_xy[1])
    return _segment_clear(grid.blocked, ax, ay, bx, by, step, grid.frame)


def in_view(grid: OccupancyGrid, camera: Camera, pose: Pose, point_xy) -> bool:
    """True when the camera at ``pose`` sees the map-frame point ``point_xy`` (m).

    The continuous counterpart of :func:`visibility_region`: the point's bearing from the
    optical axis is within fov/2 rad, its range is within [near, far] m, and
    :func:`line_of_sight` from the camera to the point holds. Near the wedge edges and
    range limits it may disagree with the discretised mask by about one cell.
    """
    x, y = float(point_xy[0]), float(point_xy[1])
    dx, dy = x - pose.x, y - pose.y
    if not camera.near <= math.hypot(dx, dy) <= camera.far:
        return False
    if abs(wrap_angle(math.atan2(dy, dx) - pose.theta)) > 0.5 * camera.fov:
        return False
    return line_of_sight(grid, (pose.x, pose.y), (x, y))


#: points across a body's silhouette that :func:`body_in_view` tests, in body radii
SILHOUETTE = (0.0, -1.0, 1.0, -0.5, 0.5)


def body_in_view(grid: OccupancyGrid, camera: Camera, pose: Pose, centre_xy, radius: float) -> bool:
    """True when the camera at ``pose`` sees any part of a body: an upright cylinder of
    ``radius`` m standing at the map-frame point ``centre_xy`` (m).

    The body's silhouette, seen from the camera, is its diameter across the line of sight;
    the body is in view when one of the SILHOUETTE points along it (its centre, its two
    edges, the points halfway) is in view (:func:`in_view`). So a shoulder that shows past
    a corner or the edge of the field of view counts, as evader pixels in a rendered image
    would, while the centre is hidden.
    """
    x, y = float(centre_xy[0]), float(centre_xy[1])
    dx, dy = x - pose.x, y - pose.y
    distance = math.hypot(dx, dy)
    across = (-dy / distance, dx / distance) if distance > 0.0 else (0.0, 0.0)
    return any(
        in_view(grid, camera, pose, (x + k * radius * across[0], y + k * radius * across[1]))
        for k in SILHOUETTE
    )


def fov_wedge(camera: Camera, pose: Pose, n: int = 32) -> np.ndarray:
    """(K, 2) closed polygon (map frame, m) bounding the camera's field of view at ``pose``.

    ``n`` points along the near arc from -fov/2 to +fov/2 (a single apex point when near
    is 0), then ``n`` points along the far arc back from +fov/2 to -fov/2, then the first
    point again to close the ring. For plotting and recording; ignores occlusion.
    """
    if n < 2:
        raise ValueError(f"n must be at least 2, got {n}")
    arc = pose.theta + np.linspace(-0.5 * camera.fov, 0.5 * camera.fov, n)
    near_arc = arc if camera.near > 0.0 else arc[:1]
    thetas = np.concatenate([near_arc, arc[::-1]])
    radii = np.concatenate([np.full(near_arc.size, camera.near), np.full(n, camera.far)])
    ring = np.column_stack([pose.x + radii * np.cos(thetas), pose.y + radii * np.sin(thetas)])
    return np.vstack([ring, ring[:1]])
