"""The fidelity study's tables: the grid with an identified 3D profile against the 3D pipeline.

    python docs/fidelity/compare.py OUT

OUT: the directory ``run3d.sh`` and ``run.sh`` wrote: ``OUT/3d`` (sim=pybullet,
detector=vision), ``OUT/grid`` (the grid's oracle with ``detector.profile``) and
``OUT/grid_plain`` (the grid's oracle with paper_conditions' own perception model, the
baseline), every one paper_conditions with simultaneous moves; and where
``run_person.sh`` played them, ``OUT/3d_person`` (detector=person, level camera) and its
grid twin ``OUT/grid_person`` (the profile person_level). Writes beside this script:

- ``grid_vs_3d.md``/``.csv``, ``plain_vs_3d.*`` and ``person_vs_3d.*``: each grid against
  its 3D pipeline on common seeds, per Table 1 cell (both means with 95% bootstrap CIs, the paired
  difference, two-sided Wilcoxon signed-rank p Holm-corrected across the cells:
  :func:`grid_vs_3d.compare` of docs/paper_conditions);
- ``vs_paper.md``/``.csv``: each of the three tables beside the paper's Table 1 (mean
  absolute difference, paper values inside the cell's 95% CI: :func:`vs_paper.versus`);
- ``losses.md``/``.csv``: per cell, the mean time lost per game (s) by loss cause
  (:mod:`pegame.losses`) in the profiled grid and in 3D, the mechanism behind a gap;
- the quoted figures of ``README.md`` (its ``<!-- value: NAME -->`` spans, as
  docs/results/tables.py writes its pages), with those of :mod:`framing` and of
  ``heldout.json`` (heldout.py).
"""

from __future__ import annotations

import ast
import csv
import io
import json
import sys
from pathlib import Path

from pegame.bootstrap import bootstrap_ci
from pegame.files import write_atomic

HERE = Path(__file__).resolve().parent
DOCS = HERE.parent
sys.path[:0] = [str(DOCS / "paper_conditions"), str(DOCS / "results")]
from factor_table import MAPS, PAIRINGS, games  # noqa: E402
from framing import values as framing_values  # noqa: E402
from grid_vs_3d import RATIOS, compare, render  # noqa: E402
from tables import quoted_by_hand, regenerate  # noqa: E402
from vs_paper import table, versus  # noqa: E402

SCRIPT = "docs/fidelity/compare.py"
#: the tables: their directory under OUT and their name in vs_paper
TABLES = {
    "grid_profile": "grid",
    "grid_plain": "grid_plain",
    "3d_pipeline": "3d",
    "3d_person": "3d_person",
    "grid_person": "grid_person",
}
#: the 3D tables as the pages name them
THREE_D_NAMES = {
    "3d_pipeline": "the 3D pipeline",
    "3d_person": "the 3D pipeline with detector=person",
}
#: (page, grid table, 3D table) of each grid-against-3D comparison
COMPARISONS = (
    ("grid_vs_3d", "grid_profile", "3d_pipeline"),
    ("plain_vs_3d", "grid_plain", "3d_pipeline"),
    ("person_vs_3d", "grid_person", "3d_person"),
)
CAUSES = ("missed", "blocked", "turning", "bearing", "occluded", "far", "near")


def cells(rates: dict[tuple, float]) -> dict[tuple, dict]:
    """Per cell of ``games``'s rates, the mean and its 95% bootstrap CI."""
    out = {}
    for key in {k[:3] for k in rates}:
        values = [v for k, v in rates.items() if k[:3] == key]
        low, high = bootstrap_ci(values)
        out[key] = {"mean": sum(values) / len(values), "ci_low": low, "ci_high": high}
    return out


