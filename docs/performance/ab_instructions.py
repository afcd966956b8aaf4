"""The benchmark's workloads A/B by simulated instruction, cache-miss and branch counts.

    python docs/performance/ab_instructions.py --maps hall \
        base=/path/to/old/python:/path/to/old/checkout  main=python:.

On a shared machine a figure's time moves by 30% or more from one minute to the next;
valgrind's callgrind counts what the CPU is asked to do, the same however loaded the
machine is. Each side (NAME=PYTHON:CHECKOUT, as in ``ab_games.py``) runs every workload
in its own process under ``valgrind --tool=callgrind --cache-sim=yes --branch-sim=yes``
with instrumentation off; the worker runs the workload once (numba caches, map loads),
turns instrumentation on (``callgrind_control -i on``), runs it again and turns it off.
The report gives, per workload, each side's instructions (Ir) and callgrind's cycle
estimate ``Ir + 10 (L1 misses + mispredicted branches) + 100 LL misses`` (KCachegrind's
"CEst", with the simulated caches of the machine valgrind runs on), and their ratios to
the first side. The estimate is a model, not a time: ``ab_games.py`` measures time.

Workloads, on each map of ``--maps``: ``visibility`` (Algorithm 1 from 50 poses,
``pegame.bench.bench_visibility``), ``planner`` (20 distance fields and 20 plans,
``bench_planner``), ``plans`` (20 A* plans between free poses, on their own),
``decisions`` (``pegame.bench.bench_decisions`` with 10 repeats, its set-up included);
the decisions on their own, 20 each: ``filter`` (particle filter updates, 2000 particles,
regions given), ``pursuer`` (smart pursuer decisions, each after its filter update),
``evader`` (smart evader decisions); ``sim`` (2000 grid-simulator steps), ``game`` (one
90 s S-S game, seed 0, recorder=none), ``recorded`` (the same game with recorder=rerun:
its Ir less the game's is the recording's), ``env`` (one PettingZoo episode of random
actions, seed 0) and ``vector`` (30 steps of the batched env of 128 games against the
random evader, on one thread, after an unmeasured reset). A side takes about two minutes
a workload; the sides run two at a time (``--jobs``).
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor

WORKLOADS = (
    "visibility",
    "planner",
    "decisions",
    "filter",
    "pursuer",
    "evader",
    "sim",
    "game",
    "recorded",
    "env",
    "vector",
)
#: the counts callgrind prints at exit (``==pid== NAME: count``), by our name
COUNTS = {
    "Ir": r"I\s+refs",
    "I1mr": r"I1\s+misses",
    "LLimr": r"LLi misses",
    "D1mr": r"D1\s+misses",
    "LLdmr": r"LLd misses",
    "Bm": r"Mispredicts",
}


def workload(name: str, map_name: str):
    """A function that runs workload ``name`` on map ``map_name`` once."""
    import numpy as np

    from pegame import bench

    grid = bench.load_map(bench.resolve_map_path(f"{map_name}.yaml"))
    if name == "visibility":
        return lambda: bench.bench_visibility(grid, 50)
    if name == "planner":
        return lambda: bench.bench_planner(grid, 20)
    if name == "plans":
        planner = bench.Planner(grid, 0.2)
        poses = bench.free_poses(grid, 0.2, 40, seed=7)
        return lambda: [planner.plan(a.xy, b.xy) for a, b in zip(poses[::2], poses[1::2])]
    if name == "decisions":
        return lambda: bench.bench_decisions(grid, 10)
    if name in ("filter", "pursuer", "evader"):
        return _decisions(grid, name)
    if name == "sim":
        return lambda: bench.bench_sim_steps(grid, 2000)
    if name in ("game", "recorded"):
        recorder = "rerun" if name == "recorded" else "none"
        overrides = [f"recorder={recorder}", f"env={map_name}", "game.seed=0"]
        out_dir = tempfile.mkdtemp(prefix="pegame-ab-")
        return lambda: bench.Game(bench.compose(overrides)).play(out_dir)
    if name == "env":
        from pegame.envs.parallel import parallel_env

        env = parallel_env(overrides=(f"env={map_name}",))

        def episode() -> None:
            env.reset(seed=0)
            actions = np.random.default_rng(0).uniform(-1.0, 1.0, (900, 2, 2))
            for pair in actions.astype(np.float32):
                env.step({"pursuer": pair[0], "evader": pair[1]})
                if not env.agents:
                    break

        return episode
    if name == "vector":  # the batched env's tick and observations, on one thread
        from pegame.envs.vector import vector_env

        overrides = (f"env={map_name}", "evader.model=action")
        batched = vector_env(128, overrides=overrides, opponent="random")
        steps = np.random.default_rng(0).uniform(-1.0, 1.0, (30, 128, 2)).astype(np.float32)

        batched.reset(seed=0)  # once: a run steps on the same games (30 of 900 steps)

        def batched_steps() -> None:
            for step in steps:
                batched.step(step)

        return batched_steps
    raise ValueError(f"unknown workload {name!r}; allowed: {', '.join(WORKLOADS)}")


def _decisions(grid, name: str):
    """The decisions of ``pegame.bench.bench_decisions`` without its set-up: 20 of
    workload ``name`` ('filter', 'pursuer' or 'evader') from the bench's poses."""
    import numpy as np

    from pegame import bench, registry

    def plugin(kind: str, plugin_name: str, seed: int):
        cls = registry.load(kind, plugin_name)
        config = registry.make_config(kind, cls, {})
        return cls(config, context, np.random.default_rng(seed))

    camera = bench.Camera()
    context = bench.Context(
        grid, bench.Body(0.2, 0.5, 1.8), bench.Body(0.25, 0.5, 1.8), camera, 0.1, 1.0
    )
    poses = bench.free_poses(grid, 0.25, 42, seed=3)
    pairs = list(zip(poses[::2], poses[1::2]))
    given = getattr(bench, "MaskRegion", None) or bench.VisibilityRegion.given  # 95c61d7's
    regions = [given(bench.visibility_region(grid, p, camera)) for p, _ in pairs]
    pf, pursuer, evader = (
        plugin("estimator", "particle_filter", 0),
        plugin("pursuer", "smart", 1),
        plugin("evader", "smart", 2),
    )
    pf.reset((pairs[0][0],), (None,), bench.VisibilityRegion(grid, pairs[0][0], camera))
    pursuer.reset(pairs[0][0])
    evader.reset(pairs[0][1])

    def run() -> None:
        for (p, e), region in zip(pairs, regions):
            if name == "evader":
                evader.decide(bench.EvaderObservation(0.0, e, p))
                continue
            belief = pf.update(0.1, (p,), (None,), region)
            if name == "pursuer":
                pursuer.decide(bench.PursuerObservation(0.0, p, None, belief, region))

    return run


