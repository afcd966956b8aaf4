"""The study's table for docs/teams/README.md, from the report's CSVs:
``python docs/teams/summary.py docs/teams/report`` prints one Markdown row per
(map, evaders, pursuers): each team's mean tracking rate with its 95% bootstrap CI and n,
and the paired difference cooperative - independent with its CI and Holm-corrected
Wilcoxon p (pegame.report's compare_pairing.csv)."""

from __future__ import annotations

import csv
import sys
from pathlib import Path

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


if __name__ == "__main__":
    main(Path(sys.argv[1]))
