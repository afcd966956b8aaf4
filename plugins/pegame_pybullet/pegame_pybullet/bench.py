"""Measurements of the PyBullet simulator for ``python -m pegame.bench`` and the README.

- :func:`rtf`: real-time factor of whole games (simulated seconds per second).
- :func:`visibility_agreement`: how often "evader pixels present" in PyBullet agrees with
  the grid simulator's geometric visibility (:func:`pegame.visibility.body_in_view`), and why
  not.
- :func:`memory_growth`: resident memory over many reset/close cycles in one process.
"""

from __future__ import annotations

import ctypes
import math
import os
import tempfile
import time
from collections import Counter
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

from pegame import registry
from pegame.config import compose
from pegame.game import Game, spawn
from pegame.grid import OccupancyGrid
from pegame.types import Camera, Pose, Velocity, wrap_angle
from pegame.visibility import line_of_sight
from pegame_pybullet.sim import PybulletSimulator

ARC = Velocity(0.3, 0.5)  # m/s, rad/s: a command that keeps the agents moving


def rtf(
    env: str = "enclosed",
    seeds: Iterable[int] = (0,),
    t_max: float = 90.0,
    overrides: Sequence[str] = (),
) -> dict[str, float]:
    """Real-time factor of S-S games (smart pursuer and evader) in PyBullet with the
    segmentation detector and no recorder, camera at ``sim.camera_hz`` (10 Hz) and 160x120
    unless ``overrides`` say otherwise: ``rtf`` is simulated time over wall-clock time,
    ``rtf_cpu`` over this process's CPU time (the one-core figure on a shared machine). Both
    are totals over the games of ``seeds``; game construction is not timed."""
    sim_time = wall = cpu = 0.0
    with tempfile.TemporaryDirectory() as out:
        for seed in seeds:
            game = Game(
                compose(
                    [
                        "sim=pybullet",
                        "detector=segmentation",
                        "pursuer=smart",
                        "evader=smart",
                        "recorder=none",
                        f"env={env}",
                        f"game.t_max={t_max}",
                        f"game.seed={seed}",
                        *overrides,
                    ]
                )
            )
            start, start_cpu = time.perf_counter(), time.process_time()
            game.play(out)
            wall += time.perf_counter() - start
            cpu += time.process_time() - start_cpu
            sim_time += game.scenario.settings.t_max
    return {"rtf": sim_time / wall, "rtf_cpu": sim_time / cpu}


def _why(grid: OccupancyGrid, camera: Camera, radius: float, pursuer: Pose, evader: Pose) -> str:
    """Why pixels of the evader show while its body, as the grid models it, is not in view
    (see :func:`visibility_agreement`)."""
    dx, dy = evader.x - pursuer.x, evader.y - pursuer.y
    distance = math.hypot(dx, dy)
    if distance <= radius:
        return "overlap"
    widen = math.asin(min(1.0, radius / distance))
    bearing = abs(wrap_angle(math.atan2(dy, dx) - pursuer.theta))
    if bearing > 0.5 * camera.fov:
        return "fov_edge" if bearing <= 0.5 * camera.fov + widen else "other"
    if not camera.near <= distance <= camera.far:
        return "range_edge" if camera.near - radius <= distance <= camera.far + radius else "other"
    # The body's silhouette seen from the camera: its two extreme points across the ray.
    nx, ny = -dy / distance * radius, dx / distance * radius
    for side in (1.0, -1.0):
        if line_of_sight(
            grid, (pursuer.x, pursuer.y), (evader.x + side * nx, evader.y + side * ny)
        ):
            return "occlusion_edge"
    return "other"


