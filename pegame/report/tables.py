"""Table 1 ("Mean tracking success rate across various environments and speed ratios") as
Markdown, CSV and LaTeX, in the paper's layout: one row per speed ratio v_p/v_e, one column
per environment x pairing. A sweep's other factors (see :mod:`pegame.report.cells`) come
first, as columns of their own, so each row is one combination of them and one speed
ratio. The table is of one measure (:mod:`pegame.report.measures`, the tracking rate by
default); rates are fractions in CSV and percentages in text. ``table1.md`` ends with the
provenance and with what is missing or failed.
"""

from __future__ import annotations

import csv
import io
import re
from collections.abc import Callable, Iterable, Sequence
from typing import Any

from pegame.bootstrap import BOOT_LEVEL, BOOT_RESAMPLES
from pegame.report.cells import MAP_ORDER, PAIRING_ORDER, Cell, ordered, value_key, value_text
from pegame.report.measures import TRACKING, Measure
from pegame.report.statistics import DESCRIBED

MAP_TITLES = {"hall": "Complex Hall", "enclosed": "Enclosed Room", "brick": "Brick Room"}


def interval_text(cell: dict[str, Any], measure: Measure) -> str:
    """'[55.0, 67.2]': a described cell's CI in the measure's shown unit."""
    low, high = (f"{measure.scale * cell[k]:.{measure.digits}f}" for k in ("ci_low", "ci_high"))
    return f"[{low}, {high}]"


def cell_text(cell: dict[str, Any] | None, measure: Measure = TRACKING) -> str:
    """'61.3% [55.0, 67.2] n=40' for a described cell, '–' for none or no games that
    define the measure."""
    if cell is None or not cell["n"]:
        return "–"
    return f"{measure.shown(cell['mean'])} {interval_text(cell, measure)} n={cell['n']}"


class Layout:
    """Where each cell goes: the factor columns, rows (other factors x speed ratio), maps
    and pairings in the paper's order, and the described cells by position."""

    def __init__(self, cells: list[Cell], described: list[dict[str, Any]]):
        self.factors = list(cells[0].factors) if cells else []
        self.maps = ordered({c.map for c in cells}, MAP_ORDER)
        self.pairings = ordered({c.pairing for c in cells}, PAIRING_ORDER)
        rows = {(c.facet, c.speed_ratio): c.factors for c in cells}
        self.rows = sorted(rows, key=lambda r: ([value_key(v) for v in rows[r].values()], r[1]))
        self.row_factors = rows
        self.lookup = {
            (c.facet, c.speed_ratio, c.map, c.pairing): d for c, d in zip(cells, described)
        }

    def row_cells(self, row: tuple) -> list[dict[str, Any] | None]:
        """The described cells of one row, map-major, None where the sweep has none."""
        return [self.lookup.get((*row, m, p)) for m in self.maps for p in self.pairings]

    def factor_texts(self, row: tuple) -> list[str]:
        """The other factors' values of one row, as text."""
        return [value_text(v) for v in self.row_factors[row].values()]


def render_table_md(layout: Layout, notes: list[str], measure: Measure = TRACKING) -> str:
    """Table 1 of ``measure`` in Markdown, then ``notes`` (the provenance and problem
    sections)."""
    header = (
        layout.factors + ["v_p/v_e"] + [f"{m} {p}" for m in layout.maps for p in layout.pairings]
    )
    lines = [
        f"# Table 1: mean {measure.label}",
        "",
        f"Mean {measure.axis_label()} per environment, pursuer-to-evader speed ratio v_p/v_e and "
        f"pairing (R-R: random pursuer, random evader; S-R: smart pursuer, random evader; S-S: "
        f"smart pursuer, smart evader), with its {100 * BOOT_LEVEL:.0f}% percentile-bootstrap "
        f"confidence interval ({BOOT_RESAMPLES:,} resamples) and the number of games n"
        + ("" if measure is TRACKING else " that define it")
        + ". Layout "
        "of the paper's Table 1"
        + (
            "; the columns before v_p/v_e are the settings that differ between the sweep's "
            "configurations."
            if layout.factors
            else "."
        )
        + (
            ""
            if measure is TRACKING
            else " The hypotheses (hypotheses.md) are tested on the tracking rate."
        ),
        "",
        "| " + " | ".join(header) + " |",
        "|" + "---|" * len(header),
    ]
    for row in layout.rows:
        texts = (
            layout.factor_texts(row)
            + [f"{row[1]:g}"]
            + [cell_text(c, measure) for c in layout.row_cells(row)]
        )
        lines.append("| " + " | ".join(texts) + " |")
    return "\n".join(lines + [""] + notes) + "\n"


