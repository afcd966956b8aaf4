"""``python -m pegame.report DIR [DIR ...] [--out OUT]``: aggregate sweeps like the paper.

Reads every ``results.jsonl`` below one or more Hydra multirun directories
(:mod:`~pegame.report.load`), groups the games into cells, one per configuration
(:mod:`~pegame.report.cells`: every setting that differs between the jobs is a factor;
the paper's axes are environment x speed ratio v_p/v_e x pairing, the others are shown
beside them), and per cell computes the mean tracking success rate with a 95%
percentile-bootstrap confidence interval, the median and the standard deviation
(:mod:`~pegame.report.statistics`). It writes into the output directory

- ``table1.md`` / ``table1.csv`` / ``table1.tex``: the paper's Table 1 with CIs and n, one
  column per other factor (:mod:`~pegame.report.tables`); the Markdown ends with the
  provenance (code versions, configurations, warnings) and with the failed cells, failed
  games, missing and unfinished jobs, duplicates and skipped lines;
- ``fig5a_speed_ratio``, ``fig5b_environment``, ``fig8_pairing``: box plots like the
  paper's Fig. 5 and Fig. 8, PNG and SVG, one panel per combination of the other factors
  (:mod:`~pegame.report.figures`);
- ``hypotheses.md``: the paper's three hypotheses, tested per combination of the other
  factors (:mod:`~pegame.report.hypotheses`), unpaired (Mann-Whitney U) and, on the seeds
  both pairings share, paired (Wilcoxon signed-rank, :mod:`~pegame.report.paired`);
- with ``--compare FACTOR=A,B`` (repeatable): ``compare_<FACTOR>.md`` / ``.csv``, value B
  of one factor against value A per cell on common seeds (:mod:`~pegame.report.compare`);
- ``report.json``: all of the above, machine-readable.

Every file is written atomically; a file that cannot be written is a :class:`ReportError`.
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from pegame.errors import PegameError
from pegame.files import write_atomic
from pegame.report.cells import (
    Cell,
    canonical,
    code_version,
    group_cells,
    identity,
    other_factors,
    select,
)
from pegame.report.compare import (
    CompareError,
    compare,
    file_stem,
    parse_compare,
    render_compare_csv,
    render_compare_md,
)
from pegame.report.figures import figure_bytes, figures
from pegame.report.hypotheses import (
    UNTESTED,
    hypotheses,
    hypotheses_per_facet,
    render_hypotheses,
    title,
)
from pegame.report.load import ReportError, Sweep, load_sweep
from pegame.report.statistics import (
    ALPHA,
    BOOT_LEVEL,
    BOOT_RESAMPLES,
    BOOT_SEED,
    bootstrap_ci,
    holm,
)
from pegame.report.tables import (
    Layout,
    problem_sections,
    render_problems,
    render_provenance,
    render_table_csv,
    render_table_md,
    render_table_tex,
)

__all__ = [
    "ALPHA",
    "UNTESTED",
    "CompareError",
    "ReportError",
    "bootstrap_ci",
    "compare",
    "holm",
    "hypotheses",
    "load_sweep",
    "main",
    "write_report",
]

log = logging.getLogger("pegame.report")


def provenance(games: list[dict[str, Any]], cells: list[Cell]) -> dict[str, Any]:
    """The code versions (full provenance, with game counts) and config hashes the report
    covers, and a warning per cell that mixes code versions or config hashes."""
    versions: dict[str, dict[str, Any]] = {}
    hashes: dict[str, int] = {}
    for game in games:
        full = game.get("provenance")
        entry = versions.setdefault(
            canonical(full), {"version": code_version(game), "provenance": full, "games": 0}
        )
        entry["games"] += 1
        hashes[identity(game)] = hashes.get(identity(game), 0) + 1
    warnings = [
        f"cell {cell.label()} mixes {' and '.join(cell.mixed())}: "
        f"{len(cell.code_versions())} code versions, {len(cell.config_hashes())} config hashes"
        for cell in cells
        if cell.mixed()
    ]
    for warning in warnings:
        log.warning("%s", warning)
    return {
        "code_versions": [versions[k] for k in sorted(versions)],
        "config_hashes": [{"config_hash": h, "games": n} for h, n in sorted(hashes.items())],
        "warnings": warnings,
    }


def aggregate(sweep: Sweep, dirs: list[Path]) -> tuple[dict[str, Any], list[Cell]]:
    """report.json's content and the cells."""
    chosen = select(sweep.records)
    cells = group_cells(chosen.games, other_factors(chosen.games))
    return {
        "sweep_dirs": [str(d) for d in dirs],
        "games": len(chosen.games),
        "bootstrap": {"resamples": BOOT_RESAMPLES, "level": BOOT_LEVEL, "seed": BOOT_SEED},
        "alpha": ALPHA,
        "factors": list(cells[0].factors) if cells else [],
        "cells": [cell.summary() for cell in cells],
        "hypotheses": hypotheses_per_facet(cells),
        "provenance": provenance(chosen.games, cells),
        "failed_cells": sweep.invalid,
        "failed_games": chosen.failed,
        "missing_jobs": sweep.missing,
        "unfinished_jobs": sweep.unfinished,
        "duplicates": {
            "count": sum(len(d["dropped"]) for d in chosen.duplicates),
            "games": chosen.duplicates,
        },
        "skipped_lines": sweep.skipped,
        "job_summaries": sweep.summaries,
    }, cells


