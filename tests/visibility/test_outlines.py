"""Outlines of visibility regions (pegame.visibility.outlines): the numba kernel against
its plain reference, and the outline against Algorithm 1's region."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pegame.grid import OccupancyGrid
from pegame.types import Camera, Pose
from pegame.visibility import visibility_region
from pegame.visibility.outlines import NEAR_ARC_POINTS, free_runs, visibility_outlines


@pytest.mark.slow
@pytest.mark.parametrize("origin", [(0.0, 0.0, 0.0), (-0.7, 1.3, 0.4)])
def test_visibility_outlines_match_their_reference_and_bound_the_region(origin):
    # Sparse walls on a large grid, so that the kernel's jumps over free cells are long.
    rng = np.random.default_rng(8)
    data = np.zeros((150, 150), dtype=np.int8)
    data[rng.random(data.shape) < 0.003] = 100
    data[40:110, 75] = 100
    grid = OccupancyGrid(data, 0.05, origin)
    camera = Camera()
    free = np.argwhere(~grid.blocked)[rng.choice(int((~grid.blocked).sum()), 60)]
    xs, ys = grid.cell_to_world(free[:, 0], free[:, 1])
    thetas = rng.uniform(-math.pi, math.pi, 60)
    fast = visibility_outlines(grid, xs, ys, thetas, camera, 64, z=0.01)
    slow = visibility_outlines(grid, xs, ys, thetas, camera, 64, z=0.01, compiled=False)
    np.testing.assert_array_equal(fast, slow)
    assert fast.shape == (60, 64 + NEAR_ARC_POINTS + 1, 3) and np.array_equal(
        fast[:, 0], fast[:, -1]
    )
    in_region = []
    for outline, x, y, theta in zip(fast, xs, ys, thetas):
        mask = visibility_region(grid, Pose(x, y, theta), camera)
        reach = np.hypot(outline[:64, 0] - x, outline[:64, 1] - y)
        assert np.all(reach >= camera.near - 1e-4) and np.all(reach <= camera.far + 1e-4)
        rows, cols = grid.world_to_cell(outline[:64, 0], outline[:64, 1])
        beyond_near = reach > camera.near + 1e-4
        in_region.extend(mask[rows[beyond_near], cols[beyond_near]])
    # the far ends lie in visible cells (float32 rounding may move one across a cell edge)
    assert len(in_region) > 2000 and np.mean(in_region) > 0.95


def test_free_runs_never_jump_into_a_blocked_cell():
    # From any point of a free cell, every sample one cell apart along any ray, up to its
    # run, is free: checked on many random rays against the blocked mask.
    rng = np.random.default_rng(3)
    data = np.zeros((80, 90), dtype=np.int8)
    data[rng.random(data.shape) < 0.02] = 100
    grid = OccupancyGrid(data, 0.1)
    runs = free_runs(grid)
    assert np.array_equal(runs == 0, grid.blocked)
    rows, cols = np.nonzero(~grid.blocked)
    pick = rng.choice(rows.size, 3000)
    for r, c in zip(rows[pick], cols[pick]):
        v, u = r + rng.random(), c + rng.random()
        a = rng.uniform(-math.pi, math.pi)
        k = np.arange(int(runs[r, c]))
        fr, fc = (
            np.floor(v + k * math.sin(a)).astype(int),
            np.floor(u + k * math.cos(a)).astype(int),
        )
        inside = (fr >= 0) & (fr < grid.height) & (fc >= 0) & (fc < grid.width)
        assert inside.all() and not grid.blocked[fr, fc].any()
