"""The paper's three hypotheses (Sec. "Experiments"), tested per environment x speed ratio
with one-sided Mann-Whitney U tests, Holm-Bonferroni corrected at alpha = 0.05, and
``hypotheses.md``.

A sweep with other factors (settings beyond the paper's axes, see
:mod:`pegame.report.cells`) is tested separately per combination of those factors: each
combination is its own family for the Holm correction.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from pegame.report.cells import MAP_ORDER, Cell, facets, ordered, value_text
from pegame.report.statistics import ALPHA, describe, holm, mann_whitney
from pegame.report.tables import cell_text

REASONABLE_RATE = 0.45  # the paper: S-S "over 45% success rate" in most scenarios
UNTESTED = "not tested (missing data)"

Rates = dict[tuple[str, float, str], list[float]]  # (map, speed_ratio, pairing) -> rates


def cell_summary(rates: Rates, cell: tuple[str, float, str]) -> dict[str, Any] | None:
    """:func:`describe` of a cell, None when it has no games."""
    return describe(rates[cell]) if cell in rates else None


def mann_whitney_cells(
    rates: Rates, cells: list[tuple[str, float]], x: str, y: str, alternative: str
) -> list[dict[str, Any]]:
    """Per (map, speed_ratio): one-sided Mann-Whitney U of pairing ``x``'s rates against
    ``y``'s, Holm-corrected across the tested cells; ``holds`` is None when untested."""
    rows = []
    for map_name, ratio in cells:
        a, b = rates.get((map_name, ratio, x), []), rates.get((map_name, ratio, y), [])
        row = {
            "map": map_name,
            "speed_ratio": ratio,
            "x": x,
            "y": y,
            "x_stats": cell_summary(rates, (map_name, ratio, x)),
            "y_stats": cell_summary(rates, (map_name, ratio, y)),
            "U": None,
            "p": None,
            "p_holm": None,
            "holds": None,
        }
        if a and b:
            u, p = mann_whitney(a, b, alternative)
            row.update(U=u, p=p)
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
    return {
        "verdict": word,
        "k": k,
        "n": n,
        "untested": len(rows) - n,
        "text": UNTESTED if n == 0 else f"{word} (in {k} of {n} cells)",
    }


def hypothesis_1(rates: Rates, cells: list[tuple[str, float]]) -> dict[str, Any]:
    """H1: the smart pursuer tracks better than a random pursuer (S-R > R-R per cell)."""
    rows = mann_whitney_cells(rates, cells, "S-R", "R-R", "greater")
    return {
        "id": "H1",
        "pairings": ["S-R", "R-R"],
        "claim": "The smart pursuer can track the evader better than a random pursuer.",
        "tested": "Per environment and speed ratio: S-R tracking rates are stochastically "
        "greater than R-R (one-sided Mann-Whitney U, alternative='greater').",
        "rows": rows,
        "summary": verdict(rows),
    }


def hypothesis_2(rates: Rates, cells: list[tuple[str, float]]) -> dict[str, Any]:
    """H2: the smart pursuer keeps tracking when slower than the evader (v_p/v_e < 1)."""
    maps = sorted({m for m, _ in cells}, key=[m for m, _ in cells].index)
    slow = sorted({r for _, r in cells if r < 1}) or [0.5]
    rows = mann_whitney_cells(rates, [(m, r) for m in maps for r in slow], "S-R", "R-R", "greater")
    for row in rows:
        row["x_stats_at_1"] = cell_summary(rates, (row["map"], 1.0, "S-R"))
    return {
        "id": "H2",
        "pairings": ["S-R", "R-R"],
        "claim": "The smart pursuer maintains a high tracking rate even with comparatively "
        "slower speed than the evader (paper: at half the evader's speed, Fig. 5a).",
        "tested": "At each speed ratio v_p/v_e < 1 (the paper's 0.5), per environment: S-R "
        "tracking rates are stochastically greater than R-R (one-sided Mann-Whitney "
        "U, alternative='greater'). The S-R mean there is shown beside the S-R mean "
        "at v_p/v_e = 1 for reference; 'high' has no threshold in the paper and is "
        "not tested.",
        "rows": rows,
        "summary": verdict(rows),
    }


