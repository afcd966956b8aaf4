"""``python -m pegame.report DIR [DIR ...] [--out OUT] [--metric NAME] [--paper]``:
aggregate sweeps like the paper.

Reads every ``results.jsonl`` below one or more Hydra multirun directories
(:mod:`~pegame.report.load`), groups the games into cells, one per configuration
(:mod:`~pegame.report.cells`: every setting that differs between the jobs is a factor;
the paper's axes are environment x speed ratio v_p/v_e x pairing, the others are shown
beside them), and per cell computes the mean of one measure (``--metric``, one of
:data:`~pegame.report.measures.MEASURES`; the tracking success rate by default) with a
95% percentile-bootstrap confidence interval, the median and the standard deviation
(:mod:`~pegame.report.statistics`). It writes into the output directory

- ``table1.md`` / ``table1.csv`` / ``table1.tex``: the paper's Table 1 with CIs and n, one
  column per other factor (:mod:`~pegame.report.tables`); the Markdown ends with the
  provenance (code versions, configurations, warnings) and with the failed cells, failed
  games, missing and unfinished jobs, duplicates and skipped lines;
- ``fig5a_speed_ratio``, ``fig5b_environment``, ``fig8_pairing``: box plots like the
  paper's Fig. 5 and Fig. 8, PNG and SVG, one panel per combination of the other factors,
  and ``curve_<factor>`` per numeric factor, the mean with its CI against the factor's
  value (:mod:`~pegame.report.figures`);
- ``hypotheses.md``: the paper's three hypotheses on the tracking rate (whatever the
  measure), tested per combination of the other factors
  (:mod:`~pegame.report.hypotheses`), unpaired (Mann-Whitney U) and, on the seeds both
  pairings share, paired (Wilcoxon signed-rank, :mod:`~pegame.report.paired`); then the
  paper's trends T1 (tracking rises with v_p/v_e: Jonckheere-Terpstra, and Page's L on
  common seeds) and T2 (S-S < S-R) (:mod:`~pegame.report.trends`);
- ``estimation.md`` / ``.csv`` when the games carry an estimation error or N_eff: the
  estimator's measures per cell (:mod:`~pegame.report.estimation`);
- ``losses.md`` / ``.csv`` and the stacked bars ``loss_causes.png`` / ``.svg`` when the
  games carry loss causes: why tracks are lost, per cell (:mod:`~pegame.report.losses`);
- with ``--paper``: ``vs_paper.md`` / ``.csv``, our tracking rates beside the paper's
  Table 1 with the difference (:mod:`~pegame.report.paper`);
- with ``--compare FACTOR=A,B`` (repeatable): ``compare_<FACTOR>.md`` / ``.csv``, value B
  of one factor against value A per cell on common seeds (:mod:`~pegame.report.compare`);
- with ``--noninferior FACTOR=A,B --margin DELTA`` (repeatable, one margin):
  ``noninferior_<FACTOR>.md`` / ``.csv``, whether A's tracking rate is no worse than B's by
  more than DELTA per cell, a one-sided paired bootstrap test on common seeds with Holm
  (:mod:`~pegame.report.noninferiority`);
- ``report.json``: all of the above, machine-readable.

With a measure other than the tracking rate, the files of that measure (tables, figures,
comparisons, report.json) carry its name, ``table1_<NAME>.md``, so they sit beside the
tracking-rate report of the same directory. The stages are logged at INFO on the
``pegame.report`` logger. Every file is written atomically; a file that cannot be written
is a :class:`ReportError`.
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from pegame.bootstrap import BOOT_LEVEL, BOOT_RESAMPLES, BOOT_SEED, bootstrap_ci
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
from pegame.report.estimation import (
    carried,
    estimation,
    render_estimation_csv,
    render_estimation_md,
)
from pegame.report.figures import figure_bytes, figures
from pegame.report.hypotheses import (
    UNTESTED,
    facet_text,
    hypotheses,
    hypotheses_per_facet,
    per_facet,
    render_hypotheses,
    title,
)
from pegame.report.load import ReportError, Sweep, find_job_dirs, load_sweep
from pegame.report.losses import loss_files
from pegame.report.measures import MEASURES, TRACKING, Measure, MeasureError, measure
from pegame.report.noninferiority import (
    MarginError,
    check_margin,
    noninferior,
    render_noninferior_csv,
    render_noninferior_md,
)
from pegame.report.noninferiority import file_stem as noninferior_stem
from pegame.report.paper import render_paper_csv, render_paper_md, versus_paper
from pegame.report.statistics import ALPHA, holm
from pegame.report.tables import (
    Layout,
    problem_sections,
    render_problems,
    render_provenance,
    render_table_csv,
    render_table_md,
    render_table_tex,
)
from pegame.report.trends import render_trends, trends

__all__ = [
    "ALPHA",
    "UNTESTED",
    "MEASURES",
    "CompareError",
    "MarginError",
    "MeasureError",
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


def aggregate(
    sweep: Sweep, dirs: list[Path], measured: Measure = TRACKING
) -> tuple[dict[str, Any], list[Cell]]:
    """report.json's content and the cells; the cells' statistics are of ``measured``,
    the hypotheses of the tracking rate."""
    chosen = select(sweep.records)
    cells = group_cells(chosen.games, other_factors(chosen.games))
    factors = list(cells[0].factors) if cells else []
    log.info(
        "%d games, %d cells%s; statistics of %s (%s bootstrap resamples per cell)",
        len(chosen.games),
        len(cells),
        f", factors beside the paper's axes: {', '.join(factors)}" if factors else "",
        measured.name,
        f"{BOOT_RESAMPLES:,}",
    )
    described = [cell.summary(measured.name) for cell in cells]
    if cells and not any(d["n"] for d in described):
        log.warning("no game defines %s: its tables and figures are empty", measured.name)
    log.info("testing hypotheses H1-H3 and the trends T1-T2 on the tracking rate")
    return {
        "sweep_dirs": [str(d) for d in dirs],
        "games": len(chosen.games),
        "metric": measured.name,
        "bootstrap": {"resamples": BOOT_RESAMPLES, "level": BOOT_LEVEL, "seed": BOOT_SEED},
        "alpha": ALPHA,
        "factors": factors,
        "cells": described,
        "hypotheses": hypotheses_per_facet(cells),
        "trends": per_facet(cells, trends),
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


def named(name: str, measured: Measure) -> str:
    """A file name of the measure's report: 'table1.md', or 'table1_mean_distance.md' for
    a measure other than the tracking rate."""
    if measured is TRACKING:
        return name
    stem, _, suffix = name.rpartition(".")
    return f"{stem}_{measured.name}.{suffix}"


def extra_tables(report: dict[str, Any], cells: list[Cell], paper: bool) -> dict[str, str]:
    """estimation.md/.csv when the games carry the estimator's measures, vs_paper.md/.csv
    with ``paper``; their content is added to ``report``."""
    files: dict[str, str] = {}
    if carried(cells):
        log.info("tabulating the estimator's error, N_eff and resamplings")
        report["estimation"] = estimation(cells)
        files["estimation.md"] = render_estimation_md(report["estimation"])
        files["estimation.csv"] = render_estimation_csv(report["estimation"])
    if paper:
        log.info("setting our tracking rates beside the paper's Table 1")
        rates = (
            report["cells"]
            if report["metric"] == TRACKING.name
            else [cell.summary(TRACKING.name) for cell in cells]
        )
        report["vs_paper"] = versus_paper(cells, rates)
        files["vs_paper.md"] = render_paper_md(report["vs_paper"])
        files["vs_paper.csv"] = render_paper_csv(report["vs_paper"])
    return files


def write_report(
    sweep_dirs: str | Path | list[str | Path],
    out_dir: str | Path | None = None,
    comparisons: Sequence[tuple[str, str, str]] = (),
    metric: str = TRACKING.name,
    paper: bool = False,
    noninferiors: Sequence[tuple[str, str, str]] = (),
    margin: float | None = None,
) -> dict[str, Any]:
    """Aggregate one or more sweep directories and write the tables, figures,
    hypotheses.md and report.json into ``out_dir`` (default: the sweep directory; required
    for several), and per (factor, A, B) of ``comparisons`` compare_<factor>.md / .csv
    (:func:`~pegame.report.compare.compare`), all of the measure ``metric`` (file names
    with its name unless it is the tracking rate); with ``paper`` also vs_paper.md / .csv;
    per (factor, A, B) of ``noninferiors`` noninferior_<factor>.md / .csv, A against B at
    the non-inferiority ``margin`` (a fraction of the tracking rate; required with them,
    :func:`~pegame.report.noninferiority.noninferior`). Returns report.json's content."""
    measured = measure(metric)
    dirs = [Path(d) for d in ([sweep_dirs] if isinstance(sweep_dirs, (str, Path)) else sweep_dirs)]
    if out_dir is None and len(dirs) != 1:
        raise ReportError(
            f"A report of {len(dirs)} sweep directories needs an output directory (--out)."
        )
    out = Path(out_dir) if out_dir is not None else dirs[0]
    for option, specs in (("--compare", comparisons), ("--noninferior", noninferiors)):
        factors = [factor for factor, _, _ in specs]
        twice = sorted({f for f in factors if factors.count(f) > 1})
        if twice:
            raise CompareError(
                f"{option} names {', '.join(twice)} more than once: one per factor "
                f"(each writes its own file named after the factor)."
            )
    if noninferiors:
        margin = check_margin(margin)
    for directory in dirs:
        if directory.is_dir():
            log.info("loading %d job dirs below %s", len(find_job_dirs(directory)), directory)
    report, cells = aggregate(load_sweep(dirs), dirs, measured)
    report["comparisons"] = [compare(cells, *spec, measured) for spec in comparisons]
    report["noninferiority"] = [noninferior(cells, *spec, margin) for spec in noninferiors]
    layout = Layout(cells, report["cells"])
    notes = render_provenance(report["provenance"]) + render_problems(problem_sections(report))
    files: dict[str, str | bytes] = {
        named("table1.md", measured): render_table_md(layout, notes, measured),
        named("table1.csv", measured): render_table_csv(cells, report["cells"]),
        named("table1.tex", measured): render_table_tex(layout, measured),
        "hypotheses.md": render_hypotheses(report["hypotheses"])
        + "\n"
        + render_trends(report["trends"]),
        **extra_tables(report, cells, paper),
    }
    for comparison in report["comparisons"]:
        stem = file_stem(comparison["factor"])
        files[named(f"{stem}.md", measured)] = render_compare_md(comparison)
        files[named(f"{stem}.csv", measured)] = render_compare_csv(comparison)
    for result in report["noninferiority"]:
        stem = noninferior_stem(result["factor"])
        files[f"{stem}.md"] = render_noninferior_md(result)
        files[f"{stem}.csv"] = render_noninferior_csv(result)
    log.info("drawing the figures (PNG and SVG)")
    for name, fig in figures(cells, report["cells"], measured).items():
        for fmt in ("png", "svg"):
            files[named(f"{name}.{fmt}", measured)] = figure_bytes(fig, fmt)
    files.update(loss_files(report, cells))
    report_name = named("report.json", measured)
    report["outputs"] = sorted([*files, report_name])
    files[report_name] = json.dumps(report, indent=2) + "\n"
    log.info("writing %d files into %s", len(files), out)
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
    parser.add_argument(
        "--noninferior",
        action="append",
        default=[],
        metavar="FACTOR=A,B",
        help="test in every cell that value A of a factor tracks no worse than value B by more "
        "than --margin (one-sided paired bootstrap on common seeds, Holm across the cells; "
        "on the tracking rate); writes noninferior_FACTOR.md/.csv (repeatable, one per factor)",
    )
    parser.add_argument(
        "--margin",
        type=float,
        default=None,
        metavar="DELTA",
        help="the non-inferiority margin of --noninferior, a fraction of the tracking rate "
        "(0.02: 2 percentage points); required with it",
    )
    parser.add_argument(
        "--metric",
        default=TRACKING.name,
        metavar="NAME",
        help="the measure of result.json that the tables, CIs, figures and comparisons are of "
        f"(default {TRACKING.name}; one of {', '.join(MEASURES)}); the files of another "
        "measure carry its name (table1_NAME.md); the hypotheses stay on the tracking rate",
    )
    parser.add_argument(
        "--paper",
        action="store_true",
        help="also write vs_paper.md/.csv: our tracking rate beside the paper's Table 1, "
        "with the difference, per cell on the paper's axes",
    )
    args = parser.parse_args(argv)
    try:
        comparisons = [parse_compare(text) for text in args.compare]
        noninferiors = [parse_compare(text, "--noninferior") for text in args.noninferior]
        if noninferiors:
            check_margin(args.margin)
        elif args.margin is not None:
            parser.error("--margin is the margin of --noninferior FACTOR=A,B; give both")
        measured = measure(args.metric)
    except (CompareError, MarginError, MeasureError) as error:
        parser.error(str(error))
    for directory in args.sweep_dirs:
        if not directory.is_dir():
            parser.error(f"not a directory: {directory}")
    if args.out is None and len(args.sweep_dirs) > 1:
        parser.error("several sweep directories need --out")
    logging.basicConfig(level=logging.INFO, format="%(levelname)s: %(message)s")
    try:
        report = write_report(
            args.sweep_dirs,
            args.out,
            comparisons,
            args.metric,
            args.paper,
            noninferiors,
            args.margin,
        )
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
    if measured is not TRACKING:
        print(
            f"tables, figures and comparisons of {measured.name} -> "
            f"{named('table1.md', measured)}; the hypotheses are tested on the tracking rate"
        )
    for h in report["hypotheses"] + report["trends"]:
        paired = h["summary_paired"]
        print(
            f"{title(h)}: {h['summary']['text']} by {h['test']}; "
            f"{paired['text']} by {paired['test']}"
        )
    for c in report["comparisons"]:
        s = c["summary"]
        print(
            f"{c['factor']}: {c['b']} against {c['a']}: significant in {s['significant']} of "
            f"{s['tested']} tested cells -> "
            f"{named(file_stem(c['factor']) + '.md', measured)}"
        )
    for n in report["noninferiority"]:
        s = n["summary"]
        print(
            f"{n['factor']}: {n['a']} no worse than {n['b']} by more than "
            f"{100 * n['margin']:g} points: non-inferior in {s['noninferior']} of "
            f"{s['tested']} tested cells -> {noninferior_stem(n['factor'])}.md"
        )
    if "estimation" in report:
        print("the estimator's error while unseen, N_eff and resamplings per cell -> estimation.md")
    if "loss_causes" in report:
        print("why tracks are lost, the loss causes per cell -> losses.md, loss_causes.png")
    for s in report.get("vs_paper", {}).get("summaries", []):
        where = f" ({facet_text(s['factors'])})" if s["factors"] else ""
        print(
            f"vs paper{where}: {s['cells']} cells, mean absolute difference "
            f"{100 * s['mean_absolute_difference']:.1f} pp, the paper's mean inside our CI in "
            f"{s['paper_inside_ci']} of {s['cells']} -> vs_paper.md"
        )
    return 0
