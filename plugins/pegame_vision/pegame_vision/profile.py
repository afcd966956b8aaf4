"""The detection profile of a 3D detector, measured on played games (system identification).

``python -m pegame_vision.profile [--detector person] [--envs enclosed hall brick]
[--seeds 2] [--first-seed 0] [--t-max 60] [--match iou] [--out DIR] [overrides]`` plays S-S games in PyBullet driven by
``detector=segmentation`` with the detector under test judged beside it
(:func:`pegame_vision.evaluate.judged_game`), and measures on every frame on which the
reference sees the evader how often the detector finds it (``--match iou``: box IoU >= 0.5
with the reference's; ``--match any``: it reports a detection at all, which is what a game
counts, the world holding one person), as a function of

- ``range``: the evader's horizontal distance from the camera (m);
- ``bearing``: the absolute angle between the camera's heading and the evader (rad);
- ``visible``: the fraction of its body in view
  (:meth:`pegame_pybullet.sim.PybulletSimulator.evader_visible_fraction`);
- ``lateral_speed``: the evader's speed across the line of sight relative to the pursuer
  (m/s), from its true poses one frame apart,

each on its own (marginal tables), with the number of frames per bin; and, on frames on
which the reference sees nothing, how often the detector reports something (false
detections per frame), its median position error (m), that error split along the line of
sight (mean, signed: positive beyond the evader's centre, and std; m) and across it (std,
m), and its CPU time per frame (ms). Every number comes from the 3D games alone. Writes
``<detector>.csv`` (columns ``variable,low,high,frames,p_detect``; the false detection
rate, the position error and the CPU time as rows of variable ``false_detection``,
``position_error_m``, ``error_along_mean_m``, ``error_along_std_m``, ``error_across_std_m``
and ``cpu_ms``), ``<detector>.md`` (the tables and the command and commit that made them)
and ``<detector>_frames.csv`` (one row per frame: env, seed, the four variables, seen,
found (IoU) and reported; what :mod:`pegame.detectors.profile` is checked against on
held-out seeds,
``--first-seed``) into ``--out``.
"""

from __future__ import annotations

import argparse
import math
import subprocess
import sys
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from pegame.files import write_atomic
from pegame.types import Pose
from pegame_vision.evaluate import iou, judged_game

#: bin edges per variable
EDGES: dict[str, tuple[float, ...]] = {
    "range": (0.0, 1.0, 2.0, 3.0, 4.0, 5.0),
    # beyond pi/6, half the paper's FOV, the evader's centre is out of view, not its body
    "bearing": (0.0, 0.1, 0.2, 0.3, 0.4, math.pi / 6, 1.0),
    "visible": (0.0, 0.1, 0.3, 0.6, 1.0001),
    "lateral_speed": (0.0, 0.1, 0.3, 0.6, 10.0),
}
IOU = 0.5  # box overlap for a detection to be the evader


def frames(
    detector: str,
    envs: Iterable[str],
    seeds: Iterable[int],
    t_max: float,
    overrides: Sequence[str],
    cpu: list[float],
) -> list[dict[str, Any]]:
    """One record per new frame of every game: the variables, whether the reference saw the
    evader (``seen``), whether the detector found it (``found``) or reported something
    (``reported``), and the found detection's position error (m); the detector's CPU time
    per frame (s) is appended to ``cpu``."""
    records: list[dict[str, Any]] = []
    for env in envs:
        for seed in seeds:
            judge = judged_game(
                env, seed, t_max, detector, overrides=overrides, measure_visible=True
            )
            cpu.extend(judge.cpu)
            last: tuple[float, Pose, Pose] | None = None
            for (_, truth, seen, evader), (time, camera, visible) in zip(judge.rows, judge.views):
                if last is not None and time == last[0]:
                    continue  # the simulator's last frame again
                dx, dy = evader.x - camera.x, evader.y - camera.y
                distance = math.hypot(dx, dy)
                lateral = float("nan")
                if last is not None and distance > 1e-9:
                    before, pursuer, was = last
                    # the evader's velocity relative to the camera, across the line of sight
                    rvx = (dx - (was.x - pursuer.x)) / (time - before)
                    rvy = (dy - (was.y - pursuer.y)) / (time - before)
                    lateral = abs(rvx * dy - rvy * dx) / distance
                bearing = abs(math.remainder(math.atan2(dy, dx) - camera.theta, math.tau))
                found = seen is not None and truth is not None and iou(truth.box, seen.box) >= IOU
                error = along = across = None
                if seen is not None and truth is not None:  # the error of any detection
                    ex, ey = seen.position[0] - evader.x, seen.position[1] - evader.y
                    error = math.hypot(ex, ey)
                    if distance > 1e-9:  # the error in the line of sight's frame
                        along = (ex * dx + ey * dy) / distance
                        across = (ey * dx - ex * dy) / distance
                records.append(
                    {
                        "env": env,
                        "seed": seed,
                        "range": distance,
                        "bearing": bearing,
                        "visible": visible,
                        "lateral_speed": lateral,
                        "seen": truth is not None,
                        "found": found,
                        "reported": seen is not None,
                        "error": error,
                        "along": along,
                        "across": across,
                    }
                )
                last = (time, camera, evader)
    return records


