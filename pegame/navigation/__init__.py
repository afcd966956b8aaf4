"""Grid navigation: the role ROS move_base plays in the paper.

In the paper every agent reaches its goal through move_base: a global planner on an
inflated costmap and a local controller that drives a non-holonomic robot along the
plan. This module provides the same three pieces for occupancy grids:

* :func:`inflate` - the inflated obstacle mask (the costmap's lethal + inscribed zone);
  the grid simulator uses ``inflate(grid, body.radius)`` as the collision mask of an
  agent's centre.
* :class:`Planner` - global planning on the grid: geodesic distance fields (Dijkstra)
  and minimum-cost paths (A*) on 8-connected moves, with a cost that keeps paths clear
  of walls like move_base's inflation decay.
* :class:`PathFollower` - a pure-pursuit local controller for a unicycle.

Units and frames: positions are map-frame (x, y) in metres (ROS conventions, see
:mod:`pegame.grid`), headings and angles in radians, speeds in m/s and rad/s. Grid
arrays are (height, width) indexed [row, col] with row 0 the lowest y; distances and
costs are in metres.

Grid moves: a path steps between the centres of 8-neighbouring traversable cells; a
diagonal step is allowed only when both cells it passes between are traversable too,
so the straight segment never touches a non-traversable cell (no corner cutting). As a
consequence two cells are connected exactly when they are 4-connected.

The search kernels are compiled with numba; ``_distance_field_reference`` and
``_astar_reference`` are plain-Python implementations of the same algorithms that the
tests compare the kernels against, as ``_follow_reference`` is for the follower's kernel.

Sharing: a planner and the derived masks depend only on the grid and a few numbers, and
building one takes milliseconds, so :meth:`Planner.shared` and :func:`shared_inflation`
build them once per grid and parameters and hand the same read-only objects to every
caller (the game's spawn, both strategies, the simulator). A planner's only mutable state
is scratch memory of its searches, restored by every search before it returns; the numba
kernels hold the GIL, so two threads never use it at once.
"""

from __future__ import annotations

import heapq
import inspect
import math
from dataclasses import dataclass

import numpy as np
from numba import njit
from scipy import ndimage

from pegame.types import STOP, Body, Pose, Velocity, clamp, wrap_angle
from pegame.errors import require
from pegame.grid import OccupancyGrid

SQRT2 = math.sqrt(2.0)

