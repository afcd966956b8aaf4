"""Table 1 and the paper's trends under each named reading, side by side (docs/trends/README.md).

Reads the sweeps ``docs/trends/run.sh`` plays (``<sweeps>/<reading>/<pairing>/*/results.jsonl``,
one line per game) and writes ``readings.md`` and ``readings.csv``: each cell's mean
tracking rate under each reading beside the paper's (docs/paper_conditions/paper_table1.csv),
and per reading the paper's two trends: Kendall's tau of the tracking rate against the speed
ratio over a map's games (the statistic of the Jonckheere-Terpstra test; > 0: rises), and
S-S minus S-R per cell, paired on the common seeds. Descriptive at the sweep's n: the
report's tests (``pegame.report.trends``) are what a claim rests on.

    python docs/trends/readings.py outputs/trends --out docs/trends
"""

from __future__ import annotations

import argparse
import csv
import json
from collections import defaultdict
from pathlib import Path

import numpy as np
from scipy.stats import kendalltau

PAPER = Path(__file__).resolve().parents[1] / "paper_conditions" / "paper_table1.csv"
MAPS, RATIOS, PAIRINGS = ("hall", "enclosed", "brick"), (0.5, 1.0, 2.0), ("R-R", "S-R", "S-S")
#: the readings in the order of the README (any other sweep, a probe, follows them)
READINGS = ("paper_conditions", "held_commands", "goal_tracking", "random_waypoints")


def load(sweeps: Path) -> tuple[dict, set, dict]:
    """{(reading, pairing, map, ratio): {seed: tracking rate}}, the commits played at, and
    {(reading, pairing, ratio): [each game's loss_causes]}."""
    games: dict = defaultdict(dict)
    causes: dict = defaultdict(list)
    commits = set()
    for path in sorted(sweeps.glob("*/*/*/results.jsonl")):
        reading = path.parts[-4]
        for line in path.read_text().splitlines():
            game = json.loads(line)
            if game.get("kind") != "game":
                continue
            key = (reading, game["pairing"], game["map"], float(game["speed_ratio"]))
            games[key][game["seed"]] = game["tracking_rate"]
            causes[(reading, game["pairing"], key[3])].append(game["loss_causes"])
            prov = game["provenance"]
            commits.add(prov["commit"][:7] + ("+dirty" if prov.get("dirty") else ""))
    return games, commits, causes


def paper() -> dict:
    with PAPER.open() as f:
        return {
            (r["pairing"], r["map"], float(r["speed_ratio"])): float(r["paper_mean"])
            for r in csv.DictReader(f)
        }


