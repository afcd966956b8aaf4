"""Box plots of tracking success rates like the paper's Fig. 5 (distributions across speed
ratios, 5a, and across environments, 5b) and Fig. 8 (overall, per pairing).

Each figure has one panel (facet) per combination of the sweep's other factors (see
:mod:`pegame.report.cells`), side by side on shared axes; one panel when there are none.
Figures are drawn on a bare :class:`matplotlib.figure.Figure` (Agg rendering, no pyplot
state); SVGs carry no date and stable ids, so the same report gives the same bytes.
"""

from __future__ import annotations

import io
import math
from collections.abc import Callable
from typing import Any

import matplotlib
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from pegame.report.cells import MAP_ORDER, PAIRING_ORDER, Cell, facets, ordered
from pegame.report.hypotheses import facet_text
from pegame.report.tables import MAP_TITLES

RATE_LABEL = "tracking success rate (%)"
MAX_COLUMNS = 3  # facets per row of panels


def draw_boxes(ax: Axes, groups: list[str], series: dict[str, list[list[float]]]) -> None:
    """Per x group, one box of rates (%) per series (pairing) side by side."""
    width = 0.8 / max(1, len(series))
    for j, (_label, data) in enumerate(series.items()):
        offset = (j - (len(series) - 1) / 2) * width
        kept = [(i + offset, [100 * v for v in values]) for i, values in enumerate(data) if values]
        if kept:
            ax.boxplot(
                [v for _, v in kept],
                positions=[x for x, _ in kept],
                widths=0.9 * width,
                patch_artist=True,
                manage_ticks=False,
                boxprops={"facecolor": f"C{j}"},
                medianprops={"color": "black"},
            )
    ax.set_xticks(range(len(groups)), groups)
    ax.set_xlim(-0.6, len(groups) - 0.4)
    ax.set_ylim(-5, 105)


def box_figure(
    panels: list[tuple[str, dict[str, list[list[float]]]]],
    groups: list[str],
    pairings: list[str],
    xlabel: str,
    title: str,
) -> Figure:
    """A figure of box-plot panels [(panel title, {pairing: rates per x group})]."""
    columns = min(MAX_COLUMNS, len(panels))
    rows = math.ceil(len(panels) / columns)
    width = max(6.0, 0.8 * len(groups) * max(1, len(pairings)) + 2)
    fig = Figure(figsize=(width * columns, 4.5 * rows), layout="constrained")
    axes = fig.subplots(rows, columns, squeeze=False, sharey=True).ravel()
    for index, (ax, (panel, series)) in enumerate(zip(axes, panels)):
        draw_boxes(ax, groups, series)
        ax.set(xlabel=xlabel, ylabel=RATE_LABEL if index % columns == 0 else "", title=panel)
    for ax in axes[len(panels) :]:
        ax.set_visible(False)
    fig.suptitle(title)
    if pairings:
        axes[0].legend(
            handles=[Patch(facecolor=f"C{j}", label=p) for j, p in enumerate(pairings)],
            title="pursuer-evader",
            loc="best",
        )
    return fig


def figures(cells: list[Cell]) -> dict[str, Figure]:
    """Paper Fig. 5a (by speed ratio), Fig. 5b (by environment), Fig. 8 (by pairing), one
    panel per combination of the other factors."""
    maps = ordered({c.map for c in cells}, MAP_ORDER)
    ratios = sorted({c.speed_ratio for c in cells})
    pairings = ordered({c.pairing for c in cells}, PAIRING_ORDER)
    split = facets(cells)

    def panels(groups: list[Any], keep: Callable[[Cell, Any, str], bool]) -> list[tuple[str, dict]]:
        return [
            (
                facet_text(factors),
                {
                    p: [[v for c in group if keep(c, g, p) for v in c.rates] for g in groups]
                    for p in pairings
                },
            )
            for factors, group in split
        ]

    return {
        "fig5a_speed_ratio": box_figure(
            panels(ratios, lambda c, r, p: c.speed_ratio == r and c.pairing == p),
            [f"{r:g}" for r in ratios],
            pairings,
            "pursuer-to-evader speed ratio $v_p/v_e$",
            "Success rate by speed ratio (Fig. 5a)",
        ),
        "fig5b_environment": box_figure(
            panels(maps, lambda c, m, p: c.map == m and c.pairing == p),
            [MAP_TITLES.get(m, m) for m in maps],
            pairings,
            "environment",
            "Success rate by environment (Fig. 5b)",
        ),
        "fig8_pairing": box_figure(
            panels([None], lambda c, _, p: c.pairing == p),
            ["all environments and speed ratios"],
            pairings,
            "pursuer and evader behaviour",
            "Overall success rate by pairing (Fig. 8)",
        ),
    }


def figure_bytes(fig: Figure, fmt: str) -> bytes:
    """The figure encoded as PNG or SVG; SVG without date and with stable ids (reproducible)."""
    buffer = io.BytesIO()
    with matplotlib.rc_context({"svg.hashsalt": "pegame"}):
        fig.savefig(buffer, format=fmt, dpi=150, metadata={"Date": None} if fmt == "svg" else None)
    return buffer.getvalue()
