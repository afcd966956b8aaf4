"""Compare two values of one factor, cell by cell, on common seeds (factor studies).

A *factor* is a setting that differs between a sweep's configurations (see
:mod:`pegame.report.cells`), e.g. ``detector.miss_probability``. :func:`compare` takes
every cell of the paper's layout (environment x speed ratio v_p/v_e x pairing, and each
combination of the sweep's *other* factors) where both values A and B of the factor have
games (the factor may also be one of the paper's axes, e.g. ``pairing=S-S,cooperative-S``
for two pursuers in otherwise equal cells), and compares B against A on the seeds they
share (same seed, same spawn poses): n pairs, the mean of each side on those seeds, the mean difference B - A with its
percentile-bootstrap CI over seeds, the rank-biserial correlation, and the two-sided
Wilcoxon signed-rank test (Pratt's zeros, see :mod:`pegame.report.paired`),
Holm-Bonferroni corrected across the comparison's tested cells. It compares one measure
(:mod:`pegame.report.measures`, the tracking rate by default) over the games that define
it. Rates are fractions in report.json and CSV, percent and percentage points in Markdown.

From the command line: ``python -m pegame.report DIR ... --compare FACTOR=A,B`` writes
``compare_<FACTOR>.md`` and ``compare_<FACTOR>.csv`` and adds the comparison to
report.json's ``comparisons``. A and B are written as the report writes values (0.3,
last_seen, true).
"""

from __future__ import annotations

from typing import Any

from pegame.errors import PegameError
from pegame.report.cells import AXES, Cell, file_safe, value_text
from pegame.report.measures import MEASURES, TRACKING, Measure
from pegame.report.paired import TEST_NAME, by_seed, difference_text, paired_test
from pegame.report.statistics import ALPHA, holm
from pegame.report.tables import (
    CELL_COLUMNS,
    blank,
    cell_texts,
    cells_csv,
    markdown_rows,
)

STATS = [
    "n_a",
    "n_b",
    "n_pairs",
    "mean_a",
    "mean_b",
    "mean_difference",
    "ci_low",
    "ci_high",
    "zero_differences",
    "rank_biserial",
    "W",
    "p",
    "p_holm",
]


class CompareError(PegameError, ValueError):
    """A comparison asked for a factor or a value that the sweep does not have."""


def parse_compare(text: str, option: str = "--compare") -> tuple[str, str, str]:
    """'detector.miss_probability=0,0.3' as (factor, A, B); ``option`` names the command
    line option in the error."""
    factor, _, values = text.partition("=")
    pair = values.split(",")
    if not factor or len(pair) != 2 or not all(pair):
        raise CompareError(
            f"{option} {text!r} is not FACTOR=A,B. Give one setting that differs between "
            f"the sweep's configurations and two of its values, e.g. "
            f"{option} detector.miss_probability=0,0.3."
        )
    return factor, pair[0], pair[1]


def file_stem(factor: str) -> str:
    """'compare_detector.miss_probability' (characters unsafe in file names as '_')."""
    return file_safe(f"compare_{factor}")


def cell_value(cell: Cell, factor: str) -> Any:
    """The cell's value of ``factor``: a paper axis (map, speed_ratio, pairing) or another
    factor."""
    return getattr(cell, factor) if factor in AXES else cell.factors[factor]


def check(
    cells: list[Cell], factor: str, values: tuple[str, str], option: str = "--compare"
) -> None:
    """Raise :class:`CompareError` (naming the command line ``option``) unless ``factor``
    is a factor of ``cells`` (or a paper axis) with both ``values``."""
    factors = list(cells[0].factors) if cells else []
    if factor not in factors and factor not in AXES:
        raise CompareError(
            f"{option}: {factor!r} is not a factor of this sweep (a setting that differs "
            f"between its configurations) nor a paper axis ({', '.join(AXES)}). Its "
            f"factors: {', '.join(factors) or 'none'}."
        )
    seen = sorted({value_text(cell_value(c, factor)) for c in cells})
    absent = [v for v in values if v not in seen]
    if absent:
        raise CompareError(
            f"{option} {factor}: no games with {' or '.join(map(repr, absent))}. The values "
            f"of {factor} in this sweep: {', '.join(seen)}."
        )
    if values[0] == values[1]:
        raise CompareError(f"{option} {factor}: A and B are both {values[0]!r}; give two.")


def matched(cells: list[Cell], factor: str, a: str, b: str) -> list[tuple[Cell, Cell]]:
    """(cell of A, cell of B) for every place where both values of ``factor`` have a cell:
    the same paper axes (those other than ``factor``) and the same other factors; in
    table order."""

    def place(cell: Cell) -> tuple:
        rest = tuple(cell.facet[i] for i, f in enumerate(cell.factors) if f != factor)
        axes = tuple(getattr(cell, axis) for axis in AXES if axis != factor)
        return axes, rest

    sides = {
        value: {place(c): c for c in cells if value_text(cell_value(c, factor)) == value}
        for value in (a, b)
    }
    return [(cell_a, sides[b][key]) for key, cell_a in sides[a].items() if key in sides[b]]


