"""Global planning on an occupancy grid: the global planner of move_base in the paper.

:class:`Planner` gives geodesic distance fields (Dijkstra) and minimum-cost paths (A*)
over the cells outside the inflated obstacles, on 8-connected moves without corner
cutting (:mod:`pegame.navigation.search`), with a cost that keeps paths clear of walls
like move_base's inflation decay. :meth:`Planner.shared` builds one planner per grid and
parameters (:func:`pegame.grid.per_grid`) and hands the same read-only object to every
caller (the game's spawn, both strategies); a planner's only mutable state is scratch
memory of its searches, restored by every search before it returns, and the numba kernels
hold the GIL, so two threads never use it at once.

Units and frames: map-frame (x, y) in metres (:mod:`pegame.grid`); grid arrays are
(height, width) indexed [row, col], row 0 the lowest y; distances and costs in metres.
"""

from __future__ import annotations

import inspect
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import ndimage

from pegame.errors import require
from pegame.grid import OccupancyGrid, per_grid, read_only
from pegame.navigation.inflation import DISTANCE_TOLERANCE, shared_obstacle_distance
from pegame.navigation.search import (
    MOVES,
    AStarScratch,
    BucketPool,
    Heuristic,
    Lattice,
    allowed_moves,
    astar,
    dijkstra,
    pad_flat,
)
from pegame.types import XY

#: grids with at least this many cells round A*'s keys by default (see Planner); the
#: paper's maps have at most 120 000
LARGE_GRID_CELLS = 1_000_000
#: m; A* rounds its keys down to multiples of this on large grids (see search.astar): far
#: above the round-off of a path cost (below 1e-9 m on a 4000 x 4000 grid), far below a cell
TIE_QUANTUM = 1e-8


