"""The Rerun recorder's life: start, log, finish or abort, and the sends in between.

:class:`RerunRecorder` writes one recording per game through its own
``rerun.RecordingStream`` (never the global stream) into memory (a ``rerun.BinaryStream``,
plus a live viewer with ``spawn=true``) while the game runs; :meth:`~RerunRecorder.finish`
closes it and writes its bytes to ``<game_id>.rrd.partial``, renamed to ``<game_id>.rrd``
once written and of the right size (:func:`pegame.files.write_atomic`, not synced: see
:mod:`pegame.recorders.files`);
:meth:`~RerunRecorder.abort` (a game that raised) sends what it holds, an ERROR event and
the error, and writes ``<game_id>.failed.rrd`` the same way (see
:mod:`pegame.recorders.files`). A game killed before its end leaves no recording.

Why pegame writes the file, not rerun-sdk's ``FileSink``: on a full disk the file sink
logged "No space left on device", raised nothing, and its file was renamed as complete
without its footer; with a little more room the game's thread waited forever on the
recording stream. pegame's own write raises, so a recording that cannot be written is
the game's failure (recorded, exit status 1), named in the job's log, and no broken file
is left. The cost: a game's recording is held in memory until the game ends (a 25 s
game on brick, about 0.9 MB).

Cost. On the grid simulator a control tick takes about 0.3 ms, less than a few
``rr.log`` calls. So a tick's numbers are buffered as one row and its other data in
per-entity buffers (:mod:`.columns`), all sent with ``send_columns`` every
``flush_every`` ticks (once per 90 s game by default: every send has a fixed cost of a
few tenths of a millisecond per entity; ``live_flush_every`` when a viewer is spawned).
Where a recording's instructions go (callgrind, seed 0's 90 s S-S game on enclosed, rerun-sdk
0.41): half in rerun-sdk encoding the columns into the .rrd when the game ends (LZ4
compression alone 29%), a quarter in building the columns at the send (the visibility
outlines' rays 9%), a fifth in buffering the ticks; the particles are about 40% of the
bytes. Any other error while recording (a bad value to log) disables the recorder with one
warning and leaves no file; the game goes on.
"""

from __future__ import annotations

import logging
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import rerun as rr

from pegame.api import Context, Recorder, Tick
from pegame.errors import ResultsWriteError, require
from pegame.files import make_dir, write_atomic
from pegame.recorders.files import COMPLETE, FAILED, PARTIAL, recording_path
from pegame.recorders.rerun.blueprint import game_blueprint, write_layout
from pegame.recorders.rerun.columns import ParticleRows, row_columns, tick_row, time_index
from pegame.recorders.rerun.properties import (
    flat_config,
    recording_id,
    recording_name,
    send_property,
)
from pegame.recorders.rerun.scene import (
    Z_PARTICLES,
    Buffers,
    PlanRows,
    buffer_event,
    buffer_losses,
    log_agents,
    log_image,
    log_particles,
    log_plots,
    log_sensing,
    log_static,
    log_trails,
)
from pegame.recorders.rerun.team import buffer_team

log = logging.getLogger(__name__)

APPLICATION_ID = "pegame"

#: seconds rerun-sdk may take to deliver a closed recording's last bytes
FLUSH_TIMEOUT = 60.0


