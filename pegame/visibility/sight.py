"""Continuous visibility on a grid: line of sight, a point or a body in view, the FOV wedge.

:func:`line_of_sight` samples a segment and fails at the first blocked or off-grid
sample (numpy reference: ``_line_of_sight_reference``). :func:`in_view` is the continuous
counterpart of the visibility region (:func:`pegame.visibility.visibility_region`):
bearing, range and line of sight of a point; :func:`body_in_view` extends it from a point
to a body, the ground truth of "the evader is in view". :func:`fov_wedge` is the field of
view's polygon, for plots.

The visibility tests themselves are numba kernels, here and only here: :func:`segment_clear`,
:func:`point_in_view` and :func:`silhouette_in_view` (with :func:`across`, the direction
of a body's silhouette, which :func:`pegame.detectors.perception.silhouette_hidden`
shares). The functions above call them for one pose, the batched game
(:mod:`pegame.vector.camera`) inlines them into its loop over games. They take the grid as
:func:`sight_tables` gives it (its frame as float64, the cells as a look-up table) and the
camera as its numbers (near, far, fov), not as objects: numba unboxes arrays and floats
cheaply, and an inlined kernel given a NamedTuple pays a reference count per array.
Python's ``math.hypot`` and :func:`pegame.types.wrap_angle` are there as
:mod:`pegame.numerics`'s bit-for-bit numba forms.

Units and frames: metres and radians in the map frame of :mod:`pegame.grid`; poses are
:class:`pegame.types.Pose`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from pegame.grid import OccupancyGrid, per_grid, read_only
from pegame.grid.occupancy import COS_YAW, OX, OY, RESOLUTION, ROTATED, SIN_YAW
from pegame.numerics import cell_by_division, cell_by_product, hypot, hypot_within, wrap_angle
from pegame.types import XY, Camera, Pose

#: points across a body's silhouette that :func:`body_in_view` tests, in body radii
SILHOUETTE = (0.0, -1.0, 1.0, -0.5, 0.5)
_SILHOUETTE = np.array(SILHOUETTE)

#: line-of-sight samples whose cells are found together (one vectorised pass)
_CHUNK = 32


def sight_tables(grid: OccupancyGrid) -> tuple[np.ndarray, np.ndarray]:
    """The grid as the kernels take it, built once per grid (read-only): its
    ``kernel_frame`` as float64 (6,) (a tuple of mixed types cannot enter numba's parallel
    loops), and the look-up table bool (1 + H * W,) of :func:`segment_clear`: True (off the
    grid), then ``grid.blocked`` flat."""
    return per_grid(grid, ("sight.tables",), _build_tables)


def _build_tables(grid: OccupancyGrid) -> tuple[np.ndarray, np.ndarray]:
    frame = read_only(np.array(grid.kernel_frame, dtype=np.float64))
    return frame, read_only(np.concatenate([[True], grid.blocked.ravel()]))


def _line_of_sight_reference(grid: OccupancyGrid, a_xy: XY, b_xy: XY, step: float) -> bool:
    """Plain numpy reference of :func:`line_of_sight` (``step`` given, > 0)."""
    a = np.asarray(a_xy, dtype=float)
    b = np.asarray(b_xy, dtype=float)
    count = max(1, math.ceil(float(np.hypot(*(b - a))) / step))
    t = np.linspace(0.0, 1.0, count + 1)[:, None]
    points = a + t * (b - a)
    points[-1] = b  # the end point itself: a + (b - a) may round into another cell
    rows, cols = grid.world_to_cell(points[:, 0], points[:, 1])
    if not np.all(grid.contains(rows, cols)):
        return False
    return not bool(np.any(grid.blocked[rows, cols]))


@njit(cache=True, inline="always")
def _sample_point(
    frame: np.ndarray,
    ax: float,
    ay: float,
    bx: float,
    by: float,
    k: int,
    count: int,
    rotated: bool,
) -> tuple[float, float]:
    """Grid-frame point (u, v) (m) of sample k of count along the segment from (ax, ay)
    to (bx, by): the numpy reference's, where ``np.linspace(0, 1, count + 1)`` gives
    t = k * (1 / count), and the last one at (bx, by) itself."""
    t = k * (1.0 / count)
    x, y = (bx, by) if k == count else (ax + t * (bx - ax), ay + t * (by - ay))
    u = x - frame[OX]
    v = y - frame[OY]
    if rotated:
        u, v = frame[COS_YAW] * u + frame[SIN_YAW] * v, -frame[SIN_YAW] * u + frame[COS_YAW] * v
    return u, v


@njit(cache=True, inline="always")
def _sample_cells(
    frame: np.ndarray,
    height: int,
    width: int,
    ax: float,
    ay: float,
    bx: float,
    by: float,
    count: int,
    start: int,
    size: int,
    cells: np.ndarray,
    rotated: bool,
) -> bool:
    """The cells (1 + flat index, 0 off the grid) of samples start..start + size - 1 of
    the segment into ``cells`` by :func:`pegame.numerics.cell_by_product`; returns
    whether all are decided. Inlined with ``rotated`` a constant (no branch in the loop).
    """
    inverse = 1.0 / frame[RESOLUTION]
    decided = True
    for j in range(size):
        u, v = _sample_point(frame, ax, ay, bx, by, start + j, count, rotated)
        cells[j], ok = cell_by_product(u, v, inverse, height, width)
        decided &= ok
    return decided


@njit(cache=True)
def segment_clear(
    frame: np.ndarray,
    blocked: np.ndarray,
    values: np.ndarray,
    ax: float,
    ay: float,
    bx: float,
    by: float,
    step: float,
) -> bool:
    """Kernel of :func:`line_of_sight`: True when no sample of the segment from (ax, ay)
    to (bx, by) (m), ``step`` m apart, lies in a blocked or off-grid cell; the numpy
    reference's samples and cells (:meth:`OccupancyGrid.world_to_cell`), found _CHUNK at a
    time from products (:func:`pegame.numerics.cell_by_product`; a chunk with a sample near
    a cell edge is found again by the division), then looked up in ``values``; the test
    stops at the first chunk with a blocked cell. ``frame``, ``blocked``, ``values``: the
    grid's (:func:`sight_tables`, ``grid.blocked``)."""
    height, width = blocked.shape
    rotated = frame[ROTATED] != 0.0
    count = max(1, math.ceil(math.hypot(bx - ax, by - ay) / step))
    cells = np.empty(_CHUNK, np.int64)
    for start in range(0, count + 1, _CHUNK):
        size = min(_CHUNK, count + 1 - start)
        if rotated:
            decided = _sample_cells(
                frame, height, width, ax, ay, bx, by, count, start, size, cells, True
            )
        else:
            decided = _sample_cells(
                frame, height, width, ax, ay, bx, by, count, start, size, cells, False
            )
        if not decided:
            for j in range(size):
                u, v = _sample_point(frame, ax, ay, bx, by, start + j, count, rotated)
                cells[j] = cell_by_division(u, v, frame[RESOLUTION], height, width)
        for j in range(size):
            if values[cells[j]]:
                return False
    return True


