"""``recorder=play``: the page as a recorder of the game. Each tick goes to the recorder
that records the game (``then``, by default ``rerun``: the ``.rrd``) and, as a frame, to
the page of :mod:`pegame.play` through the session (latest-only: a slow page drops
frames, never ticks).

A frame holds only what the human evader's ``show`` lets the person see: always the
time and the person's own pose; the pursuers' poses for ``pursuer`` or ``cone``; for
``cone``, each pursuer's view as the outline of its visibility region (walls hide what
is behind them: :func:`pegame.visibility.outlines.visibility_outlines`, the polygon the
Rerun recording draws, :data:`OUTLINE_RAYS` rays, as (x, y) points); the belief's mean
and up to :data:`MAX_PARTICLES` of its particles for ``belief``. Poses are (x m, y m, theta rad)
in the map frame; ``sent`` is the wall-clock time (ms since the epoch) the tick was
handed to this recorder, from which the page measures its tick-to-frame latency.
"""

from __future__ import annotations

import base64
import io
from dataclasses import dataclass
from typing import Any

import numpy as np
from PIL import Image

from pegame import registry
from pegame.api import Context, Recorder, Tick
from pegame.errors import require
from pegame.grid import OccupancyGrid
from pegame.play.session import Session, active, now_ms
from pegame.visibility.outlines import visibility_outlines

#: the most particles of a belief a frame carries (evenly subsampled)
MAX_PARTICLES = 300
#: rays of a view cone's outline (:func:`pegame.visibility.outlines.visibility_outlines`)
OUTLINE_RAYS = 64


def map_message(grid: OccupancyGrid) -> dict[str, Any]:
    """The map as the page draws it: a PNG (data URL) with one pixel per cell, free
    cells white, others dark, its top row the grid's highest y; the size in cells, the
    resolution (m) and the origin (x m, y m) of cell (0, 0)'s lower-left corner."""
    shades = np.where(grid.blocked, 60, 255).astype(np.uint8)[::-1]
    buffer = io.BytesIO()
    Image.fromarray(shades).save(buffer, format="PNG")  # uint8 (H, W): greyscale
    return {
        "name": grid.name,
        "width": grid.width,
        "height": grid.height,
        "resolution": grid.resolution,
        "origin": list(grid.origin[:2]),
        "image": "data:image/png;base64," + base64.b64encode(buffer.getvalue()).decode(),
    }


def frame(
    tick: Tick, show: tuple[str, ...], context: Context, sent: float | None = None
) -> dict[str, Any]:
    """The page's frame of ``tick`` with what ``show`` allows (module docstring), handed
    over at ``sent`` (ms since the epoch; now when None)."""
    e = tick.evader
    out: dict[str, Any] = {
        "type": "frame",
        "step": tick.step,
        "time": round(tick.time, 6),
        "evader": [e.x, e.y, e.theta],
    }
    if "pursuer" in show or "cone" in show:
        pursuers = tick.pursuers
        out["pursuers"] = [[p.x, p.y, p.theta] for p in pursuers]
    if "cone" in show:
        outlines = visibility_outlines(
            context.grid,
            [p.x for p in pursuers],
            [p.y for p in pursuers],
            [p.theta for p in pursuers],
            context.camera,
            OUTLINE_RAYS,
        )
        out["cones"] = np.round(outlines[:, :, :2].astype(float), 3).tolist()
    if "belief" in show:
        belief, shown = tick.belief, {}
        if belief.mean is not None:
            shown["mean"] = [float(v) for v in belief.mean]
        if belief.particles is not None and len(belief.particles):
            step = -(-len(belief.particles) // MAX_PARTICLES)  # ceil: at most MAX_PARTICLES
            shown["particles"] = np.round(belief.particles[::step, :2], 3).tolist()
        out["belief"] = shown
    out["sent"] = now_ms() if sent is None else sent
    return out


class PlayRecorder(Recorder):
    """Tees every tick to the game's recorder (``then``) and to the person's page."""

    description = "The page of python -m pegame.play, and the recorder named by 'then'."

    @dataclass
    class Config:
        then: str = "rerun"  # the recorder that records the game (its defaults): rerun, none

        def __post_init__(self) -> None:
            require(self.then != "play", "then", "a recorder other than play", self.then)

    def __init__(self, config: Config, context: Context, rng: np.random.Generator) -> None:
        super().__init__(config, context, rng)
        self.session: Session = active("recorder")
        cls = registry.load("recorder", config.then)
        inner = cls(registry.make_config("recorder", cls, {}), context, rng)
        self.inner = Recorder.narrow(inner)

    def start(self, out_dir: str, game_id: str, properties: dict[str, Any]) -> None:
        self.inner.start(out_dir, game_id, properties)
        context, game = self.context, properties.get("game", {})
        camera = context.camera
        self.session.send(
            {
                "type": "game",
                "map": map_message(context.grid),
                "camera": {"fov": camera.fov, "near": camera.near, "far": camera.far},
                "pursuer_radius": context.pursuer.radius,
                "evader": {
                    "radius": context.evader.radius,
                    "v_max": context.evader.v_max,
                    "w_max": context.evader.w_max,
                },
                "t_max": game.get("t_max"),
                "control_hz": game.get("control_hz"),
                "seed": game.get("seed"),
                "show": list(self.session.show),
            }
        )

    def log(self, tick: Tick) -> None:
        handed = now_ms()  # the page's tick-to-frame latency counts the recording too
        self.inner.log(tick)
        self.session.publish_frame(frame(tick, self.session.show, self.context, handed))

    def finish(self, result: dict[str, Any]) -> None:
        self.inner.finish(result)
        keys = ("pairing", "map", "seed", "tracking_rate", "visible_rate", "t_max")
        self.session.send({"type": "result", **{k: result.get(k) for k in keys}})

    def abort(self, error: BaseException) -> None:
        self.inner.abort(error)
        self.session.send({"type": "failed", "error": f"{type(error).__name__}: {error}"})
