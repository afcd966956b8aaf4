"""Where a game's time goes, A/B: per plugin call, for two pegame checkouts.

    python docs/performance/ab_components.py --seeds 8 --reps 4 --maps enclosed,hall,brick \
        base=/path/to/old/python:/path/to/old/checkout  main=python:.

Sides as in ``ab_games.py`` (NAME=PYTHON:CHECKOUT, the first the reference). Each worker
wraps the plugin methods a tick calls (``sim.step``, ``sim.sense``, ``detector.detect``,
``estimator.reset``/``update``, each strategy's ``decide``/``control``), the ground-truth
``body_in_view`` and ``TrackingMetrics.add`` in timers (``time.perf_counter_ns``) and plays
90 s S-S games with recorder=none, alternating with the other sides game by game in a
rotating order. Per (map, seed) and component the least time over ``--reps`` plays is
kept; the report gives, per map, each component's mean per control tick (us) on each
side and its difference from the reference. "loop" is the game's time outside the
wrapped calls: the tick loop, observations, ticks, trajectory rows and the visibility
region's constructor (its lazy parts run inside the estimator and the evader). The
timers add the same cost on both sides.
"""

from __future__ import annotations

import argparse
import collections
import importlib
import json
import sys
import time

from ab_games import in_turn, start_workers  # this script's directory is first on sys.path

TICKS = 900  # control ticks of a default game: 90 s at 10 Hz

WRAPPED = {
    "sim": ("step", "sense"),
    "detector": ("detect",),
    "estimator": ("reset", "update"),
    "pursuer": ("decide", "control"),
    "evader": ("decide", "control"),
}


def worker() -> None:
    """Read 'MAP SEED' lines; answer a JSON object of nanoseconds per component."""
    from pegame.config import compose
    from pegame.game import Game
    from pegame.metrics import TrackingMetrics

    spent: collections.Counter = collections.Counter()
    clock = time.perf_counter_ns

    def timed(function, name):
        def call(*args, **kwargs):
            start = clock()
            result = function(*args, **kwargs)
            spent[name] += clock() - start
            return result

        return call

    # The module whose body_in_view the loop calls: pegame.loop, or before it pegame.game.
    loop_module = importlib.import_module("pegame.game")
    try:
        loop_module = importlib.import_module("pegame.loop")
    except ImportError:
        pass
    loop_module.body_in_view = timed(loop_module.body_in_view, "in_view")
    TrackingMetrics.add = timed(TrackingMetrics.add, "metrics")

    def instrumented(overrides: list[str]) -> Game:
        game = Game(compose(["recorder=none", *overrides]))
        for kind, methods in WRAPPED.items():
            plugins = game.plugins  # by kind before GamePlugins, a role per field since
            plugin = plugins[kind] if isinstance(plugins, dict) else getattr(plugins, kind)
            for method in methods:
                setattr(plugin, method, timed(getattr(plugin, method), f"{kind}.{method}"))
        return game

    for env in ("enclosed", "hall"):  # warm up: numba caches, map loads
        instrumented([f"env={env}", "game.seed=999", "game.t_max=5"]).play(".")
    print("ready", flush=True)
    for line in sys.stdin:
        env, seed = line.split()
        game = instrumented([f"env={env}", f"game.seed={seed}"])
        spent.clear()
        start = clock()
        game.play(".")
        spent["total"] = clock() - start
        spent["loop"] = spent["total"] - sum(v for k, v in spent.items() if k != "total")
        print(json.dumps(spent), flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sides", nargs="+", help="NAME=PYTHON:CHECKOUT, the first is the reference")
    parser.add_argument("--seeds", type=int, default=8)
    parser.add_argument("--reps", type=int, default=4)
    parser.add_argument("--maps", default="enclosed,hall,brick")
    args = parser.parse_args()
    workers = start_workers(args.sides, __file__, "--worker")
    names, maps = list(workers), args.maps.split(",")
    least: dict = {name: collections.defaultdict(dict) for name in names}
    for rep in range(args.reps):
        for env in maps:
            for seed in range(args.seeds):
                for name, line in in_turn(workers, rep + seed, env, seed):
                    kept = least[name][(env, seed)]
                    for component, ns in json.loads(line).items():
                        kept[component] = min(kept.get(component, ns), ns)
    for process in workers.values():
        process.stdin.close()
    reference = names[0]
    for env in maps:
        print(env)
        components = sorted({c for n in names for c in least[n][(env, 0)]} - {"total", "loop"})
        for component in [*components, "loop", "total"]:
            per_tick = {
                name: sum(least[name][(env, s)].get(component, 0) for s in range(args.seeds))
                / (args.seeds * TICKS * 1000)
                for name in names
            }
            cells = "  ".join(f"{name} {per_tick[name]:8.2f}" for name in names)
            diffs = " ".join(f"{per_tick[n] - per_tick[reference]:+7.2f}" for n in names[1:])
            print(f"  {component:18s} {cells}  us/tick, difference {diffs}", flush=True)


if __name__ == "__main__":
    worker() if sys.argv[1:] == ["--worker"] else main()
