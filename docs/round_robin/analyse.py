"""The round-robin's table, heat maps and paired tests from the sweeps of run.sh.

python docs/round_robin/analyse.py OUT [--out docs/round_robin]

OUT holds one directory per conditions (``default``, ``paper_conditions``), each with one
multirun per pairing (``<pursuer>-<evader>``), as docs/round_robin/run.sh writes them.
Writes into --out:

- ``table.csv``: conditions, pursuer, evader, map, speed_ratio, n, mean, ci_low, ci_high
  (tracking rates as fractions; 95% percentile-bootstrap CI of the mean, 10,000
  resamples, :func:`pegame.report.statistics.describe`);
- ``heatmap_<map>.png``: mean tracking rate, pursuers x evaders, one panel per
  conditions and speed ratio;
- ``goals.md`` and ``goals.csv``: the paired tests behind issue 18's goals, cell by cell
  (map x speed ratio), on the seeds both sides played (same seed, same spawn poses): the
  one-sided Wilcoxon signed-rank test with Pratt's zeros (:mod:`pegame.report.paired`),
  Holm-Bonferroni corrected across the nine cells of each goal and conditions;
- ``summary.md``: the mean tracking rates as Markdown tables;
- ``provenance.md``: the commits, dirty flags, package versions and game counts read
  from the games' own result lines.
"""

from __future__ import annotations

import argparse
import csv
import math
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from pegame.report.load import load_sweep
from pegame.report.paired import KEYS, by_seed, paired_test
from pegame.report.statistics import ALPHA, describe, holm

CONDITIONS = ("default", "paper_conditions")
PURSUERS = ("random", "smart", "anticipating", "policy")
EVADERS = ("random", "smart", "elusive")
MAPS = ("hall", "enclosed", "brick")
RATIOS = (0.5, 1.0, 2.0)

#: (goal, conditions, (pursuer, evader) x, (pursuer, evader) y, alternative about x - y,
#: what "met" means). "greater"/"less" goals are met where the Holm-corrected p < alpha;
#: "no lower" goals where x is not significantly lower than y (Holm-corrected p >= alpha
#: of the one-sided test x < y).
GOALS = [
    (
        "pursuer beats smart vs smart evader",
        "paper_conditions",
        ("anticipating", "smart"),
        ("smart", "smart"),
        "greater",
        "higher",
    ),
    (
        "pursuer no lower vs smart evader",
        "default",
        ("anticipating", "smart"),
        ("smart", "smart"),
        "less",
        "no lower",
    ),
    (
        "pursuer no worse vs random evader",
        "paper_conditions",
        ("anticipating", "random"),
        ("smart", "random"),
        "less",
        "no lower",
    ),
    (
        "pursuer no worse vs random evader",
        "default",
        ("anticipating", "random"),
        ("smart", "random"),
        "less",
        "no lower",
    ),
    (
        "evader beats smart vs smart pursuer",
        "paper_conditions",
        ("smart", "elusive"),
        ("smart", "smart"),
        "less",
        "lower",
    ),
    (
        "evader beats smart vs smart pursuer",
        "default",
        ("smart", "elusive"),
        ("smart", "smart"),
        "less",
        "lower",
    ),
]


def load(out: Path) -> tuple[dict, list[dict]]:
    """({(conditions, pursuer, evader, map, ratio): [game record, ...]}, every record)."""
    cells: dict[tuple, list[dict]] = defaultdict(list)
    records = []
    for conditions in CONDITIONS:
        root = out / conditions
        if not root.is_dir():
            continue
        for pairing in sorted(p for p in root.iterdir() if p.is_dir()):
            sweep = load_sweep(pairing)
            for record in sweep.records:
                records.append({**record, "conditions": conditions})
                if record.get("kind") == "game":
                    key = (
                        conditions,
                        record["pursuer"],
                        record["evader"],
                        record["map"],
                        float(record["speed_ratio"]),
                    )
                    cells[key].append(record)
    return cells, records


def write_table(cells: dict, path: Path) -> dict:
    """table.csv; returns {key: mean}."""
    means = {}
    with path.open("w", newline="") as f:
        out = csv.writer(f)
        out.writerow(
            [
                "conditions",
                "pursuer",
                "evader",
                "map",
                "speed_ratio",
                "n",
                "mean",
                "ci_low",
                "ci_high",
            ]
        )
        for conditions in CONDITIONS:
            for pursuer in PURSUERS:
                for evader in EVADERS:
                    for name in MAPS:
                        for ratio in RATIOS:
                            key = (conditions, pursuer, evader, name, ratio)
                            games = cells.get(key)
                            if not games:
                                continue
                            d = describe([float(g["tracking_rate"]) for g in games])
                            means[key] = d["mean"]
                            out.writerow(
                                [
                                    conditions,
                                    pursuer,
                                    evader,
                                    name,
                                    f"{ratio:g}",
                                    d["n"],
                                    f"{d['mean']:.6f}",
                                    f"{d['ci_low']:.6f}",
                                    f"{d['ci_high']:.6f}",
                                ]
                            )
    return means


