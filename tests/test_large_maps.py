"""Large maps: what keeps a game on a 4000 x 4000 map within seconds and 2 GB, tested on
small maps (the 4000 x 4000 figures are measured by ``python -m pegame.bench_maps``).

A* with rounded keys (large grids only), float32 landmark tables that stay consistent,
the per-map structures' bytes per cell, the smart evader's per-map cells against its
reference on rotated maps, the grey-level lookup of map loading, the figure's block
drawing and the scaled maps of the bench.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pegame.bench_maps import format_rows, measure_parts, scaled_map, write_map
from pegame.config import resolve_map_path
from pegame.evaders import escape
from pegame.evaders.escape import EscapeSearch
from pegame.figures import MAX_DRAWN_CELLS, drawn_shades, map_shades
from pegame.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid, load_map
from pegame.grid.ros import _MapSpec, _occupancy
from pegame.navigation import LARGE_GRID_CELLS, TIE_QUANTUM, Planner
from pegame.navigation.inflation import obstacle_distance, obstacle_distance_reference
from pegame.navigation.search import (
    MOVES,
    SQRT2,
    _reference_neighbours,
    allowed_moves,
    astar_reference,
)
from pegame.types import Camera, Pose
from pegame.visibility import visibility_region

CAMERA = Camera(fov=math.pi / 3, near=0.3, far=5.0, angle_step=0.004, distance_step=0.05)


def open_grid(height: int, width: int, resolution: float = 0.05) -> OccupancyGrid:
    return OccupancyGrid(np.zeros((height, width), dtype=np.int8), resolution)


def pillared_grid(seed: int, size: int = 60, resolution: float = 0.1, origin=(0.0, 0.0, 0.0)):
    """Free space with random pillars and a wall ring."""
    rng = np.random.default_rng(seed)
    data = np.zeros((size, size), dtype=np.int8)
    data[[0, -1], :] = data[:, [0, -1]] = OCCUPIED
    for _ in range(size // 6):
        r, c = rng.integers(2, size - 6, 2)
        data[r : r + rng.integers(1, 5), c : c + rng.integers(1, 5)] = OCCUPIED
    data[rng.random((size, size)) < 0.005] = UNKNOWN
    return OccupancyGrid(data, resolution, origin)


# ------------------------------------------------------------------ A* on large grids


def test_rounded_keys_search_along_one_path_where_exact_keys_flood_the_ties():
    """An off-diagonal search across open space: every cell of the parallelogram between
    the ends lies on an optimal octile path, and exact keys (their f differ in the last
    bits) expand most of it; rounded keys reach few more cells than the path's."""
    grid = open_grid(300, 600)
    exact = Planner(grid, 0.2, tie_quantum=0.0).plan((1.0, 1.0), (29.0, 9.0))
    rounded = Planner(grid, 0.2, tie_quantum=TIE_QUANTUM).plan((1.0, 1.0), (29.0, 9.0))
    assert rounded.cost == pytest.approx(exact.cost, abs=1e-9)
    assert rounded.searched < 5 * len(rounded.path) < exact.searched / 5