def time_lost(root: Path) -> dict[tuple, dict[str, float]]:
    """Per cell, the mean per game of the time lost (s) and the losses (``<cause>_n``) by
    each loss cause, and of the share of time the evader was in view (``visible``); and
    the games."""
    sums: dict[tuple, dict[str, float]] = {}
    for path in sorted(root.rglob("results.jsonl")):
        for line in path.read_text().splitlines():
            record = json.loads(line)
            if record.get("kind") != "game":
                continue
            key = (record["map"], float(record["speed_ratio"]), record["pairing"])
            causes = record["loss_causes"]
            causes = ast.literal_eval(causes) if isinstance(causes, str) else causes
            cell = sums.setdefault(key, {"games": 0.0, "visible": 0.0})
            cell["games"] += 1
            cell["visible"] += float(record["visible_rate"])
            for cause in CAUSES:
                cell[cause] = cell.get(cause, 0.0) + causes[cause]["time_lost_s"]
                cell[f"{cause}_n"] = cell.get(f"{cause}_n", 0.0) + causes[cause]["count"]
    return {k: {c: v[c] / v["games"] if c != "games" else v[c] for c in v} for k, v in sums.items()}


def mechanism(sides: dict[str, dict]) -> dict[str, str]:
    """The README's figures on why the sides (a name and its :func:`time_lost`) differ, over
    the smart pursuer's cells all sides played: the share of time in view, the time lost to
    misses and while turning per game, the losses sideways (``bearing``) per game and
    their mean length."""
    keys = [k for k in set.intersection(*(set(t) for t in sides.values())) if k[2] != "R-R"]
    out = {"mechanism_cells": str(len(keys))}
    for side, table in sides.items():
        cells = [table[k] for k in keys]
        out[f"visible_{side}"] = f"{100 * sum(c['visible'] for c in cells) / len(cells):.1f}%"
        for cause in ("missed", "turning"):
            out[f"{cause}_s_{side}"] = f"{sum(c[cause] for c in cells) / len(cells):.1f} s"
        per_loss = sum(c["bearing"] for c in cells) / sum(c["bearing_n"] for c in cells)
        out[f"bearing_loss_s_{side}"] = f"{per_loss:.1f} s"
        out[f"bearing_n_{side}"] = f"{sum(c['bearing_n'] for c in cells) / len(cells):.1f}"
    return out


def to_csv(rows: list[dict]) -> str:
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, list(rows[0]), lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return buffer.getvalue()


def losses(grid: dict, three_d: dict) -> tuple[str, str]:
    """The loss-cause table (markdown, CSV) of the cells on both sides."""
    rows = []
    for m in MAPS:
        for ratio in RATIOS:
            for pairing in PAIRINGS:
                key = (m, ratio, pairing)
                if key in grid and key in three_d:
                    row = {"map": m, "speed_ratio": ratio, "pairing": pairing}
                    for cause in CAUSES:
                        row[f"{cause}_grid"] = grid[key][cause]
                        row[f"{cause}_3d"] = three_d[key][cause]
                    rows.append(row)
    lines = [
        "# Time lost by loss cause: the profiled grid and the 3D pipeline",
        "",
        f"Mean seconds lost per 90 s game, grid / 3D, per cause (`pegame.losses`). "
        f"Generated by `{SCRIPT}`.",
        "",
        "| map | v_p/v_e | pairing | " + " | ".join(CAUSES) + " |",
        "|---|---|---|" + "---|" * len(CAUSES),
    ]
    for r in rows:
        lines.append(
            f"| {r['map']} | {r['speed_ratio']:g} | {r['pairing']} | "
            + " | ".join(f"{r[c + '_grid']:.1f} / {r[c + '_3d']:.1f}" for c in CAUSES)
            + " |"
        )
    return "\n".join(lines) + "\n", to_csv(rows)


