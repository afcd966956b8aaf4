"""The smart evader's escape-point search: Algorithm 2's argmin over the candidate cells
(paper, Sec. "Smart Evader"; the strategy is :mod:`pegame.evaders.smart`).

For the evader at pose e and the pursuer at pose p, the candidates are the cells the
evader can reach (traversable for its radius and connected to its own cell,
:meth:`pegame.navigation.Planner.reachable`) outside the pursuer's visibility region V
grown by the hide margin (m, cell centre to cell centre), on the candidate stride (row
and column multiples of k). Each costs cost_effort / cost_dist, the distances (m) from e
and from p to its centre: straight-line (``euclidean``, the paper) or shortest
8-connected grid paths (``geodesic``, the evader's over the cells traversable for its
radius, the pursuer's over those traversable for the pursuer's radius). dist 0 costs
+inf; dist +inf (out of the pursuer's reach) costs 0. :class:`EscapeSearch` finds the
argmin: lowest cost, then lowest row-major cell index (row * width + col).

Units and frames: metres and radians in the map frame of :mod:`pegame.grid` (x right,
y up, row 0 = lowest y). Candidates are cell centres.

Fast path. :meth:`EscapeSearch.escape` returns the same goal, cost and recorded
candidates as the plain numpy :meth:`EscapeSearch.escape_reference` (the tests hold it to
that, bit for bit), in numba kernels that skip most of the work:

- The hide margin grows V by a disc: every run of visible cells in a row marks, in each
  row within the margin, the run widened by the disc's half-width at that row offset,
  inside V's bounding box padded by the margin. The disc holds the offsets whose
  distance, computed as the Euclidean distance transform computes it, is within the
  margin, so the grown V is the transform's.
- The candidate cells of the evader's connected component are built once per component
  and grouped in square tiles (kept on the grid across games by
  :func:`pegame.grid.per_grid`, per planner radius and candidate stride). Tiles are
  scored in increasing order of a lower bound of their cost (the nearest distance to the
  evader over the farthest distance to the pursuer), and the search stops at the first tile
  whose bound exceeds the best cost
  found by more than round-off could explain (a relative slack of 1e-9). Ties are broken
  explicitly by cell index, as np.argmin's first minimum does in row-major order. With
  geodesic distances there is no such bound and every tile is scored.
- The recorded candidates are picked from the component's cells by counting past the
  few cells V hides, without listing every candidate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numba import njit
from numpy.typing import ArrayLike
from scipy.ndimage import distance_transform_edt

from pegame.grid import OccupancyGrid, per_grid
from pegame.grid.cells import cell_centre, cell_centres
from pegame.navigation import Planner
from pegame.types import Camera, Pose, Region
from pegame.visibility import VisibilityRegion, visibility_region
from pegame.visibility.lazy import rays_reaching, sight_and_rays
from pegame.visibility.rays import directions, ray_tables
from pegame.visibility.region import march_ray

DISTANCES = ("euclidean", "geodesic")

#: most candidate points put into Plan.info["candidates"] for the recorder (an evenly
#: strided subsample: enough to show the set, few enough not to hide the map)
MAX_RECORDED_CANDIDATES = 250
#: edge (cells) of the square tiles that the fast argmin search scores or skips as a whole
TILE = 8
#: edge (tiles) of the square groups of tiles whose bounds the lazy search starts from
GROUP = 4
#: samples a ray is marched beyond what a tile's block needs, when it is marched: later
#: tiles often need a few more, and a piece of a ray costs about as much as this many
#: samples (escape_goal on game states: 80 us per decision with none, 67 with 16 or 32, 71
#: marching every ray to its end)
RAY_SLACK = 16
#: tiles sorted by bound before the search starts (see EscapeSearch.escape); more than
#: the paper maps have (at most 1900), so theirs are all sorted at once as before
FIRST_TILES = 4096
#: a tile is skipped only when its cost bound exceeds the best cost by this relative
#: amount: far more than the round-off of the bound and of the costs (~1e-15)
BOUND_SLACK = 1e-9


@dataclass(frozen=True)
class Escape:
    """One decision's argmin. cell: flat row-major index (row * width + col) of the goal
    cell, -1 when there is no candidate. cost: its cost_escape (+inf when none). count:
    the number of candidates. sample: flat indices of every
    ceil(count / MAX_RECORDED_CANDIDATES)-th candidate in row-major order."""

    cell: int
    cost: float
    count: int
    sample: np.ndarray


def escape_costs(effort: np.ndarray, dist: np.ndarray) -> np.ndarray:
    """Algorithm 2's cost effort / dist per candidate (both in m, same shape).

    A candidate at dist 0 (under the pursuer) costs +inf; dist +inf (out of the pursuer's
    reach) with a finite effort costs 0.
    """
    cost = np.full(effort.shape, np.inf)
    np.divide(effort, dist, out=cost, where=dist > 0)
    return cost


def subsample(points: np.ndarray, limit: int) -> np.ndarray:
    """At most ``limit`` rows of ``points`` (K, ...), evenly spaced in their order."""
    return points[:: _sample_step(len(points), limit)]


def _sample_step(count: int, limit: int) -> int:
    return max(1, math.ceil(count / limit))


def disc_half_widths(margin: float, resolution: float) -> np.ndarray:
    """Half-widths (cells) of the disc of cells within ``margin`` (m) of a cell, per row
    offset 0, 1, ..., R: the largest column offset whose distance, computed as
    scipy's distance_transform_edt does (sqrt of the integer squared offset, in cells,
    times ``resolution`` m), is at most ``margin``."""
    reach = 0
    while (reach + 1) * resolution <= margin:
        reach += 1
    widths = np.zeros(reach + 1, dtype=np.int64)
    for row in range(reach + 1):
        while math.sqrt(row * row + (widths[row] + 1) ** 2) * resolution <= margin:
            widths[row] += 1
    return widths


# ------------------------------------------------------------------ numba kernels


@njit(cache=True)
def _grow(
    visible: np.ndarray, r0: int, r1: int, c0: int, c1: int, half_widths: np.ndarray
) -> tuple[np.ndarray, int, int]:
    """The cells within the disc of ``half_widths`` of a cell of ``visible`` (H, W), whose
    True cells all lie in rows [r0, r1) and columns [c0, c1): a bool window and its top
    row and left column."""
    reach = half_widths.size - 1
    height, width = visible.shape
    top, left = max(r0 - reach, 0), max(c0 - reach, 0)
    bottom, right = min(r1 + reach, height), min(c1 + reach, width)
    grown = np.zeros((bottom - top, right - left), dtype=np.bool_)
    for row in range(r0, r1):
        col = c0
        while col < c1:
            if not visible[row, col]:
                col += 1
                continue
            start = col
            while col < c1 and visible[row, col]:
                col += 1
            # The run [start, col) widened by the disc's half-width, in every row it reaches.
            for offset in range(-reach, reach + 1):
                target = row + offset
                if top <= target < bottom:
                    half = half_widths[abs(offset)]
                    lo, hi = max(start - half, left), min(col + half, right)
                    grown[target - top, lo - left : hi - left] = True
    return grown, top, left


@njit(cache=True)
def _exposed_positions(
    exposed: np.ndarray, top: int, left: int, width: int, position: np.ndarray
) -> np.ndarray:
    """Increasing indices, in a component's row-major cell list, of its cells that are
    True in the ``exposed`` window at (top, left); ``position`` maps a flat cell index to
    its index in the list, -1 outside the list."""
    found = np.empty(exposed.size, dtype=np.int64)
    count = 0
    for row in range(exposed.shape[0]):
        base = (row + top) * width + left
        for col in range(exposed.shape[1]):
            if exposed[row, col] and position[base + col] >= 0:
                found[count] = position[base + col]
                count += 1
    return found[:count]


@njit(cache=True)
def _tile_bounds(boxes: np.ndarray, ex: float, ey: float, px: float, py: float) -> np.ndarray:
    """Lower bound (T,) of effort / dist over each tile's box (x min, x max, y min,
    y max) (m) of cell centres: the box's nearest distance to the evader at (ex, ey) over
    its farthest distance to the pursuer at (px, py)."""
    bounds = np.empty(boxes.shape[0])
    for t in range(boxes.shape[0]):
        bounds[t] = _box_bound(boxes, t, ex, ey, px, py)
    return bounds


@njit(cache=True, inline="always")
def _box_bound(boxes: np.ndarray, t: int, ex: float, ey: float, px: float, py: float) -> float:
    """:func:`_tile_bounds` of box ``t``. A box holding another has a bound no larger
    (its nearest distance no larger, its farthest no smaller, in floats too)."""
    x0, x1, y0, y1 = boxes[t, 0], boxes[t, 1], boxes[t, 2], boxes[t, 3]
    nx, ny = max(x0 - ex, ex - x1, 0.0), max(y0 - ey, ey - y1, 0.0)
    fx, fy = max(abs(x0 - px), abs(x1 - px)), max(abs(y0 - py), abs(y1 - py))
    far = math.sqrt(fx * fx + fy * fy)
    return math.sqrt(nx * nx + ny * ny) / far if far > 0.0 else np.inf


class TiledCells(NamedTuple):
    """A component's candidate cells grouped by tile (:func:`_group_by_tile`), on their grid."""

    starts: np.ndarray  # int64 (T + 1,), where each tile's cells begin in rows and cols
    rows: np.ndarray  # int32 (K,), the cells' rows, grouped by tile
    cols: np.ndarray  # int32 (K,), their columns
    frame: tuple  # the grid's OccupancyGrid.kernel_frame
    grid_width: int  # the grid's columns


