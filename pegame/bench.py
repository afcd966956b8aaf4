"""``python -m pegame.bench [--json] [--quick]``: speed of the kernels and of whole games.

Every figure is a median over repeated runs in one process on one core (no kernel here
is multi-threaded), measured together so that ratios between figures are meaningful on a noisy
machine. Numba kernels are compiled (or loaded from cache) by a warm-up call first; the
first-call cost is reported separately as ``jit_warmup_s``. Keys whose piece does not exist
yet are null. Figures taken on each paper map are under ``maps``; the top-level key is the
worst map's (the most ms, the fewest S-S games per second). ``team_game_s`` is the cost of
a game by team size (N pursuers v M evaders). ``loss_causes_overhead`` is the extra time a
game's ticks take to follow its losses of track and their causes (:mod:`pegame.losses`).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import resource
import statistics
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from pegame import registry
from pegame.api import Context, EvaderObservation, PursuerObservation
from pegame.bench_maps import SIZES, format_rows, map_scaling
from pegame.config import compose, resolve_map_path
from pegame.game import Game
from pegame.grid import OccupancyGrid, load_map
from pegame.losses import Loss, LossCauses
from pegame.navigation import Planner
from pegame.types import Belief, Body, Camera, Detection, Plan, Pose, Velocity
from pegame.visibility import MaskRegion, VisibilityRegion, visibility_region

PAPER_MAPS = ("hall", "enclosed", "brick")


def median_ms(fn: Callable[[], Any], repeat: int) -> float:
    """Median wall time of ``fn()`` over ``repeat`` calls, milliseconds."""
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return 1e3 * statistics.median(times)


def machine() -> dict[str, Any]:
    """A description of this machine for the report."""
    cpu = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "platform": platform.platform(),
    }


def free_poses(grid: OccupancyGrid, radius: float, n: int, seed: int = 0) -> list[Pose]:
    """``n`` random poses on cells traversable for a disc of ``radius`` m."""
    rng = np.random.default_rng(seed)
    rows, cols = np.nonzero(Planner.shared(grid, radius).traversable)
    picks = rng.integers(rows.size, size=n)
    poses = []
    for k in picks:
        x, y = grid.cell_to_world(rows[k], cols[k])
        poses.append(Pose(x, y, float(rng.uniform(-math.pi, math.pi))))
    return poses


def bench_visibility(grid: OccupancyGrid, repeat: int) -> float:
    poses = iter(free_poses(grid, 0.2, repeat + 1) * 2)
    camera = Camera()
    return median_ms(lambda: visibility_region(grid, next(poses), camera), repeat)


def bench_planner(grid: OccupancyGrid, repeat: int) -> tuple[float, float]:
    """(distance field ms, start-to-goal plan ms) for the pursuer's planner."""
    planner = Planner(grid, 0.2)
    starts = iter(free_poses(grid, 0.2, 2 * repeat + 2, seed=1) * 2)
    field_ms = median_ms(lambda: planner.distance_field(next(starts).xy), repeat)
    plan_ms = median_ms(lambda: planner.plan(next(starts).xy, next(starts).xy), repeat)
    return field_ms, plan_ms


def bench_sim_steps(grid: OccupancyGrid, steps: int) -> float:
    """Grid-simulator control steps per second (both agents moving)."""
    from pegame.sims.grid import GridSimulator
    from pegame.types import Velocity

    context = Context(grid, Body(0.2, 0.5, 1.8), Body(0.25, 0.5, 1.8), Camera(), 0.1, 1.0)
    sim = GridSimulator(GridSimulator.Config(), context, np.random.default_rng(0))
    p, e = free_poses(grid, 0.25, 2, seed=2)
    sim.reset((p,), (e,))
    cmds = (Velocity(0.4, 0.3),)
    start = time.perf_counter()
    for _ in range(steps):
        sim.step(cmds, cmds, 0.1)
    return steps / (time.perf_counter() - start)


