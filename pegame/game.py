"""A game from a composed config: its scenario, its plugins, its play and its result
(paper, Sec. "Simulation based validation").

Protocol: both agents spawn at random free poses (seeded) with the evader in the
pursuer's view; the game lasts ``game.t_max`` seconds of control ticks played by
:class:`pegame.loop.TickLoop` (the order of a tick is written there, once). The pursuer
learns about the evader only through its detector; the evader is told the pursuer's pose.

A :class:`Scenario` is the config validated once: the map, the bodies, the camera, the
plugin classes and their configs. ``scenario.game(seed)`` builds one :class:`Game`: every
component gets its own generator from the master seed (one SeedSequence stream per
component, in :data:`STREAMS` order), so the same scenario and seed give the same game.
"""

from __future__ import annotations

import csv
import io
import json
import logging
import math
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
from omegaconf import DictConfig, OmegaConf

from pegame import registry
from pegame.api import INTERFACES, Context
from pegame.config import EnvConfig, GameConfig, resolve_map_path, typed
from pegame.errors import SpawnError
from pegame.files import write_atomic
from pegame.grid import OccupancyGrid, load_map
from pegame.loop import TickLoop
from pegame.metrics import TrackingMetrics
from pegame.navigation import Planner
from pegame.types import Body, Camera, Pose
from pegame.visibility import in_view, visibility_region

log = logging.getLogger(__name__)

#: the order in which components draw their generators from the master seed: the spawn,
#: then the plugin kinds in api.INTERFACES order (append only: games depend on it)
STREAMS = ("spawn", *INTERFACES)


def cached_map(path: Path) -> OccupancyGrid:
    """The map at ``path``, loaded once per process while the file is unchanged: grids
    are immutable, so the games of a job share one (and the planners cached on it)."""
    try:
        stamp = path.stat().st_mtime_ns
    except OSError:
        return load_map(path)  # raises the MapError that names the missing file
    return _load_map_once(str(path), stamp)


@lru_cache(maxsize=8)
def _load_map_once(path: str, stamp: int) -> OccupancyGrid:
    return load_map(path)


#: the paper's letters for its agents; other strategies appear by name in pairings
PAPER_LETTERS = {"random": "R", "smart": "S"}


def pairing(pursuer: str, evader: str) -> str:
    """The paper's pairing label, e.g. 'S-R' for a smart pursuer and a random evader
    ('policy-S' for a pursuer named policy)."""
    return f"{PAPER_LETTERS.get(pursuer, pursuer)}-{PAPER_LETTERS.get(evader, evader)}"


def spawn(context: Context, rng: np.random.Generator, attempts: int = 500) -> tuple[Pose, Pose]:
    """Random start poses: the pursuer on a free cell it can move from, the evader on a
    free cell in the pursuer's view (FOV, range, line of sight) that the pursuer can reach.

    Raises SpawnError when ``attempts`` pursuer draws give no valid pair.
    """
    grid, camera = context.grid, context.camera
    pursuer_space = Planner.shared(grid, context.pursuer.radius).traversable
    evader_space = Planner.shared(grid, context.evader.radius).traversable
    rows, cols = np.nonzero(pursuer_space)
    for _ in range(attempts if rows.size else 0):
        k = int(rng.integers(rows.size))
        x, y = grid.cell_to_world(rows[k], cols[k])
        pursuer = Pose(x, y, float(rng.uniform(-math.pi, math.pi)))
        er, ec = np.nonzero(visibility_region(grid, pursuer, camera) & evader_space)
        order = rng.permutation(er.size)
        for j in order[:20]:
            ex, ey = grid.cell_to_world(er[j], ec[j])
            if in_view(grid, camera, pursuer, (ex, ey)):
                return pursuer, Pose(ex, ey, float(rng.uniform(-math.pi, math.pi)))
    raise SpawnError(
        f"No valid spawn on map '{grid.name}': after {attempts} tries there is no free pose for "
        f"the pursuer (radius {context.pursuer.radius} m) with a free cell for the evader (radius "
        f"{context.evader.radius} m) in its view (range {camera.near}-{camera.far} m, FOV "
        f"{camera.fov:.3f} rad). Use a map with more free space, smaller radii or a longer camera range."
    )


@dataclass
class Outcome:
    """A played game: its result (JSON-ready, no wall-clock values) and trajectory rows."""

    result: dict[str, Any]
    trajectory: list[tuple]


TRAJECTORY_HEADER = (
    "step",
    "time",
    "pursuer_x",
    "pursuer_y",
    "pursuer_theta",
    "evader_x",
    "evader_y",
    "evader_theta",
    "detected",
    "in_view",
)


