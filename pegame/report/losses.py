"""Why tracks are lost, per cell: ``losses.md`` / ``.csv`` and the stacked bars
``loss_causes.png`` / ``.svg``.

Each game line carries ``loss_causes`` (:mod:`pegame.losses`: per cause the count of
losses of track, how many were reacquired, the time lost and the mean time to
reacquire, summed over a team's pursuer-evader pairs). Per cell, over its games that
carry them (n; older lines without them are left out), and per cause in
:data:`pegame.losses.CAUSES` order:

- ``count_per_game``: the mean number of losses per game;
- ``time_lost_per_game_s``: the mean time lost per game (s; a loss not reacquired by the
  game's end counts to the end);
- ``share``: the cause's fraction of the cell's losses (None without losses);
- ``mean_reacquire_s``: the mean time to reacquire over every reacquired loss of the
  cell's games (s; each game's mean weighted by its reacquired losses; None without one).

The figure has two panels, losses per game and time lost per game, one stacked bar per
cell with a segment per cause. Written whenever some game carries loss causes.
"""

from __future__ import annotations

import math
from typing import Any

from matplotlib.figure import Figure

from pegame.losses import CAUSES
from pegame.report.cells import Cell, value_text
from pegame.report.figures import figure_bytes
from pegame.report.tables import (
    CELL_COLUMNS,
    blank,
    cell_texts,
    cells_csv,
    markdown_rows,
)

STATS = ("count_per_game", "time_lost_per_game_s", "share", "mean_reacquire_s")


def carried(games: list[dict[str, Any]]) -> list[dict[str, dict[str, Any]]]:
    """The ``loss_causes`` of the games that carry them."""
    return [g["loss_causes"] for g in games if isinstance(g.get("loss_causes"), dict)]


def _of(causes: dict[str, Any], cause: str, key: str) -> float:
    """A game's ``key`` of ``cause`` (0 when the game has none of it)."""
    value = (causes.get(cause) or {}).get(key)
    return 0.0 if value is None else float(value)


def cell_losses(cell: Cell) -> dict[str, Any]:
    """A cell's row: its place, ``games`` (n that carry loss causes), ``losses_per_game``
    and per cause its :data:`STATS` (module docstring)."""
    games = carried(cell.games)
    n = len(games)
    counts = {c: math.fsum(_of(g, c, "count") for g in games) for c in CAUSES}
    total = math.fsum(counts.values())
    row: dict[str, Any] = {
        "map": cell.map,
        "speed_ratio": cell.speed_ratio,
        "pairing": cell.pairing,
        "factors": cell.factors,
        "games": n,
        "losses_per_game": total / n if n else None,
    }
    for cause in CAUSES:
        reacquired = math.fsum(_of(g, cause, "reacquired") for g in games)
        waited = math.fsum(
            _of(g, cause, "mean_reacquire_s") * _of(g, cause, "reacquired") for g in games
        )
        row[cause] = {
            "count_per_game": counts[cause] / n if n else None,
            "time_lost_per_game_s": (
                math.fsum(_of(g, cause, "time_lost_s") for g in games) / n if n else None
            ),
            "share": counts[cause] / total if total else None,
            "mean_reacquire_s": waited / reacquired if reacquired else None,
        }
    return row


def losses_table(cells: list[Cell]) -> dict[str, Any]:
    """{factors, causes, rows}: a :func:`cell_losses` row per cell."""
    return {
        "factors": list(cells[0].factors) if cells else [],
        "causes": list(CAUSES),
        "rows": [cell_losses(c) for c in cells],
    }


def _number(value: float | None, digits: int) -> str:
    return "–" if value is None else f"{value:.{digits}f}"


