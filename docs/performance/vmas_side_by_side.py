"""pegame's batched env against VMAS, side by side: env steps per second on one core.

    python -m venv /tmp/vmasvenv
    /tmp/vmasvenv/bin/pip install -r docs/performance/requirements-vmas.txt
    /tmp/vmasvenv/bin/pip install -e ".[rl]"   # pegame and gymnasium, in the same venv
    /tmp/vmasvenv/bin/python docs/performance/vmas_side_by_side.py    # measure, then render
    python docs/performance/vmas_side_by_side.py render    # vmas.md and README from the csv
    python docs/performance/vmas_side_by_side.py --check   # exit 1 if either is stale

VMAS (Bettini et al., "VMAS: A Vectorized Multi-Agent Simulator for Collective Robot
Learning", DARSL 2022; ``vmas`` on PyPI) steps its environments as PyTorch tensors. Its
PyPI ``torch`` is the multi-GB CUDA build, so VMAS stays out of pegame's dependencies and
tests: it lives in a venv of its own with torch's CPU build pinned
(``requirements-vmas.txt``), and only ``measure`` imports it.

One process times every contestant at each size (1, 64, 1024, 4096 environments), on one
core: ``NUMBA_NUM_THREADS=1`` (set here before numba loads) and
``torch.set_num_threads(1)``. The contestants, every agent's actions uniformly random
(drawn before the timed window):

- pegame's batched env (:func:`pegame.envs.vector.vector_env`) on a paper map (``--map``,
  default enclosed: the oracle detector's ray-cast occlusion through the map's walls,
  the map crop in the observation), the learning pursuer against the random evader
  (``evader.model=action``, drawn inside the kernels), with the default observation
  (1032 floats: 8 features and the 32 x 32 map crop) and with a crop of one cell
  (``crop_cells=1``: 9 floats, the size of VMAS's observations); both roles learning
  (``role='both'``); and against the smart evader (its decisions in Python, game by
  game), each round whole decision periods of it (``decide_every`` ticks);
- VMAS ``simple_tag`` 1v1 (one adversary, one good agent) with its 2 landmarks
  (obstacles), and without them (VMAS's cheapest 1v1); VMAS ``discovery`` with one agent
  and its lidar (15 rays, 7 targets).

An env step is one step of one environment: pegame's is one control tick of 0.1 s (one
substep of the grid simulator, detection, observation, reward), VMAS's one step of
its physics (10 substeps in ``simple_tag``, 1 in ``discovery``) with observations
and rewards. Rounds alternate ABAB... (the order reversed every other round) so that the
machine's other load hits every contestant alike; a contestant's steps per round are
fixed after a warm-up call to last about ``--seconds``. pegame's games are reset
between rounds, untimed, when one would end inside the next round (VMAS's never end:
no ``max_steps``). A round is timed in the process's CPU time
(``time.process_time``: every thread's, so a helper thread of torch or numba would count),
which a shared machine's other processes do not stretch as they do wall time; they
still share the caches. The figures are medians over rounds; a ratio is the median of the
same rounds' ratios. The results: ``vmas.csv`` (a row per contestant and size),
``vmas.json`` (provenance: commit, versions, CPU, load before and after, date) and the
page ``vmas.md``; README's table is generated from them (``<!-- generated: vmas -->``).
"""

from __future__ import annotations

import argparse
import csv
import importlib.util
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

os.environ["NUMBA_NUM_THREADS"] = "1"  # before numba is imported: the per-core figure

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
CSV, PROVENANCE, PAGE, README = (
    HERE / "vmas.csv",
    HERE / "vmas.json",
    HERE / "vmas.md",
    ROOT / "README.md",
)
SIZES = (1, 64, 1024, 4096)
#: the contestant whose ratio to each VMAS scenario the tables give
REFERENCE = "pegame, random evader"
#: the same with a crop of one cell: an observation of 9 floats (VMAS's: 6 to 19)
CROPLESS = "pegame, random evader, 1-cell crop"
COLUMNS = (
    "contestant",
    "num_envs",
    "steps_per_s",
    "low",
    "high",
    "rounds",
    "steps_per_round",
    "reference_ratio",
    "cropless_ratio",
)