def worker(name: str, map_name: str) -> None:
    """Run the workload once, then again with callgrind's instrumentation on."""
    run = workload(name, map_name)
    run()
    control = ["callgrind_control", "-i"]
    subprocess.run([*control, "on", str(os.getpid())], check=True, capture_output=True)
    run()
    subprocess.run([*control, "off", str(os.getpid())], check=True, capture_output=True)


def counts(side: str, name: str, map_name: str, keep: str | None = None) -> dict[str, int]:
    """callgrind's counts of one side's workload (NAME=PYTHON:CHECKOUT); with ``keep`` a
    directory, its profile is kept there as ``NAME-WORKLOAD-MAP.callgrind`` (per function:
    ``callgrind_annotate``; numba's code has no symbols)."""
    python, checkout = side.split("=", 1)[1].split(":", 1)
    # the interpreter itself (a venv's keeps its venv), not a launcher script such as
    # pyenv's shim, which valgrind would trace instead
    python = subprocess.check_output(
        [python, "-c", "import sys; print(sys.executable)"], text=True
    ).strip()
    with tempfile.TemporaryDirectory() as scratch:
        log = os.path.join(scratch, "valgrind.log")
        subprocess.run(
            [
                "valgrind",
                "--tool=callgrind",
                "--cache-sim=yes",
                "--branch-sim=yes",
                "--instr-atstart=no",
                f"--log-file={log}",
                f"--callgrind-out-file={os.path.join(scratch, 'callgrind.out')}",
                python,
                os.path.abspath(__file__),
                "--worker",
                name,
                map_name,
            ],
            cwd=scratch,
            env={**os.environ, "PYTHONPATH": os.path.abspath(checkout), "PYTHONHASHSEED": "0"},
            check=True,
        )
        text = open(log, encoding="utf-8").read()
        if keep is not None:
            kept = os.path.join(keep, f"{side.split('=')[0]}-{name}-{map_name}.callgrind")
            shutil.copyfile(os.path.join(scratch, "callgrind.out"), kept)
    found = {}
    for key, pattern in COUNTS.items():
        match = re.search(pattern + r":\s+([\d,]+)", text)
        if match is None:
            sys.exit(f"no {key} count in callgrind's log of {side} {name}:\n{text[-2000:]}")
        found[key] = int(match.group(1).replace(",", ""))
    return found


def cycle_estimate(c: dict[str, int]) -> int:
    """KCachegrind's cycle estimate from callgrind's counts."""
    return c["Ir"] + 10 * (c["I1mr"] + c["D1mr"] + c["Bm"]) + 100 * (c["LLimr"] + c["LLdmr"])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sides", nargs="+", help="NAME=PYTHON:CHECKOUT, the first is the reference")
    parser.add_argument("--maps", default="hall")
    parser.add_argument("--workloads", default=",".join(WORKLOADS))
    parser.add_argument("--jobs", type=int, default=2, help="valgrind processes at a time")
    parser.add_argument("--keep", metavar="DIR", help="keep each run's callgrind profile in DIR")
    args = parser.parse_args()
    if args.keep:
        os.makedirs(args.keep, exist_ok=True)
    tasks = [
        (side, name, map_name)
        for map_name in args.maps.split(",")
        for name in args.workloads.split(",")
        for side in args.sides
    ]
    with ThreadPoolExecutor(args.jobs) as pool:
        results = dict(zip(tasks, pool.map(lambda task: counts(*task, args.keep), tasks)))
    reference = args.sides[0]
    for map_name in args.maps.split(","):
        for name in args.workloads.split(","):
            base = results[(reference, name, map_name)]
            parts = [f"{map_name} {name}"]
            for side in args.sides:
                c = results[(side, name, map_name)]
                parts.append(
                    f"{side.split('=')[0]} Ir {c['Ir'] / 1e6:.1f}M ({c['Ir'] / base['Ir']:.3f}) "
                    f"CEst {cycle_estimate(c) / 1e6:.1f}M "
                    f"({cycle_estimate(c) / cycle_estimate(base):.3f})"
                )
            print(" | ".join(parts), flush=True)


if __name__ == "__main__":
    if sys.argv[1:2] == ["--worker"]:
        worker(*sys.argv[2:4])
    else:
        main()
