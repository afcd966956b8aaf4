"""The paper's two trends tested as hypotheses, beside H1-H3 (``hypotheses.md``, report.json
``trends``).

- **T1, tracking rises with the speed ratio.** The paper's Table 1 has the smart pursuer
  tracking a random evader better the faster it is, in every environment (S-R 55 -> 78 ->
  85% on the hall at v_p/v_e = 0.5, 1, 2). Per environment and pairing, over the speed
  ratios the sweep has (two or more): the Jonckheere-Terpstra test of all games at each
  ratio, one-sided for a rise (:func:`pegame.report.ordered.jonckheere`), and, paired, Page's
  L test on the seeds played at every ratio (the same seed starts from the same spawn
  poses at every ratio; :func:`pegame.report.ordered.page`). Each is Holm-Bonferroni
  corrected across the tested (environment, pairing) rows as its own family. Every pairing
  is tested; the paper's own means along the ratios are shown beside ours, so a row whose
  paper values do not rise either (its S-S and R-R) reads as such.
- **T2, a smart evader is tracked less than a random one: S-S < S-R** per environment and
  speed ratio: the one-sided Mann-Whitney U test and, on common seeds, the one-sided
  Wilcoxon signed-rank test (:func:`pegame.report.hypotheses.compare_cells`), each family
  Holm-corrected. It is H3's first half, stated alone (H3 also asks for S-S above 45%).

A sweep with other factors is tested per combination of them, like H1-H3.
"""

from __future__ import annotations

from decimal import ROUND_HALF_UP, Decimal
from typing import Any

from pegame.report.cells import MAP_ORDER, PAIRING_ORDER, ordered
from pegame.report.hypotheses import (
    Columns,
    Rates,
    Seeded,
    compare_cells,
    md_table,
    number_text,
    p_text,
    render_hypothesis,
    result_text,
    title,
    verdict,
    verdicts,
)
from pegame.report.ordered import JT_NAME, PAGE_NAME, jonckheere, page
from pegame.report.paper import paper_table
from pegame.report.statistics import ALPHA, holm

ARROW = " → "


def rise_row(
    rates: Rates, seeded: Seeded | None, map_name: str, pairing: str, ratios: list[float]
) -> dict[str, Any]:
    """T1 for one environment and pairing over ``ratios`` (ascending): its means, the
    paper's, the Jonckheere-Terpstra test and, on the seeds common to every ratio, Page's."""
    groups = [rates[(map_name, r, pairing)] for r in ratios]
    paper = paper_table()
    paper_means = [paper.get((map_name, r, pairing)) for r in ratios]
    row: dict[str, Any] = {
        "map": map_name,
        "pairing": pairing,
        "speed_ratios": ratios,
        "n": [len(g) for g in groups],
        "means": [sum(g) / len(g) for g in groups],
        "paper_means": None if None in paper_means else paper_means,
        **dict.fromkeys(("J", "z", "tau", "p", "p_holm", "holds")),
    }
    paired: dict[str, Any] = {
        "n_pairs": 0,
        "means": None,
        "L": None,
        "z": None,
        "p": None,
        "p_holm": None,
        "holds": None,
    }
    if len(ratios) >= 2:
        jt = jonckheere(groups)
        row.update(J=jt["J"], z=jt["z"], tau=jt["tau"], p=jt["p"])
        by_ratio = [(seeded or {}).get((map_name, r, pairing), {}) for r in ratios]
        common = sorted(set.intersection(*(set(s) for s in by_ratio)))
        if common:
            blocks = [[s[seed] for s in by_ratio] for seed in common]
            test = page(blocks)
            paired.update(
                n_pairs=len(common),
                means=[sum(b[i] for b in blocks) / len(blocks) for i in range(len(ratios))],
                L=test["L"],
                z=test["z"],
                p=test["p"],
            )
    row["paired"] = paired
    return row


def rises_with_speed(rates: Rates, seeded: Seeded | None) -> dict[str, Any]:
    """T1: per environment and pairing, tracking rises with v_p/v_e (Jonckheere-Terpstra,
    and Page's L on common seeds), each family Holm-corrected."""
    maps = ordered({m for m, _, _ in rates}, MAP_ORDER)
    pairings = ordered({p for _, _, p in rates}, PAIRING_ORDER)
    rows = [
        rise_row(rates, seeded, m, p, sorted(r for m_, r, p_ in rates if (m_, p_) == (m, p)))
        for m in maps
        for p in pairings
        if any((m_, p_) == (m, p) for m_, _, p_ in rates)
    ]
    for tests in (rows, [r["paired"] for r in rows]):
        tested = [t for t in tests if t["p"] is not None]
        for t, adjusted in zip(tested, holm([t["p"] for t in tested])):
            t.update(p_holm=adjusted, holds=adjusted <= ALPHA)
    paired = {**verdict(rows, paired=True, unit="rows"), "test": PAGE_NAME}
    return {
        "id": "T1",
        "claim": "Tracking rises with the pursuer-to-evader speed ratio (the paper's Table 1: "
        "S-R rises in every environment, 55 -> 78 -> 85% on the hall).",
        "tested": "Per environment and pairing, over the speed ratios of the sweep: the "
        "tracking rates rise with v_p/v_e (one-sided Jonckheere-Terpstra test, normal "
        "approximation with the tie-corrected variance).",
        "rows": rows,
        "test": JT_NAME,
        "summary": verdict(rows, unit="rows"),
        "summary_paired": paired,
        "by_pairing": {
            p: verdict([r for r in rows if r["pairing"] == p], unit="environments")["text"]
            for p in pairings
        },
    }


