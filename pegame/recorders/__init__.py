"""Recorders: what a game leaves behind besides its result.

:class:`NullRecorder` (``recorder=none``) records nothing. :class:`RerunRecorder`
(``recorder=rerun``) writes one Rerun recording per game, ``<out_dir>/<game_id>.rrd``,
through its own ``rerun.RecordingStream`` (never the global stream); ``python -m
pegame.replay <run dir>`` opens a run's recordings. rerun-sdk is imported on first use,
so importing this module stays light.

Recording id: a UUID5 of the output directory, the game id and the run config. The same
game written to the same place always gets the same id, and two runs (two Hydra run
directories) opened together stay two recordings instead of being merged by the viewer.

Timelines: ``step`` (control tick index, sequence) and ``sim_time`` (simulation time,
duration in s). Entity paths below; ``world`` is the map frame in metres, right-handed
with z up (overlays sit a few cm above the map so that nothing z-fights), shown in a 3D
view that looks straight down on the map, as RViz does:

========================== =========================================================
world/map                  GridMap of the occupancy grid: cell size = resolution,
                           lower-left corner at the map origin (static)
world/pursuer/pose         Points3D, a ball of the body radius          every tick
world/pursuer/heading      Arrows3D                                     every tick
world/pursuer/trajectory   LineStrips3D, the segment from the previous trajectory point
                           to the position, every ``trail_every`` ticks and at the
                           last one; the map view shows every segment up to the time
                           cursor (a visible time range on this entity)
world/pursuer/fov          LineStrips3D, ``geometry.fov_wedge`` at the zero pose (static),
                           placed by a Transform3D                      every tick
world/pursuer/visible      LineStrips3D, outline of the visibility region every tick
world/pursuer/path, goal   the current plan's path and goal            new plans
world/evader/...           pose, heading, trajectory, path and goal (the chosen
                           escape point), as the pursuer's
world/evader/candidates    Points3D, ``plan.info["candidates"]``        new plans
world/detection            Points3D, the detection's map position       every tick
world/belief/mean          Points3D, the estimate                       every tick
world/belief/particles     Points3D coloured by weight, a strided subsample
camera/frame               LineStrips2D, the image border (static)
camera/image               JPEG of ``frame.rgb`` every ``image_every`` ticks, if any
camera/detection           Boxes2D, the detection's bounding box (px)   every tick
plots/tracking/detected    Scalars: detected (0/1)                      every tick
plots/tracking/rate        Scalars: running tracking rate               every tick
plots/distance/true        Scalars: pursuer-evader distance (m)         every tick
plots/distance/estimate_error  Scalars: |belief.mean - true evader| (m), when estimated
plots/n_eff                Scalars: the estimator's N_eff, when it gives one
events                     TextLog: loss, reacquisition, pursuer mode, game over
config                     TextDocument: the run config as YAML (static)
========================== =========================================================

A tick with nothing to show (no detection, no estimate) gets an empty row, which clears
the entity in the viewer. Recording properties: the recording name, ``config`` (the run
config, flattened to dotted keys) and, at the end, ``result``. The default blueprint
shows the map view large and, beside it, the camera (when the simulator renders images),
the plots, the events and the config.

Cost. On the grid simulator a control tick takes about 0.3 ms, less than a few
``rr.log`` calls. So a tick's numbers are buffered as one row and its other data in
per-entity buffers, all sent with ``send_columns`` every ``flush_every`` ticks (once per
90 s game by default: every send has a fixed cost of a few tenths of a millisecond per
entity; ``live_flush_every`` when a viewer is spawned); styles and the FOV wedge are
logged once as static, the wedge placed by a transform per tick; the visibility region
is drawn as an outline (rays cast on the grid in one compiled batch per send) and the
particles as a subsample. A failure to write (unwritable directory, full disk) or any
other error while recording disables the recorder with one warning; the game goes on.
"""

from __future__ import annotations

import json
import logging
import math
import uuid
import warnings
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from pegame.api import Recorder, Tick
from pegame.types import Pose
from pegame.errors import require

log = logging.getLogger(__name__)

APPLICATION_ID = "pegame"
STEP, SIM_TIME = "step", "sim_time"

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


class NullRecorder(Recorder):
    """Records nothing (``recorder=none``)."""

    description = "Records nothing."

    def start(self, out_dir, game_id, properties) -> None:
        pass

    def log(self, tick: Tick) -> None:
        pass

    def finish(self, result) -> None:
        pass