def game_seconds(overrides: list[str], out_dir: str) -> float:
    """Wall-clock time (s) of playing one game (not building it)."""
    return game_times(overrides, out_dir)[0]


def game_times(overrides: list[str], out_dir: str) -> tuple[float, float]:
    """(wall-clock time, CPU time of this process) (s) of playing one game (not building
    it). The CPU time leaves out what other processes take of the machine and counts
    every thread of this one (rerun-sdk's own threads take a few ms of a recorded game)."""
    game = Game(compose(overrides))
    start, cpu = time.perf_counter(), time.process_time()
    game.play(out_dir)
    return time.perf_counter() - start, time.process_time() - cpu


def games_per_second(overrides: list[str], games: int, out_dir: str) -> float:
    """Whole games per second (median game time), recorder as the overrides say."""
    times = [game_seconds([*overrides, f"game.seed={seed}"], out_dir) for seed in range(games)]
    return 1.0 / statistics.median(times)


#: the team sizes (N pursuers, M evaders) whose game cost the bench reports
TEAM_SIZES = ((1, 1), (2, 1), (3, 1), (4, 1), (2, 2), (3, 2))


def team_scaling(games: int, out_dir: str, t_max: float = 90.0) -> dict[str, float]:
    """Seconds per game of S-S teams on the enclosed map, by 'NvM' (N smart pursuers
    against M smart evaders, median over ``games`` seeds): how a game's cost grows with
    the team (one visibility region per pursuer and a detector per pair every tick, one
    estimator and one evader decision per evader)."""
    base = ["recorder=none", "env=enclosed", f"game.t_max={t_max}"]
    return {
        f"{n}v{m}": statistics.median(
            game_seconds(
                [*base, f"team.pursuers={n}", f"team.evaders={m}", f"game.seed={seed}"], out_dir
            )
            for seed in range(games)
        )
        for n, m in TEAM_SIZES
    }


def bench_decisions(
    grid: OccupancyGrid, repeat: int, pursuer_name: str = "smart", evader_name: str = "smart"
) -> dict[str, float | None]:
    """ms per decision of a pursuer (estimator update + plan, the evader not detected) and
    an evader, by default the smart ones."""
    out: dict[str, float | None] = {
        "pursuer_decision_ms": None,
        "evader_decision_ms": None,
        "pf_step_ms": None,
    }
    camera = Camera()
    context = Context(grid, Body(0.2, 0.5, 1.8), Body(0.25, 0.5, 1.8), camera, 0.1, 1.0)
    poses = free_poses(grid, 0.25, 2 * repeat + 2, seed=3)
    pairs = list(zip(poses[::2], poses[1::2]))
    if "particle_filter" in registry.available("estimator"):
        cls = registry.load("estimator", "particle_filter")
        pf = cls(registry.make_config("estimator", cls, {}), context, np.random.default_rng(0))
        p0 = pairs[0][0]
        pf.reset((p0,), (None,), VisibilityRegion(grid, p0, camera))
        # Regions computed beforehand: the step is timed without its visibility region.
        masks = [MaskRegion(visibility_region(grid, p, camera)) for p, _ in pairs]
        it = iter(list(zip(pairs, masks)) * 2)

        def pf_step() -> Belief:
            (p, _), mask = next(it)
            return pf.update(0.1, (p,), (None,), mask)

        out["pf_step_ms"] = median_ms(pf_step, repeat)
        if pursuer_name in registry.available("pursuer"):
            pcls = registry.load("pursuer", pursuer_name)
            pursuer = pcls(
                registry.make_config("pursuer", pcls, {}), context, np.random.default_rng(1)
            )
            pursuer.reset(p0)
            it2 = iter(list(zip(pairs, masks)) * 2)

            def pursuer_decision() -> Plan:
                (p, _), mask = next(it2)
                belief = pf.update(0.1, (p,), (None,), mask)
                return pursuer.decide(PursuerObservation(0.0, p, None, belief, mask))

            out["pursuer_decision_ms"] = median_ms(pursuer_decision, repeat)
    if evader_name in registry.available("evader"):
        ecls = registry.load("evader", evader_name)
        evader = ecls(registry.make_config("evader", ecls, {}), context, np.random.default_rng(2))
        evader.reset(pairs[0][1])
        it3 = iter(pairs * 2)

        def evader_decision() -> Plan:
            p, e = next(it3)
            return evader.decide(EvaderObservation(0.0, e, p))

        out["evader_decision_ms"] = median_ms(evader_decision, repeat)
    return out


