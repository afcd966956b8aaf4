"""The scene of a recording: every entity path, how it looks and what it is sent.

As in Rerun's nuScenes example, each entity tree has one ``log_<family>()``: the statics
once per recording (:func:`log_static`: map, camera border, FOV wedge, config document;
the entities' looks, :func:`styles`, are the layout's), the buffered ticks at each send
(:func:`log_agents`, :func:`log_trails`, :func:`log_sensing`, :func:`log_plots`,
:func:`log_particles`, with columns from :mod:`.columns`), and the rare rows: new plans
(:class:`PlanRows`), events (:func:`buffer_event`) and images (:func:`log_image`, logged
as they happen). The entity paths are listed in :mod:`pegame.recorders.rerun`. Positions
are in the map frame (m); the heights Z_* (m) lift the overlays above the map so that
nothing z-fights.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import lru_cache
from typing import Any

import numpy as np
import rerun as rr
import yaml

from pegame.api import Context, Tick
from pegame.grid import OccupancyGrid, per_grid
from pegame.recorders.rerun.columns import (
    SIM_TIME,
    STEP,
    Archetype,
    EntityBuffer,
    ParticleRows,
    points_at,
    stack_points,
    strips_array,
    time_index,
)
from pegame.types import Camera, Plan, Pose
from pegame.visibility import fov_wedge
from pegame.visibility.outlines import drawn_outlines

PURSUER = (220, 40, 40, 255)
EVADER = (30, 160, 60, 255)
DETECTION = (255, 200, 0, 255)
ESTIMATE = (40, 90, 230, 255)
# Particles go from pale (low weight) to dark violet (the heaviest of the tick).
LIGHT_PARTICLE = np.array([150, 190, 255, 255], dtype=float)
HEAVY_PARTICLE = np.array([110, 0, 170, 255], dtype=float)

# Heights (m) above the map, so that overlays never z-fight with it or with each other;
# markers (detection, estimate) float above the agents' discs, which would hide them.
Z_REGION, Z_PARTICLES, Z_PLAN, Z_TRAIL, Z_AGENT, Z_MARKER = 0.01, 0.02, 0.03, 0.04, 0.05, 0.4

AGENTS = (("pursuer", "p"), ("evader", "e"))  # entity tree and ROW column prefix


# ------------------------------------------------------------------------ statics


def log_static(rec: rr.RecordingStream, context: Context, properties: dict[str, Any]) -> None:
    """The map, the image border, the FOV wedge and the config document (the entities'
    looks are the layout's, :func:`styles`)."""
    rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    # The map is static; building its payload is the larger part of starting a recording.
    rec.log("world/map", per_grid(context.grid, ("recorders.rerun", "map"), grid_map), static=True)
    w, h = context.camera.image_width, context.camera.image_height
    border = [[(0, 0), (w, 0), (w, h), (0, h), (0, 0)]]
    rec.log("camera/frame", rr.LineStrips2D(border, colors=[(128, 128, 128)]), static=True)
    wedge = points_at(fov_template(context.camera), Z_REGION)
    rec.log(
        "world/pursuer/fov",
        rr.LineStrips3D([wedge], colors=[(*PURSUER[:3], 160)], radii=[0.015]),
        static=True,
    )
    dumper = getattr(yaml, "CSafeDumper", yaml.SafeDumper)  # libyaml's, when there, is faster
    text = f"```yaml\n{yaml.dump(properties, Dumper=dumper, sort_keys=False)}```\n"
    rec.log("config", rr.TextDocument(text, media_type=rr.MediaType.MARKDOWN), static=True)


def grid_map(grid: OccupancyGrid) -> rr.GridMap:
    """The occupancy grid as an ``rr.GridMap``: map-frame metres, RViz's map colours.

    GridMap draws its first data row at the top (highest y) and puts the lower-left
    corner of the image at ``translation``, so the rows (row 0 = lowest y) are flipped;
    int8 -1 (unknown) becomes 255 as RViz's colour map expects.
    """
    ox, oy, yaw = grid.origin
    data = np.ascontiguousarray(np.flipud(grid.data)).view(np.uint8)
    return rr.GridMap(
        data=data.tobytes(),
        format=rr.components.ImageFormat(
            width=grid.width, height=grid.height, color_model="L", channel_datatype="U8"
        ),
        cell_size=grid.resolution,
        translation=[ox, oy, 0.0],
        rotation_axis_angle=rr.RotationAxisAngle(axis=[0.0, 0.0, 1.0], radians=yaw),
        colormap=rr.components.Colormap.RvizMap,
    )


@lru_cache(maxsize=16)
def fov_template(camera: Camera) -> np.ndarray:
    """The camera's FOV wedge (:func:`pegame.visibility.fov_wedge`) at the zero pose, (K, 2) m."""
    return fov_wedge(camera, Pose(0.0, 0.0, 0.0), n=16)


@lru_cache(maxsize=4)
def styles(pursuer_radius: float, evader_radius: float) -> dict[str, Any]:
    """The colours and sizes (m) of every entity, per entity path: the layout's overrides
    (:func:`.blueprint.blueprint`)."""

    def faded(color: tuple[int, ...], alpha: int = 160) -> tuple[int, ...]:
        return (*color[:3], alpha)

    step_after = rr.components.InterpolationMode.StepAfter
    looks = {
        "world/detection": rr.Points3D.from_fields(colors=[DETECTION], radii=[0.12]),
        "world/belief/mean": rr.Points3D.from_fields(colors=[ESTIMATE], radii=[0.12]),
        "world/belief/particles": rr.Points3D.from_fields(radii=[0.04]),
        "world/pursuer/visible": rr.LineStrips3D.from_fields(
            colors=[(255, 140, 0, 255)], radii=[0.025]
        ),
        "world/evader/candidates": rr.Points3D.from_fields(colors=[faded(EVADER)], radii=[0.08]),
        "camera/detection": rr.Boxes2D.from_fields(colors=[DETECTION]),
        "plots/tracking/detected": rr.SeriesLines(
            colors=[DETECTION], names=["detected"], interpolation_mode=step_after
        ),
        "plots/tracking/rate": rr.SeriesLines(colors=[PURSUER], names=["tracking rate"]),
        "plots/distance/true": rr.SeriesLines(
            colors=[(90, 90, 90)], names=["pursuer-evader distance"]
        ),
        "plots/distance/estimate_error": rr.SeriesLines(
            colors=[ESTIMATE], names=["estimation error"]
        ),
        "plots/n_eff": rr.SeriesLines(colors=[(110, 0, 170)], names=["N_eff"]),
    }
    for name, color, radius in (
        ("pursuer", PURSUER, pursuer_radius),
        ("evader", EVADER, evader_radius),
    ):
        looks[f"world/{name}/pose"] = rr.Points3D.from_fields(colors=[color], radii=[radius])
        looks[f"world/{name}/heading"] = rr.Arrows3D.from_fields(colors=[color], radii=[0.03])
        looks[f"world/{name}/trajectory"] = rr.LineStrips3D.from_fields(
            colors=[color], radii=[0.03]
        )
        looks[f"world/{name}/path"] = rr.LineStrips3D.from_fields(
            colors=[faded(color)], radii=[0.02]
        )
        looks[f"world/{name}/goal"] = rr.Points3D.from_fields(
            colors=[faded(color, 220)], radii=[0.15]
        )
    return looks


# ------------------------------------------------- buffered ticks, at each send
# c: the buffered rows as columns named as in columns.ROW; every: their index columns.


def _send(rec: rr.RecordingStream, path: str, index: list, columns: Any) -> None:
    rec.send_columns(path, indexes=index, columns=columns, strict=True)


def log_agents(
    rec: rr.RecordingStream,
    c: dict[str, np.ndarray],
    every: list,
    context: Context,
    outline_rays: int,
) -> None:
    """Both poses with their heading arrows; the pursuer's FOV wedge (placed by a
    transform) and the outline of its visibility region (``outline_rays`` rays)."""
    for name, prefix in AGENTS:
        x, y, theta = c[f"{prefix}x"], c[f"{prefix}y"], c[f"{prefix}theta"]
        here = stack_points(x, y, Z_AGENT)
        length = 2 * getattr(context, name).radius + 0.3
        heading = stack_points(length * np.cos(theta), length * np.sin(theta), 0.0)
        _send(rec, f"world/{name}/pose", every, rr.Points3D.columns(positions=here))
        _send(
            rec, f"world/{name}/heading", every, rr.Arrows3D.columns(origins=here, vectors=heading)
        )
    half = 0.5 * c["ptheta"]
    rotation = np.zeros((len(half), 4), dtype=np.float32)  # quaternions (x, y, z, w) about z
    rotation[:, 2], rotation[:, 3] = np.sin(half), np.cos(half)
    wedge = rr.Transform3D.columns(
        translation=stack_points(c["px"], c["py"], 0.0), quaternion=rotation
    )
    _send(rec, "world/pursuer/fov", every, wedge)
    points, lengths = drawn_outlines(
        context.grid, c["px"], c["py"], c["ptheta"], context.camera, outline_rays, Z_REGION
    )
    strips = strips_array(points, lengths)
    _send(rec, "world/pursuer/visible", every, rr.LineStrips3D.columns(strips=strips))


def log_trails(
    rec: rr.RecordingStream,
    c: dict[str, np.ndarray],
    indexes: dict,
    trail_every: int,
    final: bool,
    trail_ends: dict[str, np.ndarray],
) -> None:
    """Both trajectories as segments, each from the previous trajectory point (kept per
    agent in ``trail_ends``, (1, 3)) to the agent's position, every ``trail_every`` ticks
    and at the last tick (``final``): the gap to the agent stays under its disc, and the
    data grows linearly with the game, where re-logging the whole trajectory would grow
    quadratically."""
    steps = c["step"].astype(np.int64)
    picked = steps % trail_every == 0
    picked[-1] |= final
    if not picked.any():
        return
    index = time_index(indexes, steps[picked], c["time"][picked])
    for name, prefix in AGENTS:
        ends = stack_points(c[f"{prefix}x"][picked], c[f"{prefix}y"][picked], Z_TRAIL)
        starts = np.concatenate([trail_ends.get(name, ends[:1]), ends[:-1]])
        trail_ends[name] = ends[-1:]
        segments = strips_array(np.stack([starts, ends], axis=1))
        _send(rec, f"world/{name}/trajectory", index, rr.LineStrips3D.columns(strips=segments))


def log_sensing(
    rec: rr.RecordingStream, c: dict[str, np.ndarray], every: list, images: bool
) -> None:
    """Detection (map point, and its box on the camera's image when the simulator renders
    images: the layout shows the image plane only then) and estimate; an empty row where
    there is none."""
    seen = np.isfinite(c["det_x"])
    sizes = seen.astype(np.int64)
    where = stack_points(c["det_x"][seen], c["det_y"][seen], Z_MARKER)
    _send(rec, "world/detection", every, rr.Points3D.columns(positions=where).partition(sizes))
    if images:
        seen_at = zip(c["confidence"][seen].tolist(), c["depth"][seen].tolist())
        labels = [f"evader {p:.2f}, {d:.2f} m" for p, d in seen_at]
        boxes = rr.Boxes2D.columns(
            centers=np.column_stack([c["box_cx"][seen], c["box_cy"][seen]]),
            half_sizes=np.column_stack([c["box_hw"][seen], c["box_hh"][seen]]),
            labels=labels,
        )
        _send(rec, "camera/detection", every, boxes.partition(sizes))
    estimated = np.isfinite(c["mean_x"])
    mean = stack_points(c["mean_x"][estimated], c["mean_y"][estimated], Z_MARKER)
    columns = rr.Points3D.columns(positions=mean).partition(estimated.astype(np.int64))
    _send(rec, "world/belief/mean", every, columns)


def log_plots(
    rec: rr.RecordingStream,
    c: dict[str, np.ndarray],
    every: list,
    index_of: Callable[[np.ndarray], list],
) -> None:
    """The time series; estimation error and N_eff only at ticks that have them
    (``index_of(mask)`` gives the index columns of those rows)."""
    detected = np.isfinite(c["det_x"]).astype(float)
    _send(rec, "plots/tracking/detected", every, rr.Scalars.columns(scalars=detected))
    _send(rec, "plots/tracking/rate", every, rr.Scalars.columns(scalars=c["rate"]))
    distance = np.hypot(c["px"] - c["ex"], c["py"] - c["ey"])
    _send(rec, "plots/distance/true", every, rr.Scalars.columns(scalars=distance))
    error = np.hypot(c["mean_x"] - c["ex"], c["mean_y"] - c["ey"])
    for path, values in (("plots/distance/estimate_error", error), ("plots/n_eff", c["n_eff"])):
        given = np.isfinite(values)
        if given.any():
            _send(rec, path, index_of(given), rr.Scalars.columns(scalars=values[given]))


def log_particles(rec: rr.RecordingStream, particles: ParticleRows, indexes: dict) -> None:
    """The buffered particle subsamples, one row per tick, coloured by their shade."""
    if particles.count:
        steps, times, positions, sizes, shades, counts = particles.take()
        columns = [
            *rr.Points3D.columns(positions=positions).partition(sizes),
            *rr.Points3D.columns(colors=_particle_palette()[shades]).partition(counts),
        ]
        _send(rec, "world/belief/particles", time_index(indexes, steps, times), columns)


@lru_cache(maxsize=1)
def _particle_palette() -> np.ndarray:
    """The 256 particle colours (0xRRGGBBAA), from LIGHT_PARTICLE (shade 0) to HEAVY_PARTICLE (255)."""
    t = np.arange(256)[:, None] / 255.0
    rgba = np.round(LIGHT_PARTICLE + t * (HEAVY_PARTICLE - LIGHT_PARTICLE)).astype(np.uint32)
    return (rgba[:, 0] << 24) | (rgba[:, 1] << 16) | (rgba[:, 2] << 8) | rgba[:, 3]


# ------------------------------------------------------ rare rows, as they happen


class Buffers(dict):
    """The :class:`EntityBuffer` of each entity path with rare rows (plans, events)."""

    def add(
        self,
        path: str,
        kind: Archetype,
        step: int,
        time: float,
        create: bool = True,
        **values: Any,
    ) -> None:
        """Buffer one row of ``kind`` at ``path``; with create=False only for an entity
        that already exists (an empty row then clears what it showed)."""
        buffer = self.get(path)
        if buffer is None:
            if not create:
                return
            buffer = self[path] = EntityBuffer(path, kind)
        buffer.add(step, time, **values)

    def send(self, rec: rr.RecordingStream, indexes: dict) -> None:
        for buffer in self.values():
            buffer.send(rec, indexes)


class PlanRows:
    """Agent ``name``'s new plans since the last send, kept by reference (a plan is not
    changed once returned, :class:`pegame.types.Plan`) and sent as rows of its path, its
    goal and the candidates it chose from: converting them together at the send costs
    less than converting each between the game's ticks."""

    def __init__(self, name: str) -> None:
        self.name = name
        self.steps: list[int] = []
        self.times: list[float] = []
        self.plans: list[Plan] = []
        self.has_candidates = False  # the candidates entity exists (an empty row clears it)

    def add(self, step: int, time: float, plan: Plan) -> None:
        self.steps.append(step)
        self.times.append(time)
        self.plans.append(plan)

    def send(self, rec: rr.RecordingStream, indexes: dict) -> None:
        """Send the buffered plans' rows and empty the buffer (``indexes``: see
        :func:`.columns.time_index`)."""
        if not self.plans:
            return
        steps, times, plans = (
            np.asarray(self.steps, dtype=np.int64),
            np.asarray(self.times),
            self.plans,
        )
        self.steps, self.times, self.plans = [], [], []
        paths = [np.asarray(plan.path, dtype=float).reshape(-1, 2) for plan in plans]
        drawn = [path for path in paths if len(path) >= 2]
        strips = strips_array([points_at(path, Z_PLAN) for path in drawn])
        index = time_index(indexes, steps, times)
        sizes = np.array([len(path) >= 2 for path in paths], dtype=np.int64)
        _send(
            rec,
            f"world/{self.name}/path",
            index,
            rr.LineStrips3D.columns(strips=strips).partition(sizes),
        )
        goals = [plan.goal for plan in plans if plan.goal is not None]
        sizes = np.array([plan.goal is not None for plan in plans], dtype=np.int64)
        columns = rr.Points3D.columns(positions=points_at(goals, Z_PLAN)).partition(sizes)
        _send(rec, f"world/{self.name}/goal", index, columns)
        found = [plan.info.get("candidates") for plan in plans]
        counts = np.array([0 if c is None else len(c) for c in found], dtype=np.int64)
        first = (
            0
            if self.has_candidates
            else int(np.argmax(counts > 0))
            if counts.any()
            else len(counts)
        )
        if first == len(counts):
            return
        self.has_candidates = True
        candidates = _flat_points([c for c in found[first:] if c is not None and len(c)], Z_PLAN)
        columns = rr.Points3D.columns(positions=candidates).partition(counts[first:])
        index = time_index(indexes, steps[first:], times[first:])
        _send(rec, f"world/{self.name}/candidates", index, columns)


def _flat_points(parts: list[np.ndarray], z: float) -> np.ndarray:
    """The (K_i, >= 2) map-frame positions (m) of ``parts``, one after the other, as
    (sum K_i, 3) float32 points at height z."""
    if not parts:
        return np.zeros((0, 3), dtype=np.float32)
    return points_at(np.concatenate([np.asarray(part, dtype=float)[:, :2] for part in parts]), z)


def buffer_event(buffers: Buffers, step: int, time: float, text: str, level: str = "INFO") -> None:
    """One line of the events log (``level``: a Rerun TextLog level, INFO, WARN, ERROR)."""
    buffers.add("events", rr.TextLog, step, time, text=[text], level=[level])


def buffer_losses(buffers: Buffers, tick: Tick) -> None:
    """One line of the losses log per loss of track begun at ``tick``, naming its pair and
    its cause (:mod:`pegame.losses`)."""
    for loss in tick.losses:
        text = f"pursuer {loss.pursuer} lost evader {loss.evader}: {loss.cause}"
        buffers.add("losses", rr.TextLog, tick.step, tick.time, text=[text], level=["WARN"])


def log_image(rec: rr.RecordingStream, tick: Tick, camera: Camera, jpeg_quality: int) -> None:
    """The tick's camera image as JPEG, logged directly: it is rare and large."""
    rec.set_time(STEP, sequence=tick.step)
    rec.set_time(SIM_TIME, duration=tick.time)
    rgb = tick.frame.rgb
    assert rgb is not None  # logged for the frames that have an image only
    size = (camera.image_width, camera.image_height)
    if rgb.shape[1::-1] != size:
        # Detections are in the camera's image_width x image_height pixel frame; a
        # simulator may render smaller, so the image is scaled to that frame.
        from PIL import Image

        rgb = np.asarray(Image.fromarray(rgb).resize(size, Image.Resampling.BILINEAR))
    rec.log("camera/image", rr.Image(rgb).compress(jpeg_quality=jpeg_quality), strict=True)
