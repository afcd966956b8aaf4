"""A recording read back into arrays, for headless replays and figures.

:func:`read_game` reads a ``game.rrd`` written by :class:`pegame.recorders.rerun.
RerunRecorder` with rerun-sdk's own chunk reader (``rerun.chunk.RrdReader``) and returns
a :class:`RecordedGame`: the map (from the recording's ``GridMap``), the camera and body
sizes (from its config properties), and per control tick the poses of every member, the
detection flag, the true distance, the estimation error, N_eff, the pursuer's visibility
outline and the belief's particles and mean. Entities are those of :mod:`.scene` (member
0 of each role) and :mod:`.team` (the others). Positions are map-frame metres, angles in
radians.

Headings: pursuer 0's comes from its FOV transform and evader 0's from its heading arrow,
as recorded; other members have no heading entity, so a pursuer's is the direction of its
recorded FOV wedge (symmetric about the optical axis) and an evader's the direction of
its last displacement.
"""

from __future__ import annotations

import math
import re
from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from pegame.grid import OccupancyGrid

_MEMBER = re.compile(r"^/world/(pursuer|evader)(?:_(\d+))?/(pose|heading|fov)$")
_SERIES = {
    "/plots/tracking/detected": "detected",
    "/plots/distance/true": "distance",
    "/plots/distance/estimate_error": "estimate_error",
    "/plots/n_eff": "n_eff",
}


@dataclass
class RecordedGame:
    """One recorded game as arrays over its T recorded control ticks.

    steps, time: (T,) tick index and simulated time (s). pursuers, evaders: (N, T, 3) and
    (M, T, 3) poses (x, y, theta), NaN where a member has no row. detected, distance,
    estimate_error, n_eff: (T,) series of the recording's plots (NaN where a tick has no
    value, such as the estimation error while the evader is seen). outlines: per tick the
    pursuer 0 visibility outline's (K, 2) polygons. particles: per tick the (P, 2)
    particle subsample about evader 0 last logged (every ``particles_every`` ticks),
    means: (T, 2) its belief mean. config: the game's flat config properties
    (``camera.fov``, ``pursuer.radius``, ...).
    """

    grid: OccupancyGrid
    config: dict[str, Any]
    steps: np.ndarray
    time: np.ndarray
    pursuers: np.ndarray
    evaders: np.ndarray
    detected: np.ndarray
    distance: np.ndarray
    estimate_error: np.ndarray
    n_eff: np.ndarray
    means: np.ndarray
    outlines: list[list[np.ndarray]] = field(default_factory=list)
    particles: list[np.ndarray] = field(default_factory=list)

    def setting(self, key: str, default: float) -> float:
        """A numeric config property (``camera.far``), else ``default``."""
        value = self.config.get(key)
        return float(value) if isinstance(value, (int, float)) else default


def _grid(batch: Any) -> OccupancyGrid:
    """The recorded ``GridMap`` (rows flipped, unknown as 255: :func:`.scene.grid_map`)."""
    shape = batch.column("GridMap:format").to_pylist()[0][0]
    data = np.asarray(batch.column("GridMap:data").to_pylist()[0], dtype=np.uint8)
    cells = np.flipud(data.reshape(shape["height"], shape["width"])).view(np.int8)
    resolution = float(batch.column("GridMap:cell_size").to_pylist()[0][0])
    ox, oy, _ = batch.column("GridMap:translation").to_pylist()[0][0]
    yaw = float(batch.column("GridMap:rotation_axis_angle").to_pylist()[0][0]["angle"])
    return OccupancyGrid(np.ascontiguousarray(cells), resolution, (ox, oy, yaw))


def _single(values: list) -> Any:
    """The one element of a component's row ([[x]] -> x), or None when the row is empty."""
    return values[0] if values else None


