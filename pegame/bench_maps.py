"""Cost against map size: setup, decisions and memory of S-S games on maps of 400 to
4000 cells a side (``python -m pegame.bench`` reports it as ``map_scaling``).

The maps are a paper map (``enclosed`` by default) scaled up by nearest cell to n x n
cells at its resolution (0.05 m), so a 4000-cell map is 200 m x 200 m of the same
room, its obstacles and walls grown with it: free-space-rich, one connected region.
:func:`scaled_map` builds one, and ``python -m pegame.bench_maps --write DIR`` writes
them as ROS maps (yaml + pgm) to play on, e.g.::

    python -m pegame.bench_maps --write maps_large --cells 4000
    python -m pegame pursuer=smart evader=smart env.map=$PWD/maps_large/enclosed_4000.yaml game.t_max=10

Per size, each in a fresh process so that its peak memory is its own:

- ``setup_s``: wall time (s) from loading the map file to the end of both strategies'
  first decisions: the obstacle distances, both agents' planners, the smart evader's
  candidate cells, the particle filter and the searches' scratch memory, everything a
  game builds once per map;
- ``pursuer_decision_ms`` (estimator update and plan to the estimate, the evader just
  lost, as :func:`pegame.bench.bench_decisions` times it) and ``evader_decision_ms``
  (escape point and path): medians (ms) over game-like starts (:func:`pegame.game.spawn`:
  the evader in the pursuer's view), after setup;
- ``peak_mb``: that process's peak resident memory (MB), Python and numba included (and
  what the launching program imports: a spawned worker imports its main module again);
- ``game_s``, ``game_cpu_s`` and ``game_peak_mb``: wall time (s), CPU time (s, user +
  system: on a shared machine the wall time also counts other work) and peak memory (MB) of
  ``python -m pegame pursuer=smart evader=smart env.map=... game.t_max=10 recorder=none``
  from launch to exit (numba's on-disk cache warm), as a user runs it.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from pegame.config import resolve_map_path
from pegame.grid import OccupancyGrid, load_map, save_map

if TYPE_CHECKING:  # pragma: no cover - typing only (the module imports them where used)
    from pegame.types import Pose, Region
    from pegame.visibility import MaskRegion

#: map sizes (cells a side) of the scaling table
SIZES = (400, 1000, 2000, 4000)
#: the paper map that is scaled up
SOURCE_MAP = "enclosed"
#: game length (s) of the timed CLI game
GAME_SECONDS = 10.0


def scaled_map(cells: int, source: str = SOURCE_MAP) -> OccupancyGrid:
    """The paper map ``source`` scaled to ``cells`` x ``cells`` by nearest cell: cell (r, c)
    takes the value of source cell (floor(r h / cells), floor(c w / cells)) for a source
    of h x w cells. Same resolution and origin as the source; named '<source>_<cells>'."""
    base = load_map(resolve_map_path(f"{source}.yaml"))
    rows = np.arange(cells) * base.height // cells
    cols = np.arange(cells) * base.width // cells
    data = base.data[np.ix_(rows, cols)]
    return OccupancyGrid(data, base.resolution, base.origin, name=f"{source}_{cells}")


def write_map(cells: int, directory: str | os.PathLike, source: str = SOURCE_MAP) -> Path:
    """Write :func:`scaled_map` as the ROS map ``directory/<source>_<cells>.yaml`` (+ .pgm)."""
    grid = scaled_map(cells, source)
    path = Path(directory) / f"{grid.name}.yaml"
    path.parent.mkdir(parents=True, exist_ok=True)
    save_map(grid, path)
    return path


class _Players:
    """The smart evader, the particle filter and the smart pursuer on one map, with the
    game's bodies and camera, and their decisions as :func:`measure_parts` times them."""

    def __init__(self, grid: OccupancyGrid) -> None:
        from pegame import registry
        from pegame.api import Context
        from pegame.types import Body, Camera

        self.grid, self.camera = grid, Camera()
        self.context = Context(
            grid, Body(0.2, 0.5, 1.8), Body(0.25, 0.5, 1.8), self.camera, 0.1, 1.0
        )
        self.rng = np.random.default_rng(0)
        evader = registry.load("evader", "smart")
        estimator = registry.load("estimator", "particle_filter")
        pursuer = registry.load("pursuer", "smart")
        rngs = [np.random.default_rng(seed) for seed in range(3)]
        self.evader = evader(registry.make_config("evader", evader, {}), self.context, rngs[0])
        self.estimator = estimator(
            registry.make_config("estimator", estimator, {}), self.context, rngs[1]
        )
        self.pursuer = pursuer(registry.make_config("pursuer", pursuer, {}), self.context, rngs[2])

    def start(self) -> tuple[Pose, Pose, MaskRegion]:
        """A game-like start (pursuer pose, evader pose, the pursuer's region)."""
        from pegame.game import spawn
        from pegame.visibility import MaskRegion, visibility_region

        p, e = spawn(self.context, self.rng)
        return p, e, MaskRegion(visibility_region(self.grid, p, self.camera))

    def evader_decision(self, p: Pose, e: Pose) -> None:
        from pegame.api import EvaderObservation

        self.evader.reset(e)
        self.evader.decide(EvaderObservation(0.0, e, p))

    def pursuer_decision(self, p: Pose, region: Region) -> None:
        """The estimator's update and the pursuer's plan to the estimate; the estimator is
        reset beforehand (not timed) over the region, as just after the evader left it."""
        from pegame.api import PursuerObservation

        belief = self.estimator.update(0.1, (p,), (None,), region)
        self.pursuer.decide(PursuerObservation(0.0, p, None, belief, region))


