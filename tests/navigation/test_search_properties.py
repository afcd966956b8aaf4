"""Property-based tests of the grid search kernels (pegame.navigation.search) on generated
small grids: the bucket-queue Dijkstra against the heapq reference and against the
shortest-path certificate (no move relaxes a cost, every reached cell has a tight move
into it), reachability against 4-connected components, and A*'s paths (allowed moves
between traversable cells, their cost the distance field's value, the reference's
optimum, nothing for a goal in another component). Costs in metres."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy import ndimage

from pegame.navigation import TIE_QUANTUM
from pegame.navigation.search import (
    MOVES,
    SQRT2,
    AStarScratch,
    BucketPool,
    Heuristic,
    Lattice,
    allowed_moves,
    astar,
    astar_reference,
    dijkstra,
    distance_field_reference,
    pad_flat,
)

Cell = tuple[int, int]


class Search:
    """A traversable mask (H, W), step-cost multipliers (H, W, >= 1) and a resolution
    (m), and the kernels' padded arrays for them."""

    def __init__(self, traversable: np.ndarray, multipliers: np.ndarray, resolution: float):
        self.traversable, self.multipliers, self.resolution = traversable, multipliers, resolution
        self.width = traversable.shape[1] + 2  # padded
        self.allowed = allowed_moves(traversable)
        self.padded_multipliers = pad_flat(multipliers, 1.0)
        self.lattice = Lattice(self.allowed, self.padded_multipliers, resolution, self.width, MOVES)

    def flat(self, cell: Cell) -> int:
        return (cell[0] + 1) * self.width + cell[1] + 1

    def cell(self, flat: int) -> Cell:
        return flat // self.width - 1, flat % self.width - 1

    def distance_field(self, source: Cell, weighted: bool) -> np.ndarray:
        """The kernel's costs (H, W) from ``source``, with a pool that always suffices."""
        pool = BucketPool.empty(8 * self.allowed.size + 1)
        dist, complete = dijkstra(self.lattice, weighted, self.flat(source), pool)
        assert complete
        return dist.reshape(-1, self.width)[1:-1, 1:-1]

    def astar(self, start: Cell, goal: Cell, tie_quantum: float) -> tuple[float, list[Cell]]:
        """A*'s cost and (row, col) path, checking that it restores its ``seen`` scratch."""
        n = self.allowed.size
        scratch = AStarScratch.empty(n)
        heuristic = Heuristic(np.zeros((0, n), np.float32), tie_quantum)
        cost, path, _ = astar(self.lattice, self.flat(start), self.flat(goal), heuristic, scratch)
        assert not scratch.seen.any()
        return float(cost), [self.cell(int(p)) for p in path]

    def step(self, a: Cell, b: Cell) -> float:
        """The weighted cost (m) of the move from a to b."""
        length = self.resolution * (SQRT2 if a[0] != b[0] and a[1] != b[1] else 1.0)
        return length * (0.5 * (self.multipliers[a] + self.multipliers[b]))

    def moves(self, cell: Cell) -> list[Cell]:
        """The cells one allowed move from ``cell`` (the kernel's move bits)."""
        bits = int(self.allowed[self.flat(cell)])
        return [(cell[0] + dr, cell[1] + dc) for k, (dr, dc) in enumerate(MOVES) if bits >> k & 1]


@st.composite
def searches(draw: st.DrawFn) -> Search:
    """Up to 12 x 12 cells, mostly traversable; multipliers 1 or up to 4."""
    shape = (draw(st.integers(1, 12)), draw(st.integers(1, 12)))
    traversable = draw(arrays(bool, shape, elements=st.sampled_from([True] * 3 + [False])))
    multipliers = draw(
        st.just(np.ones(shape)) | arrays(np.float64, shape, elements=st.floats(1.0, 4.0))
    )
    resolution = draw(st.sampled_from([0.05, 0.1, 1.0]) | st.floats(0.01, 2.0))
    return Search(traversable, multipliers, resolution)


def cells_of(search: Search) -> st.SearchStrategy[Cell]:
    height, width = search.traversable.shape
    return st.tuples(st.integers(0, height - 1), st.integers(0, width - 1))


@st.composite
def endpoints(draw: st.DrawFn) -> tuple[Search, Cell, Cell]:
    """A search and two of its cells, traversable or not."""
    search = draw(searches())
    return search, draw(cells_of(search)), draw(cells_of(search))


def connected(traversable: np.ndarray, a: Cell, b: Cell) -> bool:
    """Whether a is a traversable cell 4-connected to b (the planner's moves, no corner
    cutting, connect the same cells)."""
    labels = ndimage.label(traversable)[0]
    return bool(traversable[a] and labels[a] == labels[b])


@settings(max_examples=150)
@given(endpoints(), st.booleans())
def test_distance_field_equals_the_reference_and_is_certified(
    case: tuple[Search, Cell, Cell], weighted: bool
) -> None:
    search, source, _ = case
    assume(search.traversable[source])  # the planner searches from traversable cells only
    dist = search.distance_field(source, weighted)
    args = (search.traversable, search.multipliers, weighted, search.resolution, source)
    reference = distance_field_reference(*args)
    assert np.array_equal(np.isfinite(dist), np.isfinite(reference))
    finite = np.isfinite(dist)
    np.testing.assert_allclose(dist[finite], reference[finite], rtol=0, atol=1e-9)
    for cell in zip(*np.nonzero(search.traversable)):
        assert finite[cell] == connected(search.traversable, source, cell)
    # The certificate: every move's cost bounds its target's, and the cost of every
    # reached cell but the source is met by a move from a neighbour.
    assert dist[source] == 0.0
    multipliers = search.multipliers if weighted else np.ones_like(search.multipliers)
    unit = Search(search.traversable, multipliers, search.resolution)
    for cell in zip(*np.nonzero(finite)):
        into = [dist[m] + unit.step(m, cell) for m in unit.moves(cell)]
        assert all(dist[cell] <= value + 1e-9 for value in into)
        assert cell == source or min(into) <= dist[cell] + 1e-9


@settings(max_examples=150)
@given(endpoints(), st.sampled_from([0.0, TIE_QUANTUM]))
def test_astar_paths_are_allowed_optimal_and_cost_the_distance_field(
    case: tuple[Search, Cell, Cell], tie_quantum: float
) -> None:
    """Also for goals in a non-traversable cell or another component: no path."""
    search, start, goal = case
    assume(search.traversable[start])  # the planner starts from traversable cells only
    cost, path = search.astar(start, goal, tie_quantum)
    ref_cost, ref_path = astar_reference(
        search.traversable, search.multipliers, search.resolution, start, goal
    )
    if not (search.traversable[goal] and connected(search.traversable, start, goal)):
        assert cost == math.inf and path == [] and ref_path == []
        return
    assert path[0] == start and path[-1] == goal
    assert all(b in search.moves(a) for a, b in zip(path[:-1], path[1:]))
    assert all(search.traversable[cell] for cell in path)
    # Within q per step with rounded keys (search.astar), exact ones to round-off.
    tolerance = 1e-9 + tie_quantum * len(path)
    assert abs(cost - sum(search.step(a, b) for a, b in zip(path[:-1], path[1:]))) <= 1e-9
    assert abs(cost - search.distance_field(start, weighted=True)[goal]) <= tolerance
    assert abs(cost - ref_cost) <= tolerance
