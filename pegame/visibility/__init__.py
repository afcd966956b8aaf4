"""What the pursuer's camera sees on an occupancy grid.

- :mod:`pegame.visibility.rays`: the rays of Algorithm 1 (per-camera angle and distance
  tables, ray directions), shared by every path below so they all sample the same points;
- :mod:`pegame.visibility.region`: the paper's Algorithm 1 with occlusion,
  :func:`visibility_region` (a numba ray march) and its numpy reference
  :func:`visibility_region_reference`, and :class:`MaskRegion`, a region known by its mask;
- :mod:`pegame.visibility.lazy`: :class:`VisibilityRegion`, the same region computed on
  demand, whole or only over the cells asked about;
- :mod:`pegame.visibility.union`: :class:`UnionRegion`, what several cameras see together;
- :mod:`pegame.visibility.sight`: :func:`line_of_sight`, :func:`in_view` (a point),
  :func:`body_in_view` (a body, the ground truth of "in view") and :func:`fov_wedge`.

Both region classes implement :class:`pegame.types.Region`, the type that observations and
estimators name. Units and frames: metres and radians in the map frame of
:mod:`pegame.grid` (x right, y up).
"""

from pegame.visibility.lazy import VisibilityRegion
from pegame.visibility.region import MaskRegion, visibility_region, visibility_region_reference
from pegame.visibility.sight import SILHOUETTE, body_in_view, fov_wedge, in_view, line_of_sight
from pegame.visibility.union import UnionRegion

__all__ = [
    "SILHOUETTE",
    "MaskRegion",
    "UnionRegion",
    "VisibilityRegion",
    "body_in_view",
    "fov_wedge",
    "in_view",
    "line_of_sight",
    "visibility_region",
    "visibility_region_reference",
]
