"""The egocentric crop (pegame.observe.crop): its kernels against the plain reference, on
cell edges too, and its frame; no gymnasium needed."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pegame.grid import OccupancyGrid
from pegame.observe.crop import LocalCrop, lattice_crop, local_crop_reference


def _room(yaw: float = 0.0) -> OccupancyGrid:
    """A 4 m x 3 m room at 0.05 m/cell with a one-cell-thin wall at x = 2 m."""
    data = np.zeros((60, 80), dtype=np.int8)
    data[:, 40] = 100
    data[30:35, 10:15] = -1
    return OccupancyGrid(data, 0.05, (0.3, -0.2, yaw))


@pytest.mark.parametrize("yaw", [0.0, 0.4])
def test_crop_kernel_matches_the_reference(yaw):
    grid = _room(yaw)
    rng = np.random.default_rng(0)
    for cells, resolution in [(8, 0.5), (32, 0.2), (5, 0.05)]:
        crop = LocalCrop(grid, cells, resolution)
        for x, y, theta in rng.uniform([-1, -1, -4], [5, 4, 4], (20, 3)):
            expected = local_crop_reference(grid, x, y, theta, cells, resolution)
            assert np.array_equal(crop(x, y, theta).reshape(cells, cells), expected)


@pytest.mark.parametrize("yaw", [0.0, 0.4])
def test_crop_on_cell_edges_takes_the_division_and_matches_the_reference(yaw):
    grid = _room(yaw)
    crop = LocalCrop(grid, 32, 0.2)
    ox, oy, _ = grid.origin
    undecided = 0
    for i, j, turn in [(20, 10, 0.0), (31, 7, math.pi / 2), (44, 33, -math.pi), (12, 50, 0.0)]:
        # A cell corner, the crop's axes along the grid's: its samples lie on cell edges.
        u, v, theta = j * grid.resolution, i * grid.resolution, yaw + turn
        x = ox + math.cos(yaw) * u - math.sin(yaw) * v
        y = oy + math.sin(yaw) * u + math.cos(yaw) * v
        expected = local_crop_reference(grid, x, y, theta, 32, 0.2)
        assert np.array_equal(crop(x, y, theta).reshape(32, 32), expected)
        out = np.empty(crop.size, dtype=np.float32)
        pose = (x, y, math.cos(theta), math.sin(theta))
        undecided += not lattice_crop(crop._lattice, pose, out, 0, crop._scratch)
    assert undecided > 0  # these poses exercise the division, not only the lattice


def test_crop_is_egocentric_and_sees_thin_walls():
    grid = _room()  # the thin wall spans x in [2.3, 2.35] m
    # 0.35 m before the wall's near edge, facing it: the wall is ahead (+x, the columns).
    ahead = local_crop_reference(grid, 1.95, 1.2, 0.0, 4, 0.4)
    assert ahead[:, 2].all() and not ahead[:, :2].any()
    # Facing +y the same wall is on the robot's right (-y, the low rows).
    left = local_crop_reference(grid, 1.95, 1.2, math.pi / 2, 4, 0.4)
    assert left[1, :].all() and not left[2:, :].any()
    # Off the map is blocked: near the lower-left corner, facing -x.
    behind = local_crop_reference(grid, 0.35, 1.2, math.pi, 4, 0.5)
    assert behind[:, 2:].all()