def recorder_cost(games: int, out_dir: str) -> dict[str, float | None]:
    """The cost of recording an S-S game with recorder=rerun: ``recorder_overhead``, its
    fractional extra wall-clock time, ``recorder_cpu_overhead``, the same in CPU time of
    the process, and ``rrd_mb_per_game``, the largest .rrd (MB).

    Each seed is played without and then with the recorder, one right after the other,
    and the figures are medians of the per-seed ratios: on a shared machine, neighbouring
    games see the same load. The CPU time varies less with the load than the wall-clock
    time."""
    figures: dict[str, float | None] = dict.fromkeys(
        ("recorder_overhead", "recorder_cpu_overhead", "rrd_mb_per_game")
    )
    if not all("smart" in registry.available(g) for g in ("pursuer", "evader")):
        return figures
    base = ["pursuer=smart", "evader=smart", "env=enclosed"]
    games_per_second(
        [*base, "recorder=rerun"], 1, out_dir
    )  # imports rerun-sdk, compiles the outline kernel
    walls, cpus = [], []
    for seed in range(games):
        # Each game writes into a directory of its own, as a sweep's games write files of
        # their own: replacing an earlier game's 2 MB recording frees its blocks, which
        # cost 1 ms more than the write itself here (ext4 with discard).
        plain, recorded = (
            game_times(
                [*base, f"recorder={recorder}", f"game.seed={seed}"],
                _new_dir(out_dir, f"recorder_{recorder}_{seed}"),
            )
            for recorder in ("none", "rerun")
        )
        walls.append(recorded[0] / plain[0] - 1.0)
        cpus.append(recorded[1] / plain[1] - 1.0)
    sizes = [p.stat().st_size for p in Path(out_dir).glob("recorder_rerun_*/*.rrd")]
    figures["recorder_overhead"] = statistics.median(walls)
    figures["recorder_cpu_overhead"] = statistics.median(cpus)
    figures["rrd_mb_per_game"] = max(sizes) / 2**20 if sizes else None
    return figures


def _new_dir(parent: str, name: str) -> str:
    """``parent/name``, created empty."""
    path = Path(parent) / name
    path.mkdir()
    return str(path)


class _NoLosses(LossCauses):
    """Loss causes that follow nothing: a game's loop without them, for
    :func:`loss_causes_cost`."""

    def add_one(
        self, pursuer: Pose, evader: Pose, detected: bool, command: Velocity
    ) -> tuple[Loss, ...]:
        return ()

    def add(
        self,
        pursuers: Sequence[Pose],
        evaders: Sequence[Pose],
        detections: Sequence[Sequence[Detection | None]],
        commands: Sequence[Velocity],
    ) -> tuple[Loss, ...]:
        return ()


class _TimedLosses(LossCauses):
    """Loss causes that also add up the wall time (s) spent in them, ``seconds``."""

    seconds = 0.0

    def add_one(
        self, pursuer: Pose, evader: Pose, detected: bool, command: Velocity
    ) -> tuple[Loss, ...]:
        start = time.perf_counter()
        losses = super().add_one(pursuer, evader, detected, command)
        self.seconds += time.perf_counter() - start
        return losses

    def add(
        self,
        pursuers: Sequence[Pose],
        evaders: Sequence[Pose],
        detections: Sequence[Sequence[Detection | None]],
        commands: Sequence[Velocity],
    ) -> tuple[Loss, ...]:
        start = time.perf_counter()
        losses = super().add(pursuers, evaders, detections, commands)
        self.seconds += time.perf_counter() - start
        return losses