class RerunRecorder(Recorder):
    """One Rerun recording per game, ``<out_dir>/<game_id>.rrd`` (see the module docstring)."""

    @dataclass
    class Config:
        spawn: bool = False  # open a live Rerun viewer (single runs); the .rrd is written either way
        flush_every: int = 1000  # control ticks buffered per send (sends cost a fixed time each; a 90 s game is one)
        live_flush_every: int = 10  # the same with spawn=true, so that the live viewer keeps up
        max_particles: int = 100  # particles logged per tick, an evenly strided subsample (0: none)
        trail_every: int = 5  # control ticks between trajectory points
        outline_rays: int = 64  # rays cast on the grid to draw the visibility region's outline
        image_every: int = 10  # control ticks between logged camera images (0: none)
        jpeg_quality: int = 80  # JPEG quality (1-100) of the logged camera images

        def __post_init__(self) -> None:
            for key in ("flush_every", "live_flush_every", "trail_every"):
                require(getattr(self, key) >= 1, f"recorder.{key}", "an integer >= 1", getattr(self, key))
            for key in ("max_particles", "image_every"):
                require(getattr(self, key) >= 0, f"recorder.{key}", "an integer >= 0", getattr(self, key))
            require(self.outline_rays >= 2, "recorder.outline_rays", "an integer >= 2", self.outline_rays)
            quality = self.jpeg_quality
            require(1 <= quality <= 100, "recorder.jpeg_quality", "an integer in [1, 100]", quality)

    description = "Rerun recording per game (<game_id>.rrd): map, agents, FOV, belief, plans, plots."

    def __init__(self, config, context, rng) -> None:
        super().__init__(config, context, rng)
        self.path: Path | None = None
        self._rec = None
        self._flush_every = config.live_flush_every if config.spawn else config.flush_every
        self._rows: list[tuple] = []
        # particles: per tick with any, (step, time), the (k, 2) positions and uint8 shades
        self._particles = _ParticleRows(self._flush_every, config.max_particles)
        self._buffers: dict[str, _Buffer] = {}
        self._trail_ends: dict[str, np.ndarray] = {}  # per agent, the last trajectory point (1, 3)
        self._plans: list = [None, None]
        self._modes: dict[str, Any] = {"pursuer": None, "evader": None}
        self._detected: bool | None = None
        self._changed_at = 0.0
        self._detections = 0
        self._last: Tick | None = None

    # ------------------------------------------------------------ the Recorder API

    def start(self, out_dir: str, game_id: str, properties: dict[str, Any]) -> None:
        """Open ``<out_dir>/<game_id>.rrd`` and log the static scene and the config."""
        try:
            self._start(Path(out_dir), game_id, properties)
        except Exception as exc:  # a recording must never stop the game
            self._fail("starting", exc)

    def log(self, tick: Tick) -> None:
        """Buffer one control tick; send the buffers every ``flush_every`` ticks
        (``live_flush_every`` with a spawned viewer)."""
        if self._rec is None:
            return
        try:
            self._log(tick)
        except Exception as exc:
            self._fail("logging", exc)

    def finish(self, result: dict[str, Any]) -> None:
        """Send what is buffered and the result, then close the file."""
        if self._rec is None:
            return
        try:
            self._finish(result)
        except Exception as exc:
            self._fail("finishing", exc)

    # ------------------------------------------------------------ start and finish

    def _start(self, out_dir: Path, game_id: str, properties: dict[str, Any]) -> None:
        import rerun as rr

        out_dir.mkdir(parents=True, exist_ok=True)
        self.path = out_dir / f"{game_id}.rrd"
        rec = rr.RecordingStream(APPLICATION_ID, recording_id=recording_id(out_dir, game_id, properties))
        self._rec = rec
        # Wall-clock time would only make recordings of one game differ from run to run.
        rr.set_log_time_enabled(False, recording=rec)
        sinks = [rr.FileSink(str(self.path))]
        if self.config.spawn:
            rr.spawn(connect=False)
            sinks.append(rr.GrpcSink())
        rec.set_sinks(*sinks)
        rec.send_recording_name(recording_name(game_id, properties))
        _send_property(rec, "config", flat_config(properties))
        self._log_static(properties)

    def _log_static(self, properties: dict[str, Any]) -> None:
        """The map, the image border, the config document and every entity's style."""
        import rerun as rr
        import yaml

        rec, ctx = self._rec, self.context
        rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        # The map is static; building its payload is the larger part of starting a recording.
        rec.log("world/map", _per_grid("grid_map", ctx.grid, grid_map), static=True)
        w, h = ctx.camera.image_width, ctx.camera.image_height
        border = [[(0, 0), (w, 0), (w, h), (0, h), (0, 0)]]
        rec.log("camera/frame", rr.LineStrips2D(border, colors=[(128, 128, 128)]), static=True)
        wedge = _xyz(fov_template(ctx.camera), Z_REGION)
        rec.log("world/pursuer/fov", rr.LineStrips3D([wedge], colors=[(*PURSUER[:3], 160)], radii=[0.015]),
                static=True)
        dumper = getattr(yaml, "CSafeDumper", yaml.SafeDumper)  # libyaml's, when there, is faster
        text = f"```yaml\n{yaml.dump(properties, Dumper=dumper, sort_keys=False)}```\n"
        rec.log("config", rr.TextDocument(text, media_type=rr.MediaType.MARKDOWN), static=True)
        for path, style in _styles(float(ctx.pursuer.radius), float(ctx.evader.radius)).items():
            rec.log(path, style, static=True)

    def _finish(self, result: dict[str, Any]) -> None:
        import rerun as rr

        if self._last is not None:
            rate = result.get("tracking_rate")
            text = "game over" + (f": tracking rate {100 * rate:.1f}%" if rate is not None else "")
            self._add("events", rr.TextLog, self._last, text=[text], level=["INFO"])
        self._flush(final=True)
        _send_property(self._rec, "result", flat_config(result))
        # Closing the file sink waits for its writer: a write error (full disk) raises here.
        self._rec.disconnect()
        self._rec = None

    def _fail(self, action: str, exc: Exception) -> None:
        """Warn once (logging and warnings) and stop recording; the game goes on."""
        message = (
            f"Rerun recording {self.path or ''} disabled: {action} failed ({type(exc).__name__}: {exc}). "
            "The game goes on without it."
        )
        log.warning(message)
        warnings.warn(message, RuntimeWarning, stacklevel=3)
        rec, self._rec = self._rec, None
        if rec is not None:
            try:
                rec.disconnect()
            except Exception:  # the stream is already broken; nothing more to save
                pass

    # -------------------------------------------------------------------- per tick

    def _log(self, tick: Tick) -> None:
        """Buffer the tick: its numbers as one row (sent by :meth:`_send_rows`), its
        variable-size data (trajectories, outline, particles, plans, events) in buffers."""
        if self._last is None:
            has_image = tick.frame.rgb is not None
            self._rec.send_blueprint(blueprint(self.context.grid, self.context.camera, has_image))
        self._last = tick
        self._detections += tick.detection is not None
        self._rows.append(_row(tick, self._detections / (tick.step + 1)))
        self._log_particles(tick)
        self._log_plans(tick)
        self._log_events(tick)
        self._log_image(tick)
        if (tick.step + 1) % self._flush_every == 0:
            self._flush()

    def _add(self, path: str, kind: type, tick: Tick, create: bool = True, **values) -> None:
        """Buffer one row of ``kind`` at ``path``; with create=False only for an entity
        that already exists (an empty row then clears what it showed)."""
        buffer = self._buffers.get(path)
        if buffer is None:
            if not create:
                return
            buffer = self._buffers[path] = _Buffer(path, kind)
        buffer.add(tick.step, tick.time, **values)

    def _log_particles(self, tick: Tick) -> None:
        """A strided subsample of the particles and of their weights."""
        if self.config.max_particles:
            self._particles.add(tick.step, tick.time, tick.belief.particles, tick.belief.weights)

    def _log_plans(self, tick: Tick) -> None:
        """Paths, goals and candidates, only when a strategy has made a new plan."""
        if tick.plans[0] is self._plans[0] and tick.plans[1] is self._plans[1]:
            return
        import rerun as rr

        for index, name in enumerate(("pursuer", "evader")):
            plan = tick.plans[index]
            if plan is self._plans[index]:
                continue
            self._plans[index] = plan
            path = np.asarray(plan.path, dtype=float).reshape(-1, 2)
            strips = [_xyz(path, Z_PLAN)] if len(path) >= 2 else []
            self._add(f"world/{name}/path", rr.LineStrips3D, tick, strips=strips)
            goal = [plan.goal] if plan.goal is not None else []
            self._add(f"world/{name}/goal", rr.Points3D, tick, positions=_xyz(goal, Z_PLAN))
            candidates = plan.info.get("candidates")
            candidates = _xyz(np.zeros((0, 2)) if candidates is None else candidates, Z_PLAN)
            self._add(f"world/{name}/candidates", rr.Points3D, tick, create=len(candidates) > 0,
                      positions=candidates)
            mode = plan.info.get("mode")
            if mode is not None and mode != self._modes[name]:
                self._modes[name] = mode
                self._add("events", rr.TextLog, tick, text=[f"{name} mode: {mode}"], level=["INFO"])

    def _log_events(self, tick: Tick) -> None:
        """A TextLog line when the detector loses or reacquires the evader."""
        detected = tick.detection is not None
        if detected == self._detected:
            return
        import rerun as rr

        if self._detected is None:
            text, level = ("evader detected at start", "INFO") if detected else ("evader not detected at start", "WARN")
        elif detected:
            text, level = f"evader reacquired after {tick.time - self._changed_at:.1f} s lost", "INFO"
        else:
            text, level = f"evader lost after {tick.time - self._changed_at:.1f} s tracked", "WARN"
        self._detected, self._changed_at = detected, tick.time
        self._add("events", rr.TextLog, tick, text=[text], level=[level])

    def _log_image(self, tick: Tick) -> None:
        """The camera image as JPEG, logged directly: it is rare and large."""
        rgb = tick.frame.rgb
        every = self.config.image_every
        if rgb is None or every == 0 or tick.step % every:
            return
        import rerun as rr

        self._rec.set_time(STEP, sequence=tick.step)
        self._rec.set_time(SIM_TIME, duration=tick.time)
        size = (self.context.camera.image_width, self.context.camera.image_height)
        if rgb.shape[1::-1] != size:
            # Detections are in the camera's image_width x image_height pixel frame; a
            # simulator may render smaller, so the image is scaled to that frame.
            from PIL import Image

            rgb = np.asarray(Image.fromarray(rgb).resize(size, Image.BILINEAR))
        image = rr.Image(rgb).compress(jpeg_quality=self.config.jpeg_quality)
        self._rec.log("camera/image", image, strict=True)

    # ----------------------------------------------------------------------- flush

    def _flush(self, final: bool = False) -> None:
        """Send the buffered rows and buffers (``final``: the game's last ones). The file
        is written by rerun-sdk's own thread meanwhile; a write error surfaces when
        ``finish`` waits for it."""
        indexes: dict = {}
        if self._rows:
            columns = dict(zip(ROW, np.array(self._rows, dtype=float).T))
            self._rows = []
            self._send_rows(columns, indexes)
            self._send_trails(columns, indexes, final)
        self._send_particles(indexes)
        for buffer in self._buffers.values():
            buffer.send(self._rec, indexes)

    def _send_particles(self, indexes: dict) -> None:
        """The buffered particle subsamples, one row per tick, coloured by their shade."""
        import rerun as rr

        if self._particles.count:
            steps, times, positions, shades, sizes = self._particles.take()
            colors = _particle_palette()[shades]
            self._send("world/belief/particles", _index(indexes, steps, times),
                       rr.Points3D.columns(positions=positions, colors=colors).partition(sizes))

    def _send(self, path: str, index: list, columns) -> None:
        self._rec.send_columns(path, indexes=index, columns=columns, strict=True)

    def _send_rows(self, c: dict[str, np.ndarray], indexes: dict) -> None:
        """Send the buffered rows (columns ``c``, named as in :data:`ROW`), vectorised."""
        steps, times = c["step"].astype(np.int64), c["time"]
        every = _index(indexes, steps, times)
        self._rows_key = steps.tobytes()
        self._send_agents(c, every)
        self._send_sensing(c, every)
        self._send_plots(c, every, lambda given: _index(indexes, steps[given], times[given]))

    def _send_agents(self, c: dict[str, np.ndarray], every: list) -> None:
        """Both poses with their heading arrows, and the pursuer's FOV wedge and the
        outline of its visibility region."""
        import rerun as rr

        for name, prefix in (("pursuer", "p"), ("evader", "e")):
            x, y, theta = c[f"{prefix}x"], c[f"{prefix}y"], c[f"{prefix}theta"]
            here = _stack(x, y, Z_AGENT)
            length = 2 * getattr(self.context, name).radius + 0.3
            heading = _stack(length * np.cos(theta), length * np.sin(theta), 0.0)
            self._send(f"world/{name}/pose", every, rr.Points3D.columns(positions=here))
            self._send(f"world/{name}/heading", every, rr.Arrows3D.columns(origins=here, vectors=heading))
        ctx = self.context
        half = 0.5 * c["ptheta"]
        rotation = np.zeros((len(half), 4), dtype=np.float32)  # quaternions (x, y, z, w) about z
        rotation[:, 2], rotation[:, 3] = np.sin(half), np.cos(half)
        wedge = rr.Transform3D.columns(translation=_stack(c["px"], c["py"], 0.0), quaternion=rotation)
        self._send("world/pursuer/fov", every, wedge)
        outlines = visibility_outlines(ctx.grid, c["px"], c["py"], c["ptheta"], ctx.camera,
                                       self.config.outline_rays, Z_REGION)
        self._send("world/pursuer/visible", every, rr.LineStrips3D.columns(strips=strips_array(outlines)))

    def _send_trails(self, c: dict[str, np.ndarray], indexes: dict, final: bool) -> None:
        """Both trajectories as segments, each from the previous trajectory point to the
        agent's position, every ``trail_every`` ticks and at the last tick (``final``):
        the gap to the agent stays under its disc, and the data grows linearly with the
        game, where re-logging the whole trajectory would grow quadratically."""
        import rerun as rr

        steps = c["step"].astype(np.int64)
        picked = steps % self.config.trail_every == 0
        picked[-1] |= final
        if not picked.any():
            return
        index = _index(indexes, steps[picked], c["time"][picked])
        for name, prefix in (("pursuer", "p"), ("evader", "e")):
            ends = _stack(c[f"{prefix}x"][picked], c[f"{prefix}y"][picked], Z_TRAIL)
            starts = np.concatenate([self._trail_ends.get(name, ends[:1]), ends[:-1]])
            self._trail_ends[name] = ends[-1:]
            segments = strips_array(np.stack([starts, ends], axis=1))
            self._send(f"world/{name}/trajectory", index, rr.LineStrips3D.columns(strips=segments))

    def _send_sensing(self, c: dict[str, np.ndarray], every: list) -> None:
        """Detection (map point and image box) and estimate; an empty row where there is none."""
        import rerun as rr

        seen = np.isfinite(c["det_x"])
        sizes = seen.astype(np.int64)
        where = _stack(c["det_x"][seen], c["det_y"][seen], Z_MARKER)
        self._send("world/detection", every, rr.Points3D.columns(positions=where).partition(sizes))
        labels = [f"evader {p:.2f}, {d:.2f} m" for p, d in zip(c["confidence"][seen], c["depth"][seen])]
        boxes = rr.Boxes2D.columns(
            centers=np.column_stack([c["box_cx"][seen], c["box_cy"][seen]]),
            half_sizes=np.column_stack([c["box_hw"][seen], c["box_hh"][seen]]),
            labels=labels,
        )
        self._send("camera/detection", every, boxes.partition(sizes))
        estimated = np.isfinite(c["mean_x"])
        mean = _stack(c["mean_x"][estimated], c["mean_y"][estimated], Z_MARKER)
        columns = rr.Points3D.columns(positions=mean).partition(estimated.astype(np.int64))
        self._send("world/belief/mean", every, columns)

    def _send_plots(self, c: dict[str, np.ndarray], every: list, index_of) -> None:
        """The time series; estimation error and N_eff only at ticks that have them
        (``index_of(mask)`` gives the index columns of those rows)."""
        import rerun as rr

        detected = np.isfinite(c["det_x"]).astype(float)
        self._send("plots/tracking/detected", every, rr.Scalars.columns(scalars=detected))
        self._send("plots/tracking/rate", every, rr.Scalars.columns(scalars=c["rate"]))
        distance = np.hypot(c["px"] - c["ex"], c["py"] - c["ey"])
        self._send("plots/distance/true", every, rr.Scalars.columns(scalars=distance))
        error = np.hypot(c["mean_x"] - c["ex"], c["mean_y"] - c["ey"])
        for path, values in (("plots/distance/estimate_error", error), ("plots/n_eff", c["n_eff"])):
            given = np.isfinite(values)
            if given.any():
                self._send(path, index_of(given), rr.Scalars.columns(scalars=values[given]))


