"""The grid search kernels of the planner: Dijkstra and A* on 8-connected moves.

Grid moves: a path steps between the centres of 8-neighbouring traversable cells; a
diagonal step is allowed only when both cells it passes between are traversable too,
so the straight segment never touches a non-traversable cell (no corner cutting). As a
consequence two cells are connected exactly when they are 4-connected. A step costs its
length (m) times the mean of its two cells' multipliers (>= 1) when weighted.

The kernels (numba) work on flat arrays of the grid padded with one ring of
non-traversable cells, so a neighbour is a fixed index offset and needs no bounds check.
Which of the 8 moves a cell allows (target traversable, no corner cutting) is precomputed
as one bit per move (:func:`allowed_moves`), so a search reads one byte per cell instead
of up to three traversable flags per move. :func:`dijkstra` is Dijkstra's algorithm with
a bucket queue, :func:`astar` A* with an indexed binary heap; the plain-Python
:func:`distance_field_reference` and :func:`astar_reference` (heapq on (row, col) cells)
implement the same algorithms for the tests to compare against. The kernels take their
arrays grouped by meaning (:class:`Lattice`, :class:`Heuristic`, :class:`AStarScratch`,
:class:`BucketPool`) and unpack them once at entry; the planner passes them as plain
tuples of those fields, which numba types in C (a NamedTuple argument it types in Python,
field by field: about 0.6 us a call).
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Iterator
from typing import NamedTuple

import numpy as np
from numba import njit

SQRT2 = math.sqrt(2.0)

#: the 8 moves as (row step, col step); orthogonal moves first
MOVES = np.array(
    [(1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (1, -1), (-1, 1), (-1, -1)], dtype=np.int64
)


class Lattice(NamedTuple):
    """The padded grid as the search kernels walk it."""

    allowed: np.ndarray  # uint8 per flat padded cell: bit k set when move k is allowed
    multipliers: np.ndarray  # float64 per flat padded cell: step cost multiplier, >= 1
    resolution: float  # m, the cells' edge
    padded_width: int  # cells per padded row
    moves: np.ndarray  # int64 (8, 2), the (row, col) steps of the bits: MOVES


class Heuristic(NamedTuple):
    """A*'s lower bound and key rounding (see :func:`astar`)."""

    landmark_costs: np.ndarray  # float32 (K, n) scaled costs from K landmarks; K may be 0
    tie_quantum: float  # m; keys rounded down to multiples of it, 0: exact keys


class AStarScratch(NamedTuple):
    """A*'s scratch arrays, one entry per flat padded cell (see :func:`astar`)."""

    g: np.ndarray  # float64, cost from the start (m)
    parent: np.ndarray  # int32, the cell a cell was reached from
    keys: np.ndarray  # float64, the heap's keys
    ties: np.ndarray  # float64, the heap's tie breaks
    nodes: np.ndarray  # int32, the heap's cells
    pos: np.ndarray  # int32, a cell's heap slot
    touched: np.ndarray  # int32, the cells a search reached, in order
    seen: np.ndarray  # bool, all False between searches

    @classmethod
    def empty(cls, n: int) -> AStarScratch:
        """Scratch for ``n`` cells, uninitialised but ``seen`` (all False)."""
        floats, ints = (np.empty(n) for _ in range(3)), (np.empty(n, np.int32) for _ in range(4))
        g, keys, ties = floats
        parent, nodes, pos, touched = ints
        return cls(g, parent, keys, ties, nodes, pos, touched, np.zeros(n, np.bool_))


class BucketPool(NamedTuple):
    """Dijkstra's bucket entries (see :func:`dijkstra`): int32, the same length."""

    cell: np.ndarray  # the entry's flat cell
    next: np.ndarray  # the next entry in its bucket, -1 at the end

    @classmethod
    def empty(cls, size: int) -> BucketPool:
        """A pool of ``size`` entries (8 n + 1 always suffice for n cells)."""
        return cls(np.empty(size, np.int32), np.empty(size, np.int32))


def pad_flat(array: np.ndarray, fill: float | bool) -> np.ndarray:
    """``array`` (H, W) padded with one ring of ``fill``, flattened to ((H+2) * (W+2),)."""
    return np.pad(array, 1, constant_values=fill).ravel()


@njit(cache=True)
def _move_tables(
    padded_width: int, moves: np.ndarray, resolution: float
) -> tuple[np.ndarray, np.ndarray]:
    """Flat index offsets (cells) and lengths (m) of the 8 moves."""
    offsets = moves[:, 0] * padded_width + moves[:, 1]
    lengths = np.empty(8)
    for k in range(8):
        diagonal = moves[k, 0] != 0 and moves[k, 1] != 0
        lengths[k] = resolution * SQRT2 if diagonal else resolution
    return offsets, lengths


