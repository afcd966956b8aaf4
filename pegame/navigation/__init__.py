"""Grid navigation: the role ROS move_base plays in the paper.

In the paper every agent reaches its goal through move_base: a global planner on an
inflated costmap and a local controller that drives a non-holonomic robot along the
plan. This package provides the same pieces for occupancy grids:

- :mod:`pegame.navigation.inflation`: :func:`inflate`, the inflated obstacle mask (the
  costmap's lethal + inscribed zone), :func:`obstacle_distance` and the per-grid shared
  :func:`shared_inflation`; the grid simulator uses ``inflate(grid, body.radius)`` as the
  collision mask of an agent's centre;
- :mod:`pegame.navigation.search`: the Dijkstra and A* kernels on 8-connected moves
  without corner cutting, and their plain-Python references;
- :mod:`pegame.navigation.planner`: :class:`Planner`, global planning (distance fields
  and minimum-cost paths that keep clear of walls), and its :class:`PathResult`;
- :mod:`pegame.navigation.follower`: :class:`PathFollower`, a pure-pursuit local
  controller for a unicycle.

Units and frames: positions are map-frame (x, y) in metres (ROS conventions, see
:mod:`pegame.grid`), headings and angles in radians, speeds in m/s and rad/s. Grid
arrays are (height, width) indexed [row, col] with row 0 the lowest y; distances and
costs are in metres.
"""

from pegame.navigation.follower import PathFollower
from pegame.navigation.inflation import inflate, obstacle_distance, shared_inflation
from pegame.navigation.planner import LARGE_GRID_CELLS, TIE_QUANTUM, PathResult, Planner

__all__ = [
    "LARGE_GRID_CELLS",
    "PathFollower",
    "PathResult",
    "Planner",
    "TIE_QUANTUM",
    "inflate",
    "obstacle_distance",
    "shared_inflation",
]