def test_a_large_grid_plans_with_rounded_keys_and_no_landmark_table():
    """Regression: on grids of LARGE_GRID_CELLS or more the default planner built 12
    full-grid landmark fields at its first plan (26 s and 1.5 GB on 4000 x 4000) and its
    exact keys flooded open space (17 s for one 200 m plan)."""
    grid = open_grid(1000, LARGE_GRID_CELLS // 1000)
    planner = Planner(grid, 0.2)
    result = planner.plan((1.0, 1.0), (49.0, 15.0))
    assert result.reachable and planner._landmark_table().shape[0] == 0
    assert result.searched < 5 * len(result.path)
    small = Planner(pillared_grid(0), 0.2)
    assert small.tie_quantum == 0.0  # the paper maps' planners are as before


@pytest.mark.parametrize("seed", range(4))
def test_rounded_keys_find_optimal_paths_around_obstacles(seed):
    grid = pillared_grid(seed)
    planner = Planner(grid, 0.15, tie_quantum=TIE_QUANTUM)
    rng = np.random.default_rng(seed)
    rows, cols = np.nonzero(planner.traversable)
    for _ in range(10):
        i, j = rng.integers(rows.size, size=2)
        s, g = (int(rows[i]), int(cols[i])), (int(rows[j]), int(cols[j]))
        result = planner.plan(grid.cell_to_world(*s), grid.cell_to_world(*g))
        ref_cost, _ = astar_reference(
            planner.traversable, planner.multipliers, grid.resolution, s, g
        )
        assert result.reachable == math.isfinite(ref_cost)
        if result.reachable:
            assert result.cost == pytest.approx(ref_cost, abs=1e-6)


# ------------------------------------------------------------------ float32 landmarks


@pytest.mark.parametrize("seed", range(3))
def test_float32_landmark_bounds_are_consistent_on_every_move(seed):
    """|a_u - a_v| <= c(u, v) for every allowed move, the condition for A* never to
    reopen a cell: the scaling before rounding to float32 makes it hold."""
    grid = pillared_grid(seed, size=80, resolution=0.05)
    planner = Planner(grid, 0.1, landmarks=3)
    table = planner._landmark_table()
    assert table.dtype == np.float32 and table.any()
    width = grid.width + 2
    multipliers = planner._padded_multipliers
    for k, (dr, dc) in enumerate(MOVES.tolist()):
        cells = np.flatnonzero((planner._allowed >> k) & 1)
        target = cells + dr * width + dc
        length = grid.resolution * (SQRT2 if dr and dc else 1.0)
        step = length * (0.5 * (multipliers[cells] + multipliers[target]))
        gap = np.abs(table[:, cells].astype(float) - table[:, target].astype(float))
        assert (gap <= step).all()


# ------------------------------------------------------------------ per-map memory


def test_the_shared_per_map_structures_stay_within_their_bytes_per_cell():
    """Regression: per cell, a planner held 22 bytes (its multipliers twice, in float64),
    its A* scratch 41 bytes written at the first plan, and the smart evader 16 bytes of
    cell centres plus 48 per candidate cell (int64 indices and float64 centres)."""
    grid = scaled_map(400)
    cells = grid.data.size
    planner = Planner.shared(grid, 0.25)
    arrays = [planner.traversable, planner._padded_multipliers, planner._labels, planner._allowed]
    assert sum(a.nbytes for a in arrays) / cells <= 8 + 4 + 1 + 1 + 0.1
    assert np.shares_memory(planner.multipliers, planner._padded_multipliers)
    search = EscapeSearch(grid, CAMERA, planner, None, "euclidean", 1, 0.3)
    rows, cols = np.nonzero(planner.traversable)
    me = Pose(*grid.cell_to_world(rows[0], cols[0]))
    search.escape(me, Pose(*grid.cell_to_world(rows[-1], cols[-1])))
    component = search._component
    candidates = component.cells.size
    parts = [component.cells, component.position, component.rows, component.cols]
    assert sum(a.nbytes for a in parts) <= 4 * cells + 12 * candidates


@pytest.mark.parametrize("seed", range(4))
def test_the_evader_s_cells_give_the_reference_escape_on_rotated_maps(seed):
    """Cell centres are computed in the kernels now; on a rotated, shifted map they are
    the floats OccupancyGrid.cell_to_world gives (the escape equals the reference)."""
    grid = pillared_grid(seed, size=50, origin=(-1.3, 2.1, 0.3 + seed))
    planner = Planner(grid, 0.12)
    search = EscapeSearch(grid, CAMERA, planner, None, "euclidean", 1 + seed % 2, 0.2)
    rng = np.random.default_rng(seed)
    rows, cols = np.nonzero(planner.traversable)
    for _ in range(6):
        i, j = rng.integers(rows.size, size=2)
        pursuer = Pose(*grid.cell_to_world(rows[i], cols[i]), rng.uniform(-math.pi, math.pi))
        in_view = planner.traversable & visibility_region(grid, pursuer, CAMERA)
        er, ec = np.nonzero(in_view) if in_view.any() else (rows, cols)
        me = Pose(*grid.cell_to_world(er[j % er.size], ec[j % ec.size]))
        fast, slow = search.escape(me, pursuer), search.escape_reference(me, pursuer)
        assert (fast.cell, fast.cost, fast.count) == (slow.cell, slow.cost, slow.count)
        np.testing.assert_array_equal(fast.sample, slow.sample)
        expected = np.column_stack(grid.cell_to_world(*np.divmod(fast.sample, grid.width)))
        np.testing.assert_array_equal(search.centres(fast.sample), expected)


# ------------------------------------------------------------------ map files and figures


@pytest.mark.parametrize("mode", ["trinary", "scale", "raw"])
@pytest.mark.parametrize("negate", [False, True])
def test_grey_images_are_looked_up_as_the_float_path_computes_them(tmp_path, mode, negate):
    """The grey-level table gives every level the value the float computation gives."""
    levels = np.arange(256, dtype=np.uint8).reshape(16, 16)
    spec = _MapSpec(tmp_path / "m.pgm", 0.05, (0.0, 0.0, 0.0), negate, 0.65, 0.196, mode)
    table = _occupancy(np.arange(256, dtype=float), None, spec)
    np.testing.assert_array_equal(table[levels], _occupancy(levels.astype(float), None, spec))
    path = tmp_path / "m.yaml"
    from PIL import Image

    Image.fromarray(levels).save(tmp_path / "m.pgm")
    path.write_text(
        f"image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: {int(negate)}\n"
        f"occupied_thresh: 0.65\nfree_thresh: 0.196\nmode: {mode}\n"
    )
    np.testing.assert_array_equal(
        load_map(path).data, np.flipud(_occupancy(levels.astype(float), None, spec))
    )


def test_the_figure_draws_a_large_map_by_darkest_blocks():
    data = np.zeros((2500, 2100), dtype=np.int8)
    data[1234, :] = OCCUPIED  # a one-cell wall must not vanish from the figure
    data[:, 77] = UNKNOWN
    grid = OccupancyGrid(data, 0.05)
    shades, block = drawn_shades(grid)
    assert block == 3 and max(shades.shape) <= MAX_DRAWN_CELLS
    assert shades.shape == (math.ceil(2500 / 3), math.ceil(2100 / 3))
    full = map_shades(grid)
    assert shades[1234 // 3, 500] == full[1234, 1500] and shades[10, 77 // 3] == full[10, 77]
    paper = load_map(resolve_map_path("enclosed.yaml"))
    drawn, one = drawn_shades(paper)
    assert one == 1 and np.array_equal(drawn, map_shades(paper))  # paper maps as before


# ------------------------------------------------------------------ the scaling bench


def test_scaled_maps_keep_the_source_s_shape_and_free_fraction(tmp_path):
    source = load_map(resolve_map_path("enclosed.yaml"))
    grid = scaled_map(1000)
    assert grid.data.shape == (1000, 1000) and grid.resolution == source.resolution
    assert np.mean(grid.data == FREE) == pytest.approx(np.mean(source.data == FREE), abs=0.01)
    assert np.array_equal(scaled_map(330).data, source.data)  # the source's own size: itself
    written = load_map(write_map(400, tmp_path))
    assert np.array_equal(written.data, scaled_map(400).data) and written.name == "enclosed_400"


def test_the_scaling_bench_measures_a_small_map(tmp_path):
    row = measure_parts(str(write_map(400, tmp_path)), repeat=2)
    assert set(row) == {"setup_s", "pursuer_decision_ms", "evader_decision_ms", "peak_mb"}
    assert all(math.isfinite(v) and v > 0 for v in row.values())
    text = "\n".join(format_rows([{"cells": 400, **row}]))
    assert "400 x  400" in text and text.rstrip().endswith("-")  # no game measured


@pytest.mark.parametrize("resolution", [0.05, 0.1, 0.037])
def test_obstacle_distances_are_scipy_s_to_the_last_bit(resolution):
    for seed in range(3):
        grid = pillared_grid(seed, size=70, resolution=resolution)
        fast, reference = obstacle_distance(grid), obstacle_distance_reference(grid)
        assert fast.dtype == reference.dtype == np.float64
        np.testing.assert_array_equal(fast.view(np.int64), reference.view(np.int64))
    paper = load_map(resolve_map_path("hall.yaml"))
    np.testing.assert_array_equal(obstacle_distance(paper), obstacle_distance_reference(paper))


def test_allowed_moves_are_the_reference_s_neighbours():
    grid = pillared_grid(5, size=40)
    planner = Planner(grid, 0.1)
    allowed = allowed_moves(planner.traversable).reshape(grid.height + 2, grid.width + 2)
    ones = np.ones(grid.data.shape)
    for row, col in np.ndindex(grid.data.shape):
        bits = allowed[row + 1, col + 1]
        mine = {(row + dr, col + dc) for k, (dr, dc) in enumerate(MOVES.tolist()) if bits >> k & 1}
        cell = (row, col)
        reference = _reference_neighbours(planner.traversable, ones, False, 0.1, cell)
        expected = {nxt for nxt, _ in reference} if planner.traversable[cell] else set()
        assert mine == expected
    assert not allowed[[0, -1], :].any() and not allowed[:, [0, -1]].any()


@pytest.mark.parametrize("distance", ["euclidean", "geodesic"])
def test_escapes_sorting_only_the_lowest_bounds_first_match_the_reference(monkeypatch, distance):
    """With few tiles sorted first, the search continues into the rest when it must, and
    the escape is still the reference's to the last bit."""
    monkeypatch.setattr(escape, "FIRST_TILES", 3)
    for seed in range(6):
        grid = pillared_grid(seed, size=90)
        planner = Planner(grid, 0.12)
        pursuer_planner = Planner(grid, 0.08) if distance == "geodesic" else None
        search = EscapeSearch(grid, CAMERA, planner, pursuer_planner, distance, 1, 0.2)
        rng = np.random.default_rng(seed)
        rows, cols = np.nonzero(planner.traversable)
        for _ in range(4):
            i, j = rng.integers(rows.size, size=2)
            pursuer = Pose(*grid.cell_to_world(rows[i], cols[i]), rng.uniform(-math.pi, math.pi))
            me = Pose(*grid.cell_to_world(rows[j], cols[j]))
            fast, slow = search.escape(me, pursuer), search.escape_reference(me, pursuer)
            assert (fast.cell, fast.cost, fast.count) == (slow.cell, slow.cost, slow.count)