@dataclass(frozen=True, eq=False)
class PathResult:
    """A planned path.

    path: float (K, 2) map-frame waypoints (m) from start to goal: cell centres, then the
    exact goal point when its cell is traversable; empty when unreachable. length: the
    polyline length of ``path`` (m). cost: the weighted grid cost of the cell path (m,
    see :class:`Planner`); inf when unreachable. reachable: whether a path was found.
    reason: '' when reachable, else why not. searched: how many cells the search reached
    (its work and memory; 0 when no search ran).
    """

    path: np.ndarray
    length: float
    reachable: bool
    reason: str = ""
    cost: float = math.inf
    searched: int = 0


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
    see :meth:`_landmark_table`); 0 (the default) keeps the octile heuristic alone.
    Landmarks cost one full weighted distance field each at the first plan and 4 bytes
    per cell each; on a large open grid they shorten the longest searches (a few times)
    but not the short ones a game makes, so they pay only when one process plans many
    long paths on one map. Paths stay optimal, but among equal-cost paths a different one
    may be chosen than with the octile heuristic alone. tie_quantum (m): A*'s keys are
    rounded down to multiples of it (see :func:`pegame.navigation.search.astar`; 0 keeps
    exact keys); None (the default) means TIE_QUANTUM on grids of at least
    LARGE_GRID_CELLS cells and 0 on smaller ones. Exact keys flood open areas with
    near-ties: a 200 m search across a free 4000 x 4000 grid expands millions of cells
    with them and not many more than the path's with rounded ones. The paper's maps keep
    exact keys, so their games stay exactly as they were (rounded keys pick other paths
    among equal-cost ones).
    """

    def __init__(
        self,
        grid: OccupancyGrid,
        radius: float,
        margin: float = 0.05,
        clearance: float = 0.5,
        clearance_weight: float = 2.0,
        goal_snap: float = 1.0,
        landmarks: int = 0,
        tie_quantum: float | None = None,
    ) -> None:
        for key, value in [
            ("radius", radius),
            ("margin", margin),
            ("clearance", clearance),
            ("clearance_weight", clearance_weight),
            ("goal_snap", goal_snap),
            ("landmarks", landmarks),
            ("tie_quantum", 0.0 if tie_quantum is None else tie_quantum),
        ]:
            # A non-negative clearance_weight also keeps every step at least as costly as
            # its length, which the A* heuristic and the bucket queue rely on.
            require(value >= 0, f"Planner.{key}", ">= 0", value)
        self.grid = grid
        self.radius = radius
        self.goal_snap = goal_snap
        inflation = radius + margin
        distance = shared_obstacle_distance(grid)
        self.traversable = read_only(distance > inflation + DISTANCE_TOLERANCE)
        # The multipliers are written straight into the kernels' padded array (ring 1.0),
        # in place: on a large map every full-size temporary costs 8 bytes per cell.
        padded = np.ones((grid.height + 2, grid.width + 2))
        multipliers = padded[1:-1, 1:-1]
        if clearance > 0:
            # 1 + clearance_weight * clip(1 - beyond / clearance, 0, 1), beyond = distance - inflation
            np.subtract(distance, inflation, out=multipliers)
            multipliers /= clearance
            np.subtract(1.0, multipliers, out=multipliers)
            np.clip(multipliers, 0.0, 1.0, out=multipliers)
            multipliers *= clearance_weight
            multipliers += 1.0
        #: float (H, W) step cost multipliers (>= 1), a view of the kernels' padded array
        self.multipliers = read_only(multipliers)
        self._padded_multipliers = read_only(padded.ravel())
        # Components under the planner's moves: without corner cutting these are the
        # 4-connected components (labels 1.., 0 for non-traversable cells).
        self._labels = read_only(ndimage.label(self.traversable)[0])
        self._any_traversable = bool(self.traversable.any())
        self._nearest: np.ndarray | None = None  # see _nearest_cells
        self._padded_width = grid.width + 2
        self._allowed = allowed_moves(self.traversable)
        # The kernels' structures as plain tuples (see pegame.navigation.search).
        self._lattice = tuple(
            Lattice(
                self._allowed, self._padded_multipliers, grid.resolution, self._padded_width, MOVES
            )
        )
        # Search scratch memory, allocated at the first search that needs it.
        self._astar_scratch: tuple | None = None
        self._bucket_pool: tuple | None = None
        self.landmarks = int(landmarks)
        if tie_quantum is None:
            tie_quantum = TIE_QUANTUM if grid.data.size >= LARGE_GRID_CELLS else 0.0
        self.tie_quantum = float(tie_quantum)
        self._landmarks: np.ndarray | None = None  # see _landmark_table

    @classmethod
    def shared(cls, grid: OccupancyGrid, radius: float, **options: Any) -> Planner:
        """The planner for ``grid``, ``radius`` and ``options`` (the other constructor
        arguments), built at the first call and returned again by every later call with
        equal parameters for as long as the grid exists. Its arrays are read-only."""
        key = ("navigation", cls, *_parameters(cls, radius, tuple(sorted(options.items()))))
        return per_grid(grid, key, lambda grid: cls(grid, radius, **options))

    def _flat(self, cell: tuple[int, int]) -> int:
        """Index of (row, col) in the kernels' padded flat arrays."""
        return (cell[0] + 1) * self._padded_width + cell[1] + 1

    # -- cells

    def _cell(self, xy: XY) -> tuple[int, int]:
        """The (row, col) containing map point xy (m), clamped into the grid."""
        row, col = self.grid.world_to_cell(xy[0], xy[1])
        return min(max(row, 0), self.grid.height - 1), min(max(col, 0), self.grid.width - 1)

    def _is_traversable(self, xy: XY) -> bool:
        row, col = self.grid.world_to_cell(xy[0], xy[1])
        return bool(self.grid.contains(row, col)) and bool(self.traversable[row, col])

    def _source_cell(self, xy: XY) -> tuple[int, int] | None:
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
            self._nearest = read_only(nearest)
        return self._nearest

    def nearest_traversable(self, xy: XY) -> tuple[float, float] | None:
        """Map-frame centre (m) of the traversable cell nearest to xy's cell (xy itself
        when its cell is traversable, up to the cell centre); None if none is traversable."""
        cell = self._source_cell(xy)
        return None if cell is None else self.grid.cell_to_world(*cell)

    @property
    def labels(self) -> np.ndarray:
        """Int (H, W): the connected components of the traversable cells under the
        planner's moves, labelled 1, 2, ...; 0 for cells not traversable. Read-only."""
        return self._labels

    def reachable(self, xy: XY) -> np.ndarray:
        """Bool (H, W): the traversable cells connected to xy's cell (or to the nearest
        traversable cell when xy's cell is not traversable)."""
        cell = self._source_cell(xy)
        if cell is None:
            return np.zeros(self.traversable.shape, dtype=bool)
        return self._labels == self._labels[cell]

    # -- searches

    def distance_field(self, xy: XY, weighted: bool = False) -> np.ndarray:
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
                self._bucket_pool = tuple(BucketPool.empty(2 * n + 1))
            dist, complete = dijkstra(self._lattice, weighted, self._flat(cell), self._bucket_pool)
            if complete:
                return dist.reshape(self.grid.height + 2, self._padded_width)[1:-1, 1:-1]
            self._bucket_pool = tuple(BucketPool.empty(8 * n + 1))

    def _landmark_table(self) -> np.ndarray:
        """Float32 (landmarks, n): weighted path costs (m) from each landmark cell to every
        flat padded cell, scaled by a factor s slightly below 1 (see below), 0 where
        unreachable. Built at the first need.

        For a landmark L and cells v, goal, |cost(L, goal) - cost(L, v)| is a lower bound of
        cost(v, goal) (triangle inequality; moves cost the same both ways), so A* may use the
        largest of these bounds and the octile distance. Landmarks are placed by farthest
        points in the largest connected region: each one is the cell farthest from those
        chosen so far, the first the farthest from the region's first cell. Cells in other
        regions get 0 bounds, which is admissible too.

        Float32 halves the table, but rounding each cost by up to 2^-24 of itself would
        make the heuristic inconsistent by that much, and A* then re-expands so many cells
        that most of the gain is lost. So the costs are scaled by s = 1 - 2^-22 D / r
        before rounding, D the largest cost and r the resolution (the cheapest step): for
        adjacent cells u, v the stored a_u, a_v then satisfy |a_u - a_v| <= s c(u, v) +
        2^-23 s D <= c(u, v), which makes the bounds (computed in float64) consistent;
        they lose a fraction 1 - s of their strength (0.1 % for a 300 m cost at 5 cm).
        When s would fall below 1/2 (costs beyond 2^21 cells) the table stays zero.
        """
        if self._landmarks is None:
            costs = np.zeros((self.landmarks, self._allowed.size), np.float32)
            if self.landmarks and self._any_traversable:
                region = np.argmax(np.bincount(self._labels.ravel())[1:]) + 1
                cell = np.unravel_index(np.argmax(self._labels == region), self._labels.shape)
                nearest = self.distance_field(self.grid.cell_to_world(*cell), weighted=True)
                fields = []
                for k in range(self.landmarks):
                    farthest = np.argmax(np.where(np.isfinite(nearest), nearest, -1.0))
                    cell = np.unravel_index(farthest, nearest.shape)
                    field = self.distance_field(self.grid.cell_to_world(*cell), weighted=True)
                    fields.append(np.where(np.isfinite(field), field, 0.0))
                    nearest = field if k == 0 else np.minimum(nearest, field)
                largest = max(float(field.max()) for field in fields)
                scale = 1.0 - 2.0**-22 * largest / self.grid.resolution
                if scale >= 0.5:
                    for k, field in enumerate(fields):
                        costs[k] = pad_flat(scale * field, 0.0)
            self._landmarks = read_only(costs)
        return self._landmarks

    def _search_scratch(self) -> tuple:
        """A*'s scratch arrays, seen all False between searches. All are left uninitialised
        or zeroed by the system (see search.astar), so a search uses the memory of the
        cells it reaches only."""
        if self._astar_scratch is None:
            self._astar_scratch = tuple(AStarScratch.empty(self._allowed.size))
        return self._astar_scratch

    def _snap_goal(self, goal_xy: XY, label: int) -> tuple[int, int] | None:
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
        if d[best] > self.goal_snap + DISTANCE_TOLERANCE:
            return None
        return int(rows[best]), int(cols[best])

    def search_tables(self) -> tuple[tuple, tuple, tuple, np.ndarray, np.ndarray]:
        """What a kernel needs to plan as :meth:`plan` does between traversable cells:
        (lattice, heuristic, scratch) as :func:`pegame.navigation.search.astar` takes
        them, the bool (H, W) traversable cells and the int (2, H, W) nearest traversable
        cell of every cell (as :meth:`plan` picks its start). The scratch is this
        planner's own: one search at a time."""
        heuristic = tuple(Heuristic(self._landmark_table(), self.tie_quantum))
        return (
            self._lattice,
            heuristic,
            self._search_scratch(),
            self.traversable,
            self._nearest_cells(),
        )

    def plan(self, start_xy: XY, goal_xy: XY) -> PathResult:
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
        goal: tuple[int, int] | None
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
        heuristic = tuple(Heuristic(self._landmark_table(), self.tie_quantum))
        cost, cells, searched = astar(
            self._lattice, self._flat(start), self._flat(goal), heuristic, self._search_scratch()
        )
        rows, cols = np.divmod(cells, self._padded_width)
        x, y = self.grid.cell_to_world(rows - 1, cols - 1)
        path = np.column_stack([x, y])
        if exact_goal:
            path = np.vstack([path, np.asarray(goal_xy, dtype=float).reshape(1, 2)])
        length = float(np.hypot(*np.diff(path, axis=0).T).sum())
        return PathResult(path, length, True, "", float(cost), int(searched))


#: (class, radius, options) -> :func:`_parameters`, filled as they are asked for
_BOUND: dict[tuple[type, float, tuple[tuple[str, Any], ...]], tuple[Any, ...]] = {}


def _parameters(cls: type, radius: float, options: tuple[tuple[str, Any], ...]) -> tuple[Any, ...]:
    """The constructor arguments of ``cls`` after the grid for ``radius`` and the (name,
    value) ``options``, the defaults filled in (so that omitted and explicit defaults
    share a planner); cached: binding a signature costs about 40 us, and every plugin
    constructor asks for its planner. (A dict, not functools.cache: mypy does not take a
    class for the Hashable that the cache's arguments are typed as.)"""
    key = (cls, radius, options)
    bound = _BOUND.get(key)
    if bound is None:
        arguments = inspect.signature(cls).bind(None, radius, **dict(options))
        arguments.apply_defaults()
        bound = _BOUND[key] = tuple(arguments.arguments.values())[1:]
    return bound