class Scenario:
    """A composed config validated once: settings, camera, map, plugin classes and their
    configs, and the game context. Every bad value or name raises a PegameError here,
    before any game is played. ``base_dir``: where relative map paths are found."""

    def __init__(self, cfg: DictConfig, base_dir: str | Path | None = None) -> None:
        self.settings: GameConfig = typed(cfg.game, GameConfig, "game")
        camera: Camera = typed(cfg.camera, Camera, "camera")
        env: EnvConfig = typed(cfg.env, EnvConfig, "env")
        self.env_name = env.name
        grid = cached_map(resolve_map_path(env.map, base_dir))
        self.names = {kind: str(cfg[kind].name) for kind in INTERFACES}
        self.classes = {kind: registry.load(kind, self.names[kind]) for kind in INTERFACES}
        self.configs = {
            kind: registry.make_config(
                kind, self.classes[kind], {k: v for k, v in cfg[kind].items() if k != "name"}
            )
            for kind in INTERFACES
        }
        evader_cfg, pursuer_cfg = self.configs["evader"], self.configs["pursuer"]
        self.context = Context(
            grid=grid,
            pursuer=Body(
                pursuer_cfg.radius,
                self.settings.speed_ratio * evader_cfg.v_max,
                pursuer_cfg.w_max,
                pursuer_cfg.a_max,
                pursuer_cfg.alpha_max,
            ),
            evader=Body(
                evader_cfg.radius,
                evader_cfg.v_max,
                evader_cfg.w_max,
                evader_cfg.a_max,
                evader_cfg.alpha_max,
            ),
            camera=camera,
            control_dt=1.0 / self.settings.control_hz,
            decision_dt=1.0 / self.settings.decision_hz,
        )
        for config in self.configs.values():  # the checks that need the camera or the rates
            check_context = getattr(config, "check_context", None)
            if check_context is not None:
                check_context(self.context)
        self.config = OmegaConf.to_container(cfg, resolve=True)

    def game(self, seed: int) -> Game:
        """The game of this scenario with master seed ``seed``."""
        return Game(self, seed)


class Game:
    """One game: a scenario's plugins (by kind) built with the generators of ``seed``.

    source: a :class:`Scenario`, or a composed config to build one from (with
    ``base_dir``); seed: the master seed, by default the config's ``game.seed``.
    """

    def __init__(
        self,
        source: Scenario | DictConfig,
        seed: int | None = None,
        base_dir: str | Path | None = None,
    ) -> None:
        scenario = source if isinstance(source, Scenario) else Scenario(source, base_dir)
        self.scenario = scenario
        self.seed = scenario.settings.seed if seed is None else seed
        self.context = scenario.context
        streams = dict(zip(STREAMS, np.random.SeedSequence(self.seed).spawn(len(STREAMS))))
        self.spawn_rng = np.random.default_rng(streams["spawn"])
        self.plugins = {
            kind: scenario.classes[kind](
                scenario.configs[kind], self.context, np.random.default_rng(streams[kind])
            )
            for kind in INTERFACES
        }

    def start(self, external: tuple[str, ...] = (), estimate: bool = True) -> TickLoop:
        """Spawn both agents and return the game's tick loop at tick 0 (see TickLoop)."""
        settings = self.scenario.settings
        loop = TickLoop(
            self.plugins,
            self.context,
            settings.ticks,
            settings.decide_every,
            external,
            estimate,
            substeps=settings.substeps,
            turn_order=settings.turn_order,
        )
        loop.start(*spawn(self.context, self.spawn_rng))
        return loop

    def play(self, out_dir: str | Path, recording_name: str = "game") -> Outcome:
        """Play the game; the recorder (if any) writes ``recording_name`` into ``out_dir``."""
        recorder = self.plugins["recorder"]
        config = {
            **self.scenario.config,
            "game": {**self.scenario.config["game"], "seed": self.seed},
        }
        try:
            loop = self.start()
            recorder.start(str(out_dir), recording_name, config)
            trajectory: list[tuple] = []
            try:
                while not loop.done:
                    t = loop.advance()
                    p, e = t.pursuer, t.evader
                    trajectory.append(
                        (
                            t.step,
                            round(t.time, 6),
                            p.x,
                            p.y,
                            p.theta,
                            e.x,
                            e.y,
                            e.theta,
                            int(t.detection is not None),
                            int(t.in_view),
                        )
                    )
                result = self._result(loop.metrics)
            except BaseException as error:
                recorder.abort(error)
                raise
            recorder.finish(result)
        finally:
            self.plugins["sim"].close()
        return Outcome(result, trajectory)

    def _result(self, metrics: TrackingMetrics) -> dict[str, Any]:
        s, names = self.scenario.settings, self.scenario.names
        return {
            "pairing": pairing(names["pursuer"], names["evader"]),
            "pursuer": names["pursuer"],
            "evader": names["evader"],
            "estimator": names["estimator"],
            "detector": names["detector"],
            "sim": names["sim"],
            "map": self.scenario.env_name,
            "seed": self.seed,
            "speed_ratio": s.speed_ratio,
            "t_max": s.t_max,
            "control_hz": s.control_hz,
            "decision_hz": s.decision_hz,
            "ticks": s.ticks,
            **metrics.summary(),
        }


def write_outcome(outcome: Outcome, out_dir: str | Path) -> None:
    """Write ``trajectory.csv`` then ``result.json`` (last, atomically) into ``out_dir``."""
    out_dir = Path(out_dir)
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(TRAJECTORY_HEADER)
    writer.writerows(outcome.trajectory)
    write_atomic(out_dir / "trajectory.csv", buffer.getvalue())
    write_atomic(out_dir / "result.json", json.dumps(outcome.result, indent=2) + "\n")


def summary_line(result: dict[str, Any]) -> str:
    """One line for the terminal: pairing, map, tracking rate, game duration."""
    return (
        f"{result['pairing']} ({result['pursuer']} pursuer vs {result['evader']} evader) on "
        f"{result['map']}: tracking rate {100 * result['tracking_rate']:.1f}% "
        f"(in view {100 * result['visible_rate']:.1f}%) over {result['t_max']:g} s, seed {result['seed']}"
    )