def csv_value(value: Any) -> Any:
    """A setting value for CSV: numbers and strings as they are, None empty, others JSON."""
    return (
        ""
        if value is None
        else value
        if isinstance(value, (int, float, str))
        else value_text(value)
    )


#: the columns that name a row of a per-cell table (estimation, vs_paper, compare) after
#: its other factors: in Markdown, and in CSV
CELL_COLUMNS = ("environment", "v_p/v_e", "pairing")
CELL_CSV_COLUMNS = ("map", "speed_ratio", "pairing")


def cell_texts(row: dict[str, Any]) -> list[str]:
    """The Markdown texts that name a per-cell row: its other factors' values, then
    :data:`CELL_COLUMNS`."""
    factors = [value_text(v) for v in row["factors"].values()]
    return [*factors, row["map"], value_text(row["speed_ratio"]), row["pairing"]]


def cell_values(row: dict[str, Any]) -> list[Any]:
    """The CSV values that name a per-cell row: its other factors, then
    :data:`CELL_CSV_COLUMNS`."""
    factors = [csv_value(v) for v in row["factors"].values()]
    return [*factors, row["map"], row["speed_ratio"], row["pairing"]]


def blank(value: Any) -> Any:
    """A CSV cell: empty where there is no value."""
    return "" if value is None else value


def cells_csv(
    factors: Sequence[str],
    columns: Sequence[str],
    rows: Iterable[dict[str, Any]],
    values: Callable[[dict[str, Any]], list[Any]],
) -> str:
    """A per-cell table as CSV: the header ``factors``, :data:`CELL_CSV_COLUMNS`,
    ``columns``; then each row's :func:`cell_values` and ``values(row)``."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow([*factors, *CELL_CSV_COLUMNS, *columns])
    for row in rows:
        writer.writerow([*cell_values(row), *values(row)])
    return buffer.getvalue()


def markdown_rows(header: list[str], rows: list[list[str]]) -> list[str]:
    """A Markdown table's lines: the header, its rule, one line per row of texts."""
    return [
        "| " + " | ".join(header) + " |",
        "|" + "---|" * len(header),
        *("| " + " | ".join(texts) + " |" for texts in rows),
    ]


def render_table_csv(cells: list[Cell], described: list[dict[str, Any]]) -> str:
    """One row per cell: map, speed_ratio, pairing, the other factors, statistics; rates as
    fractions."""
    factors = list(cells[0].factors) if cells else []
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(["map", "speed_ratio", "pairing", *factors, *DESCRIBED])
    for cell, stats in zip(cells, described):
        writer.writerow(
            [
                cell.map,
                cell.speed_ratio,
                cell.pairing,
                *(csv_value(v) for v in cell.factors.values()),
                *("" if stats[s] is None else stats[s] for s in DESCRIBED),
            ]
        )
    return buffer.getvalue()


def tex_escape(text: str) -> str:
    """Escape LaTeX's special characters in a plain string."""
    return re.sub(r"([&%$#_{}])", r"\\\1", text)


def tex_cell(cell: dict[str, Any] | None, measure: Measure = TRACKING) -> str:
    """A table cell in LaTeX: mean, then CI and n in small type."""
    if cell is None or not cell["n"]:
        return "--"
    return (
        f"{tex_escape(measure.shown(cell['mean']))} {{\\scriptsize "
        f"{interval_text(cell, measure)} $n$={cell['n']}}}"
    )


