"""``python -m pegame.report <multirun dir> [--out DIR]``: aggregate a sweep like the paper.

Reads every ``results.jsonl`` below a Hydra multirun directory (one JSON record per line:
``game``, ``failed`` or ``summary``) and computes, per environment x pursuer-to-evader speed
ratio v_p/v_e x pairing (R-R, S-R, S-S, R-S: first letter of the pursuer's and the
evader's strategy), the mean tracking success rate with a 95% percentile-bootstrap
confidence interval of the mean (10,000 resamples, fixed seed), the median and the standard
deviation. It writes

- ``table1.md`` / ``table1.csv`` / ``table1.tex``: the paper's Table 1 ("Mean tracking
  success rate across various environments and speed ratios"), with CIs and n; the
  Markdown ends with the missing jobs, failed games and skipped lines;
- ``fig5a_speed_ratio``, ``fig5b_environment`` (paper Fig. 5: success-rate distributions
  across speed ratios and across environments) and ``fig8_pairing`` (paper Fig. 8: overall
  distributions per pairing), box plots as PNG and SVG;
- ``hypotheses.md``: the paper's three hypotheses (Sec. "Experiments") tested per cell
  with one-sided Mann-Whitney U tests, Holm-Bonferroni corrected at alpha = 0.05;
- ``report.json``: all of the above, machine-readable.

Games are deduplicated by (map, speed_ratio, pursuer, evader, seed); the later record wins
(jobs in natural order of their directory names, lines in file order). Figures are drawn
on a bare :class:`matplotlib.figure.Figure` (Agg rendering, no pyplot state). Every file is
written atomically. Rates are fractions in [0, 1] in data files and percentages in text.
"""

from __future__ import annotations

import argparse
import csv
import io
import json
import logging
import math
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import matplotlib
import numpy as np
import yaml
from matplotlib.figure import Figure
from matplotlib.patches import Patch
from scipy.stats import mannwhitneyu

from pegame.files import write_atomic

log = logging.getLogger(__name__)

MAP_ORDER = ("hall", "enclosed", "brick")
MAP_TITLES = {"hall": "Complex Hall", "enclosed": "Enclosed Room", "brick": "Brick Room"}
PAIRING_ORDER = ("R-R", "S-R", "S-S", "R-S")
REQUIRED = {  # the keys each record kind must have to be used
    "game": ("map", "speed_ratio", "pursuer", "evader", "seed", "pairing", "tracking_rate"),
    "failed": ("map", "speed_ratio", "pairing", "seed", "error"),
    "summary": (),
}
ALPHA = 0.05
REASONABLE_RATE = 0.45  # the paper: S-S "over 45% success rate" in most scenarios
BOOT_RESAMPLES = 10_000
BOOT_LEVEL = 0.95
BOOT_SEED = 0
RATE_LABEL = "tracking success rate (%)"
UNTESTED = "not tested (missing data)"

Cell = tuple[str, float, str]  # (map, speed_ratio, pairing)


# --------------------------------------------------------------------------- loading


@dataclass
class Sweep:
    """What a multirun directory holds: job-relative paths are POSIX strings."""

    records: list[dict[str, Any]] = field(default_factory=list)  # game/failed, tagged "job"
    summaries: list[dict[str, Any]] = field(default_factory=list)
    missing: list[dict[str, Any]] = field(default_factory=list)  # {"job", "overrides"}
    unfinished: list[str] = field(default_factory=list)  # jobs whose last record is no summary
    skipped: list[dict[str, Any]] = field(default_factory=list)  # {"file", "line", "reason"}


def natural_key(text: str) -> list[Any]:
    """Sort key that orders '2/x' before '10/x'."""
    return [int(part) if part.isdigit() else part for part in re.split(r"(\d+)", text)]


def relative(path: Path, root: Path) -> str:
    """``path`` relative to ``root`` as a POSIX string ('.' for root itself)."""
    return path.relative_to(root).as_posix() or "."


