"""Continuous visibility on a grid: line of sight, a point or a body in view, the FOV wedge.

:func:`line_of_sight` samples a segment and fails at the first blocked or off-grid
sample; it is a numba kernel with the numpy reference ``_line_of_sight_reference``.
:func:`in_view` is the continuous counterpart of the visibility region
(:func:`pegame.visibility.visibility_region`): bearing, range and line of sight of a
point; :func:`body_in_view` extends it from a point to a body, the ground truth of
"the evader is in view". :func:`fov_wedge` is the field of view's polygon, for plots.

Units and frames: metres and radians in the map frame of :mod:`pegame.grid`; poses are
:class:`pegame.types.Pose`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from pegame.grid import OccupancyGrid, cell_blocked, point_cell
from pegame.types import XY, Camera, Pose, wrap_angle


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


@njit(cache=True)
def _segment_clear(
    blocked: np.ndarray,
    ax: float,
    ay: float,
    bx: float,
    by: float,
    step: float,
    frame: tuple,
) -> bool:
    """Kernel of :func:`line_of_sight`: the same samples as the numpy reference, where
    ``np.linspace(0, 1, count + 1)`` gives t = k * (1 / count), and the end point itself."""
    count = max(1, math.ceil(math.hypot(bx - ax, by - ay) / step))
    dx, dy = bx - ax, by - ay
    dt = 1.0 / count
    for k in range(count + 1):
        x, y = (bx, by) if k == count else (ax + k * dt * dx, ay + k * dt * dy)
        row, col = point_cell(x, y, frame)
        if cell_blocked(blocked, row, col):
            return False
    return True


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
    ax, ay = float(a_xy[0]), float(a_xy[1])
    bx, by = float(b_xy[0]), float(b_xy[1])
    return _segment_clear(grid.blocked, ax, ay, bx, by, step, grid.kernel_frame)


def in_view(grid: OccupancyGrid, camera: Camera, pose: Pose, point_xy: XY) -> bool:
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
