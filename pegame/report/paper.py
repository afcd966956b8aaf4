"""Our tracking rates beside the paper's Table 1 (``--paper``): ``vs_paper.md`` / ``.csv``.

The paper's means (fractions; Table 1 of the paper, transcribed from its .tex source) are
package data, ``pegame/report/paper_table1.csv`` (map, speed_ratio, pairing,
paper_mean). Per cell of ours on the paper's axes (its environments, speed ratios and the
pairings R-R, S-R, S-S), and per combination of the sweep's other factors: our mean
tracking rate with its 95% bootstrap CI and n, the paper's mean, the difference ours -
paper and whether the paper's mean lies inside our CI; per combination, the mean absolute
difference and how many of the paper's values lie inside our CIs. Cells off the paper's
axes (R-S, another map or speed ratio) are left out and listed. The paper reports means
only (40 games per cell, no spread), so the difference carries our uncertainty alone.
"""

from __future__ import annotations

import csv
import io
import math
from importlib.resources import files
from typing import Any

from pegame.report.cells import Cell, facets
from pegame.report.hypotheses import facet_text
from pegame.report.tables import (
    CELL_COLUMNS,
    cell_text,
    cell_texts,
    cells_csv,
    markdown_rows,
)

PAPER_FILE = "paper_table1.csv"
Place = tuple[str, float, str]  # (map, speed_ratio, pairing)
STATS = ["n", "mean", "ci_low", "ci_high", "paper_mean", "difference", "paper_inside_ci"]


def paper_table() -> dict[Place, float]:
    """The paper's Table 1: {(map, speed_ratio, pairing): mean tracking rate (fraction)}."""
    text = files("pegame.report").joinpath(PAPER_FILE).read_text(encoding="utf-8")
    return {
        (row["map"], float(row["speed_ratio"]), row["pairing"]): float(row["paper_mean"])
        for row in csv.DictReader(io.StringIO(text))
    }


def versus_paper(cells: list[Cell], described: list[dict[str, Any]]) -> dict[str, Any]:
    """{factors, rows, summaries, left_out}: ``described`` are the cells' tracking-rate
    statistics. A row is a cell on the paper's axes (its place, other ``factors``, n, mean,
    ci_low, ci_high, paper_mean, difference = mean - paper_mean, paper_inside_ci); a
    summary per combination of the other factors gives its cells, the mean absolute
    difference and how many paper values lie inside our CIs; ``left_out`` names our cells
    that the paper's table does not have."""
    paper = paper_table()
    stats = {id(c): d for c, d in zip(cells, described)}
    rows: list[dict[str, Any]] = []
    summaries: list[dict[str, Any]] = []
    left_out: list[str] = []
    for factors, group in facets(cells):
        own = []
        for cell in group:
            place = (cell.map, cell.speed_ratio, cell.pairing)
            if place not in paper:
                left_out.append(cell.label())
                continue
            d = stats[id(cell)]
            difference = d["mean"] - paper[place]
            own.append(
                {
                    "map": cell.map,
                    "speed_ratio": cell.speed_ratio,
                    "pairing": cell.pairing,
                    "factors": factors,
                    **{k: d[k] for k in ("n", "mean", "ci_low", "ci_high")},
                    "paper_mean": paper[place],
                    "difference": difference,
                    "paper_inside_ci": d["ci_low"] <= paper[place] <= d["ci_high"],
                }
            )
        rows += own
        if own:
            summaries.append(
                {
                    "factors": factors,
                    "cells": len(own),
                    "paper_cells": len(paper),
                    "mean_absolute_difference": math.fsum(abs(r["difference"]) for r in own)
                    / len(own),
                    "paper_inside_ci": sum(r["paper_inside_ci"] for r in own),
                }
            )
    names = list(cells[0].factors) if cells else []
    return {"factors": names, "rows": rows, "summaries": summaries, "left_out": left_out}


def render_paper_md(versus: dict[str, Any]) -> str:
    """vs_paper.md: one row per cell on the paper's axes, the summaries, what is left out."""
    header = [
        *versus["factors"],
        *CELL_COLUMNS,
        "ours [CI] n",
        "paper",
        "ours - paper",
        "paper in our CI",
    ]
    rows = [
        [
            *cell_texts(row),
            cell_text(row),
            f"{100 * row['paper_mean']:.2f}%",
            f"{100 * row['difference']:+.1f} pp",
            "yes" if row["paper_inside_ci"] else "no",
        ]
        for row in versus["rows"]
    ]
    lines = [
        "# Tracking rate: ours beside the paper's Table 1",
        "",
        "Per cell on the paper's axes: our mean tracking success rate with its 95% "
        "percentile-bootstrap CI and n, the paper's mean (Table 1; the paper gives no "
        "spread), the difference in percentage points and whether the paper's mean lies "
        "inside our CI.",
        "",
        *markdown_rows(header, rows),
    ]
    lines += ["", "## Summary", ""]
    for s in versus["summaries"]:
        where = f" ({facet_text(s['factors'])})" if s["factors"] else ""
        lines.append(
            f"- {s['cells']} of the paper's {s['paper_cells']} cells{where}: mean absolute "
            f"difference {100 * s['mean_absolute_difference']:.1f} pp, the paper's mean inside "
            f"our CI in {s['paper_inside_ci']} of {s['cells']}"
        )
    left_out = versus["left_out"]
    lines += ["", f"## Left out (not in the paper's Table 1): {len(left_out)}", ""]
    lines += [f"- {label}" for label in left_out] or ["None."]
    return "\n".join(lines) + "\n"


def render_paper_csv(versus: dict[str, Any]) -> str:
    """vs_paper.csv: the other factors, map, speed_ratio, pairing, then :data:`STATS`
    (fractions)."""
    return cells_csv(versus["factors"], STATS, versus["rows"], lambda row: [row[s] for s in STATS])