def heat_maps(means: dict, out: Path) -> None:
    """heatmap_<map>.png: pursuers x evaders, a panel per conditions and speed ratio."""
    for name in MAPS:
        fig, axes = plt.subplots(2, 3, figsize=(12, 7.5), constrained_layout=True)
        for i, conditions in enumerate(CONDITIONS):
            for j, ratio in enumerate(RATIOS):
                ax = axes[i, j]
                grid = np.full((len(PURSUERS), len(EVADERS)), np.nan)
                for a, pursuer in enumerate(PURSUERS):
                    for b, evader in enumerate(EVADERS):
                        grid[a, b] = means.get((conditions, pursuer, evader, name, ratio), np.nan)
                image = ax.imshow(100 * grid, vmin=0, vmax=100, cmap="viridis")
                for a in range(len(PURSUERS)):
                    for b in range(len(EVADERS)):
                        text = "–" if math.isnan(grid[a, b]) else f"{100 * grid[a, b]:.0f}"
                        light = not math.isnan(grid[a, b]) and grid[a, b] < 0.6
                        ax.text(
                            b,
                            a,
                            text,
                            ha="center",
                            va="center",
                            color="white" if light else "black",
                            fontsize=11,
                        )
                ax.set_xticks(range(len(EVADERS)), EVADERS)
                ax.set_yticks(range(len(PURSUERS)), PURSUERS)
                ax.set_title(f"{conditions}, v_p/v_e = {ratio:g}", fontsize=10)
                if j == 0:
                    ax.set_ylabel("pursuer")
                if i == 1:
                    ax.set_xlabel("evader")
        fig.colorbar(image, ax=axes, shrink=0.6, label="mean tracking rate (%)")
        fig.suptitle(f"Round-robin on {name}: mean tracking rate (%); n per cell in table.csv")
        fig.savefig(out / f"heatmap_{name}.png", dpi=110)
        plt.close(fig)


def write_summary(means: dict, path: Path) -> None:
    """summary.md: the mean tracking rates (%) as one table per conditions and speed ratio,
    pursuers x (map, evader); '–' where a cell was not played."""
    lines = [
        "# Round-robin: mean tracking rate (%)",
        "",
        "Rows: pursuers; columns: map / evader; n = 40 games per cell unless "
        "provenance.md lists it. CIs are in table.csv.",
    ]
    header = [f"{name} / {evader}" for name in MAPS for evader in EVADERS]
    for conditions in CONDITIONS:
        for ratio in RATIOS:
            lines += [
                "",
                f"## {conditions}, v_p/v_e = {ratio:g}",
                "",
                "| pursuer | " + " | ".join(header) + " |",
                "|---|" + "---|" * len(header),
            ]
            for pursuer in PURSUERS:
                values = [
                    means.get((conditions, pursuer, evader, name, ratio))
                    for name in MAPS
                    for evader in EVADERS
                ]
                text = ["–" if v is None else f"{100 * v:.1f}" for v in values]
                lines.append(f"| {pursuer} | " + " | ".join(text) + " |")
    lines += [
        "",
        "## Mean over the three speed ratios: hall / enclosed / brick",
        "",
        "| pursuer \\ evader | "
        + " | ".join(f"{evader} ({conditions})" for conditions in CONDITIONS for evader in EVADERS)
        + " |",
        "|---|" + "---|" * (len(CONDITIONS) * len(EVADERS)),
    ]
    for pursuer in PURSUERS:
        row = []
        for conditions in CONDITIONS:
            for evader in EVADERS:
                per_map = []
                for name in MAPS:
                    values = [means.get((conditions, pursuer, evader, name, r)) for r in RATIOS]
                    played = [v for v in values if v is not None]
                    per_map.append(
                        f"{100 * sum(played) / len(played):.0f}"
                        + ("" if len(played) == len(RATIOS) else "*")
                        if played
                        else "–"
                    )
                row.append(" / ".join(per_map))
        lines.append(f"| {pursuer} | " + " | ".join(row) + " |")
    lines += ["", "\\* not every speed ratio played: the mean of those that were."]
    path.write_text("\n".join(lines) + "\n")


def goal_tests(cells: dict) -> list[dict]:
    """One row per goal, conditions and cell, Holm-corrected per goal and conditions."""
    rows = []
    for goal, conditions, x, y, alternative, meaning in GOALS:
        family = []
        for name in MAPS:
            for ratio in RATIOS:
                a = cells.get((conditions, *x, name, ratio), [])
                b = cells.get((conditions, *y, name, ratio), [])
                test = paired_test(by_seed(a), by_seed(b), alternative)
                family.append(
                    {
                        "goal": goal,
                        "conditions": conditions,
                        "x": "-".join(x),
                        "y": "-".join(y),
                        "alternative": alternative,
                        "meaning": meaning,
                        "map": name,
                        "speed_ratio": ratio,
                        **test,
                    }
                )
        tested = [r for r in family if r["p"] is not None]
        for row, p in zip(tested, holm([r["p"] for r in tested])):
            row["p_holm"] = p
            significant = p < ALPHA
            row["met"] = (not significant) if meaning == "no lower" else significant
        for row in family:
            row.setdefault("p_holm", None)
            row.setdefault("met", None)
        rows.extend(family)
    return rows