class Window(NamedTuple):
    """Cells of the grid in a window: a bool block placed at (top, left)."""

    cells: np.ndarray  # bool (h, w)
    top: int  # the window's first row in the grid
    left: int  # its first column


class Costs(NamedTuple):
    """What Algorithm 2's cost effort / dist of a cell is computed from."""

    agents: tuple[float, float, float, float]  # (evader x, evader y, pursuer x, pursuer y), m
    effort: np.ndarray  # float (H * W,) the evader's path costs (m), or empty: Euclidean
    dist: np.ndarray  # float (H * W,) the pursuer's, or empty


@njit(cache=True)
def _best_candidate(
    tiles: np.ndarray,
    bounds: np.ndarray,
    cells: tuple,
    exposed: tuple,
    costs: tuple,
    best: tuple[int, float],
) -> tuple[int, float, bool]:
    """Algorithm 2's argmin over the ``cells`` of ``tiles`` outside the ``exposed`` window
    and the ``best`` (flat cell, cost) found before them ((-1, inf) for none): (flat cell,
    cost, stopped), stopped when a tile's bound ended the search before the last tile.

    ``tiles`` lists the tiles by increasing bound, ``bounds`` (T,) the bounds. With flat
    distance fields ``costs.effort`` and ``costs.dist`` (m) the costs come from them, else
    from Euclidean distances computed as :meth:`EscapeSearch.costs` does.
    """
    window, top, left = exposed
    best_cell, best_cost = best
    for t in tiles:
        if bounds[t] > best_cost * (1.0 + BOUND_SLACK):
            return best_cell, best_cost, True
        best_cell, best_cost = _score_tile(t, cells, window, top, left, costs, best_cell, best_cost)
    return best_cell, best_cost, False