def find_job_dirs(root: Path) -> list[Path]:
    """Directories at or below ``root`` holding a job (a ``.hydra`` dir or a results.jsonl)."""
    dirs = {p.parent for p in root.rglob("results.jsonl")}
    dirs |= {p.parent for p in root.rglob(".hydra") if p.is_dir()}
    return sorted(dirs, key=lambda d: natural_key(relative(d, root)))


def read_overrides(job: Path) -> list[str] | None:
    """The job's Hydra overrides from ``.hydra/overrides.yaml``, None when absent."""
    path = job / ".hydra" / "overrides.yaml"
    return (yaml.safe_load(path.read_text()) or []) if path.is_file() else None


def parse_line(line: str) -> tuple[dict[str, Any] | None, str | None]:
    """A results.jsonl line as (record, None), or (None, why it is unusable)."""
    try:
        record = json.loads(line)
    except json.JSONDecodeError as error:
        return None, f"invalid JSON ({error.msg}; truncated write?)"
    if not isinstance(record, dict) or record.get("kind") not in REQUIRED:
        return None, f"not a record of kind {', '.join(REQUIRED)}"
    absent = [key for key in REQUIRED[record["kind"]] if record.get(key) is None]
    if absent:
        return None, f"{record['kind']} record without {', '.join(absent)}"
    return record, None


def read_jsonl(path: Path, name: str) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """The records of one results.jsonl and its skipped lines ({file: name, line, reason})."""
    records, skipped = [], []
    text = path.read_text(encoding="utf-8", errors="replace")  # a cut may split a character
    for number, line in enumerate(text.splitlines(), start=1):
        if not line.strip():
            continue
        record, reason = parse_line(line)
        if reason is not None:
            log.warning("skipping %s line %d: %s", name, number, reason)
            skipped.append({"file": name, "line": number, "reason": reason})
        else:
            records.append(record)
    return records, skipped


def load_sweep(root: str | Path) -> Sweep:
    """Read every job below the multirun directory ``root``."""
    root = Path(root)
    if not root.is_dir():
        raise FileNotFoundError(f"No such multirun directory: {root}")
    sweep = Sweep()
    for job in find_job_dirs(root):
        name, path = relative(job, root), job / "results.jsonl"
        if not path.is_file():
            sweep.missing.append({"job": name, "overrides": read_overrides(job)})
            continue
        records, skipped = read_jsonl(path, relative(path, root))
        sweep.skipped += skipped
        tagged = [{**record, "job": name} for record in records]
        sweep.records += [r for r in tagged if r["kind"] != "summary"]
        sweep.summaries += [r for r in tagged if r["kind"] == "summary"]
        if not tagged or tagged[-1]["kind"] != "summary":  # killed, maybe after a resume
            sweep.unfinished.append(name)
    return sweep


# ----------------------------------------------------------------------- aggregation


def game_key(record: dict[str, Any]) -> tuple:
    """The identity of a game: (map, speed_ratio, pursuer, evader, seed)."""
    return (record["map"], float(record["speed_ratio"]), record["pursuer"], record["evader"],
            int(record["seed"]))


def slot_key(record: dict[str, Any]) -> tuple:
    """What a failed record names: (map, speed_ratio, pairing, seed)."""
    return record["map"], float(record["speed_ratio"]), record["pairing"], int(record["seed"])


def latest(records: list[dict[str, Any]]) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """Finished games deduplicated by :func:`game_key` (the later record wins) and the failed
    games (deduplicated by :func:`slot_key`) that no later finished game replaced."""
    games: dict[tuple, tuple[int, dict]] = {}
    failures: dict[tuple, tuple[int, dict]] = {}
    for index, record in enumerate(records):
        if record["kind"] == "game":
            games[game_key(record)] = (index, record)
        elif record["kind"] == "failed":
            failures[slot_key(record)] = (index, record)
    finished: dict[tuple, int] = {}
    for index, record in games.values():
        finished[slot_key(record)] = max(index, finished.get(slot_key(record), -1))
    failed = [r for key, (i, r) in failures.items() if finished.get(key, -1) < i]
    return [record for _, record in games.values()], failed


