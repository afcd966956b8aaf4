"""The paper's three hypotheses (Sec. "Experiments"), tested per environment x speed ratio
with one-sided Mann-Whitney U tests, Holm-Bonferroni corrected at alpha = 0.05, and
``hypotheses.md``.

Beside each Mann-Whitney test, where both pairings have games on common seeds (same seed,
same spawn poses), the paired test of :mod:`pegame.report.paired`: a one-sided Wilcoxon
signed-rank test in the hypothesis' direction on those seeds, Holm-corrected across the
hypothesis' cells as its own family, with the mean paired difference (bootstrap CI) and
the rank-biserial correlation. The verdict (``summary``) stays the Mann-Whitney one; the
paired verdict is ``summary_paired``.

A sweep with other factors (settings beyond the paper's axes, see
:mod:`pegame.report.cells`) is tested separately per combination of those factors: each
combination is its own family for the Holm correction.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from pegame.report.cells import MAP_ORDER, Cell, facets, ordered, value_text
from pegame.report.paired import TEST_NAME, BySeed, by_seed, difference_text, paired_test
from pegame.report.statistics import ALPHA, describe, holm, mann_whitney
from pegame.report.tables import cell_text

REASONABLE_RATE = 0.45  # the paper: S-S "over 45% success rate" in most scenarios
UNTESTED = "not tested (missing data)"

Rates = dict[tuple[str, float, str], list[float]]  # (map, speed_ratio, pairing) -> rates
Seeded = dict[tuple[str, float, str], BySeed]  # (map, speed_ratio, pairing) -> {seed: rate}
UNPAIRED_TEST = "Mann-Whitney U"


def cell_summary(rates: Rates, cell: tuple[str, float, str]) -> dict[str, Any] | None:
    """:func:`describe` of a cell, None when it has no games."""
    return describe(rates[cell]) if cell in rates else None


def compare_cells(
    rates: Rates,
    seeded: Seeded | None,
    cells: list[tuple[str, float]],
    x: str,
    y: str,
    alternative: str,
) -> list[dict[str, Any]]:
    """Per (map, speed_ratio): one-sided Mann-Whitney U of pairing ``x``'s rates against
    ``y``'s, Holm-corrected across the tested cells; ``holds`` is None when untested. Each
    row's ``paired`` is the Wilcoxon signed-rank test of x - y on the common seeds of
    ``seeded`` (none when ``seeded`` is None), Holm-corrected across its tested cells."""
    rows: list[dict[str, Any]] = []
    for map_name, ratio in cells:
        a, b = rates.get((map_name, ratio, x), []), rates.get((map_name, ratio, y), [])
        row: dict[str, Any] = {
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
        x_seeds, y_seeds = ((seeded or {}).get((map_name, ratio, p), {}) for p in (x, y))
        row["paired"] = {
            **paired_test(x_seeds, y_seeds, alternative),
            "p_holm": None,
            "holds": None,
        }
        rows.append(row)
    tested = [row for row in rows if row["p"] is not None]
    for row, adjusted in zip(tested, holm([row["p"] for row in tested])):
        row.update(p_holm=adjusted, holds=adjusted <= ALPHA)
    paired = [row["paired"] for row in rows if row["paired"]["p"] is not None]
    for test, adjusted in zip(paired, holm([test["p"] for test in paired])):
        test.update(p_holm=adjusted, holds=adjusted <= ALPHA)
    return rows


def verdict(
    rows: list[dict[str, Any]], paired: bool = False, unit: str = "cells"
) -> dict[str, Any]:
    """holds / fails / partly over the tested cells (or other ``unit``), or not tested: of
    the Mann-Whitney tests, or with ``paired`` of the Wilcoxon signed-rank tests (then
    tagged with ``test``)."""
    outcomes = [row["paired"]["holds"] if paired else row["holds"] for row in rows]
    tested = [holds for holds in outcomes if holds is not None]
    k, n = sum(tested), len(tested)
    word = "not tested" if n == 0 else "holds" if k == n else "fails" if k == 0 else "partly"
    summary = {
        "verdict": word,
        "k": k,
        "n": n,
        "untested": len(rows) - n,
        "text": UNTESTED if n == 0 else f"{word} (in {k} of {n} {unit})",
    }
    return {**summary, "test": TEST_NAME} if paired else summary


def verdicts(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """A hypothesis' rows and both verdicts, each naming the test it rests on."""
    return {
        "rows": rows,
        "test": UNPAIRED_TEST,
        "summary": verdict(rows),
        "summary_paired": verdict(rows, paired=True),
    }


