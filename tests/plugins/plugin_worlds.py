"""A small map with known walls for the plugin tests (imports no plugin)."""

from __future__ import annotations

import numpy as np

from pegame.grid import OccupancyGrid

RESOLUTION = 0.05  # m per cell
WALL_X = 2.0  # m, the near face of the interior wall
BLOCK = (45, 51, 10, 21)  # rows and cols [start, stop) of an occupied block


def small_map() -> OccupancyGrid:
    """4 m x 3 m at 5 cm: an interior wall two cells thick at x = 2.0-2.1 m, from y = 0 to
    2.0 m, and a block; unknown cells in the top-right corner."""
    data = np.zeros((60, 80), dtype=np.int8)
    col = int(round(WALL_X / RESOLUTION))
    data[:40, col:col + 2] = 100
    rows, cols = slice(BLOCK[0], BLOCK[1]), slice(BLOCK[2], BLOCK[3])
    data[rows, cols] = 100
    data[55:, 75:] = -1
    return OccupancyGrid(data, RESOLUTION, name="small")
