"""The game loop and its result (paper, Sec. "Simulation based validation").

Protocol: both agents spawn at random free poses (seeded) with the evader in the
pursuer's view; the game lasts ``game.t_max`` seconds. At every control tick (period
1 / ``game.control_hz``) the simulator renders the pursuer's camera, the detector looks
for the evader, the estimator updates its belief from the detection and the pursuer's
visibility region; at every decision tick (1 / ``game.decision_hz``) the evader decides
first, then the pursuer; both then act concurrently at control rate. The pursuer learns
about the evader only through its detector; the evader is told the pursuer's pose. The
ground truth ``in_view`` of every tick is whether any part of the evader's body is in the
pursuer's view (:func:`pegame.visibility.body_in_view`).
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
from pegame.api import Context, EvaderObservation, PursuerObservation, Tick
from pegame.types import Body, Camera, Plan, Pose
from pegame.config import EnvConfig, GameConfig, resolve_map_path, typed
from pegame.errors import SpawnError
from pegame.files import write_atomic
from pegame.visibility import VisibilityRegion, body_in_view, in_view, visibility_region
from pegame.grid import OccupancyGrid, load_map
from pegame.metrics import TrackingMetrics
from pegame.navigation import Planner

log = logging.getLogger(__name__)

#: the order in which components draw their generators from the master seed; append only
STREAMS = ("spawn", "sim", "detector", "estimator", "pursuer", "evader", "recorder")
PLUGIN_GROUPS = ("sim", "detector", "estimator", "pursuer", "evader", "recorder")


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
    "step", "time", "pursuer_x", "pursuer_y", "pursuer_theta",
    "evader_x", "evader_y", "evader_theta", "detected", "in_view",
)


class Game:
    """One game, built from a composed config (see :func:`build`)."""

    def __init__(self, cfg: DictConfig, base_dir: str | Path | None = None) -> None:
        self.settings: GameConfig = typed(cfg.game, GameConfig, "game")
        self.camera: Camera = typed(cfg.camera, Camera, "camera")
        env: EnvConfig = typed(cfg.env, EnvConfig, "env")
        self.env_name = env.name
        grid = cached_map(resolve_map_path(env.map, base_dir))
        self.names = {group: str(cfg[group].name) for group in PLUGIN_GROUPS}
        classes = {group: registry.load(group, self.names[group]) for group in PLUGIN_GROUPS}
        configs = {
            group: registry.make_config(
                group, classes[group], {k: v for k, v in cfg[group].items() if k != "name"}
            )
            for group in PLUGIN_GROUPS
        }
        evader_cfg, pursuer_cfg = configs["evader"], configs["pursuer"]
        self.context = Context(
            grid=grid,
            pursuer=Body(pursuer_cfg.radius, self.settings.speed_ratio * evader_cfg.v_max, pursuer_cfg.w_max),
            evader=Body(evader_cfg.radius, evader_cfg.v_max, evader_cfg.w_max),
            camera=self.camera,
            control_dt=1.0 / self.settings.control_hz,
            decision_dt=1.0 / self.settings.decision_hz,
        )
        streams = dict(zip(STREAMS, np.random.SeedSequence(self.settings.seed).spawn(len(STREAMS))))
        self.spawn_rng = np.random.default_rng(streams["spawn"])
        self.plugins = {
            group: classes[group](configs[group], self.context, np.random.default_rng(streams[group]))
            for group in PLUGIN_GROUPS
        }
        self.config = OmegaConf.to_container(cfg, resolve=True)

    def play(self, out_dir: str | Path, recording_name: str = "game") -> Outcome:
        """Play the game; the recorder (if any) writes ``recording_name`` into ``out_dir``."""
        sim, detector, estimator = self.plugins["sim"], self.plugins["detector"], self.plugins["estimator"]
        pursuer, evader, recorder = self.plugins["pursuer"], self.plugins["evader"], self.plugins["recorder"]
        grid, camera, dt = self.context.grid, self.camera, self.context.control_dt
        evader_radius = self.context.evader.radius
        ticks = int(round(self.settings.t_max * self.settings.control_hz))
        decide_every = max(1, int(round(self.settings.control_hz / self.settings.decision_hz)))

        start_p, start_e = spawn(self.context, self.spawn_rng)
        sim.reset(start_p, start_e)
        detector.reset()
        pursuer.reset(start_p)
        evader.reset(start_e)
        recorder.start(str(out_dir), recording_name, self.config)
        metrics = TrackingMetrics(dt)
        trajectory: list[tuple] = []
        p_plan = e_plan = Plan()
        try:
            for step in range(ticks):
                time = step * dt
                p_pose, e_pose = sim.poses
                frame = sim.sense(time)
                detection = detector.detect(frame)
                visible = VisibilityRegion(grid, p_pose, camera)
                if step == 0:
                    belief = estimator.reset(p_pose, detection, visible)
                else:
                    belief = estimator.update(dt, p_pose, detection, visible)
                seen = body_in_view(grid, camera, p_pose, (e_pose.x, e_pose.y), evader_radius)
                e_obs = EvaderObservation(time, e_pose, p_pose, visible)
                p_obs = PursuerObservation(time, p_pose, detection, belief, visible)
                if step % decide_every == 0:
                    e_plan = evader.decide(e_obs)
                    p_plan = pursuer.decide(p_obs)
                commands = (pursuer.control(p_obs), evader.control(e_obs))
                metrics.add(p_pose, e_pose, detection is not None, seen, belief)
                trajectory.append(
                    (step, round(time, 6), p_pose.x, p_pose.y, p_pose.theta,
                     e_pose.x, e_pose.y, e_pose.theta, int(detection is not None), int(seen))
                )
                recorder.log(Tick(step, time, p_pose, e_pose, frame, detection, belief, visible,
                                  seen, commands, (p_plan, e_plan)))
                sim.step(commands[0], commands[1], dt)
            result = self._result(ticks, metrics)
        except BaseException as error:
            recorder.abort(error)
            raise
        else:
            recorder.finish(result)
        finally:
            sim.close()
        return Outcome(result, trajectory)

    def _result(self, ticks: int, metrics: TrackingMetrics) -> dict[str, Any]:
        s, names = self.settings, self.names
        return {
            "pairing": pairing(names["pursuer"], names["evader"]),
            "pursuer": names["pursuer"],
            "evader": names["evader"],
            "estimator": names["estimator"],
            "detector": names["detector"],
            "sim": names["sim"],
            "map": self.env_name,
            "seed": s.seed,
            "speed_ratio": s.speed_ratio,
            "t_max": s.t_max,
            "control_hz": s.control_hz,
            "decision_hz": s.decision_hz,
            "ticks": ticks,
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