def write_goals(rows: list[dict], out: Path) -> None:
    keys = ["goal", "conditions", "x", "y", "alternative", "map", "speed_ratio", *KEYS]
    keys += ["p_holm", "met"]
    with (out / "goals.csv").open("w", newline="") as f:
        writer = csv.DictWriter(f, keys, extrasaction="ignore")
        writer.writeheader()
        writer.writerows(rows)
    lines = [
        "# The goals of issue 18, cell by cell",
        "",
        "Paired on common seeds (same seed, same spawn poses): one-sided Wilcoxon "
        "signed-rank test with Pratt's zeros of x - y (scipy.stats.wilcoxon), "
        "Holm-Bonferroni corrected across the nine cells of each goal and conditions, "
        f"alpha = {ALPHA}; mean paired difference in percentage points with its "
        "percentile-bootstrap CI over seeds. 'higher'/'lower' goals are met where the "
        "corrected p is below alpha; 'no lower' goals where x is not significantly "
        "lower than y (corrected p of the one-sided test x < y at least alpha).",
        "",
    ]
    seen = []
    for row in rows:
        head = (row["goal"], row["conditions"])
        if head not in seen:
            seen.append(head)
            family = [r for r in rows if (r["goal"], r["conditions"]) == head]
            met = sum(bool(r["met"]) for r in family)
            lines += [
                "",
                f"## {row['goal']} ({row['conditions']}): {row['x']} against "
                f"{row['y']}, goal '{row['meaning']}': met in {met} of {len(family)} cells",
                "",
                "| map | v_p/v_e | pairs | x mean | y mean | x - y [CI] | W | p | p (Holm) | met |",
                "|---|---|---|---|---|---|---|---|---|---|",
            ]
            for r in family:
                if r["p"] is None:
                    lines.append(
                        f"| {r['map']} | {r['speed_ratio']:g} | {r['n_pairs']} | – | – "
                        "| – | – | – | – | not tested |"
                    )
                    continue
                lines.append(
                    f"| {r['map']} | {r['speed_ratio']:g} | {r['n_pairs']} | "
                    f"{100 * r['mean_x']:.1f}% | {100 * r['mean_y']:.1f}% | "
                    f"{100 * r['mean_difference']:+.1f} pp [{100 * r['ci_low']:+.1f}, "
                    f"{100 * r['ci_high']:+.1f}] | {r['W']:g} | {r['p']:.3g} | "
                    f"{r['p_holm']:.3g} | {'yes' if r['met'] else 'no'} |"
                )
    (out / "goals.md").write_text("\n".join(lines) + "\n")


def write_provenance(records: list[dict], cells: dict, out: Path) -> None:
    games = [r for r in records if r.get("kind") == "game"]
    failed = [r for r in records if r.get("kind") == "failed"]
    commits = defaultdict(int)
    versions = set()
    for g in games:
        p = g.get("provenance", {})
        commits[(p.get("commit"), p.get("dirty"))] += 1
        versions.add(
            f"pegame {p.get('pegame')}, Python {p.get('python')}, numpy "
            f"{p.get('numpy')}, numba {p.get('numba')}"
        )
    short = [k for k, games_ in cells.items() if len(games_) < 40]
    lines = [
        "# Provenance of the round-robin (read from the games' result lines)",
        "",
        f"- games: {len(games)}, failed: {len(failed)}, cells: {len(cells)}, cells "
        f"with fewer than 40 games: {len(short)}",
    ]
    for (commit, dirty), n in sorted(commits.items(), key=str):
        lines.append(f"- commit {commit} ({'dirty' if dirty else 'clean'}): {n} games")
    lines += [f"- {v}" for v in sorted(versions)]
    if short:
        lines += ["", "Cells with fewer than 40 games:", ""]
        lines += [f"- {' '.join(map(str, k))}: {len(cells[k])}" for k in sorted(short)]
    (out / "provenance.md").write_text("\n".join(lines) + "\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sweeps", type=Path, help="run.sh's OUT directory")
    parser.add_argument("--out", type=Path, default=Path("docs/round_robin"))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    cells, records = load(args.sweeps)
    means = write_table(cells, args.out / "table.csv")
    heat_maps(means, args.out)
    write_summary(means, args.out / "summary.md")
    write_goals(goal_tests(cells), args.out)
    write_provenance(records, cells, args.out)


if __name__ == "__main__":
    main()