def cell(games: dict, reading: str, pairing: str, env: str, ratio: float) -> dict:
    """The cell's games under ``reading``; a reading that does not change ``pairing`` (the
    smart pursuer's track for R-R) plays paper_conditions' games there."""
    own = games.get((reading, pairing, env, ratio))
    return own if own else games.get(("paper_conditions", pairing, env, ratio), {})


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sweeps", type=Path)
    parser.add_argument("--out", type=Path, default=Path("docs/trends"))
    args = parser.parse_args()
    games, commits, causes = load(args.sweeps)
    played = {k[0] for k in games}
    readings = [r for r in READINGS if r in played] + sorted(played - set(READINGS))
    ref = paper()
    rows, lines = [], ["# Table 1 under each reading", ""]
    n = sorted({len(v) for v in games.values()})
    lines += [
        f"Mean tracking rate (%) per cell, n = {'/'.join(map(str, n))} games per cell (seeds "
        f"0..n-1), played at {', '.join(sorted(commits))}; a reading that does not change a "
        "pairing shows paper_conditions' games there (in italics). Written by "
        "`python docs/trends/readings.py <sweeps>`.",
        "",
    ]
    for pairing in PAIRINGS:
        lines += [
            f"## {pairing}",
            "",
            "| map | v_p/v_e | paper | " + " | ".join(readings) + " |",
            "|---|---|---|" + "---|" * len(readings),
        ]
        for env in MAPS:
            for ratio in RATIOS:
                cells = []
                for reading in readings:
                    rates = cell(games, reading, pairing, env, ratio)
                    mean = 100 * np.mean(list(rates.values())) if rates else float("nan")
                    inherited = not games.get((reading, pairing, env, ratio))
                    cells.append(f"*{mean:.1f}*" if inherited else f"{mean:.1f}")
                    rows.append([reading, pairing, env, ratio, len(rates), f"{mean / 100:.4f}"])
                lines.append(
                    f"| {env} | {ratio:g} | {100 * ref[(pairing, env, ratio)]:.1f} | "
                    + " | ".join(cells)
                    + " |"
                )
        lines.append("")
    lines += trends(games, readings, ref)
    lines += loss_table(causes, readings)
    (args.out / "readings.md").write_text("\n".join(lines))
    with (args.out / "readings.csv").open("w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["reading", "pairing", "map", "speed_ratio", "n", "mean"])
        writer.writerows(rows)


def trends(games: dict, readings: list[str], ref: dict) -> list[str]:
    """The paper's trends per reading: tau against the ratio, S-S - S-R paired on seeds."""
    lines = [
        "## The paper's trends",
        "",
        "Kendall's tau of the tracking rate against v_p/v_e over a map's games (> 0: "
        "rises, the paper's trend for S-R on every map), and S-S minus S-R (points, mean over "
        "the common seeds; < 0 is the paper's H3 cell, which holds in 7 of its 9).",
        "",
        "| reading | pairing | hall | enclosed | brick |",
        "|---|---|---|---|---|",
    ]
    for reading in ["paper"] + readings:
        for pairing in PAIRINGS:
            taus = []
            for env in MAPS:
                if reading == "paper":
                    values = [ref[(pairing, env, r)] for r in RATIOS]
                    taus.append(kendalltau(RATIOS, values).statistic)
                    continue
                x, y = [], []
                for ratio in RATIOS:
                    rates = cell(games, reading, pairing, env, ratio)
                    x += [ratio] * len(rates)
                    y += list(rates.values())
                taus.append(kendalltau(x, y).statistic if y else float("nan"))
            lines.append(
                f"| {reading} | {pairing} tau | " + " | ".join(f"{t:+.2f}" for t in taus) + " |"
            )
        diffs = []
        for env in MAPS:
            cells = []
            for ratio in RATIOS:
                if reading == "paper":
                    d = ref[("S-S", env, ratio)] - ref[("S-R", env, ratio)]
                else:
                    ss = cell(games, reading, "S-S", env, ratio)
                    sr = cell(games, reading, "S-R", env, ratio)
                    common = sorted(set(ss) & set(sr))
                    d = np.mean([ss[s] - sr[s] for s in common]) if common else float("nan")
                cells.append(f"{100 * d:+.1f}")
            diffs.append(" / ".join(cells))
        lines.append(f"| {reading} | S-S - S-R at 0.5 / 1 / 2 | " + " | ".join(diffs) + " |")
    return lines + [""]


def loss_table(causes: dict, readings: list[str]) -> list[str]:
    """Losses per game by cause and the mean seconds to reacquire, per reading, pairing
    and speed ratio, pooled over the three maps (result.json's ``loss_causes``)."""
    names = ("bearing", "turning", "missed", "blocked", "occluded", "far", "near")
    lines = [
        "## Loss causes by speed ratio",
        "",
        "Losses per game by cause (`pegame.losses`), pooled over the three maps, with the "
        "mean seconds to reacquire in brackets (losses never reacquired left out of it), "
        "and the seconds without a detection per game.",
        "",
        "| reading | pairing | v_p/v_e | " + " | ".join(names) + " | s lost |",
        "|---|---|---|" + "---|" * (len(names) + 1),
    ]
    for reading in readings:
        for pairing in PAIRINGS:
            for ratio in RATIOS:
                played = causes.get((reading, pairing, ratio))
                if not played:
                    continue
                cells, lost = [], 0.0
                for name in names:
                    count = sum(g[name]["count"] for g in played)
                    back = sum(g[name]["reacquired"] for g in played)
                    mean = sum(
                        g[name]["mean_reacquire_s"] * g[name]["reacquired"]
                        for g in played
                        if g[name]["reacquired"]
                    )
                    lost += sum(g[name]["time_lost_s"] for g in played)
                    text = f"{count / len(played):.1f}"
                    cells.append(text + (f" ({mean / back:.1f})" if back else ""))
                lines.append(
                    f"| {reading} | {pairing} | {ratio:g} | "
                    + " | ".join(cells)
                    + f" | {lost / len(played):.0f} |"
                )
    return lines + [""]


if __name__ == "__main__":
    main()
