"""Where a step of pegame's batched env spends its time, per game, at the side-by-side's
sizes (``vmas_side_by_side.py``): the tick kernel (:func:`pegame.vector.kernels.play`:
the move, the ray-cast detection, the tally), the observation
(``BatchedGame.observations``: the pose features and the 32 x 32 map crop, a new array)
and the rest of ``env.step`` (the actions' checks, the infos), in CPU time on one numba
thread, the random evader's env on a paper map.

    python docs/performance/vmas_profile.py   # writes vmas_profile.csv; then
    python docs/performance/vmas_side_by_side.py render

No VMAS needed. Rounds alternate over the sizes; each part's figure is the median over
rounds of its CPU time per game and env step (us).
"""

from __future__ import annotations

import argparse
import csv
import os
import statistics
import time
from pathlib import Path

os.environ["NUMBA_NUM_THREADS"] = "1"  # before numba is imported: one core

import numpy as np

HERE = Path(__file__).resolve().parent
CSV = HERE / "vmas_profile.csv"
SIZES = (1, 64, 1024, 4096)
PARTS = ("step", "tick", "observation")


def per_game(call, games: int, repeats: int) -> float:
    """CPU time per game (us) of ``call()``, over ``repeats`` calls."""
    start = time.process_time()
    for _ in range(repeats):
        call()
    return 1e6 * (time.process_time() - start) / (repeats * games)


def parts(env, actions: np.ndarray, playing: np.ndarray) -> dict:
    """The calls timed: a whole env step, the tick kernel, the observation."""
    from pegame.vector import kernels

    game = env.game
    table, role = game.opponent.table, game.opponent.role
    return {
        "step": lambda: env.step(actions),
        "tick": lambda: kernels.play(game.world, game.rules, game.state, playing, 1, table, role),
        "observation": lambda: game.observations("pursuer"),
    }


def profile(map_name: str, rounds: int) -> list[dict]:
    from pegame.envs.vector import vector_env

    envs = {}
    for size in SIZES:
        env = vector_env(
            size, overrides=[f"env={map_name}", "evader.model=action"], opponent="random"
        )
        env.reset(seed=0)
        env.step(np.zeros((size, 2), np.float32))
        envs[size] = env
    rng = np.random.default_rng(0)
    times: dict[tuple[int, str], list[float]] = {}
    for _ in range(rounds):
        for size, env in envs.items():
            game, repeats = env.game, max(10, 4000 // size)
            if game.state.steps.max() + 3 * repeats >= game.rules.ticks:
                env.reset(seed=int(rng.integers(2**31)))
            actions = rng.uniform(-1.0, 1.0, (size, 2)).astype(np.float32)
            calls = parts(env, actions, np.ones(size, np.bool_))
            for part, call in calls.items():
                times.setdefault((size, part), []).append(per_game(call, size, repeats))
    rows = []
    for size in SIZES:
        median = {part: statistics.median(times[size, part]) for part in PARTS}
        rest = median["step"] - median["tick"] - median["observation"]
        rows.append(
            {
                "num_envs": size,
                **{p: round(v, 3) for p, v in median.items()},
                "rest": round(rest, 3),
                "load_1m": round(os.getloadavg()[0], 1),
            }
        )
        print(rows[-1], flush=True)
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--map", default="enclosed", help="pegame's map (default enclosed)")
    parser.add_argument("--rounds", type=int, default=15, help="rounds (default 15)")
    args = parser.parse_args()
    rows = profile(args.map, args.rounds)
    with CSV.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)


if __name__ == "__main__":
    main()