class Contestant:
    """One env of ``num_envs`` environments stepped in rounds of ``steps`` steps."""

    name: str
    period = 1  # a round's steps are a multiple of this

    def __init__(self, num_envs: int) -> None:
        self.num_envs = num_envs
        self.steps = self.period

    def calibrate(self, seconds: float) -> None:
        """Fix the round's steps so that a round lasts about ``seconds`` (a warm-up)."""
        self.round()  # loads the kernels (numba's cache) or warms torch
        rate = self.round() / self.num_envs
        self.steps = self.period * max(1, round(seconds * rate / self.period))
        self.steps = min(self.steps, self.longest())

    def longest(self) -> int:
        return sys.maxsize

    def round(self) -> float:
        """One round's env steps per second."""
        raise NotImplementedError


class Pegame(Contestant):
    """pegame's batched env of ``role`` against ``opponent`` on ``map``."""

    def __init__(
        self,
        num_envs: int,
        map_name: str,
        role: str,
        opponent: str | None,
        name: str,
        overrides: tuple[str, ...] = (),
        **settings: int,
    ) -> None:
        from pegame.envs.vector import vector_env

        env = vector_env(
            num_envs,
            overrides=[f"env={map_name}", *overrides],
            opponent=opponent,
            role=role,
            **settings,
        )
        game = env.game
        self.name, self.env, self.roles = name, env, game.roles
        self.period = math.lcm(game.rules.decide_every, game.ticks_per_action)
        self.period //= game.ticks_per_action
        self.rng = np.random.default_rng(0)
        self.games = self.played = 0
        super().__init__(num_envs)
        self._reset()

    def longest(self) -> int:
        """Whole periods that fit in one game (a game never ends inside a round)."""
        return self.period * ((self.env.game.steps - 1) // self.period)

    def _reset(self) -> None:
        self.env.reset(seed=self.games * self.num_envs)
        self.games, self.played = self.games + 1, 0

    def round(self) -> float:
        if self.played + self.steps >= self.env.game.steps:
            self._reset()
        draws = self.rng.uniform(-1.0, 1.0, (self.steps, len(self.roles), self.num_envs, 2))
        draws = draws.astype(np.float32)
        single = len(self.roles) == 1
        batches = [b[0] if single else dict(zip(self.roles, b)) for b in draws]
        step = self.env.step
        start = time.process_time()
        for batch in batches:
            step(batch)
        elapsed = time.process_time() - start
        self.played += self.steps
        return self.steps * self.num_envs / elapsed


class Vmas(Contestant):
    """VMAS's ``scenario`` with its keyword arguments ``options``, on the CPU."""

    def __init__(self, num_envs: int, scenario: str, name: str, **options: int) -> None:
        import vmas

        self.name = name
        self.env = vmas.make_env(
            scenario, num_envs=num_envs, device="cpu", continuous_actions=True, seed=0, **options
        )
        self.env.reset()
        super().__init__(num_envs)

    def round(self) -> float:
        env = self.env
        batches = [
            [env.get_random_action(agent) for agent in env.agents] for _ in range(self.steps)
        ]
        start = time.process_time()
        for batch in batches:
            env.step(batch)
        return self.steps * self.num_envs / (time.process_time() - start)


def contestants(num_envs: int, map_name: str) -> list[Contestant]:
    return [
        Pegame(num_envs, map_name, "pursuer", "random", REFERENCE, ("evader.model=action",)),
        Pegame(
            num_envs,
            map_name,
            "pursuer",
            "random",
            CROPLESS,
            ("evader.model=action",),
            crop_cells=1,
        ),
        Pegame(num_envs, map_name, "both", None, "pegame, both learning"),
        Pegame(num_envs, map_name, "pursuer", "smart", "pegame, smart evader"),
        Vmas(num_envs, "simple_tag", "VMAS simple_tag 1v1", num_adversaries=1, num_good_agents=1),
        Vmas(
            num_envs,
            "simple_tag",
            "VMAS simple_tag 1v1, no landmarks",
            num_adversaries=1,
            num_good_agents=1,
            num_landmarks=0,
        ),
        Vmas(num_envs, "discovery", "VMAS discovery, 1 agent", n_agents=1),
    ]


def measure_size(num_envs: int, map_name: str, rounds: int, seconds: float) -> list[dict]:
    """The rows of one size: every contestant over ``rounds`` alternating rounds."""
    field = contestants(num_envs, map_name)
    for contestant in field:
        contestant.calibrate(seconds)
    rates: dict[str, list[float]] = {c.name: [] for c in field}
    for index in range(rounds):
        for contestant in field if index % 2 == 0 else field[::-1]:
            rates[contestant.name].append(contestant.round())
    rows = []
    for contestant in field:
        mine = rates[contestant.name]
        ratios = {
            name: statistics.median(r / m for r, m in zip(rates[name], mine))
            for name in (REFERENCE, CROPLESS)
        }
        rows.append(
            {
                "contestant": contestant.name,
                "num_envs": num_envs,
                "steps_per_s": round(statistics.median(mine)),
                "low": round(min(mine)),
                "high": round(max(mine)),
                "rounds": rounds,
                "steps_per_round": contestant.steps,
                "reference_ratio": round(ratios[REFERENCE], 3),
                "cropless_ratio": round(ratios[CROPLESS], 3),
            }
        )
        print(
            f"{num_envs:5d} {contestant.name:36s} {rows[-1]['steps_per_s']:>10,d} steps/s"
            f" ({rows[-1]['low']:,}-{rows[-1]['high']:,}), {REFERENCE} / it "
            f"{rows[-1]['reference_ratio']:.2f}",
            flush=True,
        )
    return rows


def cpu() -> dict:
    """The CPU's model and whether it has AVX-512 (Linux /proc/cpuinfo)."""
    text = Path("/proc/cpuinfo").read_text() if Path("/proc/cpuinfo").exists() else ""
    lines = dict(line.split(":", 1) for line in text.splitlines() if ":" in line)
    lines = {key.strip(): value.strip() for key, value in lines.items()}
    return {
        "model": lines.get("model name", platform.processor()),
        "avx512": "avx512f" in lines.get("flags", "").split(),
        "cores": os.cpu_count(),
    }


def provenance() -> dict:
    import numba
    import torch
    import vmas

    def git(*args: str) -> str:
        return subprocess.run(
            ["git", *args], cwd=ROOT, capture_output=True, text=True, check=True
        ).stdout.strip()

    return {
        "commit": git("rev-parse", "HEAD")[:12],
        "pegame_dirty": bool(git("status", "--porcelain", "--untracked-files=no", "--", "pegame")),
        "date": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "python": platform.python_version(),
        "torch": torch.__version__,
        "vmas": vmas.__version__,
        "numba": numba.__version__,
        "numpy": np.__version__,
        "cpu": cpu(),
        "torch_threads": torch.get_num_threads(),
        "numba_threads": numba.config.NUMBA_NUM_THREADS,
    }


def measure(map_name: str, rounds: int, seconds: float) -> None:
    import torch

    torch.set_num_threads(1)
    load = [round(os.getloadavg()[0], 2)]
    rows = [row for size in SIZES for row in measure_size(size, map_name, rounds, seconds)]
    load.append(round(os.getloadavg()[0], 2))
    with CSV.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, COLUMNS)
        writer.writeheader()
        writer.writerows(rows)
    facts = {**provenance(), "map": map_name, "seconds_per_round": seconds, "load_1m": load}
    PROVENANCE.write_text(json.dumps(facts, indent=1, sort_keys=True) + "\n")