#: the numbers buffered per tick, in this order (NaN where there is nothing)
ROW = (
    "step", "time", "px", "py", "ptheta", "ex", "ey", "etheta",
    "det_x", "det_y", "box_cx", "box_cy", "box_hw", "box_hh", "confidence", "depth",
    "mean_x", "mean_y", "n_eff", "rate",
)
_NO_DETECTION = (math.nan,) * 8


def _row(tick: Tick, rate: float) -> tuple:
    """The tick's numbers in :data:`ROW` order; rate: the running tracking rate."""
    p, e, det, belief = tick.pursuer, tick.evader, tick.detection, tick.belief
    if det is None:
        seen = _NO_DETECTION
    else:
        box = det.box
        seen = (det.position[0], det.position[1], box.x + 0.5 * box.w, box.y + 0.5 * box.h,
                0.5 * box.w, 0.5 * box.h, det.confidence, det.depth)
    mean = belief.mean if belief.mean is not None else (math.nan, math.nan)
    n_eff = belief.n_eff if belief.n_eff is not None else math.nan
    return (tick.step, tick.time, p.x, p.y, p.theta, e.x, e.y, e.theta, *seen, *mean, n_eff, rate)


# ----------------------------------------------------------------------- buffering


class _Buffer:
    """Rows of one entity waiting to be sent with ``send_columns``.

    A row is one tick's step and time and, per component, one value per instance: a
    numeric array of shape (n, ...), a list of n strings, or (for ``strips``) a list of
    n (K, 3) arrays.
    """

    def __init__(self, path: str, kind: type) -> None:
        self.path, self.kind = path, kind
        self.steps: list[int] = []
        self.times: list[float] = []
        self.sizes: list[int] = []
        self.values: dict[str, list] = {}

    def add(self, step: int, time: float, **values) -> None:
        self.steps.append(step)
        self.times.append(time)
        self.sizes.append(len(next(iter(values.values()))))
        for key, value in values.items():
            self.values.setdefault(key, []).append(value)

    def send(self, rec, indexes: dict) -> None:
        """Send the buffered rows as one chunk and empty the buffer; ``indexes`` caches
        time columns (see :func:`_index`)."""
        if not self.steps:
            return
        columns = {key: _column(key, parts) for key, parts in self.values.items()}
        index = _index(indexes, np.asarray(self.steps, dtype=np.int64), np.asarray(self.times))
        columns = self.kind.columns(**columns).partition(self.sizes)
        rec.send_columns(self.path, indexes=index, columns=columns, strict=True)
        self.steps, self.times, self.sizes, self.values = [], [], [], {}


