"""Non-inferiority: is value A of a factor no worse than value B by more than a stated
margin, cell by cell, on common seeds? (``--noninferior FACTOR=A,B --margin DELTA``)

"No worse than" is not "not significantly worse": a test of A < B that fails to reject is
an absence of evidence, and it passes a real shortfall whose interval lies wholly below
zero. Here the claim is the alternative and the shortfall the null, against a margin
DELTA fixed before looking (Wellek, *Testing Statistical Hypotheses of Equivalence and
Noninferiority*, 2nd ed. 2010, ch. 1-2). Per cell, on the seeds both sides played (same
seed, same spawn poses), with d = A - B the paired difference of the tracking rates
(fractions; DELTA = 0.02 is 2 percentage points):

    H0: mean(d) <= -DELTA    against    H1: mean(d) > -DELTA.

The test is the paired percentile bootstrap of mean(d) (the report's resamples: 10,000
with a fixed seed, :func:`pegame.bootstrap.bootstrap_means`): p = (1 + #{resample means
<= -DELTA}) / (1 + resamples), the p-value that inverts the one-sided percentile bound
(Davison & Hinkley, *Bootstrap Methods and their Application*, 1997, Sec. 4.4; its
smallest value is 1 / 10,001), Holm-Bonferroni corrected across the comparison's tested
cells. A is non-inferior in a cell where the corrected p is at most alpha = 0.05
(one-sided); shown beside it, the one-sided 95% lower bound of mean(d) (the 5th percentile
of the resample means), which lies above -DELTA where the uncorrected p is below 0.05. The
bound is on the mean, so a few seeds lost badly count in full (a rank test on d + DELTA
would not see them behind many small gains).

It is always on the tracking rate (higher is better), whatever ``--metric`` is.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from pegame.bootstrap import BOOT_RESAMPLES, bootstrap_means
from pegame.errors import PegameError
from pegame.report.cells import Cell, file_safe
from pegame.report.compare import cell_place, check, matched
from pegame.report.paired import BySeed, by_seed
from pegame.report.statistics import ALPHA, holm
from pegame.report.tables import (
    CELL_COLUMNS,
    blank,
    cell_texts,
    cells_csv,
    markdown_rows,
)

TEST = "paired percentile bootstrap of the mean difference, one-sided"
KEYS = ("n_pairs", "mean_x", "mean_y", "mean_difference", "lower_bound", "p")
STATS = [
    "n_a",
    "n_b",
    "n_pairs",
    "mean_a",
    "mean_b",
    "mean_difference",
    "lower_bound",
    "margin",
    "p",
    "p_holm",
    "noninferior",
]


class MarginError(PegameError, ValueError):
    """A non-inferiority margin that is missing, negative or not below 1."""


def check_margin(margin: float | None) -> float:
    """``margin`` as a float in [0, 1); :class:`MarginError` otherwise."""
    if margin is None or not math.isfinite(margin) or not 0 <= margin < 1:
        raise MarginError(
            f"--margin {margin} is not a non-inferiority margin. Give the largest shortfall "
            f"of the tracking rate that still counts as no worse, as a fraction in [0, 1) "
            f"stated before looking at the results, e.g. --margin 0.02 (2 percentage points)."
        )
    return float(margin)


def noninferiority_test(x: BySeed, y: BySeed, margin: float) -> dict[str, Any]:
    """Is ``x`` no worse than ``y`` by more than ``margin`` on their common seeds?
    {n_pairs, mean_x, mean_y, mean_difference (x - y), lower_bound (one-sided 95%), p};
    every value but n_pairs None without common seeds."""
    seeds = sorted(x.keys() & y.keys())
    if not seeds:
        return {key: 0 if key == "n_pairs" else None for key in KEYS}
    a = np.array([x[s] for s in seeds])
    b = np.array([y[s] for s in seeds])
    differences = np.round(a - b, 12)
    means = bootstrap_means(differences.tolist())
    below = int(np.sum(means <= -margin + 1e-12))
    return {
        "n_pairs": len(seeds),
        "mean_x": math.fsum(a) / len(seeds),
        "mean_y": math.fsum(b) / len(seeds),
        "mean_difference": math.fsum(differences) / len(seeds),
        "lower_bound": float(np.percentile(means, 100 * ALPHA)),
        "p": (1 + below) / (1 + BOOT_RESAMPLES),
    }


def decide(rows: list[dict[str, Any]]) -> None:
    """Holm-correct the tested rows' p in place and set ``noninferior`` (None: untested)."""
    tested = [row for row in rows if row["p"] is not None]
    for row in rows:
        row.update(p_holm=None, noninferior=None)
    for row, adjusted in zip(tested, holm([row["p"] for row in tested])):
        row.update(p_holm=adjusted, noninferior=adjusted <= ALPHA)