class RerunRecorder(Recorder):
    """One Rerun recording per game, ``<out_dir>/<game_id>.rrd`` once the game finished
    (see :mod:`pegame.recorders.rerun`)."""

    @dataclass
    class Config:
        spawn: bool = (
            False  # open a live Rerun viewer (single runs); the .rrd is written either way
        )
        flush_every: int = 1000  # control ticks buffered per send (sends cost a fixed time each; a 90 s game is one)
        live_flush_every: int = 10  # the same with spawn=true, so that the live viewer keeps up
        max_particles: int = (
            64  # particles logged per logged tick, an evenly strided subsample (0: none)
        )
        particles_every: int = (
            2  # control ticks between logged particle clouds (the viewer holds the last)
        )
        trail_every: int = 5  # control ticks between trajectory points
        outline_rays: int = 48  # rays cast on the grid to draw the visibility region's outline
        image_every: int = 10  # control ticks between logged camera images (0: none)
        jpeg_quality: int = 80  # JPEG quality (1-100) of the logged camera images

        def __post_init__(self) -> None:
            for key in ("flush_every", "live_flush_every", "trail_every", "particles_every"):
                require(
                    getattr(self, key) >= 1,
                    key,
                    "an integer >= 1",
                    getattr(self, key),
                )
            for key in ("max_particles", "image_every"):
                require(
                    getattr(self, key) >= 0,
                    key,
                    "an integer >= 0",
                    getattr(self, key),
                )
            require(
                self.outline_rays >= 2,
                "outline_rays",
                "an integer >= 2",
                self.outline_rays,
            )
            quality = self.jpeg_quality
            require(1 <= quality <= 100, "jpeg_quality", "an integer in [1, 100]", quality)

    description = (
        "Rerun recording per game (<game_id>.rrd): map, agents, FOV, belief, plans, plots."
    )

    def __init__(self, config: Config, context: Context, rng: np.random.Generator) -> None:
        super().__init__(config, context, rng)
        self.path: Path | None = None  # the recording's file: partial, then complete or failed
        self._game: tuple[Path, str] | None = None  # (out_dir, game_id)
        self._rec: rr.RecordingStream | None = None
        self._stream: rr.BinaryStream | None = None  # the recording's bytes until written
        self._flush_every = config.live_flush_every if config.spawn else config.flush_every
        self._rows: list[tuple] = []  # columns.tick_row of each tick since the last send
        # Particle rows between two sends: the ticks of a send's window that are multiples
        # of particles_every.
        rows = -(-self._flush_every // config.particles_every)
        self._particles = ParticleRows(rows, config.max_particles, Z_PARTICLES)
        self._buffers = Buffers()
        self._trail_ends: dict[str, np.ndarray] = {}  # per agent, the last trajectory point (1, 3)
        self._plans: list = [None, None]  # the latest (pursuer, evader) plans
        self._plan_rows = (PlanRows("pursuer"), PlanRows("evader"))
        self._modes: dict[str, Any] = {"pursuer": None, "evader": None}
        self._detected: bool | None = None
        self._changed_at = 0.0
        self._detections = 0
        self._last: Tick | None = None
        self._has_image = False  # whether the simulator renders images (known at the first tick)

    # ------------------------------------------------------------ the Recorder API

    def start(self, out_dir: str, game_id: str, properties: dict[str, Any]) -> None:
        """Open ``<out_dir>/<game_id>.rrd.partial`` and log the static scene and the config."""
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
        except ResultsWriteError:  # the layout file could not be written: as a recording
            raise
        except Exception as exc:
            self._fail("logging", exc)

    def finish(self, result: dict[str, Any]) -> None:
        """Send what is buffered and the result, close the recording and write it to
        ``<game_id>.rrd``. ResultsWriteError when it cannot be written: the game fails."""
        if self._rec is None:
            return
        try:
            self._finish(result)
        except ResultsWriteError:
            raise
        except Exception as exc:
            self._fail("finishing", exc)

    def abort(self, error: BaseException) -> None:
        """Send what is buffered, an ERROR event and the error (property ``failure``),
        close the recording and write it to ``<game_id>.failed.rrd`` (a write that fails
        is a warning: the game has failed already)."""
        if self._rec is None:
            return
        try:
            self._abort(error)
        except Exception as exc:
            self._fail("aborting", exc)

    # ---------------------------------------------------------- start and the end

    def _start(self, out_dir: Path, game_id: str, properties: dict[str, Any]) -> None:
        make_dir(out_dir)
        self._game = (out_dir, game_id)
        self.path = recording_path(out_dir, game_id, PARTIAL)
        rec = rr.RecordingStream(
            APPLICATION_ID, recording_id=recording_id(out_dir, game_id, properties)
        )
        self._rec = rec
        # Wall-clock time would only make recordings of one game differ from run to run.
        rr.set_log_time_enabled(False, recording=rec)
        self._stream = rr.binary_stream(recording=rec)
        if self.config.spawn:
            rr.spawn(connect=False)
            rec.set_sinks(rr.GrpcSink(), self._stream)
        rec.send_recording_name(recording_name(game_id, properties))
        send_property(rec, "config", flat_config(properties))
        log_static(rec, self.context, properties)

    def _finish(self, result: dict[str, Any]) -> None:
        if self._last is not None:
            rate = result.get("tracking_rate")
            text = "game over" + (f": tracking rate {100 * rate:.1f}%" if rate is not None else "")
            buffer_event(self._buffers, self._last.step, self._last.time, text)
        self._flush(final=True)
        rec, game = self._rec, self._game
        assert rec is not None and game is not None  # finish returns early without them
        send_property(rec, "result", flat_config(result))
        self._close(COMPLETE)
        # A failed copy of this game from an earlier run is superseded by this one.
        recording_path(*game, FAILED).unlink(missing_ok=True)

    def _abort(self, error: BaseException) -> None:
        step, time = (self._last.step, self._last.time) if self._last is not None else (0, 0.0)
        described = f"{type(error).__name__}: {error}"
        buffer_event(
            self._buffers, step, time, f"game failed after step {step}: {described}", "ERROR"
        )
        self._flush(final=True)
        rec = self._rec
        assert rec is not None  # abort returns early without a recording
        send_property(
            rec,
            "failure",
            {"error": type(error).__name__, "message": str(error), "step": step},
        )
        self._close(FAILED)

    def _close(self, status: str) -> None:
        """Close the stream and write its bytes to the file named for ``status``, through
        the partial name. ResultsWriteError naming the file when rerun-sdk does not
        deliver them or the write fails; no file is left then."""
        rec, stream, self._rec, self._stream = self._rec, self._stream, None, None
        assert rec is not None and stream is not None and self._game is not None  # started
        final = recording_path(*self._game, status)
        try:
            data = stream.read(flush=True, flush_timeout_sec=FLUSH_TIMEOUT)
        except Exception as exc:
            raise ResultsWriteError(f"Could not write the recording {final}: {exc}") from None
        finally:
            rec.disconnect()
        write_atomic(final, data or b"", staging=self.path, sync=False)
        self.path = final

    def _fail(self, action: str, exc: Exception) -> None:
        """Warn once (logging and warnings) and stop recording; the game goes on."""
        message = (
            f"Rerun recording {self.path or ''} disabled: {action} failed ({type(exc).__name__}: {exc}). "
            "The game goes on without it."
        )
        log.warning(message)
        warnings.warn(message, RuntimeWarning, stacklevel=3)
        rec, self._rec, self._stream = self._rec, None, None
        if rec is not None:
            try:
                rec.disconnect()
            except Exception:  # the stream is already broken; nothing more to save
                pass

    # -------------------------------------------------------------------- per tick

    def _log(self, tick: Tick) -> None:
        """Buffer the tick: its numbers as one row, its variable-size data (particles,
        plans, events) in buffers; images are logged at once."""
        rec = self._rec
        assert rec is not None  # log returns early without a recording
        if self._last is None:
            self._has_image = tick.frame.rgb is not None
            self._layout(rec, self._has_image)
        self._last = tick
        self._rows.append(tick_row(tick))
        particles = self.config.max_particles if tick.step % self.config.particles_every == 0 else 0
        if particles:
            self._particles.add(tick.step, tick.time, tick.belief.particles, tick.belief.weights)
        self._log_plans(tick)
        self._log_detection_events(tick)
        buffer_losses(self._buffers, tick)
        buffer_team(self._buffers, tick, self.context, particles)
        every = self.config.image_every
        if tick.frame.rgb is not None and every and tick.step % every == 0:
            log_image(rec, tick, self.context.camera, self.config.jpeg_quality)
        if (tick.step + 1) % self._flush_every == 0:
            self._flush()

    def _layout(self, rec: rr.RecordingStream, has_image: bool) -> None:
        """The layout file of the output directory (:mod:`.blueprint`); the layout itself
        to a spawned viewer."""
        assert self._game is not None  # logging only after start
        write_layout(self._game[0], APPLICATION_ID, self.context, has_image)
        if self.config.spawn:
            rec.send_blueprint(game_blueprint(self.context, has_image))

    def _log_plans(self, tick: Tick) -> None:
        """Paths, goals and candidates, only when a strategy has made a new plan, and an
        event when its mode (``plan.info["mode"]``) changes."""
        for index, name in enumerate(("pursuer", "evader")):
            plan = tick.plans[index]
            if plan is self._plans[index]:
                continue
            self._plans[index] = plan
            self._plan_rows[index].add(tick.step, tick.time, plan)
            mode = plan.info.get("mode")
            if mode is not None and mode != self._modes[name]:
                self._modes[name] = mode
                buffer_event(self._buffers, tick.step, tick.time, f"{name} mode: {mode}")

    def _log_detection_events(self, tick: Tick) -> None:
        """An event when the detector loses (with the loss's cause) or reacquires the evader."""
        detected = tick.detection is not None
        if detected == self._detected:
            return
        if self._detected is None:
            text, level = (
                ("evader detected at start", "INFO")
                if detected
                else ("evader not detected at start", "WARN")
            )
        elif detected:
            text, level = (
                f"evader reacquired after {tick.time - self._changed_at:.1f} s lost",
                "INFO",
            )
        else:
            text, level = f"evader lost after {tick.time - self._changed_at:.1f} s tracked", "WARN"
            causes = [loss.cause for loss in tick.losses if (loss.pursuer, loss.evader) == (0, 0)]
            text += "".join(f": {cause}" for cause in causes)
        self._detected, self._changed_at = detected, tick.time
        buffer_event(self._buffers, tick.step, tick.time, text, level)

    def _flush(self, final: bool = False) -> None:
        """Send the buffered rows and buffers (``final``: the game's last ones), one
        ``log_<family>`` of :mod:`.scene` per entity tree. The file is written by
        rerun-sdk's own thread meanwhile; a write error surfaces when the file is closed."""
        rec, indexes = self._rec, dict[bytes, list]()
        assert rec is not None  # flushed only while recording
        if self._rows:
            c = row_columns(self._rows, self._detections)
            self._rows = []
            self._detections += int(np.isfinite(c["det_x"]).sum())
            steps, times = c["step"].astype(np.int64), c["time"]
            every = time_index(indexes, steps, times)
            log_agents(rec, c, every, self.context, self.config.outline_rays)
            log_sensing(rec, c, every, self._has_image)
            log_plots(rec, c, every, lambda given: time_index(indexes, steps[given], times[given]))
            log_trails(rec, c, indexes, self.config.trail_every, final, self._trail_ends)
        log_particles(rec, self._particles, indexes)
        for plans in self._plan_rows:
            plans.send(rec, indexes)
        self._buffers.send(rec, indexes)
