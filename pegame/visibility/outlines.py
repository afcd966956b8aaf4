"""Outlines of visibility regions: closed polygons that draw a camera's region cheaply.

A recording shows the pursuer's visibility region every tick; drawing the mask of
:func:`pegame.visibility.visibility_region` (thousands of cells) would cost more than the
game. :func:`visibility_outlines` draws it at ``rays`` angles instead: rays at the centres
of equal slices of the FOV are cast from the camera one cell apart, as in the paper's
Algorithm 1 with the occlusion extension of :mod:`pegame.visibility`, up to the first
blocked cell or the far range, and the polygon runs along their far ends, then back along
the near arc.

:func:`outlines_reference` is the plain Python march that samples every cell; the numba
kernel runs the same code with ``jump``: it skips the samples that the grid's
:func:`free_runs` (a clearance map from a Euclidean distance transform) shows to be free,
with the same result. Units and frames: metres and radians in the map frame of
:mod:`pegame.grid`; cells through the grid's :class:`pegame.grid.GridFrame`.
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import NamedTuple

import numpy as np
from numba import njit
from numpy.typing import ArrayLike

from pegame.grid import OccupancyGrid, per_grid, read_only
from pegame.grid.occupancy import COS_YAW, OX, OY, RESOLUTION, SIN_YAW
from pegame.navigation.inflation import shared_obstacle_distance
from pegame.types import Camera

#: points along the near arc of an outline (the arc is short: near is a few decimetres)
NEAR_ARC_POINTS = 8


class OutlineRays(NamedTuple):
    """The rays of an outline relative to the camera's optical axis, as kernels read them.

    ray_cos, ray_sin: (n,) cos and sin of the ray angles (rad from the axis); arc_cos,
    arc_sin: (m,) the same for the points of the near arc, from +fov/2 back to -fov/2;
    near, far: the camera's sensing range (m).
    """

    ray_cos: np.ndarray
    ray_sin: np.ndarray
    arc_cos: np.ndarray
    arc_sin: np.ndarray
    near: float
    far: float


@lru_cache(maxsize=16)
def outline_rays(camera: Camera, rays: int) -> OutlineRays:
    """``rays`` rays at the centres of equal slices of the camera's FOV, and
    NEAR_ARC_POINTS points along its near arc."""
    angles = camera.fov * ((np.arange(rays) + 0.5) / rays - 0.5)
    arc = np.linspace(0.5 * camera.fov, -0.5 * camera.fov, NEAR_ARC_POINTS)
    return OutlineRays(
        np.cos(angles),
        np.sin(angles),
        np.cos(arc),
        np.sin(arc),
        float(camera.near),
        float(camera.far),
    )


def outlines_reference(
    runs: np.ndarray,
    frame: tuple,
    rays: OutlineRays,
    xs: np.ndarray,
    ys: np.ndarray,
    thetas: np.ndarray,
    z: float,
    jump: bool = False,
) -> np.ndarray:
    """Closed (P, n + m + 1, 3) float32 polygons (map frame, m, at height z) around the
    visibility regions of the camera at the P poses (xs, ys, thetas) (m, m, rad): the far
    ends of the n rays of ``rays`` (:class:`OutlineRays`), then its m points back along
    the near arc, then the first point again.

    Rays leave each pose at theta + a_i and are sampled in the grid frame (``frame``, a
    :class:`pegame.grid.GridFrame`) one cell apart, up to the first sample in a blocked
    cell (``runs`` 0, see :func:`free_runs`) or off the grid. With ``jump`` the samples
    that ``runs`` shows to be free are skipped, which gives the same result as sampling
    every cell (jump=False, the plain reference). A ray that ends before the near range
    is drawn at the near range.
    """
    height, width = runs.shape
    n, m = rays.ray_cos.size, rays.arc_cos.size
    out = np.empty((xs.size, n + m + 1, 3), dtype=np.float32)
    c, s, resolution = frame[COS_YAW], frame[SIN_YAW], frame[RESOLUTION]
    near = rays.near
    # Cells that straddle the near range are only partly seen: reach starts one cell beyond it.
    start = near / resolution + 1.0
    count = math.floor(rays.far / resolution) + 1
    du, dv = np.empty(n), np.empty(n)  # ray directions in the grid frame (cells per sample)
    d = np.empty(n, dtype=np.int64)  # the next sample of each ray (count: the ray is done)
    last = np.empty(n, dtype=np.int64)  # the last free sample of each ray
    for p in range(xs.size):
        x, y, theta = xs[p], ys[p], thetas[p]
        u = (c * (x - frame[OX]) + s * (y - frame[OY])) / resolution
        v = (-s * (x - frame[OX]) + c * (y - frame[OY])) / resolution
        cm, sm = math.cos(theta), math.sin(theta)  # the heading in the map frame
        cg, sg = c * cm + s * sm, c * sm - s * cm  # the heading in the grid frame
        for i in range(n):
            du[i] = cg * rays.ray_cos[i] - sg * rays.ray_sin[i]
            dv[i] = sg * rays.ray_cos[i] + cg * rays.ray_sin[i]
            d[i], last[i] = 0, -1
        # All rays advance one step per round: their steps are independent, so the
        # processor overlaps their memory reads (twice as fast as one ray at a time).
        marching = n
        while marching:
            marching = 0
            for i in range(n):
                if d[i] >= count:
                    continue
                fc, fr = u + d[i] * du[i], v + d[i] * dv[i]
                # Range checks on the floats, so that int() (truncation) equals floor.
                if fr < 0.0 or fr >= height or fc < 0.0 or fc >= width:
                    d[i] = count
                    continue
                run = runs[int(fr), int(fc)]
                if run == 0:
                    d[i] = count
                    continue
                last[i] = min(d[i] + (run - 1 if jump else 0), count - 1)
                d[i] = last[i] + 1
                marching += 1
        for i in range(n):
            reach = last[i] * resolution if last[i] >= start else near
            cw = cm * rays.ray_cos[i] - sm * rays.ray_sin[i]
            sw = sm * rays.ray_cos[i] + cm * rays.ray_sin[i]
            out[p, i, 0], out[p, i, 1], out[p, i, 2] = x + reach * cw, y + reach * sw, z
        for j in range(m):
            cw = cm * rays.arc_cos[j] - sm * rays.arc_sin[j]
            sw = sm * rays.arc_cos[j] + cm * rays.arc_sin[j]
            out[p, n + j, 0], out[p, n + j, 1], out[p, n + j, 2] = x + near * cw, y + near * sw, z
        out[p, n + m] = out[p, 0]
    return out


_outlines_kernel = njit(cache=True)(outlines_reference)


def simplify_reference(outlines: np.ndarray, tolerance: float) -> tuple[np.ndarray, np.ndarray]:
    """Closed (P, K, 3) polygons (:func:`visibility_outlines`) with the vertices dropped
    that lie within ``tolerance`` (m, in the map plane) of the segment joining the
    vertices kept on either side: ((M, 3) float32 vertices of all polygons one after the
    other, (P,) int64 vertex counts). Each polygon keeps its first and last vertex and its
    order; a vertex is kept when the segment from the last kept vertex to the one after it
    passes farther than ``tolerance`` from a vertex in between (greedy, one pass).
    The ray ends lie on the grid's cells to within a cell, so half a cell loses nothing
    the outline holds; a wall seen by many rays becomes a few vertices."""
    count, size = outlines.shape[0], outlines.shape[1]
    out = np.empty((count * size, 3), dtype=np.float32)
    lengths = np.zeros(count, dtype=np.int64)
    n = 0
    for p in range(count):
        start, kept = n, 0
        out[n] = outlines[p, 0]
        n += 1
        for i in range(1, size - 1):
            # In float64, so that the compiled kernel and this plain code round alike
            # (numba's float() of a float32 stays float32).
            f64 = np.float64
            ax, ay = f64(outlines[p, kept, 0]), f64(outlines[p, kept, 1])
            dx, dy = f64(outlines[p, i + 1, 0]) - ax, f64(outlines[p, i + 1, 1]) - ay
            squared = dx * dx + dy * dy
            for j in range(kept + 1, i + 1):
                px, py = f64(outlines[p, j, 0]) - ax, f64(outlines[p, j, 1]) - ay
                t = 0.0 if squared == 0.0 else min(1.0, max(0.0, (px * dx + py * dy) / squared))
                ex, ey = px - t * dx, py - t * dy
                if ex * ex + ey * ey > tolerance * tolerance:
                    out[n] = outlines[p, i]
                    n += 1
                    kept = i
                    break
        out[n] = outlines[p, size - 1]
        n += 1
        lengths[p] = n - start
    return out[:n], lengths


_simplify_kernel = njit(cache=True)(simplify_reference)


def simplify_outlines(
    outlines: np.ndarray, tolerance: float, compiled: bool = True
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`simplify_reference`, compiled (compiled=False: the plain code itself)."""
    simplify = _simplify_kernel if compiled else simplify_reference
    return simplify(outlines, float(tolerance))