def allowed_moves(traversable: np.ndarray) -> np.ndarray:
    """Uint8 per flat padded cell of the bool (H, W) ``traversable``: bit k set when move
    k of MOVES is allowed from the cell, i.e. the cell and its target are traversable
    and, for a diagonal move, so are the two cells it passes between. One vectorised
    pass per move over the whole grid (the padding ring allows no move)."""
    height, width = traversable.shape
    padded = np.pad(traversable, 1, constant_values=False)
    allowed = np.zeros(padded.shape, dtype=np.uint8)

    def shifted(dr: int, dc: int) -> np.ndarray:
        return padded[1 + dr : height + 1 + dr, 1 + dc : width + 1 + dc]

    for k, (dr, dc) in enumerate(MOVES.tolist()):
        ok = traversable & shifted(dr, dc)
        if dr and dc:
            ok &= shifted(dr, 0)
            ok &= shifted(0, dc)
        allowed[1:-1, 1:-1] |= ok.view(np.uint8) << k
    return allowed.ravel()


@njit(cache=True)
def dijkstra(lattice: tuple, weighted: bool, source: int, pool: tuple) -> tuple[np.ndarray, bool]:
    """Least path cost (m) over ``lattice`` from flat cell ``source`` to every cell, inf if
    unreachable; each step's length times its cells' mean multiplier when ``weighted``.

    Dijkstra with a bucket queue (Dinitz's variant of Dial's algorithm): bucket b holds
    cells with cost in [b w, (b+1) w) for a width w no larger than the cheapest move, so
    no cell can improve another in its own bucket and every cell of the lowest bucket is
    final. This gives the same costs as a binary heap at a fraction of the time. Buckets
    are singly linked lists in the entry ``pool`` (scratch) kept on a ring; a cell whose
    cost drops is added again and its older entries are skipped. Returns (costs, True), or
    (partial costs, False) when the pool was too small (a cell enters it at most once per
    neighbour, so 8 n + 1 entries always suffice).
    """
    allowed, multipliers, resolution, padded_width, moves = lattice
    entry_cell, entry_next = pool
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
def _sift_up(
    keys: np.ndarray,
    ties: np.ndarray,
    nodes: np.ndarray,
    pos: np.ndarray,
    slot: int,
    node: int,
    key: float,
    tie: float,
) -> None:
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
def _pop(keys: np.ndarray, ties: np.ndarray, nodes: np.ndarray, pos: np.ndarray, size: int) -> int:
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
        child += (right < size) & (
            (key_r < key_c) | ((key_r == key_c) & (ties[right] < ties[child]))
        )
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
def _octile(resolution: float, row: int, col: int, goal_row: int, goal_col: int) -> float:
    """Octile distance (m) between two cells: a lower bound of any path cost."""
    dr = abs(row - goal_row)
    dc = abs(col - goal_col)
    return resolution * (max(dr, dc) + (SQRT2 - 1.0) * min(dr, dc))