def hypothesis_3(rates: Rates, cells: list[tuple[str, float]]) -> dict[str, Any]:
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
        "id": "H3",
        "pairings": ["S-S", "S-R"],
        "claim": "The smart pursuer maintains a reasonably high tracking performance even when "
        "the evader is aware of the intentions of the pursuer; tracking a smart evader "
        "succeeds less often than tracking a random one, and the smart pursuer has "
        "over 45% success rate in the majority of the scenarios.",
        "tested": "Per environment and speed ratio: S-S tracking rates are stochastically "
        "less than S-R (one-sided Mann-Whitney U, alternative='less'), and the S-S "
        f"mean exceeds {100 * REASONABLE_RATE:.0f}%; a cell holds when both do.",
        "rows": rows,
        "summary": verdict(rows),
        "reasonable_cells": {"k": sum(reasonable), "n": len(reasonable)},
        "note": f"S-S mean above {100 * REASONABLE_RATE:.0f}% in {sum(reasonable)} of "
        f"{len(reasonable)} cells (paper: in the majority of the scenarios).",
    }


def hypotheses(rates: Rates) -> list[dict[str, Any]]:
    """The paper's three hypotheses, each tested per (map, speed_ratio) cell of ``rates``."""
    maps = ordered({m for m, _, _ in rates}, MAP_ORDER)
    present = {(m, r) for m, r, _ in rates}
    cells = [(m, r) for m in maps for r in sorted({r for _, r, _ in rates}) if (m, r) in present]
    return [hypothesis_1(rates, cells), hypothesis_2(rates, cells), hypothesis_3(rates, cells)]


def facet_text(factors: dict[str, Any]) -> str:
    """'estimator.name=last_seen, detector.miss_probability=0.3' ('' without factors)."""
    return ", ".join(f"{key}={value_text(value)}" for key, value in factors.items())


def hypotheses_per_facet(cells: list[Cell]) -> list[dict[str, Any]]:
    """The three hypotheses per combination of the other factors, each tagged with its
    ``factors``: three entries when the sweep has no other factors."""
    tests = []
    for factors, group in facets(cells):
        rates = {(c.map, c.speed_ratio, c.pairing): c.rates for c in group}
        tests += [{**h, "factors": factors} for h in hypotheses(rates)]
    return tests


def title(h: dict[str, Any]) -> str:
    """'H1' or 'H1 (detector.miss_probability=0.3)'."""
    return f"{h['id']} ({facet_text(h['factors'])})" if h.get("factors") else h["id"]


def p_text(value: float | None) -> str:
    """A p-value for a table."""
    return "–" if value is None else f"{value:.3g}"


def result_text(row: dict[str, Any]) -> str:
    """holds / fails / not tested for one cell."""
    return UNTESTED if row["holds"] is None else "holds" if row["holds"] else "fails"


def render_hypothesis(
    h: dict[str, Any], extra: list[tuple[str, Callable[[dict], str]]]
) -> list[str]:
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
        f"## {title(h)}: {h['summary']['text']}",
        "",
        f"Paper's claim: {h['claim']}",
        "",
        f"Tested: {h['tested']} Alpha = {ALPHA}, Holm-Bonferroni correction across the "
        f"{h['summary']['n']} tested cells.",
        "",
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
        "H3": [
            (f"S-S > {100 * REASONABLE_RATE:.0f}%", lambda r: flag[r["reasonable"]]),
            ("S-S < S-R (Holm)", lambda r: flag[r["tracked_less"]]),
        ],
    }
    lines = [
        "# The paper's hypotheses",
        "",
        "Mann-Whitney U tests compare the tracking-rate distributions of two pairings in one "
        "cell (environment x speed ratio); U is the statistic of the first pairing. A cell "
        f"lacking either pairing is {UNTESTED}. A sweep with settings beyond the paper's "
        "axes is tested separately per combination of them (named after the hypothesis), "
        "each combination its own family for the Holm correction.",
        "",
    ]
    for h in tests:
        lines += render_hypothesis(h, extras[h["id"]])
    return "\n".join(lines)
