"""Box plots of a measure (the tracking success rate by default, see
:mod:`pegame.report.measures`) like the paper's Fig. 5 (distributions across speed ratios,
5a, and across environments, 5b) and Fig. 8 (overall, per pairing), and a curve per
numeric factor.

Each box figure has one panel (facet) per combination of the sweep's other factors (see
:mod:`pegame.report.cells`), side by side on shared axes; one panel when there are none.
A numeric factor (n_particles = 100, 500, 2000) is also drawn as ``curve_<factor>``: the
cells' means with their 95% bootstrap CIs (error bars) against the factor's value, one
panel per environment, one line per combination of speed ratio, pairing and the other
factors. Figures are drawn on a bare :class:`matplotlib.figure.Figure` (Agg rendering, no
pyplot state); SVGs carry no date and stable ids, so the same report gives the same bytes.
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

from pegame.report.cells import (
    MAP_ORDER,
    PAIRING_ORDER,
    Cell,
    facets,
    file_safe,
    numeric_factors,
    ordered,
    value_text,
)
from pegame.report.hypotheses import facet_text
from pegame.report.measures import TRACKING, Measure
from pegame.report.tables import MAP_TITLES

MAX_COLUMNS = 3  # facets per row of panels


def draw_boxes(
    ax: Axes, groups: list[str], series: dict[str, list[list[float]]], measure: Measure
) -> None:
    """Per x group, one box of the measure (in its shown unit) per series (pairing) side by
    side; rates on a fixed 0-100% axis."""
    width = 0.8 / max(1, len(series))
    for j, (_label, data) in enumerate(series.items()):
        offset = (j - (len(series) - 1) / 2) * width
        kept = [
            (i + offset, [measure.scale * v for v in values])
            for i, values in enumerate(data)
            if values
        ]
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
    if measure.is_rate:
        ax.set_ylim(-5, 105)


def panel_grid(count: int, width: float) -> tuple[Figure, list[Axes]]:
    """A figure of ``count`` panels of ``width`` inches, at most :data:`MAX_COLUMNS` per
    row, sharing the y axis; the unused panels of the last row hidden."""
    columns = min(MAX_COLUMNS, count)
    rows = math.ceil(count / columns)
    fig = Figure(figsize=(width * columns, 4.5 * rows), layout="constrained")
    axes = list(fig.subplots(rows, columns, squeeze=False, sharey=True).ravel())
    for ax in axes[count:]:
        ax.set_visible(False)
    return fig, axes[:count]


def box_figure(
    panels: list[tuple[str, dict[str, list[list[float]]]]],
    groups: list[str],
    pairings: list[str],
    xlabel: str,
    title: str,
    measure: Measure = TRACKING,
) -> Figure:
    """A figure of box-plot panels [(panel title, {pairing: values per x group})]."""
    width = max(6.0, 0.8 * len(groups) * max(1, len(pairings)) + 2)
    fig, axes = panel_grid(len(panels), width)
    columns = min(MAX_COLUMNS, len(panels))
    for index, (ax, (panel, series)) in enumerate(zip(axes, panels)):
        draw_boxes(ax, groups, series, measure)
        ax.set(
            xlabel=xlabel,
            ylabel=measure.axis_label() if index % columns == 0 else "",
            title=panel,
        )
    fig.suptitle(title)
    if pairings:
        axes[0].legend(
            handles=[Patch(facecolor=f"C{j}", label=p) for j, p in enumerate(pairings)],
            title="pursuer-evader",
            loc="best",
        )
    return fig


def heading(measure: Measure) -> str:
    """The measure's label capitalised for a figure's title: 'Tracking success rate'."""
    return measure.label[:1].upper() + measure.label[1:]


def box_figures(cells: list[Cell], measure: Measure = TRACKING) -> dict[str, Figure]:
    """Paper Fig. 5a (by speed ratio), Fig. 5b (by environment), Fig. 8 (by pairing) of
    ``measure``, one panel per combination of the other factors."""
    maps = ordered({c.map for c in cells}, MAP_ORDER)
    ratios = sorted({c.speed_ratio for c in cells})
    pairings = ordered({c.pairing for c in cells}, PAIRING_ORDER)
    split = facets(cells)

    def panels(groups: list[Any], keep: Callable[[Cell, Any, str], bool]) -> list[tuple[str, dict]]:
        return [
            (
                facet_text(factors),
                {
                    p: [
                        [v for c in group if keep(c, g, p) for v in c.values(measure.name)]
                        for g in groups
                    ]
                    for p in pairings
                },
            )
            for factors, group in split
        ]

    what = heading(measure)
    return {
        "fig5a_speed_ratio": box_figure(
            panels(ratios, lambda c, r, p: c.speed_ratio == r and c.pairing == p),
            [f"{r:g}" for r in ratios],
            pairings,
            "pursuer-to-evader speed ratio $v_p/v_e$",
            f"{what} by speed ratio (Fig. 5a)",
            measure,
        ),
        "fig5b_environment": box_figure(
            panels(maps, lambda c, m, p: c.map == m and c.pairing == p),
            [MAP_TITLES.get(m, m) for m in maps],
            pairings,
            "environment",
            f"{what} by environment (Fig. 5b)",
            measure,
        ),
        "fig8_pairing": box_figure(
            panels([None], lambda c, _, p: c.pairing == p),
            ["all environments and speed ratios"],
            pairings,
            "pursuer and evader behaviour",
            f"Overall {measure.label} by pairing (Fig. 8)",
            measure,
        ),
    }


Point = tuple[float, dict[str, Any]]  # (the factor's value, the described cell)


def curve_lines(
    cells: list[Cell], described: list[dict[str, Any]], factor: str
) -> dict[str, dict[str, list[Point]]]:
    """{map: {line label: points sorted by the factor's value}}: one line per combination
    of speed ratio, pairing and the other factors; cells without games that define the
    measure left out."""
    maps = ordered({c.map for c in cells}, MAP_ORDER)
    lines: dict[str, dict[str, list[Point]]] = {m: {} for m in maps}
    for cell, stats in zip(cells, described):
        if not stats["n"]:
            continue
        rest = [f"{k}={value_text(v)}" for k, v in cell.factors.items() if k != factor]
        label = ", ".join([f"v_p/v_e {cell.speed_ratio:g}", cell.pairing, *rest])
        lines[cell.map].setdefault(label, []).append((float(cell.factors[factor]), stats))
    return {
        m: {label: sorted(points, key=lambda p: p[0]) for label, points in by_label.items()}
        for m, by_label in lines.items()
    }


def curve_figure(
    cells: list[Cell], described: list[dict[str, Any]], factor: str, measure: Measure
) -> Figure:
    """The mean of ``measure`` with its CI against the numeric ``factor``, one panel per
    environment; a log x axis when the values are positive and span a factor of 10 or
    more."""
    lines = curve_lines(cells, described, factor)
    labels = list(dict.fromkeys(label for by_label in lines.values() for label in by_label))
    fig, axes = panel_grid(len(lines), 6.0)
    xs = [float(c.factors[factor]) for c in cells]
    logarithmic = min(xs) > 0 and max(xs) >= 10 * min(xs)
    for index, (ax, (map_name, by_label)) in enumerate(zip(axes, lines.items())):
        for label, points in by_label.items():
            color = f"C{labels.index(label) % 10}"
            x = [value for value, _ in points]
            y = [measure.scale * stats["mean"] for _, stats in points]
            low = [measure.scale * stats["ci_low"] for _, stats in points]
            high = [measure.scale * stats["ci_high"] for _, stats in points]
            ax.plot(x, y, marker="o", color=color, label=label)
            ax.errorbar(
                x,
                y,
                yerr=[[m - lo for m, lo in zip(y, low)], [hi - m for m, hi in zip(y, high)]],
                fmt="none",
                ecolor=color,
                capsize=3,
            )
        if logarithmic:
            ax.set_xscale("log")
        ax.set_xticks(sorted(set(xs)), [value_text(v) for v in sorted(set(xs))])
        ax.set(
            xlabel=factor,
            ylabel=measure.axis_label() if index % MAX_COLUMNS == 0 else "",
            title=MAP_TITLES.get(map_name, map_name),
        )
        if measure.is_rate:
            ax.set_ylim(-5, 105)
    handles: dict[str, Any] = {}
    for ax in axes:
        for handle, label in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(label, handle)
    if handles:
        fig.legend(
            list(handles.values()),
            list(handles),
            loc="outside lower center",
            ncols=min(3, len(handles)),
        )
    fig.suptitle(f"{heading(measure)} against {factor} (mean, 95% CI)")
    return fig


def figures(
    cells: list[Cell], described: list[dict[str, Any]], measure: Measure = TRACKING
) -> dict[str, Figure]:
    """The box figures and ``curve_<factor>`` per numeric factor, of ``measure``;
    ``described`` are the cells' statistics of it."""
    curves = {
        file_safe(f"curve_{factor}"): curve_figure(cells, described, factor, measure)
        for factor in numeric_factors(cells)
    }
    return {**box_figures(cells, measure), **curves}


def figure_bytes(fig: Figure, fmt: str) -> bytes:
    """The figure encoded as PNG or SVG; SVG without date and with stable ids (reproducible)."""
    buffer = io.BytesIO()
    with matplotlib.rc_context({"svg.hashsalt": "pegame"}):
        fig.savefig(buffer, format=fmt, dpi=150, metadata={"Date": None} if fmt == "svg" else None)
    return buffer.getvalue()
