"""Obstacle inflation: the costmap's lethal and inscribed zone, as move_base inflates it.

:func:`inflate` gives the cells where a disc of an agent's radius would overlap an
obstacle; the grid simulator uses ``inflate(grid, body.radius)`` as the collision mask of
an agent's centre, and the planner inflates by the radius plus a margin. Both derive from
the Euclidean distance transform :func:`obstacle_distance`, computed once per grid
(:func:`pegame.grid.per_grid`), as is each radius's shared mask
(:func:`shared_inflation`).

Units: metres; arrays are (height, width) indexed [row, col], row 0 the lowest y.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from scipy import ndimage

from pegame.grid import OccupancyGrid, per_grid, read_only

#: distances equal to the radius up to float rounding count as within it (m)
DISTANCE_TOLERANCE = 1e-9


def obstacle_distance(grid: OccupancyGrid) -> np.ndarray:
    """Float64 (H, W): distance (m) from each cell centre to the nearest blocked cell centre.

    Blocked cells (occupied or unknown) are at distance 0, and every cell outside the grid
    counts as blocked, so no cell is farther than its distance to the ring of cells just
    outside the border.

    Fast path of :func:`obstacle_distance_reference`, with the same floats: scipy's
    feature transform (the nearest blocked cell of every cell), then the distances from
    it by the operations distance_transform_edt applies, in one pass (numba) instead of
    its full-grid integer and float temporaries (about 50 bytes per cell at once).
    """
    # One ring of blocked padding is enough: the nearest outside cell is always in it.
    free = np.pad(~grid.blocked, 1, constant_values=False)
    nearest = ndimage.distance_transform_edt(
        free, sampling=grid.resolution, return_distances=False, return_indices=True
    )
    return _feature_distances(nearest, float(grid.resolution))


def obstacle_distance_reference(grid: OccupancyGrid) -> np.ndarray:
    """:func:`obstacle_distance` by scipy's distance_transform_edt alone."""
    free = np.pad(~grid.blocked, 1, constant_values=False)
    distance = ndimage.distance_transform_edt(free, sampling=grid.resolution)
    return distance[1:-1, 1:-1]


@njit(cache=True)
def _feature_distances(nearest: np.ndarray, resolution: float) -> np.ndarray:
    """Float64 (H, W): distance (m) from each inner cell of the padded (H + 2, W + 2)
    grid to its feature ``nearest[:, row, col]`` (int32 (2, H + 2, W + 2) row and column),
    as scipy computes it: sqrt((dr * res)^2 + (dc * res)^2), each factor a float64."""
    height, width = nearest.shape[1] - 2, nearest.shape[2] - 2
    out = np.empty((height, width))
    for row in range(height):
        for col in range(width):
            dr = float(nearest[0, row + 1, col + 1] - (row + 1)) * resolution
            dc = float(nearest[1, row + 1, col + 1] - (col + 1)) * resolution
            out[row, col] = math.sqrt(dr * dr + dc * dc)
    return out


def inflate(grid: OccupancyGrid, radius: float) -> np.ndarray:
    """Bool (H, W): True where a disc of ``radius`` (m) centred on the cell centre would
    contain the centre of a blocked cell, counting cells outside the grid as blocked.

    Blocked cells are always True. An agent's centre may never lie in a True cell of
    ``inflate(grid, body.radius)``. The result is a new writable array; see
    :func:`shared_inflation` for the shared read-only one.
    """
    return shared_obstacle_distance(grid) <= radius + DISTANCE_TOLERANCE


def shared_inflation(grid: OccupancyGrid, radius: float) -> np.ndarray:
    """``inflate(grid, radius)``, computed once per grid and radius and shared (read-only)."""
    return per_grid(
        grid,
        ("navigation", "inflation", float(radius)),
        lambda grid: read_only(inflate(grid, radius)),
    )


def shared_obstacle_distance(grid: OccupancyGrid) -> np.ndarray:
    """:func:`obstacle_distance`, computed once per grid (read-only)."""
    return per_grid(
        grid, ("navigation", "obstacle distance"), lambda grid: read_only(obstacle_distance(grid))
    )