def visibility_agreement(
    env: str = "enclosed",
    seeds: Iterable[int] = range(3),
    t_max: float = 90.0,
    pursuer: str = "smart",
    evader: str = "smart",
    min_visible: float = 0.0,
) -> dict[str, Any]:
    """Agreement of PyBullet's ground-truth visibility with the grid's, on the same poses.

    Each game is played in the grid simulator (``sim=grid detector=oracle``, seeds
    ``seeds``), then every tick's poses are placed in PyBullet and rendered. "Pixels" means
    the segmentation detector finds the evader (at least ``min_pixels`` evader pixels within
    the camera's range), "in view" is the game's ground truth,
    :func:`pegame.visibility.body_in_view` of the evader's body (a cylinder of its radius).
    With ``min_visible`` > 0, pixels count only when at least that fraction of the evader's
    body is visible (:meth:`PybulletSimulator.evader_visible_fraction`, an extra render per
    tick). Returns the fraction of ticks where both agree, the tick count, and the
    disagreements by cause: pixels while the body is out of view, with the 3D person
    reaching past the cylinder near the field of view's edge (``fov_edge``), the range
    limits (``range_edge``) or an occluder's edge (``occlusion_edge``), or else ``other``;
    and ``missed``, the body in view without evader pixels (a sliver of the body below
    ``min_pixels``, or hidden by the camera's vertical field of view or near clip).
    """
    agree = ticks = 0
    causes: Counter[str] = Counter()
    with tempfile.TemporaryDirectory() as out:
        for seed in seeds:
            base = [
                f"env={env}",
                f"pursuer={pursuer}",
                f"evader={evader}",
                "recorder=none",
                f"game.t_max={t_max}",
                f"game.seed={seed}",
            ]
            played = Game(compose(["sim=grid", "detector=oracle", *base])).play(out)
            game = Game(compose(["sim=pybullet", "detector=segmentation", *base]))
            sim = PybulletSimulator.narrow(game.plugins.sim)
            detector, context = game.plugins.detector, game.context
            try:
                for row in played.trajectory:
                    p, e = Pose(*row[2:5]), Pose(*row[5:8])
                    sim.place(p, e)
                    pixels = detector.detect(sim.sense_1v1(row[1])) is not None
                    if pixels and min_visible > 0:
                        pixels = sim.evader_visible_fraction() >= min_visible
                    in_view = bool(row[9])
                    ticks += 1
                    if pixels == in_view:
                        agree += 1
                    elif pixels:
                        causes[_why(context.grid, context.camera, context.evader.radius, p, e)] += 1
                    else:
                        causes["missed"] += 1
            finally:
                sim.close()
    return {"agreement": agree / ticks, "ticks": ticks, "differences": dict(causes)}


def _rss_mb() -> float:
    """This process's resident memory (MB) on Linux, after handing freed heap pages back to
    the system (glibc's malloc_trim), so that it counts live memory and not the ~30 MB a
    closed physics server leaves in malloc's cache; elsewhere the peak RSS."""
    try:
        ctypes.CDLL("libc.so.6").malloc_trim(0)
        with open("/proc/self/statm") as statm:
            return int(statm.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20
    except OSError:
        import resource

        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def memory_growth(cycles: int = 30, env: str = "enclosed", steps: int = 10) -> dict[str, float]:
    """Resident memory (MB) after one warm-up game's worth of simulator use and after
    ``cycles`` more, each a fresh simulator: reset (connect, build the world), ``steps``
    control ticks of sensing and moving, close (disconnect), as a game does."""
    game = Game(compose(["sim=pybullet", "recorder=none", f"env={env}"]))
    cls = registry.load("sim", "pybullet")
    config = registry.make_config("sim", cls, {})
    rng = np.random.default_rng(0)

    def cycle(k: int) -> None:
        sim = cls(config, game.context, rng)
        pursuer, evader = spawn(game.context, np.random.default_rng(k))
        sim.reset((pursuer,), (evader,))
        try:
            for step in range(steps):
                sim.sense(step * game.context.control_dt)
                sim.step((ARC,), (ARC,), game.context.control_dt)
        finally:
            sim.close()

    cycle(0)
    start = _rss_mb()
    for k in range(1, cycles + 1):
        cycle(k)
    end = _rss_mb()
    return {"cycles": cycles, "rss_start_mb": start, "rss_end_mb": end, "growth_mb": end - start}
