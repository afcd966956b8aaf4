"""The estimator's measures per cell (``estimation.md`` / ``.csv``): how far the belief's
mean was from the evader while it was unseen (m), the particle filter's mean effective
sample size N_eff and its resampling count per game, each as the mean over the cell's
games with its 95% percentile-bootstrap CI and the n of games that define it.

Written whenever some game carries an estimation error or an N_eff (an estimator with a
belief mean; a particle filter). A game whose evader was never out of sight has no
estimation error, an estimator without particles no N_eff: those games are left out of
that measure's n.
"""

from __future__ import annotations

from typing import Any

from pegame.report.cells import Cell
from pegame.report.measures import MEASURES, values
from pegame.report.statistics import describe
from pegame.report.tables import (
    CELL_COLUMNS,
    blank,
    cell_text,
    cell_texts,
    cells_csv,
    markdown_rows,
)

ESTIMATION = [MEASURES[name] for name in ("mean_estimation_error", "n_eff_mean", "resamplings")]
CARRIED = ("mean_estimation_error", "n_eff_mean")  # what makes the table worth writing
STATS = ("n", "mean", "ci_low", "ci_high")


def carried(cells: list[Cell]) -> bool:
    """Whether some game of ``cells`` has an estimation error or an N_eff."""
    return any(values(c.games, name) for c in cells for name in CARRIED)


def estimation(cells: list[Cell]) -> dict[str, Any]:
    """{factors, measures, rows}: a row per cell (map, speed_ratio, pairing, factors,
    games, and per measure name its :func:`describe`)."""
    return {
        "factors": list(cells[0].factors) if cells else [],
        "measures": [m.name for m in ESTIMATION],
        "rows": [
            {
                "map": c.map,
                "speed_ratio": c.speed_ratio,
                "pairing": c.pairing,
                "factors": c.factors,
                "games": len(c.games),
                **{m.name: describe(c.values(m.name)) for m in ESTIMATION},
            }
            for c in cells
        ],
    }


def render_estimation_md(table: dict[str, Any]) -> str:
    """estimation.md: one row per cell, a column per measure."""
    header = [
        *table["factors"],
        *CELL_COLUMNS,
        "games",
        *(f"{m.axis_label()} [CI] n" for m in ESTIMATION),
    ]
    rows = [
        [*cell_texts(row), str(row["games"]), *(cell_text(row[m.name], m) for m in ESTIMATION)]
        for row in table["rows"]
    ]
    lines = [
        "# The estimator: error while unseen, N_eff and resampling",
        "",
        "Per cell, the mean over its games with a 95% percentile-bootstrap CI and n, the "
        "games that define the measure: the mean distance between the belief's mean and the "
        "evader at the ticks it was not detected (a game that never lost it has none), the "
        "particle filter's mean effective sample size N_eff = 1 / sum(w_i^2) (none for an "
        "estimator without particles) and the resamplings per game.",
        "",
        *markdown_rows(header, rows),
    ]
    return "\n".join(lines) + "\n"


def render_estimation_csv(table: dict[str, Any]) -> str:
    """estimation.csv: the other factors, map, speed_ratio, pairing, games, then per
    measure its n, mean, ci_low and ci_high (empty where no game defines it)."""
    columns = [f"{name}_{s}" for name in table["measures"] for s in STATS]
    return cells_csv(
        table["factors"],
        ["games", *columns],
        table["rows"],
        lambda row: [
            row["games"],
            *(blank(row[name][s]) for name in table["measures"] for s in STATS),
        ],
    )