# ------------------------------------------------------------------ the tables


def tables() -> Callable[..., str]:
    """docs/results/tables.py's ``regenerate`` (generated blocks and value spans)."""
    spec = importlib.util.spec_from_file_location("tables", ROOT / "docs/results/tables.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.regenerate


def results() -> tuple[list[dict[str, str]], dict]:
    with CSV.open(newline="") as handle:
        return list(csv.DictReader(handle)), json.loads(PROVENANCE.read_text())


def grid(rows: list[dict[str, str]], names: list[str], cell: Callable[[dict], str]) -> str:
    """A markdown table: a row per name, a column per size."""
    index = {(r["contestant"], int(r["num_envs"])): r for r in rows}
    sizes = sorted({int(r["num_envs"]) for r in rows})
    head = [f"{s:,} env" + ("s" if s > 1 else "") for s in sizes]
    out = ["| | " + " | ".join(head) + " |", "|---" * (len(sizes) + 1) + "|"]
    out += [
        "| " + name + " | " + " | ".join(cell(index[name, s]) for s in sizes) + " |"
        for name in names
    ]
    return "\n".join(out)


def rates_table() -> str:
    rows, _ = results()
    names = list(dict.fromkeys(r["contestant"] for r in rows))
    return grid(rows, names, lambda r: f"{int(r['steps_per_s']):,}")


def ratios_table(column: str = "reference_ratio") -> str:
    """pegame's contestant of ``column`` over each VMAS scenario, per size."""
    rows, _ = results()
    names = [n for n in dict.fromkeys(r["contestant"] for r in rows) if n.startswith("VMAS")]
    return grid(rows, names, lambda r: times(float(r[column])))


def times(ratio: float) -> str:
    """A ratio with two significant digits or whole (``1.7x``, ``0.76x``, ``56x``)."""
    return f"{ratio:.0f}x" if ratio >= 10 else f"{ratio:.2g}x"


def profile_table() -> str:
    """``vmas_profile.csv`` (``vmas_profile.py``): a step's CPU time per game, by part."""
    with (HERE / "vmas_profile.csv").open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    out = ["| envs | step | tick kernel | observation | rest of the step |", "|---" * 5 + "|"]
    for r in rows:
        cells = [f"{int(r['num_envs']):,}"] + [
            f"{float(r[key]):.2f} us" for key in ("step", "tick", "observation", "rest")
        ]
        out.append("| " + " | ".join(cells) + " |")
    return "\n".join(out)


def machine() -> str:
    _, facts = results()
    avx = "with" if facts["cpu"]["avx512"] else "without"
    return (
        f"{facts['cpu']['model']} ({avx} AVX-512, {facts['cpu']['cores']} cores), "
        f"load {facts['load_1m'][0]:.1f} before and {facts['load_1m'][1]:.1f} after, "
        f"{facts['date'][:10]}, pegame `{facts['commit'][:7]}`"
        + (" with uncommitted changes" if facts["pegame_dirty"] else "")
    )


def versions() -> str:
    _, facts = results()
    return ", ".join(f"{key} {facts[key]}" for key in ("python", "torch", "vmas", "numba", "numpy"))


def lowest() -> str:
    """The lowest ratio of pegame (random evader) to a VMAS scenario, and where."""
    rows, _ = results()
    low = min(
        (r for r in rows if r["contestant"].startswith("VMAS")),
        key=lambda r: float(r["reference_ratio"]),
    )
    return f"{times(float(low['reference_ratio']))} ({low['contestant']}, {low['num_envs']} envs)"


VALUES = {
    "vmas_machine": machine,
    "vmas_versions": versions,
    "vmas_lowest": lowest,
    "vmas_map": lambda: results()[1]["map"],
}
PAGES = {
    PAGE: {
        "vmas_rates": rates_table,
        "vmas_ratios": ratios_table,
        "vmas_cropless": lambda: ratios_table("cropless_ratio"),
        "vmas_profile": profile_table,
    },
    README: {"vmas_ratios": ratios_table},
    ROOT / "docs/explanation/performance.md": {},
}


def render(check: bool) -> int:
    """Rewrite (or with ``check``, compare) the page's and README's generated parts."""
    regenerate = tables()
    stale = []
    for path, blocks in PAGES.items():
        text = path.read_text()
        fresh = regenerate(text, blocks, VALUES)
        if fresh != text:
            stale.append(path)
            if not check:
                path.write_text(fresh)
    if check and stale:
        names = ", ".join(str(p.relative_to(ROOT)) for p in stale)
        print(
            f"{names}: stale, run python docs/performance/vmas_side_by_side.py render",
            file=sys.stderr,
        )
        return 1
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("command", nargs="?", default="measure", choices=("measure", "render"))
    parser.add_argument("--check", action="store_true", help="exit 1 if a page is stale")
    parser.add_argument("--map", default="enclosed", help="pegame's map (default enclosed)")
    parser.add_argument("--rounds", type=int, default=15, help="rounds per size (default 15)")
    parser.add_argument(
        "--seconds",
        type=float,
        default=0.25,
        help="a contestant's time per round, about (s; default 0.25)",
    )
    args = parser.parse_args(argv)
    if args.command == "measure" and not args.check:
        measure(args.map, args.rounds, args.seconds)
    return render(args.check)


if __name__ == "__main__":
    sys.exit(main())