def read_game(path: str | Path) -> RecordedGame:
    """Read the recording at ``path`` (module docstring). Raises ValueError when it holds
    no map or no pursuer poses (not a game recording)."""
    from rerun.chunk import RrdReader

    grid: OccupancyGrid | None = None
    config: dict[str, Any] = {}
    rows: dict[str, dict[int, Any]] = defaultdict(dict)
    times: dict[int, float] = {}
    for chunk in RrdReader(Path(path)).stream().to_chunks():
        batch = chunk.to_record_batch()
        entity = chunk.entity_path
        if chunk.is_static:
            if entity == "/world/map":
                grid = _grid(batch)
            elif entity == "/__properties/config":
                config = {
                    name: _single(batch.column(name).to_pylist()[0])
                    for name in batch.schema.names
                    if not name.startswith("rerun.")
                }
            continue
        names = set(batch.schema.names)
        if "step" not in names:
            continue
        steps = batch.column("step").to_pylist()
        for step, moment in zip(steps, batch.column("sim_time").to_pylist()):
            times[step] = moment.total_seconds() if hasattr(moment, "total_seconds") else moment
        component = next(
            (
                name
                for name in (
                    "Scalars:scalars",
                    "Points3D:positions",
                    "Arrows3D:vectors",
                    "Transform3D:quaternion",
                    "LineStrips3D:strips",
                )
                if name in names
            ),
            None,
        )
        if component is None:
            continue
        for step, value in zip(steps, batch.column(component).to_pylist()):
            rows[entity][step] = value
    if grid is None or not rows.get("/world/pursuer/pose"):
        raise ValueError(f"{path} holds no game: no map or no pursuer poses")
    steps = np.array(sorted(rows["/world/pursuer/pose"]), dtype=np.int64)
    return RecordedGame(
        grid=grid,
        config=config,
        steps=steps,
        time=np.array([times[s] for s in steps], dtype=float),
        pursuers=_poses(rows, "pursuer", steps),
        evaders=_poses(rows, "evader", steps),
        **{name: _series(rows.get(entity, {}), steps) for entity, name in _SERIES.items()},
        means=_points(rows.get("/world/belief/mean", {}), steps),
        outlines=[
            [
                np.asarray(strip, dtype=float)[:, :2]
                for strip in rows["/world/pursuer/visible"].get(s) or []
            ]
            for s in steps
        ]
        if "/world/pursuer/visible" in rows
        else [[] for _ in steps],
        particles=_latest(rows.get("/world/belief/particles", {}), steps),
    )


def _latest(values: dict[int, Any], steps: np.ndarray) -> list[np.ndarray]:
    """Per step, the (P, 2) points of the latest row at or before it, as the viewer
    shows them (the particles are logged every ``particles_every`` ticks); (0, 2) before
    the first row and after an empty one."""
    out, last = [], np.empty((0, 2))
    for step in steps.tolist():
        if step in values:
            last = np.asarray(values[step] or np.empty((0, 3)), dtype=float)[:, :2]
        out.append(last)
    return out


def _series(values: dict[int, Any], steps: np.ndarray) -> np.ndarray:
    """A scalar series at ``steps`` (NaN where a step has no value)."""
    out = np.full(len(steps), np.nan)
    for i, step in enumerate(steps):
        value = values.get(int(step))
        if value:
            out[i] = float(value[0])
    return out


def _points(values: dict[int, Any], steps: np.ndarray) -> np.ndarray:
    """The first point of each step's row, (T, 2), NaN where there is none."""
    out = np.full((len(steps), 2), np.nan)
    for i, step in enumerate(steps):
        value = values.get(int(step))
        if value:
            out[i] = value[0][:2]
    return out


def _members(rows: dict[str, dict[int, Any]], role: str) -> list[tuple[int, str]]:
    """(member index, entity prefix) of every member of ``role`` that has poses."""
    found = set()
    for entity in rows:
        match = _MEMBER.match(entity)
        if match and match.group(1) == role and match.group(3) == "pose":
            found.add((int(match.group(2) or 0), entity.rsplit("/", 1)[0]))
    return sorted(found)


def _poses(rows: dict[str, dict[int, Any]], role: str, steps: np.ndarray) -> np.ndarray:
    """(members, T, 3) poses of ``role`` (module docstring for the headings)."""
    members = _members(rows, role)
    out = np.full((max(len(members), 1), len(steps), 3), np.nan)
    for k, (_, prefix) in enumerate(members):
        out[k, :, :2] = _points(rows[f"{prefix}/pose"], steps)
        out[k, :, 2] = _headings(rows, prefix, steps, out[k, :, :2])
    return out


def _headings(
    rows: dict[str, dict[int, Any]], prefix: str, steps: np.ndarray, xy: np.ndarray
) -> np.ndarray:
    """Each step's heading of the member at ``prefix`` (rad)."""
    theta = np.full(len(steps), np.nan)
    arrows, fov = rows.get(f"{prefix}/heading", {}), rows.get(f"{prefix}/fov", {})
    for i, step in enumerate(steps):
        arrow, wedge = arrows.get(int(step)), fov.get(int(step))
        if arrow:
            theta[i] = math.atan2(arrow[0][1], arrow[0][0])
        elif wedge and len(wedge[0]) == 4 and not isinstance(wedge[0][0], (list, tuple)):
            qx, qy, qz, qw = wedge[0]  # pursuer 0: the wedge's transform, about z
            theta[i] = 2.0 * math.atan2(qz, qw)
        elif wedge and np.all(np.isfinite(xy[i])):
            strip = np.asarray(wedge[0], dtype=float)[:, :2] - xy[i]
            centre = strip.mean(axis=0)
            theta[i] = math.atan2(centre[1], centre[0])
    missing = np.isnan(theta)
    if missing.any():  # an evader past member 0: the direction of its last displacement
        moved = np.diff(xy, axis=0, prepend=xy[:1])
        direction = np.arctan2(moved[:, 1], moved[:, 0])
        still = np.hypot(moved[:, 0], moved[:, 1]) < 1e-9
        for i in np.flatnonzero(missing).tolist():
            theta[i] = theta[i - 1] if still[i] and i > 0 else direction[i]
    return np.nan_to_num(theta)
