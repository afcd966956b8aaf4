"""Occupancy-grid maps: the grid, its ROS map files, numba cell helpers and a per-grid cache.

- :mod:`pegame.grid.occupancy`: :class:`OccupancyGrid` (nav_msgs/OccupancyGrid, frozen),
  its map-to-cell transform :class:`GridFrame` and the cell values FREE, OCCUPIED, UNKNOWN;
- :mod:`pegame.grid.ros`: :func:`load_map` and :func:`save_map` of ROS map_server YAML and
  image files;
- :mod:`pegame.grid.cells`: :func:`point_cell` and :func:`cell_blocked`, the numba helpers
  every grid kernel uses to find and test the cell of a map point, and
  :func:`pegame.grid.cells.cell_centres` of many cells at once;
- :mod:`pegame.grid.cache`: :func:`per_grid`, the one cache of objects derived from a grid,
  and :func:`read_only` for the arrays it shares.

Units and frames: metres and radians in ROS's map frame (x right, y up); row 0 of a grid
is the lowest y.
"""

from pegame.grid.cache import per_grid, read_only
from pegame.grid.cells import cell_blocked, point_cell
from pegame.grid.occupancy import FREE, OCCUPIED, UNKNOWN, GridFrame, OccupancyGrid
from pegame.grid.ros import load_map, save_map

__all__ = [
    "FREE",
    "OCCUPIED",
    "UNKNOWN",
    "GridFrame",
    "OccupancyGrid",
    "cell_blocked",
    "load_map",
    "per_grid",
    "point_cell",
    "read_only",
    "save_map",
]