@njit(cache=True, inline="always")
def _score_tile(
    t: int,
    cells: tuple,
    window: np.ndarray,
    top: int,
    left: int,
    costs: tuple,
    best_cell: int,
    best_cost: float,
) -> tuple[int, float]:
    """The argmin of the (flat cell, cost) ``best_cell, best_cost`` and tile ``t``'s
    ``cells`` outside the bool ``window`` placed at (top, left) (cells off it are
    outside): lowest cost, then lowest flat index."""
    starts, rows, cols, frame, grid_width = cells
    agents, effort, dist = costs
    ex, ey, px, py = agents
    height, width = window.shape
    for k in range(starts[t], starts[t + 1]):
        row, col = rows[k] - top, cols[k] - left
        if 0 <= row < height and 0 <= col < width and window[row, col]:
            continue
        cell = rows[k] * grid_width + cols[k]
        if effort.size:
            e, d = effort[cell], dist[cell]
        else:
            x, y = cell_centre(rows[k], cols[k], frame)
            ax, ay, bx, by = x - ex, y - ey, x - px, y - py
            e, d = math.sqrt(ax * ax + ay * ay), math.sqrt(bx * bx + by * by)
        cost = e / d if d > 0.0 else np.inf
        if cost < best_cost or (cost == best_cost and (best_cell < 0 or cell < best_cell)):
            best_cell, best_cost = cell, cost
    return best_cell, best_cost