def ordered(values: set[str], preferred: tuple[str, ...]) -> list[str]:
    """``values`` with the ``preferred`` ones first in that order, the rest sorted."""
    return [v for v in preferred if v in values] + sorted(values - set(preferred))


def rates_by_cell(games: list[dict[str, Any]]) -> dict[Cell, list[float]]:
    """Tracking rates grouped by (map, speed_ratio, pairing)."""
    rates: dict[Cell, list[float]] = {}
    for game in games:
        cell = (game["map"], float(game["speed_ratio"]), game["pairing"])
        rates.setdefault(cell, []).append(float(game["tracking_rate"]))
    return rates


def axes_of(rates: dict[Cell, list[float]]) -> tuple[list[str], list[float], list[str]]:
    """The maps, speed ratios and pairings present, in the paper's order."""
    maps = ordered({m for m, _, _ in rates}, MAP_ORDER)
    pairings = ordered({p for _, _, p in rates}, PAIRING_ORDER)
    return maps, sorted({r for _, r, _ in rates}), pairings


def bootstrap_ci(values: list[float], resamples: int = BOOT_RESAMPLES, level: float = BOOT_LEVEL,
                 seed: int = BOOT_SEED) -> tuple[float, float]:
    """Percentile-bootstrap confidence interval of the mean of ``values`` (non-empty)."""
    x = np.asarray(values, dtype=float)
    rng = np.random.default_rng(seed)
    chunk = max(1, 2**20 // x.size)  # bounds memory for large samples
    means = np.concatenate([
        x[rng.integers(0, x.size, size=(min(chunk, resamples - start), x.size))].mean(axis=1)
        for start in range(0, resamples, chunk)
    ])
    low, high = np.percentile(means, [50 * (1 - level), 50 * (1 + level)])
    return float(low), float(high)


def describe(values: list[float]) -> dict[str, Any]:
    """n, exact mean (math.fsum, order-independent), bootstrap CI, median and sample std."""
    low, high = bootstrap_ci(values)
    return {
        "n": len(values),
        "mean": math.fsum(values) / len(values),
        "ci_low": low,
        "ci_high": high,
        "median": float(np.median(values)),
        "std": float(np.std(values, ddof=1)) if len(values) > 1 else None,
    }


def cell_summary(rates: dict[Cell, list[float]], cell: Cell) -> dict[str, Any] | None:
    """:func:`describe` of a cell, None when it has no games."""
    return describe(rates[cell]) if cell in rates else None


def table_cells(rates: dict[Cell, list[float]]) -> list[dict[str, Any]]:
    """One described cell per (map, speed_ratio, pairing) with data, in table order."""
    maps, ratios, pairings = axes_of(rates)
    return [
        {"map": m, "speed_ratio": r, "pairing": p, **describe(rates[(m, r, p)])}
        for m in maps for r in ratios for p in pairings if (m, r, p) in rates
    ]


# ------------------------------------------------------------------------ hypotheses


def holm(pvalues: list[float]) -> list[float]:
    """Holm-Bonferroni adjusted p-values, in input order (reject where <= alpha)."""
    adjusted = [0.0] * len(pvalues)
    running = 0.0
    for rank, index in enumerate(sorted(range(len(pvalues)), key=pvalues.__getitem__)):
        running = max(running, min(1.0, (len(pvalues) - rank) * pvalues[index]))
        adjusted[index] = running
    return adjusted


def mann_whitney_cells(rates: dict[Cell, list[float]], cells: list[tuple[str, float]], x: str,
                       y: str, alternative: str) -> list[dict[str, Any]]:
    """Per (map, speed_ratio): one-sided Mann-Whitney U of pairing ``x``'s rates against
    ``y``'s, Holm-corrected across the tested cells; ``holds`` is None when untested."""
    rows = []
    for map_name, ratio in cells:
        a, b = rates.get((map_name, ratio, x), []), rates.get((map_name, ratio, y), [])
        row = {"map": map_name, "speed_ratio": ratio, "x": x, "y": y,
               "x_stats": cell_summary(rates, (map_name, ratio, x)),
               "y_stats": cell_summary(rates, (map_name, ratio, y)),
               "U": None, "p": None, "p_holm": None, "holds": None}
        if a and b:
            result = mannwhitneyu(a, b, alternative=alternative)
            row.update(U=float(result.statistic), p=float(result.pvalue))
        rows.append(row)
    tested = [row for row in rows if row["p"] is not None]
    for row, adjusted in zip(tested, holm([row["p"] for row in tested])):
        row.update(p_holm=adjusted, holds=adjusted <= ALPHA)
    return rows


def verdict(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """holds / fails / partly over the tested cells, or not tested."""
    tested = [row["holds"] for row in rows if row["holds"] is not None]
    k, n = sum(tested), len(tested)
    word = "not tested" if n == 0 else "holds" if k == n else "fails" if k == 0 else "partly"
    return {"verdict": word, "k": k, "n": n, "untested": len(rows) - n,
            "text": UNTESTED if n == 0 else f"{word} (in {k} of {n} cells)"}


def hypothesis_1(rates: dict[Cell, list[float]], cells: list[tuple[str, float]]) -> dict[str, Any]:
    """H1: the smart pursuer tracks better than a random pursuer (S-R > R-R per cell)."""
    rows = mann_whitney_cells(rates, cells, "S-R", "R-R", "greater")
    return {
        "id": "H1", "pairings": ["S-R", "R-R"],
        "claim": "The smart pursuer can track the evader better than a random pursuer.",
        "tested": "Per environment and speed ratio: S-R tracking rates are stochastically "
                  "greater than R-R (one-sided Mann-Whitney U, alternative='greater').",
        "rows": rows, "summary": verdict(rows),
    }


def hypothesis_2(rates: dict[Cell, list[float]], cells: list[tuple[str, float]]) -> dict[str, Any]:
    """H2: the smart pursuer keeps tracking when slower than the evader (v_p/v_e < 1)."""
    maps = sorted({m for m, _ in cells}, key=[m for m, _ in cells].index)
    slow = sorted({r for _, r in cells if r < 1}) or [0.5]
    rows = mann_whitney_cells(rates, [(m, r) for m in maps for r in slow], "S-R", "R-R", "greater")
    for row in rows:
        row["x_stats_at_1"] = cell_summary(rates, (row["map"], 1.0, "S-R"))
    return {
        "id": "H2", "pairings": ["S-R", "R-R"],
        "claim": "The smart pursuer maintains a high tracking rate even with comparatively "
                 "slower speed than the evader (paper: at half the evader's speed, Fig. 5a).",
        "tested": "At each speed ratio v_p/v_e < 1 (the paper's 0.5), per environment: S-R "
                  "tracking rates are stochastically greater than R-R (one-sided Mann-Whitney "
                  "U, alternative='greater'). The S-R mean there is shown beside the S-R mean "
                  "at v_p/v_e = 1 for reference; 'high' has no threshold in the paper and is "
                  "not tested.",
        "rows": rows, "summary": verdict(rows),
    }


def hypothesis_3(rates: dict[Cell, list[float]], cells: list[tuple[str, float]]) -> dict[str, Any]:
    """H3: a smart evader is tracked less than a random one (S-S < S-R), yet reasonably
    (S-S mean above 45%); a cell holds when both do."""
    rows = mann_whitney_cells(rates, cells, "S-S", "S-R", "less")
    for row in rows:
        stats = row["x_stats"]
        row["tracked_less"] = row["holds"]
        row["reasonable"] = None if stats is None else stats["mean"] > REASONABLE_RATE
        if row["holds"] is not None:
            row["holds"] = row["tracked_less"] and row["reasonable"]
    reasonable = [row["reasonable"] for row in rows if row["reasonable"] is not None]
    return {
        "id": "H3", "pairings": ["S-S", "S-R"],
        "claim": "The smart pursuer maintains a reasonably high tracking performance even when "
                 "the evader is aware of the intentions of the pursuer; tracking a smart evader "
                 "succeeds less often than tracking a random one, and the smart pursuer has "
                 "over 45% success rate in the majority of the scenarios.",
        "tested": "Per environment and speed ratio: S-S tracking rates are stochastically "
                  "less than S-R (one-sided Mann-Whitney U, alternative='less'), and the S-S "
                  f"mean exceeds {100 * REASONABLE_RATE:.0f}%; a cell holds when both do.",
        "rows": rows, "summary": verdict(rows),
        "reasonable_cells": {"k": sum(reasonable), "n": len(reasonable)},
        "note": f"S-S mean above {100 * REASONABLE_RATE:.0f}% in {sum(reasonable)} of "
                f"{len(reasonable)} cells (paper: in the majority of the scenarios).",
    }


def hypotheses(rates: dict[Cell, list[float]]) -> list[dict[str, Any]]:
    """The paper's three hypotheses, each tested per (map, speed_ratio) cell."""
    maps, ratios, _ = axes_of(rates)
    present = {(m, r) for m, r, _ in rates}
    cells = [(m, r) for m in maps for r in ratios if (m, r) in present]
    return [hypothesis_1(rates, cells), hypothesis_2(rates, cells), hypothesis_3(rates, cells)]


# ------------------------------------------------------------------------- rendering


def percent(value: float | None, digits: int = 1) -> str:
    """A fraction as a percentage string, '–' for None."""
    return "–" if value is None else f"{100 * value:.{digits}f}%"


def cell_text(cell: dict[str, Any] | None) -> str:
    """'61.3% [55.0, 67.2] n=40' for a described cell, '–' for none."""
    if cell is None:
        return "–"
    return (f"{percent(cell['mean'])} [{100 * cell['ci_low']:.1f}, {100 * cell['ci_high']:.1f}] "
            f"n={cell['n']}")


def layout(cells: list[dict[str, Any]]) -> tuple[list[float], list[str], list[str], dict]:
    """Rows (speed ratios), maps and pairings of the table, and cells by (map, ratio, pairing)."""
    lookup = {(c["map"], c["speed_ratio"], c["pairing"]): c for c in cells}
    maps, ratios, pairings = axes_of(lookup)
    return ratios, maps, pairings, lookup


def render_table_md(cells: list[dict[str, Any]], sweep: Sweep, failed: list[dict[str, Any]]) -> str:
    """Table 1 in Markdown, then the "Missing and failed" section."""
    ratios, maps, pairings, lookup = layout(cells)
    header = ["v_p/v_e"] + [f"{m} {p}" for m in maps for p in pairings]
    lines = [
        "# Table 1: mean tracking success rate",
        "",
        f"Mean tracking success rate per environment, pursuer-to-evader speed ratio v_p/v_e and "
        f"pairing (R-R: random pursuer, random evader; S-R: smart pursuer, random evader; S-S: "
        f"smart pursuer, smart evader), with its {100 * BOOT_LEVEL:.0f}% percentile-bootstrap "
        f"confidence interval ({BOOT_RESAMPLES:,} resamples) and the number of games n. Layout "
        f"of the paper's Table 1.",
        "",
        "| " + " | ".join(header) + " |",
        "|" + "---|" * len(header),
    ]
    for r in ratios:
        row = [f"{r:g}"] + [cell_text(lookup.get((m, r, p))) for m in maps for p in pairings]
        lines.append("| " + " | ".join(row) + " |")
    return "\n".join(lines + [""] + render_problems(sweep, failed)) + "\n"


def render_problems(sweep: Sweep, failed: list[dict[str, Any]]) -> list[str]:
    """The "Missing and failed" section: failed games, missing and unfinished jobs, skipped lines."""
    sections = {
        "Failed games": [
            f"- {f['map']}, v_p/v_e {float(f['speed_ratio']):g}, {f['pairing']}, seed {f['seed']} "
            f"(job {f['job']}): {f['error']} (traceback: {f['job']}/{f.get('traceback_file')})"
            for f in failed
        ],
        "Missing jobs (no results.jsonl)": [
            f"- job {m['job']}: overrides "
            + (" ".join(m["overrides"]) if m["overrides"] is not None else "unknown")
            for m in sweep.missing
        ],
        "Unfinished jobs (no summary line at the end)": [f"- job {job}" for job in sweep.unfinished],
        "Skipped lines": [f"- {s['file']} line {s['line']}: {s['reason']}" for s in sweep.skipped],
    }
    lines = ["## Missing and failed", ""]
    for title, items in sections.items():
        lines += [f"### {title}: {len(items)}", ""] + (items + [""] if items else ["None.", ""])
    return lines


def render_table_csv(cells: list[dict[str, Any]]) -> str:
    """One row per cell; rates as fractions."""
    buffer = io.StringIO()
    columns = ["map", "speed_ratio", "pairing", "n", "mean", "ci_low", "ci_high", "median", "std"]
    writer = csv.DictWriter(buffer, columns, extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    writer.writerows(cells)
    return buffer.getvalue()


def tex_escape(text: str) -> str:
    """Escape LaTeX's special characters in a plain string."""
    return re.sub(r"([&%$#_{}])", r"\\\1", text)


def tex_cell(cell: dict[str, Any] | None) -> str:
    """A table cell in LaTeX: mean, then CI and n in small type."""
    if cell is None:
        return "--"
    return (f"{100 * cell['mean']:.1f}\\% {{\\scriptsize [{100 * cell['ci_low']:.1f}, "
            f"{100 * cell['ci_high']:.1f}] $n$={cell['n']}}}")


def render_table_tex(cells: list[dict[str, Any]]) -> str:
    """Table 1 as a booktabs tabular in the paper's layout."""
    ratios, maps, pairings, lookup = layout(cells)
    width = len(pairings)
    groups = " & ".join(
        f"\\multicolumn{{{width}}}{{c}}{{\\textbf{{{tex_escape(MAP_TITLES.get(m, m))}}}}}" for m in maps
    )
    rules = " ".join(f"\\cmidrule(lr){{{2 + i * width}-{1 + (i + 1) * width}}}" for i in range(len(maps)))
    lines = [
        "% Generated by pegame.report: mean tracking success rate, 95% bootstrap CI and n per cell"
        " (paper, Table 1). Needs \\usepackage{booktabs}.",
        "\\begin{tabular}{l" + (" " + "c" * width) * len(maps) + "}",
        "\\toprule",
        f"\\textbf{{Speed ratio}} & {groups} \\\\" if maps else "\\textbf{Speed ratio} \\\\",
        rules,
        " & ".join(["$v_p/v_e$"] + [tex_escape(p) for _ in maps for p in pairings]) + " \\\\",
        "\\midrule",
    ]
    for r in ratios:
        row = [f"{r:g}"] + [tex_cell(lookup.get((m, r, p))) for m in maps for p in pairings]
        lines.append(" & ".join(row) + " \\\\")
    return "\n".join(lines + ["\\bottomrule", "\\end{tabular}"]) + "\n"


def p_text(value: float | None) -> str:
    """A p-value for a table."""
    return "–" if value is None else f"{value:.3g}"


def result_text(row: dict[str, Any]) -> str:
    """holds / fails / not tested for one cell."""
    return UNTESTED if row["holds"] is None else "holds" if row["holds"] else "fails"


def render_hypothesis(h: dict[str, Any], extra: list[tuple[str, Callable[[dict], str]]]) -> list[str]:
    """One hypothesis: claim, test, per-cell table (with ``extra`` columns), verdict."""
    x, y = h["pairings"]
    columns = [
        ("environment", lambda r: r["map"]),
        ("v_p/v_e", lambda r: f"{r['speed_ratio']:g}"),
        (f"{x} mean [CI]", lambda r: cell_text(r["x_stats"])),
        (f"{y} mean [CI]", lambda r: cell_text(r["y_stats"])),
        *extra,
        ("U", lambda r: "–" if r["U"] is None else f"{r['U']:g}"),
        ("p", lambda r: p_text(r["p"])),
        ("p (Holm)", lambda r: p_text(r["p_holm"])),
        ("result", result_text),
    ]
    lines = [
        f"## {h['id']}: {h['summary']['text']}", "",
        f"Paper's claim: {h['claim']}", "",
        f"Tested: {h['tested']} Alpha = {ALPHA}, Holm-Bonferroni correction across the "
        f"{h['summary']['n']} tested cells.", "",
        "| " + " | ".join(name for name, _ in columns) + " |",
        "|" + "---|" * len(columns),
    ]
    lines += ["| " + " | ".join(fn(row) for _, fn in columns) + " |" for row in h["rows"]]
    return lines + [""] + ([h["note"], ""] if "note" in h else [])


def render_hypotheses(tests: list[dict[str, Any]]) -> str:
    """hypotheses.md: the three hypotheses with their per-cell tests and verdicts."""
    flag = {None: "–", True: "yes", False: "no"}
    extras = {
        "H1": [],
        "H2": [("S-R mean [CI] at v_p/v_e = 1", lambda r: cell_text(r["x_stats_at_1"]))],
        "H3": [(f"S-S > {100 * REASONABLE_RATE:.0f}%", lambda r: flag[r["reasonable"]]),
               ("S-S < S-R (Holm)", lambda r: flag[r["tracked_less"]])],
    }
    lines = [
        "# The paper's hypotheses",
        "",
        "Mann-Whitney U tests compare the tracking-rate distributions of two pairings in one "
        "cell (environment x speed ratio); U is the statistic of the first pairing. A cell "
        f"lacking either pairing is {UNTESTED}.",
        "",
    ]
    for h in tests:
        lines += render_hypothesis(h, extras[h["id"]])
    return "\n".join(lines)


def box_figure(groups: list[str], series: dict[str, list[list[float]]], xlabel: str,
               title: str) -> Figure:
    """Box plots of tracking rates (%): per x group, one box per series (pairing) side by side."""
    fig = Figure(figsize=(max(6.0, 0.8 * len(groups) * max(1, len(series)) + 2), 4.5),
                 layout="constrained")
    ax = fig.add_subplot()
    width = 0.8 / max(1, len(series))
    for j, (label, data) in enumerate(series.items()):
        offset = (j - (len(series) - 1) / 2) * width
        kept = [(i + offset, [100 * v for v in values]) for i, values in enumerate(data) if values]
        if kept:
            ax.boxplot([v for _, v in kept], positions=[x for x, _ in kept], widths=0.9 * width,
                       patch_artist=True, manage_ticks=False, boxprops={"facecolor": f"C{j}"},
                       medianprops={"color": "black"})
    ax.set_xticks(range(len(groups)), groups)
    ax.set_xlim(-0.6, len(groups) - 0.4)
    ax.set(xlabel=xlabel, ylabel=RATE_LABEL, title=title, ylim=(-5, 105))
    if series:
        ax.legend(handles=[Patch(facecolor=f"C{j}", label=label) for j, label in enumerate(series)],
                  title="pursuer-evader", loc="best")
    return fig


def figures(rates: dict[Cell, list[float]]) -> dict[str, Figure]:
    """Paper Fig. 5a (by speed ratio), Fig. 5b (by environment), Fig. 8 (by pairing)."""
    maps, ratios, pairings = axes_of(rates)

    def pooled(keep: Callable[[Cell], bool]) -> list[float]:
        return [v for cell, values in rates.items() if keep(cell) for v in values]

    return {
        "fig5a_speed_ratio": box_figure(
            [f"{r:g}" for r in ratios],
            {p: [pooled(lambda c: c[1] == r and c[2] == p) for r in ratios] for p in pairings},
            "pursuer-to-evader speed ratio $v_p/v_e$", "Success rate by speed ratio (Fig. 5a)"),
        "fig5b_environment": box_figure(
            [MAP_TITLES.get(m, m) for m in maps],
            {p: [pooled(lambda c: c[0] == m and c[2] == p) for m in maps] for p in pairings},
            "environment", "Success rate by environment (Fig. 5b)"),
        "fig8_pairing": box_figure(
            ["all environments and speed ratios"],
            {p: [pooled(lambda c: c[2] == p)] for p in pairings},
            "pursuer and evader behaviour", "Overall success rate by pairing (Fig. 8)"),
    }


def figure_bytes(fig: Figure, fmt: str) -> bytes:
    """The figure encoded as PNG or SVG; SVG without date and with stable ids (reproducible)."""
    buffer = io.BytesIO()
    with matplotlib.rc_context({"svg.hashsalt": "pegame"}):
        fig.savefig(buffer, format=fmt, dpi=150, metadata={"Date": None} if fmt == "svg" else None)
    return buffer.getvalue()


# ----------------------------------------------------------------------------- entry


def write_report(multirun_dir: str | Path, out_dir: str | Path | None = None) -> dict[str, Any]:
    """Aggregate the multirun directory and write the tables, figures, hypotheses.md and
    report.json into ``out_dir`` (default: the multirun directory). Returns report.json's
    content."""
    sweep = load_sweep(multirun_dir)
    out = Path(out_dir if out_dir is not None else multirun_dir)
    out.mkdir(parents=True, exist_ok=True)
    games, failed = latest(sweep.records)
    rates = rates_by_cell(games)
    cells, tests = table_cells(rates), hypotheses(rates)
    texts = {
        "table1.md": render_table_md(cells, sweep, failed),
        "table1.csv": render_table_csv(cells),
        "table1.tex": render_table_tex(cells),
        "hypotheses.md": render_hypotheses(tests),
    }
    for name, fig in figures(rates).items():
        for fmt in ("png", "svg"):
            texts[f"{name}.{fmt}"] = figure_bytes(fig, fmt)
    report = {
        "multirun_dir": str(Path(multirun_dir)),
        "games": len(games),
        "bootstrap": {"resamples": BOOT_RESAMPLES, "level": BOOT_LEVEL, "seed": BOOT_SEED},
        "alpha": ALPHA,
        "cells": cells,
        "hypotheses": tests,
        "failed_games": failed,
        "missing_jobs": sweep.missing,
        "unfinished_jobs": sweep.unfinished,
        "skipped_lines": sweep.skipped,
        "job_summaries": sweep.summaries,
        "outputs": sorted([*texts, "report.json"]),
    }
    for name, data in texts.items():
        write_atomic(out / name, data)
    write_atomic(out / "report.json", json.dumps(report, indent=2) + "\n")
    return report


def main(argv: list[str] | None = None) -> int:
    """Command line: aggregate one multirun directory and print where the report went."""
    parser = argparse.ArgumentParser(
        prog="python -m pegame.report",
        description="Aggregate a pegame Hydra multirun: Table 1, Fig. 5 / Fig. 8 box plots, "
                    "hypothesis tests and report.json.")
    parser.add_argument("multirun_dir", type=Path, help="the Hydra multirun directory")
    parser.add_argument("--out", type=Path, default=None, help="output directory (default: multirun_dir)")
    args = parser.parse_args(argv)
    if not args.multirun_dir.is_dir():
        parser.error(f"not a directory: {args.multirun_dir}")
    logging.basicConfig(level=logging.INFO, format="%(levelname)s: %(message)s")
    report = write_report(args.multirun_dir, args.out)
    print(f"{report['games']} games, {len(report['failed_games'])} failed, "
          f"{len(report['missing_jobs'])} missing jobs, {len(report['skipped_lines'])} skipped "
          f"lines -> {args.out or args.multirun_dir}")
    for h in report["hypotheses"]:
        print(f"{h['id']}: {h['summary']['text']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
