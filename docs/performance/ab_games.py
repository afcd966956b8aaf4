"""Whole-game speed of two pegame checkouts, A/B: the figures of README's "This release".

    python docs/performance/ab_games.py --seeds 12 --reps 4 --maps enclosed,hall,brick \
        base=/path/to/old/python:/path/to/old/checkout  main=python:.

Each side is NAME=PYTHON:CHECKOUT (the checkout's directory is put first on PYTHONPATH,
so PYTHON needs pegame's dependencies and, for the entry points, pegame installed from a
checkout with the same plugin names). One worker process per side plays 90 s games with
the default (S-S) config and recorder=none; the workers alternate game by game, in a
rotating order, so that the machine's other load hits both alike. Per (map, seed) the
best CPU time (``time.process_time``) of ``--reps`` plays is kept; the report gives, per
map, each side's sum over seeds and its ratio to the first side, and the median of the
per-seed ratios. ``--env`` times PettingZoo episodes (both agents learners, uniformly random
actions, 900 steps) instead of games. The sides must play the same games: seeds whose tracking rates differ
are reported. ``--csv PATH`` writes every play.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time


def worker() -> None:
    """Read 'MAP SEED' lines; answer 'CPU_SECONDS TRACKING_RATE' per game."""
    from pegame.config import compose
    from pegame.game import Game

    for env in ("enclosed", "hall"):  # warm up: numba caches, map loads
        Game(compose(["recorder=none", f"env={env}", "game.seed=999", "game.t_max=5"])).play(".")
    print("ready", flush=True)
    for line in sys.stdin:
        env, seed = line.split()
        game = Game(compose(["recorder=none", f"env={env}", f"game.seed={seed}"]))
        start = time.process_time()
        rate = game.play(".").result["tracking_rate"]
        print(f"{time.process_time() - start:.6f} {rate}", flush=True)


def env_worker() -> None:
    """Read 'MAP SEED' lines; answer 'CPU_SECONDS TRACKING_RATE' per PettingZoo episode:
    both agents learners with uniformly random actions (the bench's env_steps_per_s)."""
    import numpy as np

    from pegame.envs.parallel import parallel_env

    envs = {m: parallel_env(overrides=(f"env={m}",)) for m in ("enclosed", "hall", "brick")}

    def episode(env, seed: int) -> float:
        env.reset(seed=seed)
        actions = np.random.default_rng(seed).uniform(-1.0, 1.0, (900, 2, 2)).astype(np.float32)
        for pair in actions:
            _, _, _, _, infos = env.step({"pursuer": pair[0], "evader": pair[1]})
            if not env.agents:
                break
        return infos["pursuer"]["tracking_rate"]

    for env in envs.values():  # warm up
        episode(env, 999)
    print("ready", flush=True)
    for line in sys.stdin:
        env, seed = line.split()
        start = time.process_time()
        rate = episode(envs[env], int(seed))
        print(f"{time.process_time() - start:.6f} {rate}", flush=True)


def start_workers(sides: list[str], script: str, flag: str) -> dict[str, subprocess.Popen]:
    """One worker process per NAME=PYTHON:CHECKOUT side, running ``script flag`` with the
    checkout first on PYTHONPATH, each ready (it has printed "ready"), by name."""
    workers = {}
    for side in sides:
        name, spec = side.split("=", 1)
        python, checkout = spec.split(":", 1)
        workers[name] = subprocess.Popen(
            [python, os.path.abspath(script), flag],
            cwd=os.environ.get("TMPDIR", "/tmp"),
            env={**os.environ, "PYTHONPATH": os.path.abspath(checkout)},
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )
    for name, process in workers.items():
        if process.stdout.readline().strip() != "ready":
            sys.exit(f"worker {name} did not start")
    return workers


def in_turn(workers: dict[str, subprocess.Popen], turn: int, env: str, seed: int):
    """Each worker's answer line for (``env``, ``seed``), by name, the workers asked one at
    a time in a rotating order that starts at the ``turn``-th (mod their number)."""
    names = list(workers)
    turn %= len(names)
    for name in names[turn:] + names[:turn]:
        process = workers[name]
        process.stdin.write(f"{env} {seed}\n")
        process.stdin.flush()
        yield name, process.stdout.readline()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sides", nargs="+", help="NAME=PYTHON:CHECKOUT, the first is the reference")
    parser.add_argument("--seeds", type=int, default=12, help="play seeds 0 to SEEDS - 1")
    parser.add_argument("--seed-list", help="comma-separated seeds to play instead of --seeds")
    parser.add_argument("--reps", type=int, default=4)
    parser.add_argument("--maps", default="enclosed,hall,brick")
    parser.add_argument("--csv", help="also write every game's map, seed, side, rep, seconds")
    parser.add_argument(
        "--env", action="store_true", help="time PettingZoo episodes of random actions instead"
    )
    args = parser.parse_args()
    maps = args.maps.split(",")
    seeds = [int(s) for s in args.seed_list.split(",")] if args.seed_list else range(args.seeds)
    flag = "--env-worker" if args.env else "--worker"
    workers = start_workers(args.sides, __file__, flag)
    names = list(workers)
    best: dict[str, dict[str, dict[int, float]]] = {n: {m: {} for m in maps} for n in names}
    rows = []
    for env in maps:
        for seed in seeds:
            for rep in range(args.reps):
                for name, line in in_turn(workers, seed + rep, env, seed):
                    seconds, rate = line.split()
                    seconds = float(seconds)
                    rows.append((env, seed, name, rep, seconds, rate))
                    kept = best[name][env]
                    kept[seed] = min(kept.get(seed, float("inf")), seconds)
    for process in workers.values():
        process.stdin.close()
    rates = {(env, seed, name): rate for env, seed, name, _, _, rate in rows}
    differ = sorted({(e, s) for e, s, n in rates if rates[(e, s, n)] != rates[(e, s, names[0])]})
    if differ:
        print(f"the sides played different games (tracking rates differ): {differ}", flush=True)
    if args.csv:
        with open(args.csv, "w", encoding="utf-8") as out:
            out.write("map,seed,side,rep,cpu_seconds,tracking_rate\n")
            out.writelines(",".join(map(str, row)) + "\n" for row in rows)
    reference = names[0]
    for env in maps:
        base = best[reference][env]
        parts = [env]
        for name in names:
            total = sum(best[name][env].values())
            median = statistics.median(best[name][env][s] / base[s] for s in base)
            parts.append(
                f"{name} {total:.3f} s ratio {total / sum(base.values()):.3f} "
                f"(median per-seed {median:.3f})"
            )
        print(" | ".join(parts), flush=True)


if __name__ == "__main__":
    if sys.argv[1:] == ["--worker"]:
        worker()
    elif sys.argv[1:] == ["--env-worker"]:
        env_worker()
    else:
        main()