def write_report(
    sweep_dirs: str | Path | list[str | Path],
    out_dir: str | Path | None = None,
    comparisons: Sequence[tuple[str, str, str]] = (),
) -> dict[str, Any]:
    """Aggregate one or more sweep directories and write the tables, figures,
    hypotheses.md and report.json into ``out_dir`` (default: the sweep directory; required
    for several), and per (factor, A, B) of ``comparisons`` compare_<factor>.md / .csv
    (:func:`~pegame.report.compare.compare`). Returns report.json's content."""
    dirs = [Path(d) for d in ([sweep_dirs] if isinstance(sweep_dirs, (str, Path)) else sweep_dirs)]
    if out_dir is None and len(dirs) != 1:
        raise ReportError(
            f"A report of {len(dirs)} sweep directories needs an output directory (--out)."
        )
    out = Path(out_dir) if out_dir is not None else dirs[0]
    factors = [factor for factor, _, _ in comparisons]
    twice = sorted({f for f in factors if factors.count(f) > 1})
    if twice:
        raise CompareError(
            f"--compare names {', '.join(twice)} more than once: one comparison per factor "
            f"(each writes compare_<factor>.md)."
        )
    report, cells = aggregate(load_sweep(dirs), dirs)
    report["comparisons"] = [compare(cells, *spec) for spec in comparisons]
    layout = Layout(cells, report["cells"])
    notes = render_provenance(report["provenance"]) + render_problems(problem_sections(report))
    files: dict[str, str | bytes] = {
        "table1.md": render_table_md(layout, notes),
        "table1.csv": render_table_csv(cells, report["cells"]),
        "table1.tex": render_table_tex(layout),
        "hypotheses.md": render_hypotheses(report["hypotheses"]),
    }
    for comparison in report["comparisons"]:
        stem = file_stem(comparison["factor"])
        files[f"{stem}.md"] = render_compare_md(comparison)
        files[f"{stem}.csv"] = render_compare_csv(comparison)
    for name, fig in figures(cells).items():
        for fmt in ("png", "svg"):
            files[f"{name}.{fmt}"] = figure_bytes(fig, fmt)
    report["outputs"] = sorted([*files, "report.json"])
    files["report.json"] = json.dumps(report, indent=2) + "\n"
    try:
        out.mkdir(parents=True, exist_ok=True)
        for name, data in files.items():
            write_atomic(out / name, data)
    except OSError as error:
        raise ReportError(
            f"Cannot write the report into {out}: {error.strerror or error} "
            f"({getattr(error, 'filename', None) or out}). Choose a writable "
            f"output directory with --out, or free some space."
        ) from error
    return report


def main(argv: list[str] | None = None) -> int:
    """Command line: aggregate sweep directories and print where the report went. Exit 0
    when written, 2 on bad input or when the report cannot be written."""
    parser = argparse.ArgumentParser(
        prog="python -m pegame.report",
        description="Aggregate pegame Hydra multiruns: Table 1, Fig. 5 / Fig. 8 box plots, "
        "hypothesis tests and report.json. Cells are configurations: every setting "
        "that differs between the jobs is a factor.",
    )
    parser.add_argument(
        "sweep_dirs",
        type=Path,
        nargs="+",
        metavar="DIR",
        help="Hydra multirun directories (several are compared as one study)",
    )
    parser.add_argument(
        "--out",
        type=Path,
        default=None,
        help="output directory (default: the sweep directory; required for several)",
    )
    parser.add_argument(
        "--compare",
        action="append",
        default=[],
        metavar="FACTOR=A,B",
        help="compare value B of a factor (a setting that differs between the jobs) against "
        "value A in every cell, paired on common seeds; writes compare_FACTOR.md/.csv "
        "(repeatable, one per factor)",
    )
    args = parser.parse_args(argv)
    try:
        comparisons = [parse_compare(text) for text in args.compare]
    except CompareError as error:
        parser.error(str(error))
    for directory in args.sweep_dirs:
        if not directory.is_dir():
            parser.error(f"not a directory: {directory}")
    if args.out is None and len(args.sweep_dirs) > 1:
        parser.error("several sweep directories need --out")
    logging.basicConfig(level=logging.INFO, format="%(levelname)s: %(message)s")
    try:
        report = write_report(args.sweep_dirs, args.out, comparisons)
    except PegameError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    print(
        f"{report['games']} games, {len(report['failed_games'])} failed, "
        f"{len(report['failed_cells'])} failed cells, {len(report['missing_jobs'])} missing "
        f"jobs, {report['duplicates']['count']} duplicates, {len(report['skipped_lines'])} "
        f"skipped lines -> {args.out or args.sweep_dirs[0]}"
    )
    for warning in report["provenance"]["warnings"]:
        print(f"WARNING: {warning}")
    for h in report["hypotheses"]:
        paired = h["summary_paired"]
        print(
            f"{title(h)}: {h['summary']['text']} by {h['test']}; "
            f"{paired['text']} by {paired['test']}"
        )
    for c in report["comparisons"]:
        s = c["summary"]
        print(
            f"{c['factor']}: {c['b']} against {c['a']}: significant in {s['significant']} of "
            f"{s['tested']} tested cells -> {file_stem(c['factor'])}.md"
        )
    return 0