#: the 8 moves as (row step, col step); orthogonal moves first
_MOVES = np.array(
    [(1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (1, -1), (-1, 1), (-1, -1)], dtype=np.int64
)

#: distances equal to the radius up to float rounding count as within it (m)
_DISTANCE_TOLERANCE = 1e-9

#: grids with at least this many cells get landmarks by default (see Planner)
LARGE_GRID_CELLS = 1_000_000
#: landmarks of a planner on a large grid by default
LARGE_GRID_LANDMARKS = 12


# --------------------------------------------------------------------------- inflation


def obstacle_distance(grid: OccupancyGrid) -> np.ndarray:
    """Float64 (H, W): distance (m) from each cell centre to the nearest blocked cell centre.

    Blocked cells (occupied or unknown) are at distance 0, and every cell outside the grid
    counts as blocked, so no cell is farther than its distance to the ring of cells just
    outside the border.
    """
    # One ring of blocked padding is enough: the nearest outside cell is always in it.
    free = np.pad(~grid.blocked, 1, constant_values=False)
    distance = ndimage.distance_transform_edt(free, sampling=grid.resolution)
    return distance[1:-1, 1:-1]


def inflate(grid: OccupancyGrid, radius: float) -> np.ndarray:
    """Bool (H, W): True where a disc of ``radius`` (m) centred on the cell centre would
    contain the centre of a blocked cell, counting cells outside the grid as blocked.

    Blocked cells are always True. An agent's centre may never lie in a True cell of
    ``inflate(grid, body.radius)``. The result is a new writable array; see
    :func:`shared_inflation` for the shared read-only one.
    """
    return _shared_obstacle_distance(grid) <= radius + _DISTANCE_TOLERANCE


def shared_inflation(grid: OccupancyGrid, radius: float) -> np.ndarray:
    """``inflate(grid, radius)``, computed once per grid and radius and shared (read-only)."""
    cache = _grid_cache(grid)
    key = ("inflation", float(radius))
    if key not in cache:
        cache[key] = _read_only(inflate(grid, radius))
    return cache[key]


def _shared_obstacle_distance(grid: OccupancyGrid) -> np.ndarray:
    """:func:`obstacle_distance`, computed once per grid (read-only)."""
    cache = _grid_cache(grid)
    if "obstacle_distance" not in cache:
        cache["obstacle_distance"] = _read_only(obstacle_distance(grid))
    return cache["obstacle_distance"]


class _GridCache(dict):
    """Objects derived from one grid. A pickled or copied grid gets an empty cache: its
    contents are rebuilt on demand and can be large."""

    def __reduce__(self):
        return (_GridCache, ())


def _grid_cache(grid: OccupancyGrid) -> _GridCache:
    """The cache of objects derived from ``grid``, stored on the grid itself.

    Stored on the grid, the cache lives exactly as long as the grid; a module-level
    WeakKeyDictionary would keep every grid alive, since the cached planners refer to it.
    The grid's arrays are read-only, so whatever is derived from them stays valid.
    """
    cache = vars(grid).get("_navigation_cache")
    if cache is None:
        cache = _GridCache()
        object.__setattr__(grid, "_navigation_cache", cache)  # the grid is a frozen dataclass
    return cache


def _read_only(array: np.ndarray) -> np.ndarray:
    """``array``, flagged read-only (it is shared)."""
    array.setflags(write=False)
    return array


# ----------------------------------------------------------------------- numba kernels
# The kernels work on flat arrays of the grid padded with one ring of non-traversable
# cells, so a neighbour is a fixed index offset and needs no bounds check. Which of the 8
# moves a cell allows (target traversable, no corner cutting) is precomputed as one bit per
# move, so a search reads one byte per cell instead of up to three traversable flags per
# move.


def _pad_flat(array: np.ndarray, fill) -> np.ndarray:
    """``array`` (H, W) padded with one ring of ``fill``, flattened to ((H+2) * (W+2),)."""
    return np.pad(array, 1, constant_values=fill).ravel()


@njit(cache=True)
def _move_tables(padded_width, moves, resolution):
    """Flat index offsets (cells) and lengths (m) of the 8 moves."""
    offsets = moves[:, 0] * padded_width + moves[:, 1]
    lengths = np.empty(8)
    for k in range(8):
        diagonal = moves[k, 0] != 0 and moves[k, 1] != 0
        lengths[k] = resolution * SQRT2 if diagonal else resolution
    return offsets, lengths


@njit(cache=True)
def _allowed_moves(traversable, padded_width, moves):
    """Uint8 per flat padded cell: bit k set when move k is allowed from the cell, i.e. the
    cell and its target are traversable and, for a diagonal move, so are the two cells it
    passes between."""
    allowed = np.zeros(traversable.size, dtype=np.uint8)
    offsets = moves[:, 0] * padded_width + moves[:, 1]
    for u in range(padded_width, traversable.size - padded_width):
        if not traversable[u]:
            continue
        for k in range(8):
            if not traversable[u + offsets[k]]:
                continue
            if moves[k, 0] != 0 and moves[k, 1] != 0:
                if not (traversable[u + moves[k, 0] * padded_width] and traversable[u + moves[k, 1]]):
                    continue
            allowed[u] |= 1 << k
    return allowed


@njit(cache=True)
def _dijkstra(allowed, multipliers, weighted, resolution, padded_width, source, moves, entry_cell,
              entry_next):
    """Least path cost (m) from flat cell ``source`` to every cell; inf if unreachable.

    Dijkstra with a bucket queue (Dinitz's variant of Dial's algorithm): bucket b holds
    cells with cost in [b w, (b+1) w) for a width w no larger than the cheapest move, so
    no cell can improve another in its own bucket and every cell of the lowest bucket is
    final. This gives the same costs as a binary heap at a fraction of the time. Buckets
    are singly linked lists in the entry pool ``entry_cell``/``entry_next`` (scratch, int32)
    kept on a ring; a cell whose cost drops is added again and its older entries are
    skipped. Returns (costs, True), or (partial costs, False) when the pool was too small
    (a cell enters it at most once per neighbour, so 8 n + 1 entries always suffice).
    """
    n = allowed.size
    offsets, lengths = _move_tables(padded_width, moves, resolution)
    max_step = resolution * SQRT2 * (multipliers.max() if weighted else 1.0)
    # Slightly narrower than the cheapest move (resolution) so rounding cannot break the
    # invariant; bucket indices are also forced past the current bucket.
    width = resolution * (1.0 - 1e-9)
    inverse_width = 1.0 / width
    # A power-of-two ring turns the modulo into a mask (an integer division is slow).
    ring = 1
    while ring < int(max_step / width) + 3:
        ring *= 2
    wrap = ring - 1
    dist = np.full(n, np.inf)
    done = np.zeros(n, dtype=np.bool_)
    head = np.full(ring, -1, dtype=np.int32)
    dist[source] = 0.0
    entry_cell[0], entry_next[0], head[0] = source, -1, 0
    used, pending, bucket = 1, 1, 0
    while pending > 0:
        slot = bucket & wrap
        while head[slot] != -1:
            entry = head[slot]
            head[slot] = entry_next[entry]
            pending -= 1
            u = entry_cell[entry]
            if done[u]:
                continue
            done[u] = True
            moves_u = allowed[u]
            for k in range(8):
                if not (moves_u >> k) & 1:
                    continue
                v = u + offsets[k]
                if done[v]:
                    continue
                step = lengths[k]
                if weighted:
                    step = step * (0.5 * (multipliers[u] + multipliers[v]))
                candidate = dist[u] + step
                if candidate < dist[v]:
                    if used == entry_cell.size:
                        return dist, False
                    dist[v] = candidate
                    target = max(int(candidate * inverse_width), bucket + 1) & wrap
                    entry_cell[used], entry_next[used] = v, head[target]
                    head[target] = used
                    used += 1
                    pending += 1
        bucket += 1
    return dist, True


@njit(cache=True)
def _sift_up(keys, ties, nodes, pos, slot, node, key, tie):
    """Place ``node`` with (key, tie) at heap ``slot`` or above.

    The heap is an indexed binary min-heap with decrease-key: per slot a key, a tie-break
    (smaller first) and a node; pos[node] is the node's slot, or -1 when not queued.
    """
    while slot > 0:
        parent = (slot - 1) >> 1
        if keys[parent] < key or (keys[parent] == key and ties[parent] <= tie):
            break
        keys[slot] = keys[parent]
        ties[slot] = ties[parent]
        nodes[slot] = nodes[parent]
        pos[nodes[slot]] = slot
        slot = parent
    keys[slot] = key
    ties[slot] = tie
    nodes[slot] = node
    pos[node] = slot


@njit(cache=True)
def _pop(keys, ties, nodes, pos, size):
    """Remove and return the heap's minimum node; ``size`` is the size before removal."""
    top = nodes[0]
    pos[top] = -1
    size -= 1
    if size == 0:
        return top
    node, key, tie = nodes[size], keys[size], ties[size]
    slot = 0
    while True:
        child = 2 * slot + 1
        if child >= size:
            break
        right = child + 1
        # Branch-free choice of the smaller child (a data-dependent branch mispredicts
        # about every other time); keys beyond ``size`` are read but never chosen.
        key_r, key_c = keys[right], keys[child]
        child += (right < size) & ((key_r < key_c) | ((key_r == key_c) & (ties[right] < ties[child])))
        if key < keys[child] or (key == keys[child] and tie <= ties[child]):
            break
        keys[slot] = keys[child]
        ties[slot] = ties[child]
        nodes[slot] = nodes[child]
        pos[nodes[slot]] = slot
        slot = child
    keys[slot] = key
    ties[slot] = tie
    nodes[slot] = node
    pos[node] = slot
    return top


@njit(cache=True)
def _octile(resolution, row, col, goal_row, goal_col):
    """Octile distance (m) between two cells: a lower bound of any path cost."""
    dr = abs(row - goal_row)
    dc = abs(col - goal_col)
    return resolution * (max(dr, dc) + (SQRT2 - 1.0) * min(dr, dc))


@njit(cache=True)
def _astar(allowed, multipliers, resolution, padded_width, start, goal, moves, landmark_costs, g,
           parent, keys, ties, nodes, pos, touched):
    """Minimum weighted cost (m) and flat cell path from ``start`` to ``goal`` by A*.

    The heuristic is the octile distance, admissible and consistent because every
    multiplier is >= 1, or the larger landmark bound when ``landmark_costs`` (K, n) has
    rows (see ``Planner._landmark_table``). Returns (inf, empty) when the goal is
    unreachable. The other arrays (length n) are scratch: ``g`` must be all inf and
    ``pos`` all -1 on entry, and both are restored before returning (only the ``touched``
    cells are reset, not the whole grid).
    """
    offsets, lengths = _move_tables(padded_width, moves, resolution)
    goal_row, goal_col = goal // padded_width, goal % padded_width
    to_goal = landmark_costs[:, goal].copy()
    g[start] = 0.0
    touched[0] = start
    count = 1
    parent[start] = -1
    h = _octile(resolution, start // padded_width, start % padded_width, goal_row, goal_col)
    h = _landmark_bound(landmark_costs, to_goal, start, h)
    _sift_up(keys, ties, nodes, pos, 0, start, h, h)
    size = 1
    while size > 0:
        u = _pop(keys, ties, nodes, pos, size)
        size -= 1
        if u == goal:
            break
        row, col = u // padded_width, u % padded_width
        moves_u = allowed[u]
        for k in range(8):
            if not (moves_u >> k) & 1:
                continue
            v = u + offsets[k]
            candidate = g[u] + lengths[k] * (0.5 * (multipliers[u] + multipliers[v]))
            if candidate < g[v]:
                if g[v] == np.inf:
                    touched[count] = v
                    count += 1
                g[v] = candidate
                parent[v] = u
                h = _octile(resolution, row + moves[k, 0], col + moves[k, 1], goal_row, goal_col)
                h = _landmark_bound(landmark_costs, to_goal, v, h)
                # Among equal f prefer the smaller h (the deeper cell), so open areas are
                # not flooded with ties.
                slot = pos[v] if pos[v] >= 0 else size
                if pos[v] < 0:
                    size += 1
                _sift_up(keys, ties, nodes, pos, slot, v, candidate + h, h)
    cost = g[goal]
    path = _trace(parent, start, goal) if np.isfinite(cost) else np.empty(0, dtype=np.int64)
    for i in range(count):
        g[touched[i]] = np.inf
        pos[touched[i]] = -1
    return cost, path


@njit(cache=True)
def _landmark_bound(landmark_costs, to_goal, v, h):
    """The largest of ``h`` and the landmark bounds |cost(L, goal) - cost(L, v)| (m)."""
    for k in range(to_goal.size):
        h = max(h, abs(to_goal[k] - landmark_costs[k, v]))
    return h


@njit(cache=True)
def _trace(parent, start, goal):
    """The flat cells from ``start`` to ``goal`` along the ``parent`` links."""
    count = 1
    node = goal
    while node != start:
        node = parent[node]
        count += 1
    path = np.empty(count, dtype=np.int64)
    node = goal
    for i in range(count - 1, -1, -1):
        path[i] = node
        node = parent[node]
    return path


# -------------------------------------------------------------- plain-Python references


def _reference_neighbours(traversable, multipliers, weighted, resolution, cell):
    """Yield (neighbour cell, step cost m) for the allowed moves from ``cell``."""
    height, width = traversable.shape
    r, c = cell
    for dr, dc in _MOVES.tolist():
        nr, nc = r + dr, c + dc
        if not (0 <= nr < height and 0 <= nc < width and traversable[nr, nc]):
            continue
        step = resolution
        if dr and dc:
            if not (traversable[r, nc] and traversable[nr, c]):
                continue
            step = resolution * SQRT2
        if weighted:
            step = step * (0.5 * (multipliers[r, c] + multipliers[nr, nc]))
        yield (nr, nc), step


def _distance_field_reference(traversable, multipliers, weighted, resolution, source):
    """Plain-Python Dijkstra with heapq; same contract as :func:`_dijkstra` but takes and
    returns (row, col) cells: float64 (H, W) costs (m) from ``source``, inf if unreachable."""
    dist = np.full(traversable.shape, np.inf)
    dist[source] = 0.0
    queue = [(0.0, source)]
    while queue:
        d, cell = heapq.heappop(queue)
        if d > dist[cell]:
            continue
        moves = _reference_neighbours(traversable, multipliers, weighted, resolution, cell)
        for nxt, step in moves:
            if d + step < dist[nxt]:
                dist[nxt] = d + step
                heapq.heappush(queue, (d + step, nxt))
    return dist


def _astar_reference(traversable, multipliers, resolution, start, goal):
    """Plain-Python A* with heapq and the octile heuristic on the weighted grid.

    Returns (cost m, list of (row, col) cells from start to goal), or (inf, []).
    """

    def heuristic(cell):
        dr, dc = abs(cell[0] - goal[0]), abs(cell[1] - goal[1])
        return resolution * (max(dr, dc) + (SQRT2 - 1.0) * min(dr, dc))

    g = {start: 0.0}
    parent = {start: None}
    queue = [(heuristic(start), start)]
    while queue:
        f, cell = heapq.heappop(queue)
        if cell == goal:
            break
        if f > g[cell] + heuristic(cell):
            continue
        for nxt, step in _reference_neighbours(traversable, multipliers, True, resolution, cell):
            if g[cell] + step < g.get(nxt, math.inf):
                g[nxt] = g[cell] + step
                parent[nxt] = cell
                heapq.heappush(queue, (g[nxt] + heuristic(nxt), nxt))
    if goal not in g:
        return math.inf, []
    path = [goal]
    while parent[path[-1]] is not None:
        path.append(parent[path[-1]])
    return g[goal], path[::-1]


# ---------------------------------------------------------------------------- planner


@dataclass(frozen=True, eq=False)
class PathResult:
    """A planned path.

    path: float (K, 2) map-frame waypoints (m) from start to goal: cell centres, then the
    exact goal point when its cell is traversable; empty when unreachable. length: the
    polyline length of ``path`` (m). cost: the weighted grid cost of the cell path (m,
    see :class:`Planner`); inf when unreachable. reachable: whether a path was found.
    reason: '' when reachable, else why not.
    """

    path: np.ndarray
    length: float
    reachable: bool
    reason: str = ""
    cost: float = math.inf


def _unreachable(reason: str) -> PathResult:
    return PathResult(np.zeros((0, 2)), 0.0, False, reason)


class Planner:
    """Global planner on one map for one agent size.

    grid: the occupancy map. radius: the agent's radius (m). margin (m): extra inflation
    so planned paths stay executable by an agent whose collision mask is
    ``inflate(grid, radius)``; a cell is traversable when it is outside
    ``inflate(grid, radius + margin)``. clearance (m) and clearance_weight: a traversable
    cell whose centre is d metres beyond the inflation zone (d = obstacle distance -
    radius - margin) costs ``1 + clearance_weight * max(0, 1 - d / clearance)`` times its
    length, so paths keep clear of walls when they can (no extra cost when clearance is
    0). goal_snap (m): how far a goal in a non-traversable cell may be moved (see
    :meth:`plan`). landmarks: how many landmark cost fields sharpen the A* heuristic (ALT,
    see :meth:`_landmark_table`); 0 keeps the octile heuristic alone, and None (the
    default) means LARGE_GRID_LANDMARKS on grids of at least LARGE_GRID_CELLS cells and 0
    on smaller ones, such as the paper's maps. Landmarks cost one weighted distance field
    each at the first plan and 8 bytes per cell each; on a large map a long search then
    visits several times fewer cells. Paths stay optimal, but among equal-cost paths a
    different one may be chosen than with the octile heuristic alone.
    """

    def __init__(
        self,
        grid: OccupancyGrid,
        radius: float,
        margin: float = 0.05,
        clearance: float = 0.5,
        clearance_weight: float = 2.0,
        goal_snap: float = 1.0,
        landmarks: int | None = None,
    ) -> None:
        for key, value in [
            ("radius", radius),
            ("margin", margin),
            ("clearance", clearance),
            ("clearance_weight", clearance_weight),
            ("goal_snap", goal_snap),
            ("landmarks", 0 if landmarks is None else landmarks),
        ]:
            # A non-negative clearance_weight also keeps every step at least as costly as
            # its length, which the A* heuristic and the bucket queue rely on.
            require(value >= 0, f"Planner.{key}", ">= 0", value)
        self.grid = grid
        self.radius = radius
        self.goal_snap = goal_snap
        inflation = radius + margin
        distance = _shared_obstacle_distance(grid)
        self.traversable = _read_only(distance > inflation + _DISTANCE_TOLERANCE)
        beyond = distance - inflation
        if clearance > 0:
            penalty = np.clip(1.0 - beyond / clearance, 0.0, 1.0)
        else:
            penalty = np.zeros_like(distance)
        self.multipliers = _read_only(1.0 + clearance_weight * penalty)
        # Components under the planner's moves: without corner cutting these are the
        # 4-connected components (labels 1.., 0 for non-traversable cells).
        self._labels = _read_only(ndimage.label(self.traversable)[0])
        self._any_traversable = bool(self.traversable.any())
        self._nearest: np.ndarray | None = None  # see _nearest_cells
        self._padded_width = grid.width + 2
        self._allowed = _allowed_moves(_pad_flat(self.traversable, False), self._padded_width, _MOVES)
        self._padded_multipliers = _pad_flat(self.multipliers, 1.0)
        # Search scratch memory, allocated at the first search that needs it.
        self._astar_scratch: tuple[np.ndarray, ...] | None = None
        self._bucket_pool: tuple[np.ndarray, np.ndarray] | None = None
        if landmarks is None:
            landmarks = LARGE_GRID_LANDMARKS if grid.data.size >= LARGE_GRID_CELLS else 0
        self.landmarks = int(landmarks)
        self._landmarks: np.ndarray | None = None  # see _landmark_table

    @classmethod
    def shared(cls, grid: OccupancyGrid, radius: float, **options) -> Planner:
        """The planner for ``grid``, ``radius`` and ``options`` (the other constructor
        arguments), built at the first call and returned again by every later call with
        equal parameters for as long as the grid exists. Its arrays are read-only."""
        arguments = inspect.signature(cls).bind(grid, radius, **options)
        arguments.apply_defaults()  # so that omitted and explicit defaults share a planner
        key = (cls, *list(arguments.arguments.values())[1:])
        cache = _grid_cache(grid)
        if key not in cache:
            cache[key] = cls(grid, radius, **options)
        return cache[key]

    def _flat(self, cell: tuple[int, int]) -> int:
        """Index of (row, col) in the kernels' padded flat arrays."""
        return (cell[0] + 1) * self._padded_width + cell[1] + 1

    # -- cells

    def _cell(self, xy) -> tuple[int, int]:
        """The (row, col) containing map point xy (m), clamped into the grid."""
        row, col = self.grid.world_to_cell(xy[0], xy[1])
        return min(max(row, 0), self.grid.height - 1), min(max(col, 0), self.grid.width - 1)

    def _is_traversable(self, xy) -> bool:
        row, col = self.grid.world_to_cell(xy[0], xy[1])
        return bool(self.grid.contains(row, col)) and bool(self.traversable[row, col])

    def _source_cell(self, xy) -> tuple[int, int] | None:
        """xy's cell if traversable, else the traversable cell whose centre is nearest to the
        centre of xy's cell (clamped into the grid); None if no cell is traversable."""
        if not self._any_traversable:
            return None
        row, col = self._cell(xy)
        if self.traversable[row, col]:
            return row, col
        nearest = self._nearest_cells()
        return int(nearest[0, row, col]), int(nearest[1, row, col])

    def _nearest_cells(self) -> np.ndarray:
        """Int (2, H, W): for every cell the (row, col) of the traversable cell whose centre
        is nearest (itself when traversable). Computed at the first need: most queries start
        in a traversable cell, and the transform costs about as much as the rest of init."""
        if self._nearest is None:
            _, nearest = ndimage.distance_transform_edt(~self.traversable, return_indices=True)
            self._nearest = _read_only(nearest)
        return self._nearest

    def nearest_traversable(self, xy) -> tuple[float, float] | None:
        """Map-frame centre (m) of the traversable cell nearest to xy's cell (xy itself
        when its cell is traversable, up to the cell centre); None if none is traversable."""
        cell = self._source_cell(xy)
        return None if cell is None else self.grid.cell_to_world(*cell)

    def reachable(self, xy) -> np.ndarray:
        """Bool (H, W): the traversable cells connected to xy's cell (or to the nearest
        traversable cell when xy's cell is not traversable)."""
        cell = self._source_cell(xy)
        if cell is None:
            return np.zeros(self.traversable.shape, dtype=bool)
        return self._labels == self._labels[cell]

    # -- searches

    def distance_field(self, xy, weighted: bool = False) -> np.ndarray:
        """Float64 (H, W): least path cost (m) from xy's cell to every cell over traversable
        cells, np.inf where unreachable. Unweighted, this is the geodesic distance; weighted,
        each step costs its length times the mean multiplier of its two cells. When xy's
        cell is not traversable the search starts from the nearest traversable cell."""
        cell = self._source_cell(xy)
        if cell is None:
            return np.full(self.traversable.shape, np.inf)
        n = self._allowed.size
        while True:
            if self._bucket_pool is None:
                # Cells usually enter the queue about once; start at 2 n + 1 entries and
                # grow to the bound 8 n + 1 only if a search runs out.
                self._bucket_pool = (np.empty(2 * n + 1, np.int32), np.empty(2 * n + 1, np.int32))
            dist, complete = _dijkstra(
                self._allowed, self._padded_multipliers, weighted, self.grid.resolution,
                self._padded_width, self._flat(cell), _MOVES, *self._bucket_pool,
            )
            if complete:
                return dist.reshape(self.grid.height + 2, self._padded_width)[1:-1, 1:-1]
            self._bucket_pool = (np.empty(8 * n + 1, np.int32), np.empty(8 * n + 1, np.int32))

    def _landmark_table(self) -> np.ndarray:
        """Float (landmarks, n): weighted path costs (m) from each landmark cell to every flat
        padded cell, 0 where unreachable. Built at the first need.

        For a landmark L and cells v, goal, |cost(L, goal) - cost(L, v)| is a lower bound of
        cost(v, goal) (triangle inequality; moves cost the same both ways), so A* may use the
        largest of these bounds and the octile distance. Landmarks are placed by farthest
        points in the largest connected region: each one is the cell farthest from those
        chosen so far, the first the farthest from the region's first cell. Cells in other
        regions get 0 bounds, which is admissible too. (Costs rounded to float32 would halve
        the memory, but the rounding makes the heuristic slightly inconsistent, and A* then
        re-expands so many cells that most of the gain is lost.)
        """
        if self._landmarks is None:
            costs = np.zeros((self.landmarks, self._allowed.size))
            if self.landmarks and self._any_traversable:
                region = np.argmax(np.bincount(self._labels.ravel())[1:]) + 1
                cell = np.unravel_index(np.argmax(self._labels == region), self._labels.shape)
                nearest = self.distance_field(self.grid.cell_to_world(*cell), weighted=True)
                for k in range(self.landmarks):
                    farthest = np.argmax(np.where(np.isfinite(nearest), nearest, -1.0))
                    cell = np.unravel_index(farthest, nearest.shape)
                    field = self.distance_field(self.grid.cell_to_world(*cell), weighted=True)
                    costs[k] = _pad_flat(np.where(np.isfinite(field), field, 0.0), 0.0)
                    nearest = field if k == 0 else np.minimum(nearest, field)
            self._landmarks = _read_only(costs)
        return self._landmarks

    def _search_scratch(self) -> tuple[np.ndarray, ...]:
        """A*'s scratch arrays (g, parent, keys, ties, nodes, pos, touched), g all inf and
        pos all -1 between searches."""
        if self._astar_scratch is None:
            n = self._allowed.size
            self._astar_scratch = (
                np.full(n, np.inf), np.empty(n, np.int32), np.empty(n), np.empty(n),
                np.empty(n, np.int32), np.full(n, -1, np.int32), np.empty(n, np.int32),
            )
        return self._astar_scratch

    def _snap_goal(self, goal_xy, label: int) -> tuple[int, int] | None:
        """The cell with ``label`` whose centre is nearest to goal_xy and within goal_snap."""
        res = self.grid.resolution
        row, col = self.grid.world_to_cell(goal_xy[0], goal_xy[1])
        k = int(math.ceil(self.goal_snap / res)) + 1
        r0, r1 = max(row - k, 0), min(row + k + 1, self.grid.height)
        c0, c1 = max(col - k, 0), min(col + k + 1, self.grid.width)
        if r0 >= r1 or c0 >= c1:
            return None
        rows, cols = np.nonzero(self._labels[r0:r1, c0:c1] == label)
        if rows.size == 0:
            return None
        rows, cols = rows + r0, cols + c0
        x, y = self.grid.cell_to_world(rows, cols)
        d = np.hypot(x - goal_xy[0], y - goal_xy[1])
        best = int(np.argmin(d))
        if d[best] > self.goal_snap + _DISTANCE_TOLERANCE:
            return None
        return int(rows[best]), int(cols[best])

    def plan(self, start_xy, goal_xy) -> PathResult:
        """Minimum weighted cost path from start_xy to goal_xy (map frame, m); never raises.

        A start outside the traversable cells (an agent touching the inflation zone) plans
        from the nearest traversable cell. A goal whose cell is not traversable (near a wall,
        inside an obstacle, off the map) is moved to the nearest cell reachable from the
        start within goal_snap metres, and the path ends at that cell's centre; with none
        there the result is unreachable. A goal in a traversable cell that the start cannot
        reach is unreachable (it is never moved to the other side of a wall).
        """
        start = self._source_cell(start_xy)
        if start is None:
            return _unreachable("no traversable cell in the map")
        label = self._labels[start]
        exact_goal = self._is_traversable(goal_xy)
        if exact_goal:
            goal = self.grid.world_to_cell(goal_xy[0], goal_xy[1])
            if self._labels[goal] != label:
                return _unreachable("goal is not reachable from start")
        else:
            goal = self._snap_goal(goal_xy, label)
            if goal is None:
                row, col = self.grid.world_to_cell(goal_xy[0], goal_xy[1])
                if not self.grid.contains(row, col):
                    return _unreachable("goal is outside the map")
                return _unreachable("goal is inside an obstacle")
        cost, cells = _astar(
            self._allowed, self._padded_multipliers, self.grid.resolution, self._padded_width,
            self._flat(start), self._flat(goal), _MOVES, self._landmark_table(),
            *self._search_scratch(),
        )
        rows, cols = np.divmod(cells, self._padded_width)
        x, y = self.grid.cell_to_world(rows - 1, cols - 1)
        path = np.column_stack([x, y])
        if exact_goal:
            path = np.vstack([path, np.asarray(goal_xy, dtype=float).reshape(1, 2)])
        length = float(np.hypot(*np.diff(path, axis=0).T).sum())
        return PathResult(path, length, True, "", float(cost))


# ---------------------------------------------------------------------- path follower


@njit(cache=True)
def _search_right(values, x):
    """``np.searchsorted(values, x, side="right")`` for a sorted float array."""
    lo, hi = 0, values.size
    while lo < hi:
        mid = (lo + hi) >> 1
        if values[mid] <= x:
            lo = mid + 1
        else:
            hi = mid
    return lo


@njit(cache=True)
def _follow(path, seg_len, arc, progress, lookahead, x, y):
    """One pure-pursuit step on ``path`` for an agent at (x, y) (map frame, m).

    path: float (K, 2) waypoints (K >= 1); seg_len: (K-1,) segment lengths; arc: (K,) arc
    length at each waypoint; progress: arc length (m) of the agent's progress point.
    Returns (distance to the last waypoint, new progress, lookahead target x, y), all m.

    The progress point moves forward to the closest point on the path nearby: only
    segments starting within two lookaheads of the current progress are searched, so a
    path that passes near itself does not make the agent skip ahead. The target is the
    path point one lookahead beyond it. The arithmetic repeats ``_follow_reference``
    operation for operation (math.hypot here is the C hypot, as np.hypot), so both give
    identical floats.
    """
    last_x, last_y = path[path.shape[0] - 1, 0], path[path.shape[0] - 1, 1]
    to_goal = math.hypot(last_x - x, last_y - y)
    segments = seg_len.size
    if segments > 0:
        first = min(_search_right(arc, progress) - 1, segments - 1)
        last = min(max(_search_right(arc, progress + 2 * lookahead), first + 1), segments)
        best_gap, best_arc = np.inf, 0.0
        for i in range(first, last):
            ax, ay = path[i, 0], path[i, 1]
            dx, dy = path[i + 1, 0] - ax, path[i + 1, 1] - ay
            t = ((x - ax) * dx + (y - ay) * dy) / max(seg_len[i] * seg_len[i], 1e-18)
            t = min(max(t, 0.0), 1.0)
            gap = math.hypot(ax + t * dx - x, ay + t * dy - y)
            if gap < best_gap:  # the first of equal gaps, as np.argmin
                best_gap, best_arc = gap, arc[i] + t * seg_len[i]
        progress = max(progress, best_arc)
    target_arc = progress + lookahead
    if target_arc >= arc[arc.size - 1]:
        return to_goal, progress, last_x, last_y
    i = _search_right(arc, target_arc) - 1
    t = (target_arc - arc[i]) / max(seg_len[i], 1e-18)
    target_x = path[i, 0] + t * (path[i + 1, 0] - path[i, 0])
    target_y = path[i, 1] + t * (path[i + 1, 1] - path[i, 1])
    return to_goal, progress, target_x, target_y


def _follow_reference(path, seg_len, arc, progress, lookahead, x, y):
    """Plain numpy reference of :func:`_follow`, same arguments and result."""
    xy = np.array([x, y])
    to_goal = float(np.hypot(*(path[-1] - xy)))
    if len(seg_len) > 0:
        first = int(np.searchsorted(arc, progress, side="right")) - 1
        first = min(first, len(seg_len) - 1)
        last = int(np.searchsorted(arc, progress + 2 * lookahead, side="right"))
        last = min(max(last, first + 1), len(seg_len))
        a = path[first:last]
        d = path[first + 1 : last + 1] - a
        lengths = seg_len[first:last]
        t = np.einsum("ij,ij->i", xy - a, d) / np.maximum(lengths**2, 1e-18)
        t = np.clip(t, 0.0, 1.0)
        gap = np.hypot(*(a + t[:, None] * d - xy).T)
        best = int(np.argmin(gap))
        progress = max(progress, float(arc[first + best] + t[best] * lengths[best]))
    target_arc = progress + lookahead
    if target_arc >= arc[-1]:
        target = path[-1]
    else:
        i = int(np.searchsorted(arc, target_arc, side="right")) - 1
        t = (target_arc - arc[i]) / max(seg_len[i], 1e-18)
        target = path[i] + t * (path[i + 1] - path[i])
    return to_goal, progress, float(target[0]), float(target[1])


class PathFollower:
    """Pure-pursuit controller that drives a unicycle along a waypoint path.

    body: the agent's limits (v_max m/s, w_max rad/s). lookahead (m): arc length ahead of
    the agent's progress point that it steers towards. goal_tolerance (m): the path is
    done once the agent is this close to its last waypoint. rotate_threshold (rad): above
    this heading error to the lookahead point the agent turns in place. turn_gain (1/s):
    turn rate per radian of heading error when turning in place.
    """

    def __init__(
        self,
        body: Body,
        lookahead: float = 0.5,
        goal_tolerance: float = 0.15,
        rotate_threshold: float = math.pi / 3,
        turn_gain: float = 2.0,
    ) -> None:
        require(lookahead > 0, "PathFollower.lookahead", "> 0", lookahead)
        require(goal_tolerance >= 0, "PathFollower.goal_tolerance", ">= 0", goal_tolerance)
        self.body = body
        self.lookahead = lookahead
        self.goal_tolerance = goal_tolerance
        self.rotate_threshold = rotate_threshold
        self.turn_gain = turn_gain
        self.set_path(np.zeros((0, 2)))

    def set_path(self, path) -> None:
        """Follow ``path``, float (K, 2) map-frame waypoints (m); an empty path stops."""
        self.path = np.ascontiguousarray(np.asarray(path, dtype=float).reshape(-1, 2))
        seg = np.diff(self.path, axis=0)
        self._seg_len = np.hypot(seg[:, 0], seg[:, 1])
        self._arc = np.concatenate([[0.0], np.cumsum(self._seg_len)])  # arc length at waypoints
        self._progress = 0.0  # arc length (m) of the agent's progress point; only grows
        self._done = len(self.path) == 0

    @property
    def done(self) -> bool:
        """True once the agent came within goal_tolerance of the last waypoint (or no path)."""
        return self._done

    @property
    def remaining(self) -> float:
        """Path length (m) from the agent's progress point to the end; 0 when done."""
        return 0.0 if self._done else float(self._arc[-1] - self._progress)

    def command(self, pose: Pose) -> Velocity:
        """The velocity command for the agent at ``pose`` (map frame).

        Turns in place (v = 0) when the heading error to the lookahead point exceeds
        rotate_threshold; otherwise drives the pure-pursuit arc through that point at a
        speed reduced within one lookahead of the goal and so that the turn rate stays
        within w_max.
        """
        if self._done:
            return STOP
        to_goal, progress, target_x, target_y = _follow(
            self.path, self._seg_len, self._arc, self._progress, self.lookahead, pose.x, pose.y
        )
        if to_goal <= self.goal_tolerance:
            self._done = True
            return STOP
        self._progress = progress
        dx, dy = target_x - pose.x, target_y - pose.y
        error = wrap_angle(math.atan2(dy, dx) - pose.theta)
        v_max, w_max = self.body.v_max, self.body.w_max
        if abs(error) > self.rotate_threshold:
            return Velocity(0.0, clamp(self.turn_gain * error, w_max))
        # Pure pursuit: the arc through the target tangent to the heading has curvature
        # 2 sin(error) / distance.
        curvature = 2.0 * math.sin(error) / max(math.hypot(dx, dy), 1e-9)
        v = v_max * min(1.0, max(self.remaining, to_goal) / self.lookahead)
        if abs(curvature) * v > w_max:
            v = w_max / abs(curvature)
        return Velocity(v, clamp(curvature * v, w_max))