def render_table_tex(layout: Layout, measure: Measure = TRACKING) -> str:
    """Table 1 of ``measure`` as a booktabs tabular in the paper's layout (other factors
    leftmost)."""
    maps, width, lead = layout.maps, len(layout.pairings), len(layout.factors) + 1
    groups = " & ".join(
        f"\\multicolumn{{{width}}}{{c}}{{\\textbf{{{tex_escape(MAP_TITLES.get(m, m))}}}}}"
        for m in maps
    )
    rules = " ".join(
        f"\\cmidrule(lr){{{lead + 1 + i * width}-{lead + (i + 1) * width}}}"
        for i in range(len(maps))
    )
    names = [f"\\texttt{{{tex_escape(f)}}}" for f in layout.factors]
    lines = [
        f"% Generated by pegame.report: mean {measure.axis_label()}, 95% bootstrap CI and n per "
        "cell (paper, Table 1). Needs \\usepackage{booktabs}.",
        "\\begin{tabular}{" + "l" * lead + (" " + "c" * width) * len(maps) + "}",
        "\\toprule",
        " & ".join(["" for _ in names] + ["\\textbf{Speed ratio}"] + ([groups] if maps else []))
        + " \\\\",
        rules,
        " & ".join(names + ["$v_p/v_e$"] + [tex_escape(p) for _ in maps for p in layout.pairings])
        + " \\\\",
        "\\midrule",
    ]
    for row in layout.rows:
        texts = [tex_escape(t) for t in layout.factor_texts(row)] + [f"{row[1]:g}"]
        lines.append(
            " & ".join(texts + [tex_cell(c, measure) for c in layout.row_cells(row)]) + " \\\\"
        )
    return "\n".join(lines + ["\\bottomrule", "\\end{tabular}"]) + "\n"


def version_text(version: dict[str, Any] | None) -> str:
    """'pegame 0.3.0, commit 1a2b3c4 (dirty)', 'unknown (no provenance)' for old lines."""
    if version is None:
        return "unknown (no provenance)"
    commit = version.get("commit")
    dirty = {True: " (dirty)", False: "", None: " (dirty: unknown)"}.get(version.get("dirty"), "")
    return f"pegame {version.get('pegame')}, commit {commit[:12] if commit else 'unknown'}{dirty}"


def render_provenance(provenance: dict[str, Any]) -> list[str]:
    """The "Provenance" section: the code versions and configurations covered, warnings."""
    lines = ["## Provenance", ""]
    lines += [
        f"- {version_text(v['version'])}: {v['games']} games" for v in provenance["code_versions"]
    ]
    lines += [f"- {len(provenance['config_hashes'])} configurations (config hashes)", ""]
    warnings = provenance["warnings"]
    lines += [f"### Warnings: {len(warnings)}", ""] + (
        [f"- WARNING: {w}" for w in warnings] or ["None."]
    )
    return lines + [""]


def render_problems(sections: dict[str, list[str]]) -> list[str]:
    """The "Missing and failed" section, one subsection per kind of problem."""
    lines = ["## Missing and failed", ""]
    for title, items in sections.items():
        lines += [f"### {title}: {len(items)}", ""] + (items + [""] if items else ["None.", ""])
    return lines


def problem_sections(report: dict[str, Any]) -> dict[str, list[str]]:
    """The items of :func:`render_problems` from report.json's content."""

    def overrides(entry: dict[str, Any]) -> str:
        given = entry.get("overrides")
        return " ".join(given) if given is not None else "unknown"

    return {
        "Failed cells (invalid configuration)": [
            f"- job {c['job']}: overrides {overrides(c)}: {c['error']}"
            for c in report["failed_cells"]
        ],
        "Failed games": [
            f"- {f['map']}, v_p/v_e {float(f['speed_ratio']):g}, {f['pairing']}, seed {f['seed']} "
            f"(job {f['job']}): {f['error']} (traceback: {f['job']}/{f.get('traceback_file')})"
            for f in report["failed_games"]
        ],
        "Missing jobs (no results.jsonl)": [
            f"- job {m['job']}: overrides {overrides(m)}" for m in report["missing_jobs"]
        ],
        "Unfinished jobs (no summary line at the end)": [
            f"- job {job}" for job in report["unfinished_jobs"]
        ],
        "Duplicate games (same config hash and seed; the later line counts)": [
            f"- config {d['config_hash'][:12]}, seed {d['seed']}: kept {d['kept']}, dropped "
            + ", ".join(d["dropped"])
            for d in report["duplicates"]["games"]
        ],
        "Skipped lines": [
            f"- {s['file']}"
            + (f" line {s['line']}" if s["line"] is not None else "")
            + f": {s['reason']}"
            for s in report["skipped_lines"]
        ],
    }
