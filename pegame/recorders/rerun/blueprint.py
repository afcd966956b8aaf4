"""The default layout of a recording in the Rerun viewer, assembled in one place.

The map view, large, looks straight down on the map as RViz does; beside it the camera
(when the simulator renders images), the plots (tracking, distances, N_eff) and, in
tabs, the events, the losses of track and the config. Entity paths are those of
:mod:`.scene`.
"""

from __future__ import annotations

import math

import numpy as np
import rerun.blueprint as rrb

from pegame.grid import OccupancyGrid
from pegame.recorders.rerun.columns import SIM_TIME, STEP
from pegame.types import Camera


def blueprint(grid: OccupancyGrid, camera: Camera, has_image: bool) -> rrb.Blueprint:
    """The default layout for a game on ``grid`` (its map-frame bounds place the eye)
    seen by ``camera``; has_image: whether the simulator renders camera images."""
    ox, oy, yaw = grid.origin
    corners = (
        np.array([[0, 0], [grid.width, 0], [0, grid.height], [grid.width, grid.height]])
        * grid.resolution
    )
    c, s = math.cos(yaw), math.sin(yaw)
    world = corners @ np.array([[c, s], [-s, c]]) + (ox, oy)
    (x0, y0), (x1, y1) = world.min(axis=0), world.max(axis=0)
    cx, cy, height = (x0 + x1) / 2, (y0 + y1) / 2, 1.3 * max(x1 - x0, y1 - y0)
    # An eye slightly south of the zenith keeps +y up on screen while orbiting stays about z.
    eye = rrb.EyeControls3D(
        kind=rrb.Eye3DKind.Orbital,
        position=[cx, cy - 0.02 * height, height],
        look_target=[cx, cy, 0.0],
        eye_up=[0.0, 0.0, 1.0],
    )
    # Trajectories are logged as segments: the view shows all of them up to the cursor.
    so_far = rrb.VisibleTimeRanges(
        [
            rrb.VisibleTimeRange(
                timeline,
                start=rrb.TimeRangeBoundary.infinite(),
                end=rrb.TimeRangeBoundary.cursor_relative(),
            )
            for timeline in (STEP, SIM_TIME)
        ]
    )
    map_view = rrb.Spatial3DView(
        origin="world",
        name="Map",
        eye_controls=eye,
        line_grid=rrb.LineGrid3D(visible=False),
        overrides={f"world/{name}/trajectory": so_far for name in ("pursuer", "evader")},
    )
    side: list[rrb.Container | rrb.View] = [
        rrb.TimeSeriesView(
            origin="plots/tracking", name="Tracking", axis_y=rrb.ScalarAxis(range=(0.0, 1.05))
        ),
        rrb.TimeSeriesView(origin="plots/distance", name="Distances (m)"),
        rrb.TimeSeriesView(origin="plots/n_eff", name="N_eff"),
        rrb.Tabs(
            rrb.TextLogView(origin="events", name="Events"),
            rrb.TextLogView(origin="losses", name="Losses"),
            rrb.TextDocumentView(origin="config", name="Config"),
        ),
    ]
    if has_image:
        bounds = rrb.VisualBounds2D(
            x_range=[0, camera.image_width], y_range=[0, camera.image_height]
        )
        side.insert(0, rrb.Spatial2DView(origin="camera", name="Camera", visual_bounds=bounds))
    return rrb.Blueprint(rrb.Horizontal(map_view, rrb.Vertical(*side), column_shares=[3, 2]))