def cell_place(cell: Cell, factor: str, other: str) -> dict[str, Any]:
    """A compared row's paper axes; the compared axis, when ``factor`` is one, as
    'A vs B' (``other`` is B)."""
    axes = {axis: getattr(cell, axis) for axis in AXES}
    if factor in AXES:
        axes[factor] = f"{value_text(getattr(cell, factor))} vs {other}"
    return axes


def compare(
    cells: list[Cell], factor: str, a: str, b: str, measure: Measure = TRACKING
) -> dict[str, Any]:
    """Value ``b`` of ``factor`` against value ``a`` in every cell where both have games
    (cells in table order), on ``measure``: {factor, a, b, measure (its name), others,
    test, alpha, rows, summary}. A row has
    the cell's map, speed_ratio, pairing and other ``factors``, n_a / n_b (all games of
    each side), n_pairs, mean_a / mean_b on the common seeds, mean_difference (B - A) with
    ci_low / ci_high, zero_differences, rank_biserial, W, p and p_holm; every statistic is
    None when the two sides share no seed (not tested)."""
    check(cells, factor, (a, b))
    others = [f for f in cells[0].factors if f != factor]
    rows = []
    for cell_a, cell_b in matched(cells, factor, a, b):
        test = paired_test(
            by_seed(cell_b.games, measure.name), by_seed(cell_a.games, measure.name), "two-sided"
        )
        rows.append(
            {
                **cell_place(cell_a, factor, b),
                "factors": {f: cell_a.factors[f] for f in others},
                "n_a": len(cell_a.games),
                "n_b": len(cell_b.games),
                **{k: v for k, v in test.items() if k not in ("mean_x", "mean_y")},
                "mean_a": test["mean_y"],
                "mean_b": test["mean_x"],
                "p_holm": None,
            }
        )
    tested = [row for row in rows if row["p"] is not None]
    for row, adjusted in zip(tested, holm([row["p"] for row in tested])):
        row["p_holm"] = adjusted
    return {
        "factor": factor,
        "a": a,
        "b": b,
        "measure": measure.name,
        "difference": "B - A",
        "others": others,
        "test": f"{TEST_NAME}, two-sided, Holm-Bonferroni across the tested cells",
        "alpha": ALPHA,
        "rows": rows,
        "summary": {
            "cells": len(rows),
            "tested": len(tested),
            "significant": sum(row["p_holm"] <= ALPHA for row in tested),
        },
    }


def number(value: float | None, spec: str) -> str:
    """A statistic for a table, '–' for None."""
    return "–" if value is None else format(value, spec)


def render_compare_md(comparison: dict[str, Any]) -> str:
    """compare_<factor>.md: one table row per compared cell."""
    factor, a, b = comparison["factor"], comparison["a"], comparison["b"]
    measure = MEASURES[comparison["measure"]]
    unit = "percentage points" if measure.is_rate else measure.unit or "its own units"
    header = [
        *comparison["others"],
        *CELL_COLUMNS,
        "pairs",
        f"mean ({a})",
        f"mean ({b})",
        f"{b} - {a} [CI]",
        "rank-biserial r",
        "W",
        "p",
        "p (Holm)",
    ]
    summary = comparison["summary"]
    lines = [
        f"# {factor}: {b} against {a} ({measure.label})",
        "",
        "Per cell (environment x speed ratio x pairing"
        + (", and the other factors" if comparison["others"] else "")
        + f") where both {factor}={a} and {factor}={b} have games: the games on their common "
        f"seeds (same spawn poses) are paired on the {measure.axis_label()}. Means on those "
        f"seeds, the mean paired difference {b} - {a} in {unit} with its 95% "
        f"percentile-bootstrap CI "
        f"over seeds, the matched-pairs rank-biserial correlation, and the {TEST_NAME} "
        f"(two-sided, zero_method='pratt'; W = T+, the sum of the ranks of the positive "
        f"differences), Holm-Bonferroni corrected across the "
        f"{summary['tested']} tested cells; alpha = {comparison['alpha']}. Significant in "
        f"{summary['significant']} of {summary['tested']} tested cells ({summary['cells']} "
        f"compared).",
        "",
        *markdown_rows(
            header,
            [
                [
                    *cell_texts(row),
                    f"{row['n_pairs']} (of {row['n_a']}, {row['n_b']})",
                    *(
                        "–" if row[k] is None else measure.shown(row[k])
                        for k in ("mean_a", "mean_b")
                    ),
                    difference_text(row, measure),
                    number(row["rank_biserial"], "+.2f"),
                    number(row["W"], "g"),
                    number(row["p"], ".3g"),
                    number(row["p_holm"], ".3g"),
                ]
                for row in comparison["rows"]
            ],
        ),
    ]
    return "\n".join(lines) + "\n"


def render_compare_csv(comparison: dict[str, Any]) -> str:
    """compare_<factor>.csv: the other factors, map, speed_ratio, pairing, then
    :data:`STATS`; rates as fractions, empty where not tested."""
    return cells_csv(
        comparison["others"], STATS, comparison["rows"], lambda row: [blank(row[s]) for s in STATS]
    )