@njit(cache=True)
def escape_goal(
    cells: tuple,
    tiles: tuple,
    sight: tuple,
    rays: tuple,
    half_widths: np.ndarray,
    agents: tuple,
    scratch: tuple,
) -> tuple[int, float]:
    """Algorithm 2's argmin (flat cell, cost; (-1, inf) without a candidate) for the
    evader and the pursuer at ``agents`` (ex, ey, px, py, pursuer heading) (m, rad), over
    a component's tiled ``cells`` (:class:`TiledCells`) with its ``tiles`` (boxes (T, 4),
    groups), as :meth:`EscapeSearch.kernel_inputs` gives them, computing the pursuer's
    visibility region only where the search looks: the goal and cost of
    :meth:`EscapeSearch.escape` without its count and sample of the candidates.

    Tiles are scored in increasing bound from a heap, as far as :func:`_best_candidate`
    scores them (its argmin does not depend on the order of equal bounds: every tile whose
    bound is within the slack of the final cost is scored). The heap starts with groups
    of GROUP x GROUP tiles (:func:`_group_tiles`) under their box's bound, no larger than
    their tiles' bounds; a group popped puts its tiles in, so the bounds of most tiles
    are never computed. For a tile, V grown by the hide margin (``half_widths``,
    :func:`disc_half_widths`) is only needed on its cells, so V is needed on the tile's
    block grown by the margin: the rays that can reach that block, as far as they can
    reach it (:func:`pegame.visibility.lazy.rays_reaching`), marched as the whole region
    marches them (:func:`pegame.visibility.region.march_ray`) and kept for later tiles. A
    ray marks the same cells whichever others are marched, so on the block the marks are
    the whole region's. A ray needed further than it was marched is marched RAY_SLACK
    samples beyond the need. A tile whose block no ray reaches, or that holds no mark,
    has no cell in grown V.

    sight: (blocked (H, W), kernel_frame, grid yaw) as :class:`pegame.visibility.lazy.Sight`;
    rays: the camera's :class:`pegame.visibility.lazy.Rays`; scratch: (bool (H, W) all
    False, int64 (rays,) all 0, int64 (samples,)), left as found. A ray is marched in
    pieces, each sample once: its scratch entry holds the samples marched, or -1 - the
    index of the blocked sample that stopped it.
    """
    boxes, groups = tiles
    blocked, frame, yaw = sight
    angles, distances, first = rays[0], rays[1], rays[2]
    mask, marched, ray_cells = scratch
    shape, flat = blocked.shape, (blocked.ravel(), mask.ravel())
    ex, ey, px, py, heading = agents
    eye = (px, py, heading)
    costs = ((ex, ey, px, py), np.zeros(0), np.zeros(0))
    group_boxes, group_starts, members = groups
    keys, items = (
        np.empty(group_boxes.shape[0] + boxes.shape[0]),
        np.empty(group_boxes.shape[0] + boxes.shape[0], dtype=np.int64),
    )
    size = 0
    for g in range(group_boxes.shape[0]):  # a group g is the item -1 - g, a tile t is t
        size = _push(keys, items, size, _box_bound(group_boxes, g, ex, ey, px, py), -1 - g)
    reach = half_widths.size - 1
    height, width = blocked.shape
    window = np.zeros((TILE, TILE), dtype=np.bool_)
    counts = np.empty((TILE + 2 * reach, TILE + 2 * reach + 1), dtype=np.int64)
    cos_a, sin_a = np.zeros(0), np.zeros(0)
    marked = (height, 0, width, 0)  # the rows and columns marks were made in
    lo_ray, hi_ray = angles.size, 0  # the rays marched
    best_cell, best_cost = -1, np.inf
    starts, rows, cols = cells[0], cells[1], cells[2]
    while size > 0:
        if keys[0] > best_cost * (1.0 + BOUND_SLACK):
            break
        t = items[0]
        size = _pop(keys, items, size)
        if t < 0:  # a group: its tiles join the heap
            for m in range(group_starts[-1 - t], group_starts[-t]):
                bound = _box_bound(boxes, members[m], ex, ey, px, py)
                size = _push(keys, items, size, bound, members[m])
            continue
        top = rows[starts[t]] // TILE * TILE
        left = cols[starts[t]] // TILE * TILE
        block = (
            max(top - reach, 0),
            min(top + TILE - 1 + reach, height - 1),
            max(left - reach, 0),
            min(left + TILE - 1 + reach, width - 1),
        )
        i0, i1, samples = rays_reaching(rays, eye, frame, yaw, block)
        seen = i1 > i0 and samples > first
        if seen:
            if cos_a.size == 0:
                cos_a, sin_a = directions(heading, angles, 0, angles.size)
            for i in range(i0, i1):
                done = marched[i]  # the samples marched (or -1 - the blocked one's index)
                if 0 <= done < samples:
                    ray = (cos_a[i], sin_a[i])
                    ahead = distances[done : min(samples + RAY_SLACK, distances.size)]
                    stop, marked = march_ray(
                        flat,
                        shape,
                        ray,
                        ahead,
                        max(first - done, 0),
                        px,
                        py,
                        frame,
                        ray_cells,
                        marked,
                    )
                    marched[i] = done + ahead.size if stop == ahead.size else -1 - (done + stop)
            lo_ray, hi_ray = min(lo_ray, i0), max(hi_ray, i1)
        # No mark near the tile: no cell of it lies in grown V.
        r0, r1, c0, c1 = marked
        seen = seen and r0 <= block[1] and block[0] < r1 and c0 <= block[3] and block[2] < c1
        if seen:
            _grown_tile(mask, top, left, half_widths, counts, window)
        else:
            window[:] = False
        best_cell, best_cost = _score_tile(t, cells, window, top, left, costs, best_cell, best_cost)
    r0, r1, c0, c1 = marked
    if r1 > r0:
        mask[r0:r1, c0:c1] = False
    if hi_ray > lo_ray:
        marched[lo_ray:hi_ray] = 0
    return best_cell, best_cost