def ticks_seconds(overrides: list[str], kind: type[LossCauses]) -> tuple[float, LossCauses]:
    """(CPU time (s) of playing every tick of one game, no recorder and no files; the
    game's loss causes), its losses followed by a ``kind``."""
    loop = Game(compose(["recorder=none", *overrides])).start()
    loop.losses = loop.metrics.losses = kind(loop.context, loop.n_pursuers, loop.n_evaders)
    start = time.process_time()
    while not loop.done:
        loop.advance()
    return time.process_time() - start, loop.losses


#: the games whose loss-cause cost the bench reports: the default S-S game, and R-R, the
#: cheapest tick with the most losses
LOSS_GAMES = {
    "S-S": ["pursuer=smart", "evader=smart", "env=enclosed"],
    "R-R": ["pursuer=random", "evader=random", "env=enclosed"],
}


def loss_causes_cost(games: int, t_max: float = 90.0) -> dict[str, dict[str, float]]:
    """Per pairing of :data:`LOSS_GAMES`, a game's fractional extra time for following its
    losses of track and their causes, two ways, each the median over ``games`` seeds
    after a warm-up game: ``paired``, the CPU time of its ticks with them over that
    without them, minus 1 (each seed played both ways one right after the other, in
    alternating order, so that neighbouring runs see the same load); ``inside``, in a
    third run, the wall time spent in :class:`pegame.losses.LossCauses` over the rest of
    the game's ticks (timed call by call: an upper bound, the timer's own cost included,
    and far less noisy than the difference of two games)."""
    cost = {}
    for pairing, overrides in LOSS_GAMES.items():
        ticks_seconds([*overrides, f"game.t_max={min(t_max, 5.0)}"], LossCauses)  # warm-up
        paired, inside = [], []
        for seed in range(games):
            game = [*overrides, f"game.seed={seed}", f"game.t_max={t_max}"]
            order = (_NoLosses, LossCauses) if seed % 2 == 0 else (LossCauses, _NoLosses)
            runs = {kind: ticks_seconds(game, kind)[0] for kind in order}
            paired.append(runs[LossCauses] / runs[_NoLosses] - 1.0)
            played, timed = ticks_seconds(game, _TimedLosses)
            assert isinstance(timed, _TimedLosses)  # the run of that kind
            inside.append(timed.seconds / (played - timed.seconds))
        cost[pairing] = {"paired": statistics.median(paired), "inside": statistics.median(inside)}
    return cost


def env_steps_per_second(seconds: float) -> float | None:
    """PettingZoo env steps per second with random actions (null without pettingzoo)."""
    try:
        from pegame.envs import bench_steps_per_second
    except ImportError:
        return None
    return bench_steps_per_second(seconds=seconds)["steps_per_s"]