def evader_harder(rates: Rates, seeded: Seeded | None) -> dict[str, Any]:
    """T2: S-S < S-R per environment and speed ratio (Mann-Whitney U; Wilcoxon signed-rank
    on common seeds), each family Holm-corrected."""
    maps = ordered({m for m, _, _ in rates}, MAP_ORDER)
    present = {(m, r) for m, r, _ in rates}
    cells = [(m, r) for m in maps for r in sorted({r for _, r, _ in rates}) if (m, r) in present]
    rows = compare_cells(rates, seeded, cells, "S-S", "S-R", "less")
    return {
        "id": "T2",
        "pairings": ["S-S", "S-R"],
        "claim": "Tracking a smart evader succeeds less often than tracking a random one "
        "(S-S < S-R; the paper's Table 1 has it in 7 of its 9 cells).",
        "tested": "Per environment and speed ratio: S-S tracking rates are stochastically "
        "less than S-R (one-sided Mann-Whitney U, alternative='less'); H3 without its "
        "45% condition.",
        **verdicts(rows),
    }


def trends(rates: Rates, seeded: Seeded | None = None) -> list[dict[str, Any]]:
    """T1 and T2 on one facet's rates ({(map, speed_ratio, pairing): rates}) and, for the
    paired tests, {seed: rate} of the same cells."""
    return [rises_with_speed(rates, seeded), evader_harder(rates, seeded)]


def path_text(values: list[float] | None, halves_up: bool = False) -> str:
    """'38.1 → 47.0 → 36.2%' ('–' for None); with ``halves_up`` the decimal halves of the
    values as written round up (the paper's 23.85% is 23.9, which a binary float prints as
    23.8)."""
    if values is None:
        return "–"
    if halves_up:
        texts = [
            str((Decimal(str(v)) * 100).quantize(Decimal("0.1"), rounding=ROUND_HALF_UP))
            for v in values
        ]
    else:
        texts = [f"{100 * v:.1f}" for v in values]
    return ARROW.join(texts) + "%"


def render_rise(t: dict[str, Any]) -> list[str]:
    """T1's section: claim, test, the Jonckheere-Terpstra table, the paired table."""
    place: Columns = [
        ("environment", lambda r: r["map"]),
        ("pairing", lambda r: r["pairing"]),
        ("v_p/v_e", lambda r: ARROW.join(f"{v:g}" for v in r["speed_ratios"])),
    ]
    unpaired: Columns = [
        *place,
        ("n", lambda r: ", ".join(map(str, r["n"]))),
        ("mean", lambda r: path_text(r["means"])),
        ("paper", lambda r: path_text(r["paper_means"], halves_up=True)),
        ("J", lambda r: number_text(r["J"], "g")),
        ("tau", lambda r: number_text(r["tau"], "+.2f")),
        ("z", lambda r: number_text(r["z"], "+.2f")),
        ("p", lambda r: p_text(r["p"])),
        ("p (Holm)", lambda r: p_text(r["p_holm"])),
        ("result", result_text),
    ]
    paired: Columns = [
        *place,
        ("seeds", lambda r: str(r["paired"]["n_pairs"])),
        ("mean on those seeds", lambda r: path_text(r["paired"]["means"])),
        ("L", lambda r: number_text(r["paired"]["L"], "g")),
        ("z", lambda r: number_text(r["paired"]["z"], "+.2f")),
        ("p", lambda r: p_text(r["paired"]["p"])),
        ("p (Holm)", lambda r: p_text(r["paired"]["p_holm"])),
        ("result", lambda r: result_text(r["paired"])),
    ]
    both = t["summary_paired"]
    per_pairing = "; ".join(f"{p}: {text}" for p, text in t["by_pairing"].items())
    return [
        f"## {title(t)}: {t['summary']['text']} by {t['test']}; {both['text']} by {both['test']}",
        "",
        f"Paper's trend: {t['claim']}",
        "",
        f"Tested: {t['tested']} tau = 2J/M - 1 (M the pairs of games at two different "
        f"ratios: +1 when every game at a higher ratio tracked more), z = (J - E[J]) / sd. "
        f"Alpha = {ALPHA}, Holm-Bonferroni correction across the {t['summary']['n']} tested "
        f"rows. By pairing: {per_pairing}.",
        "",
        *md_table(unpaired, t["rows"]),
        "",
        f"Paired on common seeds: {PAGE_NAME} (Page, 1963): the seeds played at every ratio "
        "of the row are blocks, their rates ranked within each seed (ties share a mean "
        "rank), L = sum of rank x position of the ratio; one-sided for a rise, normal "
        "approximation with the exact permutation variance (ties shrink it), "
        f"Holm-Bonferroni corrected as its own family across the {both['n']} tested rows.",
        "",
        *md_table(paired, t["rows"]),
        "",
    ]


def render_trends(tests: list[dict[str, Any]]) -> str:
    """The trends' part of hypotheses.md: T1 and T2 per combination of the other factors."""
    lines = [
        "# The paper's trends",
        "",
        "The two trends that the paper's Table 1 shows, tested as hypotheses: T1, tracking "
        "rises with the speed ratio v_p/v_e, per environment and pairing; T2, a smart evader "
        "is tracked less than a random one (S-S < S-R), per cell. Each test is one-sided in "
        "the paper's direction, each family Holm-Bonferroni corrected; paired tests on the "
        "seeds the compared games share (same seed, same spawn poses).",
        "",
    ]
    for t in tests:
        lines += render_rise(t) if t["id"] == "T1" else render_hypothesis(t, [], [])
    return "\n".join(lines)