@njit(cache=True)
def _grown_tile(
    mask: np.ndarray,
    top: int,
    left: int,
    half_widths: np.ndarray,
    counts: np.ndarray,
    window: np.ndarray,
) -> None:
    """Set the bool (TILE, TILE) ``window`` to the cells of the tile at (top, left) that
    :func:`_grow` marks from the True cells of ``mask`` (those within the disc of
    ``half_widths`` of one, the disc being symmetric), by running counts of the marks
    along the rows about the tile (``counts``: int scratch (TILE + 2 R, TILE + 2 R + 1),
    R the disc's reach)."""
    reach = half_widths.size - 1
    height, width = mask.shape
    for i in range(TILE + 2 * reach):
        row = top - reach + i
        total = 0
        counts[i, 0] = 0
        for j in range(TILE + 2 * reach):
            col = left - reach + j
            if 0 <= row < height and 0 <= col < width and mask[row, col]:
                total += 1
            counts[i, j + 1] = total
    for r in range(TILE):
        for c in range(TILE):
            near = False
            for offset in range(-reach, reach + 1):
                half = half_widths[abs(offset)]
                i = r + reach + offset
                # columns c - half .. c + half, at j = c + reach - half .. c + reach + half
                if counts[i, c + reach + half + 1] > counts[i, c + reach - half]:
                    near = True
                    break
            window[r, c] = near


@njit(cache=True, inline="always")
def _push(keys: np.ndarray, items: np.ndarray, size: int, key: float, item: int) -> int:
    """Add ``item`` with ``key`` to the binary min-heap keys[:size], items[:size]; the new
    size."""
    slot = size
    while slot > 0:
        parent = (slot - 1) >> 1
        if keys[parent] <= key:
            break
        keys[slot], items[slot] = keys[parent], items[parent]
        slot = parent
    keys[slot], items[slot] = key, item
    return size + 1


@njit(cache=True, inline="always")
def _pop(keys: np.ndarray, items: np.ndarray, size: int) -> int:
    """Remove the root of the binary min-heap keys[:size], items[:size]; the new size."""
    size -= 1
    key, item = keys[size], items[size]
    slot = 0
    while True:
        child = 2 * slot + 1
        if child >= size:
            break
        if child + 1 < size and keys[child + 1] < keys[child]:
            child += 1
        if keys[child] >= key:
            break
        keys[slot], items[slot] = keys[child], items[child]
        slot = child
    keys[slot], items[slot] = key, item
    return size


