"""What recorder options cost: paired games with and without the Rerun recorder.

    python docs/performance/recorder_options.py [--seeds 12] \
        "recorder.particles_every=1 recorder.max_particles=100 recorder.outline_rays=64" ...

For each seed, plays the 90 s S-S game on enclosed with ``recorder=none``, with
``recorder=rerun`` at its defaults, and with ``recorder=rerun`` plus each quoted set of
overrides, one right after the other, each game writing into a directory of its own (as
:func:`pegame.bench.recorder_cost` does), and prints per variant the median over the seeds
of the extra wall-clock and CPU time (of the process) over the unrecorded game: the
bench's ``recorder_overhead`` and ``recorder_cpu_overhead`` for those options. Single runs
move by about 0.015 on a quiet 2-core machine; compare variants measured in one run.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile

from pegame.bench import game_times

BASE = ["pursuer=smart", "evader=smart", "env=enclosed"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, default=12)
    parser.add_argument("variants", nargs="*", help="a quoted set of recorder overrides each")
    args = parser.parse_args()
    variants = {"none": ["recorder=none"], "defaults": ["recorder=rerun"]}
    variants.update({text: ["recorder=rerun", *text.split()] for text in args.variants})
    ratios: dict[str, list[tuple[float, float]]] = {name: [] for name in variants}
    with tempfile.TemporaryDirectory() as scratch:
        game_times([*BASE, "recorder=rerun"], f"{scratch}/warm-up")  # imports and compiles
        for seed in range(args.seeds):
            times = {
                name: game_times([*BASE, *overrides, f"game.seed={seed}"], f"{scratch}/{k}_{seed}")
                for k, (name, overrides) in enumerate(variants.items())
            }
            plain = times["none"]
            for name, (wall, cpu) in times.items():
                ratios[name].append((wall / plain[0] - 1.0, cpu / plain[1] - 1.0))
    for name, values in ratios.items():
        if name != "none":
            wall = statistics.median(w for w, _ in values)
            cpu = statistics.median(c for _, c in values)
            print(f"{name}: recorder_overhead {wall:.3f}, recorder_cpu_overhead {cpu:.3f}")


if __name__ == "__main__":
    main()
