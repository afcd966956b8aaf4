"""The default layout of a recording in the Rerun viewer, assembled in one place.

The map view, large, looks straight down on the map as RViz does; beside it the camera
(when the simulator renders images), the plots (tracking, distances, N_eff) and, in
tabs, the events, the losses of track and the config. Entity paths are those of
:mod:`.scene`.

The layout is written once per output directory, as the blueprint file
``<out_dir>/pegame.rbl`` (:func:`write_layout`), not into every recording: the viewer
gives every recording of the application ``pegame`` the same blueprint, and a
recording's own copy (74 kB) took rerun-sdk about 3.6 ms to build and encode, 2% of a
90 s game, repeated for every game of a sweep. ``python -m pegame.replay`` opens the
file with the recordings (``rerun DIR/pegame.rbl DIR/*.rrd`` does the same); a game
played with a spawned viewer also sends the layout to it. The entities' colours and
sizes (:func:`.scene.styles`) are part of the layout, as overrides of the views that show
them: logged into every recording, they cost another 2.7 ms of a game.
"""

from __future__ import annotations

import math
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import rerun.blueprint as rrb

from pegame.api import Context
from pegame.files import write_atomic
from pegame.grid import OccupancyGrid, per_grid
from pegame.recorders.files import LAYOUT_FILE
from pegame.recorders.rerun.columns import SIM_TIME, STEP
from pegame.recorders.rerun.scene import styles
from pegame.types import Camera


def blueprint(
    grid: OccupancyGrid, camera: Camera, has_image: bool, looks: dict[str, Any]
) -> rrb.Blueprint:
    """The default layout for a game on ``grid`` (its map-frame bounds place the eye)
    seen by ``camera``; has_image: whether the simulator renders camera images; looks:
    each entity's colours and sizes (:func:`.scene.styles`), given as the overrides of
    the view that shows it."""

    # Keys typed Any: rerun-sdk's overrides take a mapping keyed by EntityPath | str.
    def overrides(origin: str) -> dict[Any, list[Any]]:
        return {path: [look] for path, look in looks.items() if path.startswith(f"{origin}/")}

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
    in_map = overrides("world")
    for name in ("pursuer", "evader"):
        in_map.setdefault(f"world/{name}/trajectory", []).append(so_far)
    map_view = rrb.Spatial3DView(
        origin="world",
        name="Map",
        eye_controls=eye,
        line_grid=rrb.LineGrid3D(visible=False),
        overrides=in_map,
    )
    side: list[rrb.Container | rrb.View] = [
        rrb.TimeSeriesView(
            origin="plots/tracking",
            name="Tracking",
            axis_y=rrb.ScalarAxis(range=(0.0, 1.05)),
            overrides=overrides("plots/tracking"),
        ),
        rrb.TimeSeriesView(
            origin="plots/distance", name="Distances (m)", overrides=overrides("plots/distance")
        ),
        rrb.TimeSeriesView(
            origin="plots/n_eff", name="N_eff", overrides={"plots/n_eff": [looks["plots/n_eff"]]}
        ),
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
        camera_view = rrb.Spatial2DView(
            origin="camera", name="Camera", visual_bounds=bounds, overrides=overrides("camera")
        )
        side.insert(0, camera_view)
    return rrb.Blueprint(rrb.Horizontal(map_view, rrb.Vertical(*side), column_shares=[3, 2]))


def game_blueprint(context: Context, has_image: bool) -> rrb.Blueprint:
    """:func:`blueprint` of a game in ``context``, with its entities' looks."""
    looks = styles(float(context.pursuer.radius), float(context.evader.radius))
    return blueprint(context.grid, context.camera, has_image, looks)


def write_layout(out_dir: Path, application_id: str, context: Context, has_image: bool) -> None:
    """Write ``out_dir/pegame.rbl``, the layout of :func:`game_blueprint`, unless it is
    there: rerun-sdk's own blueprint file, saved once per grid and layout into a scratch
    directory and written here atomically (:func:`pegame.files.write_atomic`)."""
    path = out_dir / LAYOUT_FILE
    if path.exists():
        return

    def saved(grid: OccupancyGrid) -> bytes:
        with tempfile.TemporaryDirectory() as scratch:
            file = Path(scratch) / LAYOUT_FILE
            game_blueprint(context, has_image).save(application_id, file)
            return file.read_bytes()

    bodies = (context.pursuer.radius, context.evader.radius)
    key = ("recorders.rerun", "layout file", application_id, context.camera, bodies, has_image)
    grid = context.grid
    write_atomic(path, per_grid(grid, key, saved), sync=False)