def _index(cache: dict, steps: np.ndarray, times: np.ndarray) -> list:
    """The ``step`` and ``sim_time`` index columns of rows at ``steps`` and ``times`` (s),
    cached by steps: most entities have a row at every tick, and building them is not free."""
    import rerun as rr

    key = steps.tobytes()
    if key not in cache:
        # Whole nanoseconds, rounded as set_time rounds them (rerun-sdk would truncate).
        nanos = np.round(times * 1e9).astype(np.int64).astype("timedelta64[ns]")
        cache[key] = [rr.TimeColumn(STEP, sequence=steps), rr.TimeColumn(SIM_TIME, duration=nanos)]
    return cache[key]


def _column(key: str, parts: list) -> Any:
    """Concatenate one component's values over rows (see :class:`_Buffer`)."""
    if key == "strips":
        return strips_array([strip for part in parts for strip in part])
    if isinstance(parts[0], list):
        return [item for part in parts for item in part]
    return np.concatenate(parts)


def strips_array(strips):
    """LineStrip3D arrow array of float32 strips: a list of (K, 3) arrays or an (n, K, 3)
    array. Built in one go: rerun-sdk's own conversion loops over the strips in Python."""
    import pyarrow as pa
    import rerun as rr

    if isinstance(strips, np.ndarray):
        n, k = strips.shape[:2]
        flat = strips.reshape(n * k, 3)
        offsets = np.arange(0, (n + 1) * k, k, dtype=np.int32) if k else np.zeros(n + 1, np.int32)
    else:
        lengths = [len(strip) for strip in strips]
        flat = np.concatenate(strips) if lengths else np.zeros((0, 3), np.float32)
        offsets = np.zeros(len(lengths) + 1, dtype=np.int32)
        offsets[1:] = np.cumsum(lengths)
    points = rr.encodings.Vec3DBatch(flat).as_arrow_array()
    strip_type = pa.list_(pa.field("item", points.type, nullable=False))
    return pa.ListArray.from_arrays(pa.array(offsets), points, type=strip_type)


