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
  factors (:mod:`~pegame.report.hypotheses`);
- ``report.json``: all of the above, machine-readable.

Every file is written atomically; a file that cannot be written is a :class:`ReportError`.
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
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
    "ReportError",
    "bootstrap_ci",
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
    sweep_dirs: str | Path | list[str | Path], out_dir: str | Path | None = None
) -> dict[str, Any]:
    """Aggregate one or more sweep directories and write the tables, figures,
    hypotheses.md and report.json into ``out_dir`` (default: the sweep directory; required
    for several). Returns report.json's content."""
    dirs = [Path(d) for d in ([sweep_dirs] if isinstance(sweep_dirs, (str, Path)) else sweep_dirs)]
    if out_dir is None and len(dirs) != 1:
        raise ReportError(
            f"A report of {len(dirs)} sweep directories needs an output directory (--out)."
        )
    out = Path(out_dir) if out_dir is not None else dirs[0]
    report, cells = aggregate(load_sweep(dirs), dirs)
    layout = Layout(cells, report["cells"])
    notes = render_provenance(report["provenance"]) + render_problems(problem_sections(report))
    files: dict[str, str | bytes] = {
        "table1.md": render_table_md(layout, notes),
        "table1.csv": render_table_csv(cells, report["cells"]),
        "table1.tex": render_table_tex(layout),
        "hypotheses.md": render_hypotheses(report["hypotheses"]),
    }
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
    args = parser.parse_args(argv)
    for directory in args.sweep_dirs:
        if not directory.is_dir():
            parser.error(f"not a directory: {directory}")
    if args.out is None and len(args.sweep_dirs) > 1:
        parser.error("several sweep directories need --out")
    logging.basicConfig(level=logging.INFO, format="%(levelname)s: %(message)s")
    try:
        report = write_report(args.sweep_dirs, args.out)
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
        print(f"{title(h)}: {h['summary']['text']}")
    return 0