def hypothesis_1(
    rates: Rates, seeded: Seeded | None, cells: list[tuple[str, float]]
) -> dict[str, Any]:
    """H1: the smart pursuer tracks better than a random pursuer (S-R > R-R per cell)."""
    rows = compare_cells(rates, seeded, cells, "S-R", "R-R", "greater")
    return {
        "id": "H1",
        "pairings": ["S-R", "R-R"],
        "claim": "The smart pursuer can track the evader better than a random pursuer.",
        "tested": "Per environment and speed ratio: S-R tracking rates are stochastically "
        "greater than R-R (one-sided Mann-Whitney U, alternative='greater').",
        **verdicts(rows),
    }


def hypothesis_2(
    rates: Rates, seeded: Seeded | None, cells: list[tuple[str, float]]
) -> dict[str, Any]:
    """H2: the smart pursuer keeps tracking when slower than the evader (v_p/v_e < 1)."""
    maps = sorted({m for m, _ in cells}, key=[m for m, _ in cells].index)
    slow = sorted({r for _, r in cells if r < 1}) or [0.5]
    rows = compare_cells(
        rates, seeded, [(m, r) for m in maps for r in slow], "S-R", "R-R", "greater"
    )
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
        **verdicts(rows),
    }


def hypothesis_3(
    rates: Rates, seeded: Seeded | None, cells: list[tuple[str, float]]
) -> dict[str, Any]:
    """H3: a smart evader is tracked less than a random one (S-S < S-R), yet reasonably
    (S-S mean above 45%, over all its games); a cell holds when both do."""
    rows = compare_cells(rates, seeded, cells, "S-S", "S-R", "less")
    for row in rows:
        stats = row["x_stats"]
        row["reasonable"] = None if stats is None else stats["mean"] > REASONABLE_RATE
        for test in (row, row["paired"]):
            test["tracked_less"] = test["holds"]
            if test["holds"] is not None:
                test["holds"] = test["tracked_less"] and row["reasonable"]
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
        **verdicts(rows),
        "reasonable_cells": {"k": sum(reasonable), "n": len(reasonable)},
        "note": f"S-S mean above {100 * REASONABLE_RATE:.0f}% in {sum(reasonable)} of "
        f"{len(reasonable)} cells (paper: in the majority of the scenarios).",
    }


def hypotheses(rates: Rates, seeded: Seeded | None = None) -> list[dict[str, Any]]:
    """The paper's three hypotheses, each tested per (map, speed_ratio) cell of ``rates``;
    paired tests where ``seeded`` (the same cells' {seed: rate}) has common seeds."""
    maps = ordered({m for m, _, _ in rates}, MAP_ORDER)
    present = {(m, r) for m, r, _ in rates}
    cells = [(m, r) for m in maps for r in sorted({r for _, r, _ in rates}) if (m, r) in present]
    return [test(rates, seeded, cells) for test in (hypothesis_1, hypothesis_2, hypothesis_3)]


def facet_text(factors: dict[str, Any]) -> str:
    """'estimator.name=last_seen, detector.miss_probability=0.3' ('' without factors)."""
    return ", ".join(f"{key}={value_text(value)}" for key, value in factors.items())


def per_facet(
    cells: list[Cell], tests: Callable[[Rates, Seeded], list[dict[str, Any]]]
) -> list[dict[str, Any]]:
    """``tests`` (of a facet's rates and {seed: rate}) per combination of the other
    factors, each result tagged with its ``factors``."""
    results = []
    for factors, group in facets(cells):
        rates = {(c.map, c.speed_ratio, c.pairing): c.rates for c in group}
        seeded = {(c.map, c.speed_ratio, c.pairing): by_seed(c.games) for c in group}
        results += [{**h, "factors": factors} for h in tests(rates, seeded)]
    return results


def hypotheses_per_facet(cells: list[Cell]) -> list[dict[str, Any]]:
    """The three hypotheses per combination of the other factors, each tagged with its
    ``factors``: three entries when the sweep has no other factors."""
    return per_facet(cells, hypotheses)


def title(h: dict[str, Any]) -> str:
    """'H1' or 'H1 (detector.miss_probability=0.3)'."""
    return f"{h['id']} ({facet_text(h['factors'])})" if h.get("factors") else h["id"]


def p_text(value: float | None) -> str:
    """A p-value for a table."""
    return "–" if value is None else f"{value:.3g}"


def result_text(test: dict[str, Any]) -> str:
    """holds / fails / not tested for one cell's test (a row, or its ``paired``)."""
    return UNTESTED if test["holds"] is None else "holds" if test["holds"] else "fails"


Columns = list[tuple[str, Callable[[dict], str]]]


def md_table(columns: Columns, rows: list[dict[str, Any]]) -> list[str]:
    """A Markdown table of ``rows`` with (header, cell text) ``columns``."""
    lines = ["| " + " | ".join(name for name, _ in columns) + " |", "|" + "---|" * len(columns)]
    return lines + ["| " + " | ".join(fn(row) for _, fn in columns) + " |" for row in rows]