def main(argv: list[str]) -> int:
    if len(argv) != 1:
        print(__doc__, file=sys.stderr)
        return 2
    out = Path(argv[0])
    rates = {name: games(out / sub) for name, sub in TABLES.items()}
    values = framing_values()
    heldout = json.loads((HERE / "heldout.json").read_text())
    values["heldout_measured"] = f"{100 * heldout['measured']:.1f}%"
    values["heldout_predicted"] = f"{100 * heldout['predicted']:.1f}%"
    values["heldout_brier"] = f"{heldout['brier']:.4f}"
    values["heldout_brier_base"] = f"{heldout['brier_base']:.4f}"
    values["heldout_iou"] = f"{100 * heldout['found_iou']:.1f}%"
    values["heldout_edge"] = f"{heldout['edge_frames']} of {heldout['frames']}"
    values["heldout_edge_rate"] = f"{100 * heldout['edge_rate']:.0f}%"
    values["heldout_edge_max"] = f"{heldout['edge_max_bearing']:.2f} rad"
    for name, title, three_d in COMPARISONS:
        rows = compare(rates[title], rates[three_d])
        if not rows:  # not played yet
            continue
        against = THREE_D_NAMES[three_d]
        text, csv_text = render(rows, f"The grid ({title}) against {against}", SCRIPT)
        write_atomic(HERE / f"{name}.md", text)
        write_atomic(HERE / f"{name}.csv", csv_text)
        gaps = [abs(r["mean_difference"]) for r in rows]
        values[f"{name}_gap"] = f"{100 * sum(gaps) / len(gaps):.1f} points"
        values[f"{name}_significant"] = f"{sum(r['p_holm'] <= 0.05 for r in rows)} of {len(rows)}"
        values[f"{name}_largest"] = "{:+.1f} points ({} {} at {:g})".format(
            *max(
                (
                    (100 * r["mean_difference"], r["map"], r["pairing"], r["speed_ratio"])
                    for r in rows
                ),
                key=lambda t: abs(t[0]),
            )
        )
    paper = table(DOCS / "paper_conditions" / "paper_table1.csv")
    # every table over the cells the 3D pipeline played, so that the distances compare
    played = {k[:3] for k in rates["3d_pipeline"]}
    tables = {n: cells({k: v for k, v in r.items() if k[:3] in played}) for n, r in rates.items()}
    rows, summary = versus(paper, {name: c for name, c in tables.items() if c})
    write_atomic(HERE / "vs_paper.csv", to_csv(rows))
    lines = [
        "# The fidelity study's tables beside the paper's Table 1",
        "",
        f"Generated by `{SCRIPT}`; tracking rates of each table's cells against the "
        "paper's (docs/paper_conditions/paper_table1.csv).",
        "",
        "| table | cells | mean absolute difference from the paper | paper values inside the 95% CI |",
        "|---|---|---|---|",
    ]
    for name, (gap, inside, n) in summary.items():
        lines.append(f"| {name} | {n} | {100 * gap:.1f} points | {inside} of {n} |")
        values[f"paper_gap_{name}"] = f"{100 * gap:.1f} points"
        values[f"paper_inside_{name}"] = f"{inside} of {n}"
    write_atomic(HERE / "vs_paper.md", "\n".join(lines) + "\n")
    grid_losses, three_d_losses = time_lost(out / "grid"), time_lost(out / "3d")
    sides = {"grid": grid_losses, "plain": time_lost(out / "grid_plain"), "3d": three_d_losses}
    values.update(mechanism(sides))
    text, csv_text = losses(grid_losses, three_d_losses)
    write_atomic(HERE / "losses.md", text)
    write_atomic(HERE / "losses.csv", csv_text)
    readme = HERE / "README.md"
    fresh = regenerate(readme.read_text(), {}, {k: (lambda v=v: v) for k, v in values.items()})
    write_atomic(readme, fresh)
    by_hand = quoted_by_hand(fresh)
    if by_hand:
        print(f"README.md quotes by hand: {', '.join(by_hand)}", file=sys.stderr)
        return 1
    print("\n".join(f"{k}: {v}" for k, v in values.items()))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