def noninferior(
    cells: list[Cell], factor: str, a: str, b: str, margin: float | None
) -> dict[str, Any]:
    """Value ``a`` of ``factor`` against value ``b`` in every cell where both have games:
    {factor, a, b, margin, others, test, alpha, rows, summary}; a row has the cell's place
    and other ``factors``, n_a / n_b, the :func:`noninferiority_test` values (mean_a,
    mean_b, mean_difference = A - B), p_holm and noninferior."""
    check(cells, factor, (a, b), "--noninferior")
    margin = check_margin(margin)
    others = [f for f in cells[0].factors if f != factor]
    rows = []
    for cell_a, cell_b in matched(cells, factor, a, b):
        test = noninferiority_test(by_seed(cell_a.games), by_seed(cell_b.games), margin)
        rows.append(
            {
                **cell_place(cell_a, factor, b),
                "factors": {f: cell_a.factors[f] for f in others},
                "n_a": len(cell_a.games),
                "n_b": len(cell_b.games),
                "n_pairs": test["n_pairs"],
                "mean_a": test["mean_x"],
                "mean_b": test["mean_y"],
                "mean_difference": test["mean_difference"],
                "lower_bound": test["lower_bound"],
                "margin": margin,
                "p": test["p"],
            }
        )
    decide(rows)
    tested = [row for row in rows if row["p"] is not None]
    return {
        "factor": factor,
        "a": a,
        "b": b,
        "margin": margin,
        "difference": "A - B",
        "others": others,
        "test": f"{TEST}, Holm-Bonferroni across the tested cells",
        "alpha": ALPHA,
        "rows": rows,
        "summary": {
            "cells": len(rows),
            "tested": len(tested),
            "noninferior": sum(bool(row["noninferior"]) for row in tested),
        },
    }


def file_stem(factor: str) -> str:
    """'noninferior_pursuer.k_heading' (characters unsafe in file names as '_')."""
    return file_safe(f"noninferior_{factor}")


def points(value: float | None) -> str:
    """A difference in percentage points, '–' for None."""
    return "–" if value is None else f"{100 * value:+.1f}"


def render_noninferior_md(result: dict[str, Any]) -> str:
    """noninferior_<factor>.md: one table row per compared cell."""
    factor, a, b, margin = result["factor"], result["a"], result["b"], result["margin"]
    summary = result["summary"]
    header = [
        *result["others"],
        *CELL_COLUMNS,
        "pairs",
        f"mean ({a})",
        f"mean ({b})",
        f"{a} - {b} (pp)",
        "one-sided 95% lower bound (pp)",
        "p",
        "p (Holm)",
        "non-inferior",
    ]
    flag = {None: "not tested", True: "yes", False: "no"}
    lines = [
        f"# {factor}: is {a} no worse than {b} by more than {100 * margin:g} points?",
        "",
        f"Per cell where both {factor}={a} and {factor}={b} have games, on their common seeds "
        f"(same spawn poses), d = {a} - {b} of the tracking rate: H0 mean(d) <= "
        f"-{100 * margin:g} pp against H1 mean(d) > -{100 * margin:g} pp, by the {TEST} "
        f"(p = (1 + resample means at or below -{100 * margin:g} pp) / (1 + "
        f"{BOOT_RESAMPLES:,})), Holm-Bonferroni corrected across the {summary['tested']} "
        f"tested cells; non-inferior where the corrected p <= {result['alpha']}. "
        f"Non-inferior in {summary['noninferior']} of {summary['tested']} tested cells "
        f"({summary['cells']} compared).",
        "",
        *markdown_rows(
            header,
            [
                [
                    *cell_texts(row),
                    f"{row['n_pairs']} (of {row['n_a']}, {row['n_b']})",
                    *(
                        "–" if row[k] is None else f"{100 * row[k]:.1f}%"
                        for k in ("mean_a", "mean_b")
                    ),
                    points(row["mean_difference"]),
                    points(row["lower_bound"]),
                    "–" if row["p"] is None else f"{row['p']:.3g}",
                    "–" if row["p_holm"] is None else f"{row['p_holm']:.3g}",
                    flag[row["noninferior"]],
                ]
                for row in result["rows"]
            ],
        ),
    ]
    return "\n".join(lines) + "\n"


def render_noninferior_csv(result: dict[str, Any]) -> str:
    """noninferior_<factor>.csv: the other factors, map, speed_ratio, pairing, then
    :data:`STATS`; rates as fractions, empty where not tested."""
    return cells_csv(
        result["others"], STATS, result["rows"], lambda row: [blank(row[s]) for s in STATS]
    )