@njit(cache=True)
def astar(
    lattice: tuple, start: int, goal: int, heuristic: tuple, scratch: tuple
) -> tuple[float, np.ndarray, int]:
    """Minimum weighted cost (m), flat cell path and number of cells reached over
    ``lattice`` from flat cell ``start`` to ``goal`` by A*.

    The heuristic is the octile distance, admissible and consistent because every
    multiplier is >= 1, or the larger landmark bound when ``heuristic.landmark_costs``
    (K, n) has rows (see ``Planner._landmark_table``). Returns (inf, empty, reached) when the goal is
    unreachable.

    The heap orders cells by f = g + h, then by the smaller h. With ``tie_quantum`` q > 0
    (m) f is first rounded down to a multiple of q: on an open grid every cell of the
    parallelogram between start and goal lies on an optimal octile path, but their f
    differ in the last bits (g sums the steps in different orders), so the exact key
    never ties and A* expands most of the parallelogram (a 200 m search across a free
    map visits millions of cells). Rounded keys tie, the smaller h goes first and the
    search runs along one optimal path. A popped cell is then closed (never improved
    again): with rounded keys a cell may be popped with a g larger than its least by
    round-off, and reopening it would re-expand everything after it, again and again.
    The cost found is optimal to within q per step of the path. q = 0 keeps the exact key
    and no closed set (the paper maps' searches).

    The ``scratch`` arrays have length n. ``seen`` (bool) must be all False on entry
    and is restored before returning (only the ``touched`` cells are reset, not the whole
    grid); the others are read only where ``seen`` is set (a cell's g, heap slot and
    parent are written when the search first reaches it), so they may be allocated
    uninitialised and only the memory pages of the cells a search reaches are ever
    used: on a large map a short search costs little memory.
    """
    allowed, multipliers, resolution, padded_width, moves = lattice
    landmark_costs, tie_quantum = heuristic
    g, parent, keys, ties, nodes, pos, touched, seen = scratch
    offsets, lengths = _move_tables(padded_width, moves, resolution)
    goal_row, goal_col = goal // padded_width, goal % padded_width
    to_goal = landmark_costs[:, goal].copy()
    g[start] = 0.0
    pos[start] = -1
    seen[start] = True
    touched[0] = start
    count = 1
    parent[start] = -1
    h = _octile(resolution, start // padded_width, start % padded_width, goal_row, goal_col)
    h = _landmark_bound(landmark_costs, to_goal, start, h)
    _sift_up(keys, ties, nodes, pos, 0, start, _key(h, tie_quantum), h)
    size = 1
    while size > 0:
        u = _pop(keys, ties, nodes, pos, size)
        size -= 1
        if u == goal:
            break
        if tie_quantum > 0.0:
            pos[u] = CLOSED
        row, col = u // padded_width, u % padded_width
        moves_u = allowed[u]
        for k in range(8):
            if not (moves_u >> k) & 1:
                continue
            v = u + offsets[k]
            candidate = g[u] + lengths[k] * (0.5 * (multipliers[u] + multipliers[v]))
            if not seen[v]:
                seen[v] = True
                touched[count] = v
                count += 1
                g[v] = np.inf
                pos[v] = -1
            if candidate < g[v] and pos[v] != CLOSED:
                g[v] = candidate
                parent[v] = u
                h = _octile(resolution, row + moves[k, 0], col + moves[k, 1], goal_row, goal_col)
                h = _landmark_bound(landmark_costs, to_goal, v, h)
                # Among equal f prefer the smaller h (the deeper cell), so open areas are
                # not flooded with ties.
                slot = pos[v] if pos[v] >= 0 else size
                if pos[v] < 0:
                    size += 1
                _sift_up(keys, ties, nodes, pos, slot, v, _key(candidate + h, tie_quantum), h)
    cost = g[goal] if seen[goal] else np.inf
    path = _trace(parent, start, goal) if np.isfinite(cost) else np.empty(0, dtype=np.int64)
    for i in range(count):
        seen[touched[i]] = False
    return cost, path, count


#: ``pos`` of a cell A* has closed (with a tie quantum only)
CLOSED = -2


@njit(cache=True)
def _key(f: float, tie_quantum: float) -> float:
    """The heap key of f (m): f itself, or f rounded down to a multiple of ``tie_quantum``."""
    if tie_quantum > 0.0:
        return math.floor(f / tie_quantum) * tie_quantum
    return f


@njit(cache=True)
def _landmark_bound(landmark_costs: np.ndarray, to_goal: np.ndarray, v: int, h: float) -> float:
    """The largest of ``h`` and the landmark bounds |cost(L, goal) - cost(L, v)| (m),
    subtracted in float64 (exactly, for float32 costs: the consistency argument of
    ``Planner._landmark_table`` needs the difference unrounded)."""
    for k in range(to_goal.size):
        h = max(h, abs(np.float64(to_goal[k]) - np.float64(landmark_costs[k, v])))
    return h


@njit(cache=True)
def _trace(parent: np.ndarray, start: int, goal: int) -> np.ndarray:
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


def _reference_neighbours(
    traversable: np.ndarray,
    multipliers: np.ndarray,
    weighted: bool,
    resolution: float,
    cell: tuple[int, int],
) -> Iterator[tuple[tuple[int, int], float]]:
    """Yield (neighbour cell, step cost m) for the allowed moves from ``cell``."""
    height, width = traversable.shape
    r, c = cell
    for dr, dc in MOVES.tolist():
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


def distance_field_reference(
    traversable: np.ndarray,
    multipliers: np.ndarray,
    weighted: bool,
    resolution: float,
    source: tuple[int, int],
) -> np.ndarray:
    """Plain-Python Dijkstra with heapq; same contract as :func:`dijkstra` but takes and
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


def astar_reference(
    traversable: np.ndarray,
    multipliers: np.ndarray,
    resolution: float,
    start: tuple[int, int],
    goal: tuple[int, int],
) -> tuple[float, list[tuple[int, int]]]:
    """Plain-Python A* with heapq and the octile heuristic on the weighted grid.

    Returns (cost m, list of (row, col) cells from start to goal), or (inf, []).
    """

    def heuristic(cell: tuple[int, int]) -> float:
        dr, dc = abs(cell[0] - goal[0]), abs(cell[1] - goal[1])
        return resolution * (max(dr, dc) + (SQRT2 - 1.0) * min(dr, dc))

    g = {start: 0.0}
    parent: dict[tuple[int, int], tuple[int, int] | None] = {start: None}
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
    while (previous := parent[path[-1]]) is not None:
        path.append(previous)
    return g[goal], path[::-1]