def measure_parts(yaml_path: str, repeat: int) -> dict[str, float]:
    """Setup time, decision medians and peak memory on the map at ``yaml_path`` (module
    docstring), in this process. The decisions are first made once on the source paper
    map, so that loading numba's compiled kernels is not counted as setup."""
    timed = []
    for path in (resolve_map_path(f"{SOURCE_MAP}.yaml"), yaml_path):
        start = time.perf_counter()
        players = _Players(load_map(path))
        p, e, region = players.start()
        players.estimator.reset((p,), (None,), region)
        players.pursuer.reset(p)
        players.evader_decision(p, e)
        players.pursuer_decision(p, region)
        setup_s = time.perf_counter() - start
    for _ in range(repeat):
        p, e, region = players.start()
        tic = time.perf_counter()
        players.evader_decision(p, e)
        evader_ms = 1e3 * (time.perf_counter() - tic)
        players.estimator.reset((p,), (None,), region)
        tic = time.perf_counter()
        players.pursuer_decision(p, region)
        timed.append((evader_ms, 1e3 * (time.perf_counter() - tic)))
    return {
        "setup_s": setup_s,
        "pursuer_decision_ms": statistics.median(t[1] for t in timed),
        "evader_decision_ms": statistics.median(t[0] for t in timed),
        "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
    }


def measure_game(yaml_path: str, out_dir: str) -> tuple[float, float, float]:
    """(wall s, CPU s, peak MB) of a GAME_SECONDS S-S game played by ``python -m pegame`` on the
    map at ``yaml_path``, from launch to exit. Raises RuntimeError if the game fails."""
    command = [
        sys.executable,
        "-m",
        "pegame",
        "pursuer=smart",
        "evader=smart",
        f"env.map={yaml_path}",
        f"game.t_max={GAME_SECONDS}",
        "recorder=none",
        f"hydra.run.dir={out_dir}",
    ]
    with tempfile.TemporaryFile() as log:
        start = time.perf_counter()
        process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=log)
        _, status, usage = os.wait4(process.pid, 0)  # this child's own peak, not all children's
        wall = time.perf_counter() - start
        process.returncode = os.waitstatus_to_exitcode(status)
        if process.returncode != 0:
            log.seek(0)
            error = log.read().decode(errors="replace")
            raise RuntimeError(f"{' '.join(command)} failed:\n{error[-2000:]}")
    return wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024


def map_scaling(
    sizes: Sequence[int] = SIZES, repeat: int = 10, game: bool = True, source: str = SOURCE_MAP
) -> list[dict[str, Any]]:
    """One row per map size (module docstring) on ``source`` scaled up; ``game=False``
    skips the CLI games."""
    rows = []
    context = multiprocessing.get_context("spawn")
    with tempfile.TemporaryDirectory() as tmp:
        for cells in sizes:
            path = str(write_map(cells, tmp, source))
            with context.Pool(1) as pool:
                row: dict[str, Any] = {"cells": cells, **pool.apply(measure_parts, (path, repeat))}
            if game:
                game_s, cpu_s, peak_mb = measure_game(path, f"{tmp}/game_{cells}")
                row.update(game_s=game_s, game_cpu_s=cpu_s, game_peak_mb=peak_mb)
            rows.append(row)
    return rows


def _fmt(value: float | None) -> str:
    return "-" if value is None else f"{value:.2f}" if value < 100 else f"{value:.0f}"


def format_rows(rows: list[dict[str, Any]]) -> list[str]:
    """The scaling table as aligned text lines."""
    lines = [
        "map size against cost (a paper map scaled up, 0.05 m cells, each size in new processes):",
        f"{'cells':>11}{'setup s':>9}{'P dec ms':>10}{'E dec ms':>10}{'peak MB':>9}"
        f"{f'{GAME_SECONDS:.0f} s S-S game: wall s':>25}{'CPU s':>7}{'peak MB':>9}",
    ]
    for row in rows:
        lines.append(
            f"{row['cells']:>5} x{row['cells']:>5}{_fmt(row['setup_s']):>9}"
            f"{_fmt(row['pursuer_decision_ms']):>10}{_fmt(row['evader_decision_ms']):>10}"
            f"{_fmt(row['peak_mb']):>9}{_fmt(row.get('game_s')):>25}"
            f"{_fmt(row.get('game_cpu_s')):>7}{_fmt(row.get('game_peak_mb')):>9}"
        )
    return lines


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(
        prog="python -m pegame.bench_maps", description=__doc__.splitlines()[0]
    )
    parser.add_argument(
        "--cells", type=int, nargs="+", default=list(SIZES), help="map sizes (cells a side)"
    )
    parser.add_argument(
        "--write", metavar="DIR", help="only write the scaled maps (yaml + pgm) to DIR"
    )
    parser.add_argument("--source", default=SOURCE_MAP, help="the paper map to scale up")
    parser.add_argument("--json", action="store_true", help="print the rows as JSON")
    args = parser.parse_args(argv)
    if args.write:
        for cells in args.cells:
            print(write_map(cells, args.write, args.source))
        return
    rows = map_scaling(args.cells, source=args.source)
    print(json.dumps(rows, indent=2) if args.json else "\n".join(format_rows(rows)))


if __name__ == "__main__":
    main()
