"""The study's table for docs/teams/README.md, from the report's CSVs:
``python docs/teams/summary.py docs/teams/report`` prints one Markdown row per
(map, evaders, pursuers): each team's mean tracking rate with its 95% bootstrap CI and n,
and the paired difference cooperative - independent with its CI and Holm-corrected
Wilcoxon p (pegame.report's compare_pairing.csv).

``python docs/teams/summary.py docs/teams/report --pooled outputs/teams`` also prints the
pooled comparison over the cells with at least two pursuers, from the sweep's own
``results.jsonl`` files (games paired by map, team sizes and seed): the mean difference
cooperative - independent with its 95% percentile-bootstrap CI (10,000 resamples of the
pairs, seed 0) and the two-sided Wilcoxon signed-rank p, over all those cells and per
number of evaders."""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

import numpy as np
from scipy.stats import wilcoxon

MAPS = ("hall", "enclosed", "brick", "office")


def main(report: Path) -> None:
    cells = {}
    with (report / "table1.csv").open() as f:
        for row in csv.DictReader(f):
            key = (row["map"], row["team.evaders"], row["team.pursuers"], row["pairing"])
            cells[key] = row
    pairs = {}
    with (report / "compare_pairing.csv").open() as f:
        for row in csv.DictReader(f):
            pairs[(row["map"], row["team.evaders"], row["team.pursuers"])] = row

    def rate(row) -> str:
        if row is None:
            return "–"
        mean, low, high = (100 * float(row[k]) for k in ("mean", "ci_low", "ci_high"))
        return f"{mean:.1f} [{low:.1f}, {high:.1f}] n={row['n']}"

    print(
        "| map | evaders | pursuers | independent (S-S) | cooperative | coop - indep [CI] (pp) | p (Holm) |"
    )
    print("|---|---|---|---|---|---|---|")
    order = sorted(pairs, key=lambda k: (MAPS.index(k[0]), int(k[1]), int(k[2])))
    for key in order:
        pair = pairs[key]
        diff = "–"
        if pair["mean_difference"]:
            d, lo, hi = (100 * float(pair[k]) for k in ("mean_difference", "ci_low", "ci_high"))
            diff = f"{d:+.1f} [{lo:+.1f}, {hi:+.1f}]"
        p = f"{float(pair['p_holm']):.3g}" if pair["p_holm"] else "–"
        row = [
            *key,
            rate(cells.get((*key, "S-S"))),
            rate(cells.get((*key, "cooperative-S"))),
            diff,
            p,
        ]
        print("| " + " | ".join(row) + " |")


def pooled(sweep: Path) -> None:
    """Print the pooled paired comparison (module docstring) of the games under ``sweep``."""
    rates: dict[tuple, float] = {}
    for path in sweep.rglob("results.jsonl"):
        for line in path.read_text().splitlines():
            game = json.loads(line)
            if game.get("kind") != "game":
                continue
            team = game["config"]["team"]
            key = (game["map"], team["evaders"], team["pursuers"], game["seed"])
            rates[(*key, game["pairing"])] = game["tracking_rate"]
    pairs = [
        (key[1], rates[(*key, "cooperative-S")] - rate)
        for (*key, pairing), rate in rates.items()
        if pairing == "S-S" and key[2] >= 2 and (*key, "cooperative-S") in rates
    ]
    rng = np.random.default_rng(0)
    for label, evaders in (("all", (1, 2)), ("1 evader", (1,)), ("2 evaders", (2,))):
        d = np.array([diff for m, diff in pairs if m in evaders])
        means = d[rng.integers(0, d.size, (10_000, d.size))].mean(axis=1)
        low, high = np.percentile(means, [2.5, 97.5])
        p = wilcoxon(d).pvalue
        print(
            f"pooled {label}: {d.size} pairs, {100 * d.mean():+.1f} pp "
            f"[{100 * low:+.1f}, {100 * high:+.1f}], Wilcoxon p = {p:.2g}"
        )


if __name__ == "__main__":
    main(Path(sys.argv[1]))
    if "--pooled" in sys.argv:
        pooled(Path(sys.argv[sys.argv.index("--pooled") + 1]))