def profile_rows(
    records: list[dict[str, Any]], cpu: list[float], hit: str = "found"
) -> list[tuple[Any, ...]]:
    """(variable, low, high, frames, value) rows: per variable and bin, the frames on which
    the reference saw the evader and the fraction of them that are a ``hit`` (``found``: IoU
    matched; ``reported``: any detection); then the false detections per frame the
    reference saw nothing on, the median position error (m) of the hits, the mean and std
    of its component along the line of sight and the std across it (m), and the median CPU
    time per frame (ms), each over all frames (low and high empty)."""
    rows: list[tuple[Any, ...]] = []
    seen = [r for r in records if r["seen"]]
    hits = [r for r in seen if r[hit]]
    for variable, edges in EDGES.items():
        for low, high in zip(edges[:-1], edges[1:]):
            inside = [r[hit] for r in seen if r[variable] is not None and low <= r[variable] < high]
            rows.append(
                (variable, low, high, len(inside), float(np.mean(inside)) if inside else None)
            )
    empty = [r["reported"] for r in records if not r["seen"]]
    errors = [r["error"] for r in hits if r["error"] is not None]
    rows.append(("false_detection", "", "", len(empty), float(np.mean(empty)) if empty else None))
    rows.append(
        ("position_error_m", "", "", len(errors), float(np.median(errors)) if errors else None)
    )
    along = [r["along"] for r in hits if r["along"] is not None]
    across = [r["across"] for r in hits if r["across"] is not None]
    for name, values, statistic in (
        ("error_along_mean_m", along, np.mean),
        ("error_along_std_m", along, np.std),
        ("error_across_std_m", across, np.std),
    ):
        rows.append((name, "", "", len(values), float(statistic(values)) if values else None))
    rows.append(("cpu_ms", "", "", len(cpu), 1e3 * float(np.median(cpu)) if cpu else None))
    return rows


def _cell(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)


def main(argv: list[str] | None = None) -> Path:
    parser = argparse.ArgumentParser(
        prog="python -m pegame_vision.profile", description=__doc__.splitlines()[0]
    )
    parser.add_argument(
        "--detector", default="person", help="the detector under test (person, vision)"
    )
    parser.add_argument("--envs", nargs="+", default=["enclosed", "hall", "brick"])
    parser.add_argument("--seeds", type=int, default=2, help="games per map")
    parser.add_argument("--first-seed", type=int, default=0, help="seeds first..first+N-1")
    parser.add_argument("--t-max", type=float, default=60.0, help="s per game")
    parser.add_argument(
        "--match", choices=("iou", "any"), default="iou", help="a hit: IoU >= 0.5, or any detection"
    )
    parser.add_argument("--out", type=Path, default=Path("."), help="directory of the profile")
    parser.add_argument(
        "overrides", nargs="*", help="game config overrides, e.g. sim.camera_tilt=0"
    )
    args = parser.parse_args(argv)
    try:  # the commit the games are played at (read first: others may commit meanwhile)
        commit = subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, check=True
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        commit = "unknown"
    cpu: list[float] = []
    seeds = range(args.first_seed, args.first_seed + args.seeds)
    records = frames(args.detector, args.envs, seeds, args.t_max, args.overrides, cpu)
    rows = profile_rows(records, cpu, "found" if args.match == "iou" else "reported")
    csv = "variable,low,high,frames,p_detect\n" + "".join(
        ",".join(_cell(v) for v in row) + "\n" for row in rows
    )
    command = " ".join(
        ["python -m pegame_vision.profile", *(sys.argv[1:] if argv is None else argv)]
    )
    table = "\n".join(
        ["| variable | low | high | frames | p_detect |", "|---|---|---|---|---|"]
        + ["| " + " | ".join(_cell(v) for v in row) + " |" for row in rows]
    )
    text = (
        f"# Detection profile of detector={args.detector}\n\n"
        f"Made by `{command}` at commit {commit}: {len(records)} frames of S-S games on "
        f"{', '.join(args.envs)}, seeds {seeds[0]}-{seeds[-1]}, {args.t_max:g} s each, overrides "
        f"{args.overrides or 'none'}; from the 3D games alone (`pegame_vision.profile`'s "
        "docstring says how each number is measured).\n\n" + table + "\n"
    )
    args.out.mkdir(parents=True, exist_ok=True)
    write_atomic(args.out / f"{args.detector}.csv", csv)
    write_atomic(args.out / f"{args.detector}.md", text)
    columns = ("env", "seed", *EDGES, "seen", "found", "reported")
    write_atomic(
        args.out / f"{args.detector}_frames.csv",
        ",".join(columns)
        + "\n"
        + "".join(",".join(_cell(r[c]) for c in columns) + "\n" for r in records),
    )
    return args.out


if __name__ == "__main__":
    main()