@njit(cache=True, inline="always")
def point_in_view(
    frame: np.ndarray,
    blocked: np.ndarray,
    values: np.ndarray,
    near: float,
    far: float,
    fov: float,
    px: float,
    py: float,
    ptheta: float,
    x: float,
    y: float,
) -> bool:
    """Kernel of :func:`in_view`: whether the camera at (px, py, ptheta) (m, m, rad) with
    range [``near``, ``far``] (m) and field of view ``fov`` (rad) sees the map point
    (x, y) (m); the grid as for :func:`segment_clear`."""
    dx, dy = x - px, y - py
    if not hypot_within(dx, dy, near, far):
        return False
    if abs(wrap_angle(math.atan2(dy, dx) - ptheta)) > 0.5 * fov:
        return False
    return segment_clear(frame, blocked, values, px, py, x, y, 0.5 * frame[RESOLUTION])


@njit(cache=True, inline="always")
def across(px: float, py: float, x: float, y: float) -> tuple[float, float]:
    """The unit vector across the line of sight from (px, py) to the body at (x, y), along
    which its SILHOUETTE points lie ((0, 0) when the two coincide)."""
    dx, dy = x - px, y - py
    distance = hypot(dx, dy)
    return (-dy / distance, dx / distance) if distance > 0.0 else (0.0, 0.0)


@njit(cache=True, inline="always")
def silhouette_in_view(
    frame: np.ndarray,
    blocked: np.ndarray,
    values: np.ndarray,
    near: float,
    far: float,
    fov: float,
    px: float,
    py: float,
    ptheta: float,
    x: float,
    y: float,
    radius: float,
    first: int,
) -> bool:
    """Kernel of :func:`body_in_view`: whether one of the SILHOUETTE points from index
    ``first`` on of the body of ``radius`` m at (x, y) is in view (:func:`point_in_view`,
    the same arguments); ``first`` = 1 skips the centre, when it is known to be out of
    view (the batched game's detector tested it)."""
    ax, ay = across(px, py, x, y)
    for k in _SILHOUETTE[first:]:
        if point_in_view(
            frame,
            blocked,
            values,
            near,
            far,
            fov,
            px,
            py,
            ptheta,
            x + k * radius * ax,
            y + k * radius * ay,
        ):
            return True
    return False


def line_of_sight(grid: OccupancyGrid, a_xy: XY, b_xy: XY, step: float | None = None) -> bool:
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
    frame, values = sight_tables(grid)
    ax, ay = float(a_xy[0]), float(a_xy[1])
    bx, by = float(b_xy[0]), float(b_xy[1])
    return segment_clear(frame, grid.blocked, values, ax, ay, bx, by, step)


def in_view(grid: OccupancyGrid, camera: Camera, pose: Pose, point_xy: XY) -> bool:
    """True when the camera at ``pose`` sees the map-frame point ``point_xy`` (m).

    The continuous counterpart of :func:`visibility_region`: the point's bearing from the
    optical axis is within fov/2 rad, its range is within [near, far] m, and
    :func:`line_of_sight` from the camera to the point holds. Near the wedge edges and
    range limits it may disagree with the discretised mask by about one cell.
    """
    frame, values = sight_tables(grid)
    return point_in_view(
        frame,
        grid.blocked,
        values,
        camera.near,
        camera.far,
        camera.fov,
        pose.x,
        pose.y,
        pose.theta,
        float(point_xy[0]),
        float(point_xy[1]),
    )


def body_in_view(
    grid: OccupancyGrid, camera: Camera, pose: Pose, centre_xy: XY, radius: float
) -> bool:
    """True when the camera at ``pose`` sees any part of a body: an upright cylinder of
    ``radius`` m standing at the map-frame point ``centre_xy`` (m).

    The body's silhouette, seen from the camera, is its diameter across the line of sight;
    the body is in view when one of the SILHOUETTE points along it (its centre, its two
    edges, the points halfway) is in view (:func:`in_view`). So a shoulder that shows past
    a corner or the edge of the field of view counts, as evader pixels in a rendered image
    would, while the centre is hidden.
    """
    frame, values = sight_tables(grid)
    return silhouette_in_view(
        frame,
        grid.blocked,
        values,
        camera.near,
        camera.far,
        camera.fov,
        pose.x,
        pose.y,
        pose.theta,
        float(centre_xy[0]),
        float(centre_xy[1]),
        float(radius),
        0,
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