def render_losses_md(table: dict[str, Any]) -> str:
    """losses.md: a row per cell, per cause its losses and time lost per game."""
    causes = table["causes"]
    header = [*table["factors"], *CELL_COLUMNS, "games", "losses/game", *causes]
    rows = [
        [
            *cell_texts(row),
            str(row["games"]),
            _number(row["losses_per_game"], 2),
            *(
                f"{_number(row[c]['count_per_game'], 2)} "
                f"({_number(row[c]['time_lost_per_game_s'], 1)} s)"
                for c in causes
            ),
        ]
        for row in table["rows"]
    ]
    lines = [
        "# Why tracks are lost: loss causes per cell",
        "",
        "A loss of track is a tick at which a pursuer stops detecting an evader; its cause "
        "is read from the ground truth at that tick, the first that holds of: `missed` (the "
        "evader's centre in view, not detected), `blocked` (the pursuer stopped by an "
        "obstacle), `turning` (the pursuer turning in place), `bearing` (the evader outside "
        "the field of view sideways), `occluded` (line of sight blocked), `far` and `near` "
        "(beyond the camera's range limits); see docs/explanation/loss-causes.md. Per cause: "
        "the mean losses per game and, in brackets, the mean time lost per game (a loss "
        "not reacquired counts to the game's end); teams sum their pursuer-evader pairs. "
        "`games`: the games that carry loss causes. losses.csv adds each cause's share of "
        "the losses and its mean time to reacquire.",
        "",
        *markdown_rows(header, rows),
    ]
    return "\n".join(lines) + "\n"


def render_losses_csv(table: dict[str, Any]) -> str:
    """losses.csv: the other factors, map, speed_ratio, pairing, games, losses_per_game,
    then per cause its :data:`STATS` (empty where undefined)."""
    columns = [f"{cause}_{s}" for cause in table["causes"] for s in STATS]
    return cells_csv(
        table["factors"],
        ["games", "losses_per_game", *columns],
        table["rows"],
        lambda row: [
            row["games"],
            blank(row["losses_per_game"]),
            *(blank(row[c][s]) for c in table["causes"] for s in STATS),
        ],
    )


def _label(row: dict[str, Any]) -> str:
    """A bar's label: map, v_p/v_e, pairing and the other factors' values."""
    factors = [value_text(v) for v in row["factors"].values()]
    return "\n".join([f"{row['map']} {value_text(row['speed_ratio'])}", row["pairing"], *factors])


def losses_figure(table: dict[str, Any]) -> Figure:
    """The stacked bars: losses per game (top) and time lost per game (s, bottom), a bar
    per cell, a segment per cause."""
    rows = [r for r in table["rows"] if r["games"]]
    fig = Figure(figsize=(max(6.0, 2.0 + 0.45 * len(rows)), 7.5), layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True)
    x = list(range(len(rows)))
    for ax, key, label in (
        (top, "count_per_game", "losses per game"),
        (bottom, "time_lost_per_game_s", "time lost per game (s)"),
    ):
        base = [0.0] * len(rows)
        for k, cause in enumerate(table["causes"]):
            heights = [r[cause][key] or 0.0 for r in rows]
            ax.bar(x, heights, bottom=base, color=f"C{k}", label=cause, width=0.8)
            base = [b + h for b, h in zip(base, heights)]
        ax.set_ylabel(label)
    bottom.set_xticks(x, [_label(r) for r in rows], fontsize=7)
    top.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), title="cause")
    fig.suptitle("Why tracks are lost: loss causes per cell (mean per game)")
    return fig


def loss_files(report: dict[str, Any], cells: list[Cell]) -> dict[str, str | bytes]:
    """losses.md / .csv and loss_causes.png / .svg when some game carries loss causes
    (nothing otherwise); the table is added to ``report`` as ``loss_causes``."""
    if not any(carried(c.games) for c in cells):
        return {}
    table = report["loss_causes"] = losses_table(cells)
    fig = losses_figure(table)
    return {
        "losses.md": render_losses_md(table),
        "losses.csv": render_losses_csv(table),
        **{f"loss_causes.{fmt}": figure_bytes(fig, fmt) for fmt in ("png", "svg")},
    }