def drawn_outlines(
    grid: OccupancyGrid,
    xs: ArrayLike,
    ys: ArrayLike,
    thetas: ArrayLike,
    camera: Camera,
    rays: int,
    z: float = 0.0,
) -> tuple[np.ndarray, np.ndarray]:
    """The outlines a recording draws: :func:`visibility_outlines` simplified to half a
    cell (:func:`simplify_outlines`), as ((M, 3) float32 vertices, (P,) vertex counts)."""
    outlines = visibility_outlines(grid, xs, ys, thetas, camera, rays, z)
    return simplify_outlines(outlines, 0.5 * grid.resolution)


def visibility_outlines(
    grid: OccupancyGrid,
    xs: ArrayLike,
    ys: ArrayLike,
    thetas: ArrayLike,
    camera: Camera,
    rays: int,
    z: float = 0.0,
    compiled: bool = True,
) -> np.ndarray:
    """(P, rays + NEAR_ARC_POINTS + 1, 3) float32: closed polygons (map frame, m, at height
    z) around the visibility regions of ``camera`` at P poses (xs, ys, thetas) (m, m, rad)
    on ``grid``; see the module docstring. compiled=False runs :func:`outlines_reference`,
    which samples every cell, instead of the numba kernel, which jumps over free cells."""
    march = _outlines_kernel if compiled else outlines_reference
    xs, ys, thetas = (np.asarray(v, dtype=float).reshape(-1) for v in (xs, ys, thetas))
    return march(
        free_runs(grid),
        grid.kernel_frame,
        outline_rays(camera, rays),
        xs,
        ys,
        thetas,
        float(z),
        compiled,
    )


def free_runs(grid: OccupancyGrid) -> np.ndarray:
    """uint8 (H, W): 0 on blocked cells; on a free cell, how many samples one cell apart
    along any ray from any point of the cell are sure to be free, this one included.

    If the cell's centre lies D cells from the nearest blocked cell's centre or cell off
    the grid, every point closer than D - sqrt(2) cells to a point of the cell is free: 1 +
    floor(D - 1.5) samples (at least 1, at most 255). Small, so it stays in cache. Kept on
    the grid for its next games (:func:`pegame.grid.per_grid`).
    """
    return per_grid(grid, ("visibility.outlines", "free runs"), _free_runs)


def _free_runs(grid: OccupancyGrid) -> np.ndarray:
    clearance = shared_obstacle_distance(grid) / grid.resolution  # cells
    runs = np.where(grid.blocked, 0, 1 + np.clip(np.floor(clearance - 1.5), 0, 254))
    return read_only(runs.astype(np.uint8))