def plugin_figures(quick: bool) -> dict[str, float | None]:
    """The 3D plugins' figures: pybullet real-time factor of a 90 s S-S game (camera at
    10 Hz, the default 320x240 pitched pi/8 down), the vision (colour) and person (HOG)
    detectors' precision and recall against segmentation and the person detector's median
    latency per frame, both with a level camera (at pi/8 a person within 4 m never shows
    30 % of its body, so no frame would count); null when the plugins are not installed."""
    figures: dict[str, float | None] = dict.fromkeys(
        (
            "pybullet_rtf",
            "vision_precision",
            "vision_recall",
            "person_precision",
            "person_recall",
            "person_latency_ms",
        )
    )
    try:
        from pegame_pybullet.bench import rtf
    except ImportError:
        return figures
    figures["pybullet_rtf"] = rtf(t_max=30.0 if quick else 90.0)["rtf"]
    try:
        from pegame_vision.evaluate import evaluate
    except ImportError:
        return figures
    for detector in ("vision", "person"):
        scores = evaluate(
            seeds=range(1) if quick else range(3),
            t_max=30.0 if quick else 60.0,
            overrides=("sim.camera_tilt=0",),
            detector=detector,
        )
        for key in ("precision", "recall", "latency_ms"):
            if f"{detector}_{key}" in figures:
                figures[f"{detector}_{key}"] = scores[f"{detector}_{key}"]
    return figures


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = argparse.ArgumentParser(
        prog="python -m pegame.bench", description=__doc__.splitlines()[0]
    )
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--quick", action="store_true", help="fewer repetitions (under a minute)")
    parser.add_argument(
        "--map-sizes",
        type=int,
        nargs="+",
        metavar="CELLS",
        help=f"map sizes (cells a side) of the scaling table; default {' '.join(map(str, SIZES))}, "
        "with --quick 400 1000 and no whole games",
    )
    args = parser.parse_args(argv)
    repeat, games = (20, 2) if args.quick else (200, 5)

    report: dict[str, Any] = {"machine": machine()}
    grids = {name: load_map(resolve_map_path(f"{name}.yaml")) for name in PAPER_MAPS}
    start = time.perf_counter()
    bench_visibility(grids["hall"], 1)
    Planner(grids["hall"], 0.2).plan(*[p.xy for p in free_poses(grids["hall"], 0.2, 2)])
    report["jit_warmup_s"] = time.perf_counter() - start

    per_map: dict[str, dict[str, Any]] = {}
    for name, grid in grids.items():
        field_ms, plan_ms = bench_planner(grid, repeat)
        per_map[name] = {
            "cells": [grid.height, grid.width],
            "visibility_ms": bench_visibility(grid, repeat),
            "distance_field_ms": field_ms,
            "plan_ms": plan_ms,
            **bench_decisions(grid, max(10, repeat // 4)),
        }
        stronger = bench_decisions(grid, max(10, repeat // 4), "anticipating", "elusive")
        per_map[name]["anticipating_decision_ms"] = stronger["pursuer_decision_ms"]
        per_map[name]["elusive_decision_ms"] = stronger["evader_decision_ms"]
    report["maps"] = per_map
    report["sim_steps_per_s"] = bench_sim_steps(grids["enclosed"], 2000 if args.quick else 20000)

    with tempfile.TemporaryDirectory() as tmp:
        rr = ["pursuer=random", "evader=random", "recorder=none", "env=enclosed"]
        report["rr_games_per_s"] = games_per_second(rr, games, tmp)
        smart = all("smart" in registry.available(g) for g in ("pursuer", "evader"))
        for name, row in per_map.items():
            ss = ["pursuer=smart", "evader=smart", "recorder=none", f"env={name}"]
            row["ss_games_per_s"] = games_per_second(ss, games, tmp) if smart else None
        report.update(recorder_cost(3 * games, tmp))
        report["team_game_s"] = team_scaling(games, tmp, 30.0 if args.quick else 90.0)
    report["loss_causes_overhead"] = loss_causes_cost(3 * games)
    for key in ("visibility_ms", "distance_field_ms", "plan_ms", "pf_step_ms"):
        values = [m[key] for m in per_map.values() if m.get(key) is not None]
        report[key] = max(values) if values else None  # the worst paper map
    rates = [m["ss_games_per_s"] for m in per_map.values() if m.get("ss_games_per_s") is not None]
    report["ss_games_per_s"] = min(rates) if rates else None  # the slowest paper map
    quick_sizes = (400, 1000) if args.quick else SIZES
    report["map_scaling"] = map_scaling(
        args.map_sizes or quick_sizes, repeat=max(5, repeat // 10), game=not args.quick
    )
    report["env_steps_per_s"] = env_steps_per_second(2 if args.quick else 10)
    from pegame.envs.bench import vector_env_figures  # the env packages load on first use

    report.update(vector_env_figures(args.quick))
    report.update(plugin_figures(args.quick))
    report["peak_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024

    if args.json:
        print(json.dumps(report, indent=2))
    else:
        print(format_report(report))
    return report


def fmt(value: float | None) -> str:
    """A figure with two decimals, or '-' when it was not measured."""
    return "-" if value is None else f"{value:.2f}"


def format_report(report: dict[str, Any]) -> str:
    """The report as aligned text lines."""
    m = report["machine"]
    lines = [f"machine: {m['cpu']}, {m['cores']} cores, Python {m['python']}, numpy {m['numpy']}"]
    lines.append(f"jit warm-up (first calls): {report['jit_warmup_s']:.2f} s")
    lines.append(
        f"{'map':<10}{'cells':>10}{'visib ms':>10}{'field ms':>10}{'plan ms':>9}"
        f"{'pf ms':>8}{'P dec ms':>10}{'E dec ms':>10}{'S-S games/s':>13}"
    )
    for name, row in report["maps"].items():
        cells = "x".join(map(str, row["cells"]))
        lines.append(
            f"{name:<10}{cells:>10}{fmt(row['visibility_ms']):>10}{fmt(row['distance_field_ms']):>10}"
            f"{fmt(row['plan_ms']):>9}{fmt(row.get('pf_step_ms')):>8}"
            f"{fmt(row.get('pursuer_decision_ms')):>10}{fmt(row.get('evader_decision_ms')):>10}"
            f"{fmt(row.get('ss_games_per_s')):>13}"
        )
    stronger = ", ".join(
        f"{name} {fmt(row.get('anticipating_decision_ms'))} / {fmt(row.get('elusive_decision_ms'))}"
        for name, row in report["maps"].items()
    )
    lines.append(f"anticipating pursuer / elusive evader decision ms: {stronger or '-'}")
    lines.append(f"grid sim: {report['sim_steps_per_s']:.0f} control steps/s")
    lines.append(
        f"90 s games/s (one core): R-R {fmt(report['rr_games_per_s'])} (enclosed), "
        f"S-S {fmt(report['ss_games_per_s'])} (the slowest paper map)"
    )
    overhead, cpu = report["recorder_overhead"], report.get("recorder_cpu_overhead")
    lines.append(
        f"recorder: +{fmt(None if overhead is None else 100 * overhead)}% game time "
        f"(+{fmt(None if cpu is None else 100 * cpu)}% CPU time), "
        f"{fmt(report['rrd_mb_per_game'])} MB per 90 s game"
    )
    losses = report.get("loss_causes_overhead") or {}
    if losses:
        costs = ", ".join(
            f"{k} +{100 * v['inside']:.2f}% (paired games {100 * v['paired']:+.1f}%)"
            for k, v in losses.items()
        )
        lines.append(f"loss causes, extra game time (median, enclosed): {costs}")
    teams = report.get("team_game_s") or {}
    if teams:
        one = teams.get("1v1") or 1.0
        scaled = ", ".join(f"{k} {v:.2f} s (x{v / one:.1f})" for k, v in teams.items())
        lines.append(f"team games on enclosed (S-S, s per game): {scaled}")
    lines.append(f"env steps/s (PettingZoo, random actions): {fmt(report['env_steps_per_s'])}")
    from pegame.envs.bench import format_vector

    lines.append(format_vector(report))
    lines.append(
        f"pybullet S-S real-time factor: {fmt(report['pybullet_rtf'])}; vision vs segmentation: "
        f"precision {fmt(report['vision_precision'])}, recall {fmt(report['vision_recall'])}; "
        f"person: precision {fmt(report['person_precision'])}, recall "
        f"{fmt(report['person_recall'])}, {fmt(report['person_latency_ms'])} ms per frame"
    )
    lines.extend(format_rows(report["map_scaling"]))
    return "\n".join(lines)


if __name__ == "__main__":
    main()