@njit(cache=True)
def _sample_positions(skipped: np.ndarray, count: int, step: int) -> np.ndarray:
    """Indices in a list of the candidates numbered 0, step, 2 step, ... < count, where
    the candidates are the list's entries except the increasing indices ``skipped``."""
    picked = np.empty((count + step - 1) // step, dtype=np.int64)
    passed = 0
    for j in range(picked.size):
        index = j * step + passed
        while passed < skipped.size and skipped[passed] <= index:
            passed += 1
            index += 1
        picked[j] = index
    return picked


# ------------------------------------------------------------------ candidate cells


@njit(cache=True)
def _group_by_tile(
    candidate: np.ndarray, frame: tuple
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The cells of the bool (H, W) mask ``candidate``, row-major and grouped by tile.

    Returns (cells, position, rows, cols, starts, boxes): the flat indices (K,) in
    row-major order; per flat cell its index in ``cells``, -1 elsewhere; the rows and
    columns (K,) grouped by TILE x TILE tile (tiles row-major, cells row-major within a
    tile); where each non-empty tile's cells begin in them, (T + 1,); and each tile's
    box (x min, x max, y min, y max) (m) of its cell centres, (T, 4), centres as
    ``frame`` (``OccupancyGrid.kernel_frame``) places them. Int32 indices: this is the
    largest per-map structure of the smart evader.
    """
    height, width = candidate.shape
    count = 0
    for row in range(height):
        for col in range(width):
            count += candidate[row, col]
    cells = np.empty(count, dtype=np.int32)
    position = np.full(height * width, -1, dtype=np.int32)
    k = 0
    for row in range(height):
        for col in range(width):
            if candidate[row, col]:
                cells[k] = row * width + col
                position[row * width + col] = k
                k += 1
    rows = np.empty(count, dtype=np.int32)
    cols = np.empty(count, dtype=np.int32)
    most = ((height + TILE - 1) // TILE) * ((width + TILE - 1) // TILE)
    starts = np.empty(most + 1, dtype=np.int64)
    boxes = np.empty((most, 4))
    tiles, k = 0, 0
    for top in range(0, height, TILE):
        for left in range(0, width, TILE):
            first = k
            x0, x1, y0, y1 = np.inf, -np.inf, np.inf, -np.inf
            for row in range(top, min(top + TILE, height)):
                for col in range(left, min(left + TILE, width)):
                    if candidate[row, col]:
                        rows[k], cols[k] = row, col
                        k += 1
                        x, y = cell_centre(row, col, frame)
                        x0, x1, y0, y1 = min(x0, x), max(x1, x), min(y0, y), max(y1, y)
            if k > first:
                starts[tiles] = first
                boxes[tiles, 0], boxes[tiles, 1] = x0, x1
                boxes[tiles, 2], boxes[tiles, 3] = y0, y1
                tiles += 1
    starts[tiles] = count
    return cells, position, rows, cols, starts[: tiles + 1].copy(), boxes[:tiles].copy()


@dataclass(frozen=True, eq=False)
class _Component:
    """The candidate cells (on the candidate stride) of one connected component.

    mask: bool (H, W), the component. groups: its tiles grouped, as :func:`_group_tiles`
    returns them. The rest as :func:`_group_by_tile` returns them:
    cells, flat indices (K,), row-major; position, (H * W,) index of each flat cell in
    ``cells``, -1 elsewhere; rows and cols (K,), the cells grouped by tile; starts, (T +
    1,) where each tile's cells begin in rows and cols; boxes, (T, 4) (x min, x max, y
    min, y max) (m) of each tile's centres.
    """

    mask: np.ndarray
    cells: np.ndarray
    position: np.ndarray
    rows: np.ndarray
    cols: np.ndarray
    starts: np.ndarray
    boxes: np.ndarray
    groups: tuple[np.ndarray, np.ndarray, np.ndarray]

    @classmethod
    def build(cls, mask: np.ndarray, strided: np.ndarray, frame: tuple) -> _Component:
        """The component ``mask`` (bool (H, W)) with its cells on the ``strided`` mask
        (bool (H, W)) of a grid with map-to-cell transform ``frame``."""
        cells, position, rows, cols, starts, boxes = _group_by_tile(mask & strided, frame)
        groups = _group_tiles(rows, cols, starts, boxes)
        return cls(mask, cells, position, rows, cols, starts, boxes, groups)


def _group_tiles(
    rows: np.ndarray, cols: np.ndarray, starts: np.ndarray, boxes: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The tiles (as :func:`_group_by_tile` returns them) in groups of GROUP x GROUP tiles:
    (group boxes (G, 4), the smallest holding their tiles' boxes; where each group's
    tiles begin in ``members``, (G + 1,); members (T,), the tiles, group by group)."""
    first = starts[:-1]
    span = TILE * GROUP
    key = (rows[first].astype(np.int64) // span) * (cols.max(initial=0) // span + 1) + (
        cols[first].astype(np.int64) // span
    )
    members = np.argsort(key, kind="stable")
    ordered = key[members]
    begins = np.flatnonzero(np.r_[True, ordered[1:] != ordered[:-1]]) if members.size else members
    group_starts = np.append(begins, members.size).astype(np.int64)
    sorted_boxes = boxes[members]
    group_boxes = np.empty((begins.size, 4))
    if begins.size:
        group_boxes[:, 0] = np.minimum.reduceat(sorted_boxes[:, 0], begins)
        group_boxes[:, 1] = np.maximum.reduceat(sorted_boxes[:, 1], begins)
        group_boxes[:, 2] = np.minimum.reduceat(sorted_boxes[:, 2], begins)
        group_boxes[:, 3] = np.maximum.reduceat(sorted_boxes[:, 3], begins)
    return group_boxes, group_starts, members.astype(np.int64)


class EscapeSearch:
    """Algorithm 2's argmin for one evader (module docstring), fast and by reference.

    planner: the evader's (shared per map and radius); pursuer_planner: the pursuer's,
    for geodesic distances only (None for Euclidean ones). camera: the pursuer's, for
    the regions not given. distance: one of DISTANCES; candidate_stride: k >= 1;
    hide_margin: m >= 0.
    """

    def __init__(
        self,
        grid: OccupancyGrid,
        camera: Camera,
        planner: Planner,
        pursuer_planner: Planner | None,
        distance: str,
        candidate_stride: int,
        hide_margin: float,
    ) -> None:
        self.grid, self.camera = grid, camera
        self.planner, self.pursuer_planner = planner, pursuer_planner
        self.distance, self.candidate_stride = distance, candidate_stride
        self.hide_margin = hide_margin
        stride = np.arange(max(grid.height, grid.width)) % candidate_stride == 0
        self._strided = stride[: grid.height, None] & stride[None, : grid.width]
        self._half_widths = disc_half_widths(hide_margin, grid.resolution)
        self._component: _Component | None = None
        self._scratch: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    def escape(self, me: Pose, pursuer: Pose, visible: Region | None = None) -> Escape:
        """Algorithm 2's argmin for the evader at ``me`` and the pursuer at ``pursuer``:
        the same result as :meth:`escape_reference`, by the kernels (module docstring).

        visible: the pursuer's visibility region at ``pursuer`` when the caller has it
        (the game computes it every tick), else computed here for the camera.
        """
        grid = self.grid
        if visible is None:
            visible = VisibilityRegion(grid, pursuer, self.camera)
        component = self.component_at(me)
        exposed, top, left = self._exposed(visible)
        skipped = _exposed_positions(exposed, top, left, grid.width, component.position)
        count = component.cells.size - skipped.size
        if count == 0:
            return Escape(-1, math.inf, 0, np.zeros(0, dtype=np.int64))
        bounds, effort, dist = self._bounds(component, me, pursuer)
        cells = TiledCells(
            component.starts, component.rows, component.cols, grid.kernel_frame, grid.width
        )
        costs = Costs((me.x, me.y, pursuer.x, pursuer.y), effort, dist)
        # Plain tuples for the kernel: numba types a NamedTuple argument in Python, each
        # of its fields again (microseconds with a nested tuple), a plain tuple in C.
        arguments = (bounds, tuple(cells), tuple(Window(exposed, top, left)), tuple(costs))
        # Tiles in increasing bound, the FIRST_TILES lowest sorted first: the search
        # nearly always stops among them, and sorting every tile of a large map is most
        # of a decision. The rest follow (sorted) only when it did not.
        if bounds.size > FIRST_TILES:
            split = np.argpartition(bounds, FIRST_TILES)
            first, rest = split[:FIRST_TILES], split[FIRST_TILES:]
        else:
            first, rest = np.arange(bounds.size), np.zeros(0, dtype=np.int64)
        first = first[np.argsort(bounds[first])]
        cell, cost, stopped = _best_candidate(first, *arguments, (-1, math.inf))
        if not stopped and rest.size:
            rest = rest[np.argsort(bounds[rest])]
            cell, cost, stopped = _best_candidate(rest, *arguments, (cell, cost))
        step = _sample_step(count, MAX_RECORDED_CANDIDATES)
        sample = component.cells[_sample_positions(skipped, count, step)].astype(np.int64)
        return Escape(int(cell), float(cost), count, sample)

    def goal(self, me: Pose, pursuer: Pose) -> tuple[int, float]:
        """:meth:`escape`'s goal cell and cost (-1 and +inf without a candidate) for a
        pursuer whose region is not at hand, computing the region only where the search
        looks (:func:`escape_goal`; Euclidean distances only)."""
        if self.distance != "euclidean":
            raise ValueError("EscapeSearch.goal computes Euclidean distances only.")
        component = self.component_at(me)
        agents = (me.x, me.y, pursuer.x, pursuer.y, pursuer.theta)
        cells, tiles, sight, rays, half_widths = self.kernel_inputs(component)
        cell, cost = escape_goal(cells, tiles, sight, rays, half_widths, agents, self.scratch())
        return int(cell), float(cost)

    def kernel_inputs(self, component: _Component) -> tuple[tuple, tuple, tuple, tuple, np.ndarray]:
        """:func:`escape_goal`'s arguments before ``agents`` for the evaders of
        ``component``: (cells, tiles, sight, rays, half_widths)."""
        grid = self.grid
        cells = TiledCells(
            component.starts, component.rows, component.cols, grid.kernel_frame, grid.width
        )
        return tuple(cells), (component.boxes, component.groups), *self.view_inputs()

    def view_inputs(self) -> tuple[tuple, tuple, np.ndarray]:
        """:func:`escape_goal`'s (sight, rays, half_widths): the grid, the pursuer's
        camera and the hide margin as the kernel takes them."""
        sight, rays = sight_and_rays(self.grid, self.camera)
        return sight, rays, self._half_widths

    def scratch(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:func:`escape_goal`'s scratch memory for this search's grid and camera, made at
        the first call (the kernel leaves it as it found it)."""
        if self._scratch is None:
            angles, distances, _ = ray_tables(self.camera)
            self._scratch = (
                np.zeros(self.grid.blocked.shape, dtype=np.bool_),
                np.zeros(angles.size, dtype=np.int64),
                np.empty(distances.size, dtype=np.int64),
            )
        return self._scratch

    def escape_reference(self, me: Pose, pursuer: Pose) -> Escape:
        """:meth:`escape` in plain numpy over every candidate: the tests' reference."""
        cells = self.candidates(me, pursuer)
        if cells.size == 0:
            return Escape(-1, math.inf, 0, cells)
        cost = self.costs(me, pursuer, cells)
        best = int(np.argmin(cost))  # first minimum = lowest row-major index among ties
        sample = subsample(cells, MAX_RECORDED_CANDIDATES)
        return Escape(int(cells[best]), float(cost[best]), cells.size, sample)

    def candidates(self, me: Pose, pursuer: Pose) -> np.ndarray:
        """Flat row-major indices (row * width + col, increasing) of the candidate cells:
        reachable by the evader at ``me``, outside the visibility region of the pursuer at
        ``pursuer`` (grown by the hide margin), and on the candidate stride. Plain numpy,
        part of :meth:`escape_reference`."""
        grid = self.grid
        visible = visibility_region(grid, pursuer, self.camera)
        if self.hide_margin > 0 and visible.any():
            # Hidden means the whole body is out of view, not only its centre's cell.
            visible = distance_transform_edt(~visible) * grid.resolution <= self.hide_margin
        mask = self.planner.reachable((me.x, me.y)) & ~visible & self._strided
        return np.flatnonzero(mask)

    def costs(self, me: Pose, pursuer: Pose, cells: np.ndarray) -> np.ndarray:
        """Algorithm 2's cost_escape (dimensionless) of the flat-indexed candidate ``cells``."""
        if self.distance == "euclidean":
            x, y = self.centres(cells).T
            effort = np.sqrt((x - me.x) ** 2 + (y - me.y) ** 2)
            dist = np.sqrt((x - pursuer.x) ** 2 + (y - pursuer.y) ** 2)
        else:
            effort = self.planner.distance_field((me.x, me.y)).ravel()[cells]
            dist = self.pursuer_distances(pursuer)[cells]
        return escape_costs(effort, dist)

    def pursuer_distances(self, pursuer: Pose) -> np.ndarray:
        """Float (H * W,): the geodesic distance (m) of each flat cell from the pursuer at
        ``pursuer`` (geodesic distances only: the pursuer's planner)."""
        if self.pursuer_planner is None:
            raise ValueError("Geodesic distances need the pursuer's planner (pursuer_planner).")
        return self.pursuer_planner.distance_field((pursuer.x, pursuer.y)).ravel()

    def centres(self, cells: ArrayLike) -> np.ndarray:
        """Float (..., 2): the map-frame centres (m) of flat row-major cell indices (an
        index or an array of them), as :meth:`OccupancyGrid.cell_to_world` gives them."""
        cells = np.asarray(cells, dtype=np.int64)
        grid = self.grid
        return cell_centres(cells.ravel(), grid.width, grid.kernel_frame).reshape(*cells.shape, 2)

    def component_at(self, me: Pose) -> _Component:
        """The candidate cells of the evader's connected component: the one last used when
        the cell the planner starts from (the evader's, or the nearest traversable one)
        lies in it, else one built for an earlier game on this map (components are
        disjoint, and shared by every evader with the same planner and candidate stride),
        else a new one."""
        grid = self.grid
        # Components depend on the traversable cells (the planner's radius) and the stride.
        key = ("evaders.escape", "components", self.planner.radius, self.candidate_stride)
        shared: list[_Component] = per_grid(grid, key, lambda grid: [])
        row, col = grid.world_to_cell(me.x, me.y)
        on_grid = 0 <= row < grid.height and 0 <= col < grid.width
        source = None
        for component in [self._component, *shared]:
            if component is None:
                continue
            # A cell of a component is traversable, so it is the start cell itself.
            if on_grid and component.mask[row, col]:
                self._component = component
                return component
            if source is None:
                source = self.planner.nearest_traversable((me.x, me.y))
            if source is not None and component.mask[grid.world_to_cell(*source)]:
                self._component = component
                return component
        reachable = self.planner.reachable((me.x, me.y))
        self._component = _Component.build(reachable, self._strided, grid.kernel_frame)
        shared.append(self._component)
        return self._component

    def _exposed(self, visible: Region) -> tuple[np.ndarray, int, int]:
        """V grown by the hide margin (no candidate lies there) over a window: a bool
        mask, its top row and its left column."""
        r0, r1, c0, c1 = visible.bounds
        if r1 <= r0:
            return np.zeros((0, 0), dtype=bool), 0, 0
        return _grow(visible.mask, r0, r1, c0, c1, self._half_widths)

    def _bounds(
        self, component: _Component, me: Pose, pursuer: Pose
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per-tile cost lower bounds (T,) and, for geodesic distances, the flat effort and
        dist fields (m) (empty arrays for Euclidean ones)."""
        if self.distance == "euclidean":
            bounds = _tile_bounds(component.boxes, me.x, me.y, pursuer.x, pursuer.y)
            return bounds, np.zeros(0), np.zeros(0)
        # Path lengths have no useful bound: a cell out of the pursuer's reach costs 0.
        effort = self.planner.distance_field((me.x, me.y)).ravel()
        dist = self.pursuer_distances(pursuer)
        return np.zeros(component.boxes.shape[0]), effort, dist