class _ParticleRows:
    """The particle subsamples of up to ``capacity`` ticks, at most ``limit`` particles per
    tick (an evenly strided subsample), in arrays allocated once: map-frame positions (m)
    as float32 points at height Z_PARTICLES, and their weights (NaN where the estimator
    gives none)."""

    def __init__(self, capacity: int, limit: int) -> None:
        self.limit = limit
        self.xyz = np.full((capacity, limit, 3), Z_PARTICLES, dtype=np.float32)
        self.weights = np.zeros((capacity, limit))
        self.sizes = np.zeros(capacity, dtype=np.int64)
        self.steps = np.zeros(capacity, dtype=np.int64)
        self.times = np.zeros(capacity)
        self.count = 0
        self.started = False  # rows begin at the first tick with particles

    def add(self, step: int, time: float, particles: np.ndarray | None, weights: np.ndarray | None) -> None:
        """A row of (N, >= 2) particles and their (N,) weights; None gives an empty row,
        which clears the particles shown, once there have been some."""
        if particles is None and not self.started:
            return
        self.started = True
        row, size = self.count, 0
        if particles is not None:
            stride = -(-len(particles) // self.limit) or 1
            size = -(-len(particles) // stride)
            self.xyz[row, :size, :2] = particles[::stride, :2]
            self.weights[row, :size] = np.nan if weights is None else weights[::stride]
        self.sizes[row], self.steps[row], self.times[row] = size, step, time
        self.count += 1

    def take(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Empty the rows: (steps (T,), times (T,) s, positions (M, 3), shades (M,) uint8,
        sizes (T,)), the rows' particles one after the other. A shade is 255 * the weight
        over its tick's largest weight, rounded; 128 where the weight is NaN."""
        n, self.count = self.count, 0
        sizes, weights = self.sizes[:n].copy(), self.weights[:n]
        held = np.arange(self.limit) < sizes[:, None]
        unknown = held & np.isnan(weights)
        top = np.max(np.where(held & ~unknown, weights, 0.0), axis=1, keepdims=True)
        scale = np.divide(255.0, top, out=np.zeros_like(top), where=top > 0)
        shades = np.clip(np.where(unknown, 0.0, weights) * scale + 0.5, 0, 255).astype(np.uint8)
        shades[unknown] = 128
        kept = np.flatnonzero(held)  # take() copies rows several times faster than a bool mask
        positions = np.take(self.xyz[:n].reshape(-1, 3), kept, axis=0)
        return self.steps[:n].copy(), self.times[:n].copy(), positions, shades.ravel()[kept], sizes


def _stack(x: np.ndarray, y: np.ndarray, z) -> np.ndarray:
    """(n, 3) float32 points from coordinates (m); z is an array or one height."""
    out = np.empty((len(x), 3), dtype=np.float32)
    out[:, 0], out[:, 1], out[:, 2] = x, y, z
    return out


def _xyz(xy, z: float) -> np.ndarray:
    """(n, 3) float32 points at height z (m) from (n, 2) map-frame positions (m); copies."""
    xy = np.asarray(xy, dtype=float).reshape(-1, 2)
    return _stack(xy[:, 0], xy[:, 1], z)


@lru_cache(maxsize=16)
def fov_template(camera) -> np.ndarray:
    """The camera's FOV wedge (``geometry.fov_wedge``) at the zero pose, (K, 2) m."""
    from pegame.visibility import fov_wedge

    return fov_wedge(camera, Pose(0.0, 0.0, 0.0), n=16)


def _outlines(runs, xs, ys, thetas, ox, oy, yaw, slices, arc, near, far, resolution, z, jump):
    """Closed (n + m + 1, 3) float32 polygons around the visibility regions of the camera
    at the poses (xs, ys, thetas) (map frame, m and rad), one per pose: the far ends of n
    rays, then m points back along the near arc; n = len(slices[0]), m = len(arc[0]).

    See :func:`visibility_outlines`. Rays leave each pose at theta + a_i, where slices =
    (cos a_i, sin a_i) (a_i in rad from the optical axis; arc likewise gives the near
    arc's angles), and are sampled in the grid frame one cell apart, up to the first
    sample in a blocked cell (``runs`` 0, see :func:`free_runs`) or off the grid. With
    ``jump`` the samples that ``runs`` shows to be free are skipped, which gives the
    same result as sampling every cell (the plain reference, jump=False).
    """
    height, width = runs.shape
    slice_cos, slice_sin = slices
    arc_cos, arc_sin = arc
    n, m = slice_cos.size, arc_cos.size
    out = np.empty((xs.size, n + m + 1, 3), dtype=np.float32)
    c, s = math.cos(yaw), math.sin(yaw)
    # Cells that straddle the near range are only partly seen: reach starts one cell beyond it.
    start = near / resolution + 1.0
    count = math.floor(far / resolution) + 1
    du, dv = np.empty(n), np.empty(n)  # ray directions in the grid frame (cells per sample)
    d = np.empty(n, dtype=np.int64)  # the next sample of each ray (count: the ray is done)
    last = np.empty(n, dtype=np.int64)  # the last free sample of each ray
    for p in range(xs.size):
        x, y, theta = xs[p], ys[p], thetas[p]
        u = (c * (x - ox) + s * (y - oy)) / resolution
        v = (-s * (x - ox) + c * (y - oy)) / resolution
        cg, sg = math.cos(theta - yaw), math.sin(theta - yaw)  # the heading in the grid frame
        cm, sm = math.cos(theta), math.sin(theta)  # the heading in the map frame
        for i in range(n):
            du[i] = cg * slice_cos[i] - sg * slice_sin[i]
            dv[i] = sg * slice_cos[i] + cg * slice_sin[i]
            d[i], last[i] = 0, -1
        # All rays advance one step per round: their steps are independent, so the
        # processor overlaps their memory reads (twice as fast as one ray at a time).
        marching = n
        while marching:
            marching = 0
            for i in range(n):
                if d[i] >= count:
                    continue
                fc, fr = u + d[i] * du[i], v + d[i] * dv[i]
                # Range checks on the floats, so that int() (truncation) equals floor.
                if fr < 0.0 or fr >= height or fc < 0.0 or fc >= width:
                    d[i] = count
                    continue
                run = runs[int(fr), int(fc)]
                if run == 0:
                    d[i] = count
                    continue
                last[i] = min(d[i] + (run - 1 if jump else 0), count - 1)
                d[i] = last[i] + 1
                marching += 1
        for i in range(n):
            reach = last[i] * resolution if last[i] >= start else near
            cw = cm * slice_cos[i] - sm * slice_sin[i]
            sw = sm * slice_cos[i] + cm * slice_sin[i]
            out[p, i, 0], out[p, i, 1], out[p, i, 2] = x + reach * cw, y + reach * sw, z
        for j in range(m):
            cw = cm * arc_cos[j] - sm * arc_sin[j]
            sw = sm * arc_cos[j] + cm * arc_sin[j]
            out[p, n + j, 0], out[p, n + j, 1], out[p, n + j, 2] = x + near * cw, y + near * sw, z
        out[p, n + m] = out[p, 0]
    return out


@lru_cache(maxsize=1)
def _outlines_kernel():
    """:func:`_outlines` compiled with numba on first use (numba loads only then)."""
    from numba import njit

    return njit(cache=True)(_outlines)


def free_runs(grid) -> np.ndarray:
    """uint8 (H, W): 0 on blocked cells; on a free cell, how many samples one cell apart
    along any ray from any point of the cell are sure to be free, this one included.

    If the cell's centre lies D cells from the nearest blocked cell's centre or cell off
    the grid, every point closer than D - sqrt(2) cells to a point of the cell is free: 1 +
    floor(D - 1.5) samples (at least 1, at most 255). Small, so it stays in cache. Kept for
    the next games of the process on the same grid.
    """
    return _per_grid("free_runs", grid, _free_runs)


def _free_runs(grid) -> np.ndarray:
    from scipy.ndimage import distance_transform_edt

    free = np.pad(~grid.blocked, 1, constant_values=False)
    clearance = distance_transform_edt(free)[1:-1, 1:-1]
    runs = np.where(grid.blocked, 0, 1 + np.clip(np.floor(clearance - 1.5), 0, 254))
    return runs.astype(np.uint8)


@lru_cache(maxsize=16)
def _slices(fov: float, rays: int) -> tuple[np.ndarray, np.ndarray]:
    """(cos, sin) of the ray angles from the optical axis: the centres of ``rays`` equal
    slices of the FOV (rad)."""
    angles = fov * ((np.arange(rays) + 0.5) / rays - 0.5)
    return np.cos(angles), np.sin(angles)


#: points along the near arc of an outline (the arc is short: near is a few decimetres)
NEAR_ARC_POINTS = 8


@lru_cache(maxsize=16)
def _near_arc(fov: float) -> tuple[np.ndarray, np.ndarray]:
    """(cos, sin) of NEAR_ARC_POINTS angles from +fov/2 back to -fov/2 (rad)."""
    angles = np.linspace(0.5 * fov, -0.5 * fov, NEAR_ARC_POINTS)
    return np.cos(angles), np.sin(angles)


def visibility_outlines(grid, xs: np.ndarray, ys: np.ndarray, thetas: np.ndarray, camera,
                        rays: int, z: float = 0.0, compiled: bool = True) -> np.ndarray:
    """(P, rays + NEAR_ARC_POINTS + 1, 3) float32: closed polygons (map frame, m, at height
    z) around the visibility regions of the camera at P poses (xs, ys, thetas) (m, m, rad)
    on ``grid``.

    ``rays`` rays at the centres of equal slices of the FOV are cast from the camera one
    cell at a time up to the first blocked cell or the far range; each polygon runs along
    their far ends from the near range on, then back along the near arc. It draws the
    region that :func:`pegame.visibility.visibility_region` computes, at ``rays`` angles
    instead of every ``camera.angle_step``. The compiled kernel skips the cells that the
    grid's :func:`free_runs` shows to be free, with the same result as compiled=False, the
    plain Python reference that samples every cell.
    """
    ox, oy, yaw = grid.origin
    march = _outlines_kernel() if compiled else _outlines
    poses = (np.asarray(v, dtype=float).reshape(-1) for v in (xs, ys, thetas))
    return march(free_runs(grid), *poses, ox, oy, yaw, _slices(camera.fov, rays),
                 _near_arc(camera.fov), camera.near, camera.far, float(grid.resolution), z, compiled)


@lru_cache(maxsize=1)
def _particle_palette() -> np.ndarray:
    """The 256 particle colours (0xRRGGBBAA), from LIGHT_PARTICLE (shade 0) to HEAVY_PARTICLE (255)."""
    t = np.arange(256)[:, None] / 255.0
    rgba = np.round(LIGHT_PARTICLE + t * (HEAVY_PARTICLE - LIGHT_PARTICLE)).astype(np.uint32)
    return (rgba[:, 0] << 24) | (rgba[:, 1] << 16) | (rgba[:, 2] << 8) | rgba[:, 3]


_PER_GRID: dict[str, tuple[Any, Any]] = {}


def _per_grid(name: str, grid, build):
    """``build(grid)``, kept under ``name`` for the next games of the process on the same
    grid (grids are immutable; one grid per name is kept)."""
    hit = _PER_GRID.get(name)
    if hit is None or hit[0] is not grid:
        hit = _PER_GRID[name] = (grid, build(grid))
    return hit[1]


def grid_map(grid):
    """The occupancy grid as an ``rr.GridMap``: map-frame metres, RViz's map colours.

    GridMap draws its first data row at the top (highest y) and puts the lower-left
    corner of the image at ``translation``, so the rows (row 0 = lowest y) are flipped;
    int8 -1 (unknown) becomes 255 as RViz's colour map expects.
    """
    import rerun as rr

    ox, oy, yaw = grid.origin
    data = np.ascontiguousarray(np.flipud(grid.data)).view(np.uint8)
    return rr.GridMap(
        data=data.tobytes(),
        format=rr.components.ImageFormat(width=grid.width, height=grid.height, color_model="L",
                                         channel_datatype="U8"),
        cell_size=grid.resolution,
        translation=[ox, oy, 0.0],
        rotation_axis_angle=rr.RotationAxisAngle(axis=[0.0, 0.0, 1.0], radians=yaw),
        colormap=rr.components.Colormap.RvizMap,
    )


@lru_cache(maxsize=4)
def _styles(pursuer_radius: float, evader_radius: float) -> dict[str, Any]:
    """Static colours and sizes (m) of every entity, logged once."""
    import rerun as rr

    def faded(color, alpha=160):
        return (*color[:3], alpha)

    styles = {
        "world/detection": rr.Points3D.from_fields(colors=[DETECTION], radii=[0.12]),
        "world/belief/mean": rr.Points3D.from_fields(colors=[ESTIMATE], radii=[0.12]),
        "world/belief/particles": rr.Points3D.from_fields(radii=[0.04]),
        "world/pursuer/visible": rr.LineStrips3D.from_fields(colors=[(255, 140, 0, 255)], radii=[0.025]),
        "world/evader/candidates": rr.Points3D.from_fields(colors=[faded(EVADER)], radii=[0.08]),
        "camera/detection": rr.Boxes2D.from_fields(colors=[DETECTION]),
        "plots/tracking/detected": rr.SeriesLines(
            colors=[DETECTION], names=["detected"], interpolation_mode=rr.components.InterpolationMode.StepAfter),
        "plots/tracking/rate": rr.SeriesLines(colors=[PURSUER], names=["tracking rate"]),
        "plots/distance/true": rr.SeriesLines(colors=[(90, 90, 90)], names=["pursuer-evader distance"]),
        "plots/distance/estimate_error": rr.SeriesLines(colors=[ESTIMATE], names=["estimation error"]),
        "plots/n_eff": rr.SeriesLines(colors=[(110, 0, 170)], names=["N_eff"]),
    }
    for name, color, radius in (("pursuer", PURSUER, pursuer_radius), ("evader", EVADER, evader_radius)):
        styles[f"world/{name}/pose"] = rr.Points3D.from_fields(colors=[color], radii=[radius])
        styles[f"world/{name}/heading"] = rr.Arrows3D.from_fields(colors=[color], radii=[0.03])
        styles[f"world/{name}/trajectory"] = rr.LineStrips3D.from_fields(colors=[color], radii=[0.03])
        styles[f"world/{name}/path"] = rr.LineStrips3D.from_fields(colors=[faded(color)], radii=[0.02])
        styles[f"world/{name}/goal"] = rr.Points3D.from_fields(colors=[faded(color, 220)], radii=[0.15])
    return styles


def blueprint(grid, camera, has_image: bool):
    """The default layout: the map view looking straight down, large; beside it the
    camera (when the simulator renders images), the plots and the events."""
    import rerun.blueprint as rrb

    ox, oy, yaw = grid.origin
    corners = np.array([[0, 0], [grid.width, 0], [0, grid.height], [grid.width, grid.height]]) * grid.resolution
    c, s = math.cos(yaw), math.sin(yaw)
    world = corners @ np.array([[c, s], [-s, c]]) + (ox, oy)
    (x0, y0), (x1, y1) = world.min(axis=0), world.max(axis=0)
    cx, cy, height = (x0 + x1) / 2, (y0 + y1) / 2, 1.3 * max(x1 - x0, y1 - y0)
    # An eye slightly south of the zenith keeps +y up on screen while orbiting stays about z.
    eye = rrb.EyeControls3D(kind=rrb.Eye3DKind.Orbital, position=[cx, cy - 0.02 * height, height],
                            look_target=[cx, cy, 0.0], eye_up=[0.0, 0.0, 1.0])
    # Trajectories are logged as segments: the view shows all of them up to the cursor.
    so_far = rrb.VisibleTimeRanges([
        rrb.VisibleTimeRange(timeline, start=rrb.TimeRangeBoundary.infinite(),
                             end=rrb.TimeRangeBoundary.cursor_relative())
        for timeline in (STEP, SIM_TIME)
    ])
    trails = {f"world/{name}/trajectory": so_far for name in ("pursuer", "evader")}
    map_view = rrb.Spatial3DView(origin="world", name="Map", eye_controls=eye,
                                 line_grid=rrb.LineGrid3D(visible=False), overrides=trails)
    side = [
        rrb.TimeSeriesView(origin="plots/tracking", name="Tracking", axis_y=rrb.ScalarAxis(range=(0.0, 1.05))),
        rrb.TimeSeriesView(origin="plots/distance", name="Distances (m)"),
        rrb.TimeSeriesView(origin="plots/n_eff", name="N_eff"),
        rrb.Tabs(rrb.TextLogView(origin="events", name="Events"),
                 rrb.TextDocumentView(origin="config", name="Config")),
    ]
    if has_image:
        bounds = rrb.VisualBounds2D(x_range=[0, camera.image_width], y_range=[0, camera.image_height])
        side.insert(0, rrb.Spatial2DView(origin="camera", name="Camera", visual_bounds=bounds))
    return rrb.Blueprint(rrb.Horizontal(map_view, rrb.Vertical(*side), column_shares=[3, 2]))


# ------------------------------------------------------------------ properties


def recording_id(out_dir: Path, game_id: str, properties: dict[str, Any]) -> str:
    """UUID5 of the absolute output directory, the game id and the config (see module doc)."""
    key = json.dumps([str(Path(out_dir).resolve()), game_id, properties], sort_keys=True, default=str)
    return str(uuid.uuid5(uuid.NAMESPACE_URL, f"pegame:{key}"))


def recording_name(game_id: str, properties: dict[str, Any]) -> str:
    """'<game_id>: <pursuer> pursuer vs <evader> evader on <map>', from the run config."""

    def name(group: str) -> str:
        node = properties.get(group)
        return str(node.get("name", "?")) if isinstance(node, dict) else "?"

    return f"{game_id}: {name('pursuer')} pursuer vs {name('evader')} evader on {name('env')}"


def _send_property(rec, name: str, values: dict[str, Any]) -> None:
    """A recording property of flat {key: value} pairs (none: nothing to send). The values
    go in as one-element Arrow arrays: the same column types as rerun-sdk infers, without
    its per-value inference (half the time)."""
    import pyarrow as pa
    import rerun as rr

    if values:
        rec.send_property(name, rr.AnyValues(**{key: pa.array([value]) for key, value in values.items()}))


def flat_config(tree: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    """The config as {'game.seed': 0, ...}: numbers, bools and strings kept, the rest as text."""
    flat: dict[str, Any] = {}
    for key, value in tree.items():
        if isinstance(value, dict):
            flat.update(flat_config(value, f"{prefix}{key}."))
        elif value is not None:
            flat[f"{prefix}{key}"] = value if isinstance(value, (bool, int, float, str)) else str(value)
    return flat