def number_text(value: float | None, spec: str) -> str:
    """A statistic for a table, '–' for None."""
    return "–" if value is None else format(value, spec)


def render_hypothesis(h: dict[str, Any], extra: Columns, extra_paired: Columns) -> list[str]:
    """One hypothesis: claim, test, the per-cell table of the Mann-Whitney tests (with
    ``extra`` columns), then that of the paired tests (with ``extra_paired``), verdicts."""
    x, y = h["pairings"]
    place: Columns = [
        ("environment", lambda r: r["map"]),
        ("v_p/v_e", lambda r: f"{r['speed_ratio']:g}"),
    ]
    unpaired: Columns = [
        *place,
        (f"{x} mean [CI]", lambda r: cell_text(r["x_stats"])),
        (f"{y} mean [CI]", lambda r: cell_text(r["y_stats"])),
        *extra,
        ("U", lambda r: number_text(r["U"], "g")),
        ("p", lambda r: p_text(r["p"])),
        ("p (Holm)", lambda r: p_text(r["p_holm"])),
        ("result", result_text),
    ]
    paired: Columns = [
        *place,
        ("pairs", lambda r: str(r["paired"]["n_pairs"])),
        ("zero differences", lambda r: number_text(r["paired"]["zero_differences"], "d")),
        (f"{x} - {y} mean [CI]", lambda r: difference_text(r["paired"])),
        ("rank-biserial r", lambda r: number_text(r["paired"]["rank_biserial"], "+.2f")),
        *extra_paired,
        ("W", lambda r: number_text(r["paired"]["W"], "g")),
        ("p", lambda r: p_text(r["paired"]["p"])),
        ("p (Holm)", lambda r: p_text(r["paired"]["p_holm"])),
        ("result", lambda r: result_text(r["paired"])),
    ]
    both = h["summary_paired"]
    lines = [
        f"## {title(h)}: {h['summary']['text']} by {h['test']}; {both['text']} by {both['test']}",
        "",
        f"Paper's claim: {h['claim']}",
        "",
        f"Tested: {h['tested']} Alpha = {ALPHA}, Holm-Bonferroni correction across the "
        f"{h['summary']['n']} tested cells.",
        "",
        *md_table(unpaired, h["rows"]),
        "",
        f"Paired on common seeds: a one-sided Wilcoxon signed-rank test of {x} - {y} in the "
        f"same direction, Holm-Bonferroni corrected as its own family across the "
        f"{both['n']} cells where both pairings share seeds; mean paired difference in "
        "percentage points with its bootstrap CI over seeds.",
        "",
        *md_table(paired, h["rows"]),
    ]
    return lines + [""] + ([h["note"], ""] if "note" in h else [])


def render_hypotheses(tests: list[dict[str, Any]]) -> str:
    """hypotheses.md: the three hypotheses with their per-cell tests and verdicts."""
    flag = {None: "–", True: "yes", False: "no"}
    reasonable = (f"S-S > {100 * REASONABLE_RATE:.0f}%", lambda r: flag[r["reasonable"]])
    extras: dict[str, tuple[Columns, Columns]] = {
        "H1": ([], []),
        "H2": ([("S-R mean [CI] at v_p/v_e = 1", lambda r: cell_text(r["x_stats_at_1"]))], []),
        "H3": (
            [reasonable, ("S-S < S-R (Holm)", lambda r: flag[r["tracked_less"]])],
            [reasonable, ("S-S < S-R (Holm)", lambda r: flag[r["paired"]["tracked_less"]])],
        ),
    }
    lines = [
        "# The paper's hypotheses",
        "",
        "Mann-Whitney U tests compare the tracking-rate distributions of two pairings in one "
        "cell (environment x speed ratio); U is the statistic of the first pairing. A cell "
        f"lacking either pairing is {UNTESTED}. A sweep with settings beyond the paper's "
        "axes is tested separately per combination of them (named after the hypothesis), "
        "each combination its own family for the Holm correction. Each verdict names the "
        f"test it rests on; the first ({UNPAIRED_TEST}) is the report's verdict.",
        "",
        "Games of two pairings with the same seed start from the same spawn poses, so they "
        f"are paired: beside each Mann-Whitney test, the {TEST_NAME} (scipy.stats.wilcoxon, "
        "zero_method='pratt': a seed where both pairings tracked equally is kept in the "
        "ranking, not dropped, so ties do not overstate the evidence; all differences zero "
        "gives p = 1), its mean paired difference with a percentile-bootstrap CI over seeds "
        "and the matched-pairs rank-biserial correlation r = (T+ - T-) / (T+ + T-), W = T+. "
        f"A cell without common seeds is {UNTESTED}.",
        "",
    ]
    for h in tests:
        lines += render_hypothesis(h, *extras[h["id"]])
    return "\n".join(lines)
