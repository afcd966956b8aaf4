"""The results pages' tables and quoted figures, generated from the committed study tables.

    python docs/results/tables.py           # rewrite the generated parts of the pages
    python docs/results/tables.py --check   # exit 1 if a page is stale or quotes by hand

A generated table sits in its page between ``<!-- generated: NAME -->`` and
``<!-- end: NAME -->``, a figure quoted in the prose between ``<!-- value: NAME -->`` and
``<!-- /value -->``; the script writes both from the committed table each generator
names, so a page never copies a figure by hand. ``--check`` also fails on a result quoted
outside those spans: a percentage, a number of points or pp, a p-value in e-notation, or
a count of cells ("N of M") in a page's prose (fenced and inline code, links' targets and
HTML comments are not prose).

Sources:

- ``docs/paper_table1/``: the default sweep's Table 1 (``table1.csv``: mean tracking rate
  with its 95% bootstrap CI), its hypotheses and the paper's trends (``report.json``);
- ``docs/paper_conditions/``: the paper's values (``paper_table1.csv``, from its .tex),
  the distance of each table from them (``vs_paper.csv``), the one-factor ablations
  (``factor_table.csv``), Table 1 of the 3D pipeline (``table1_3d/table1.csv``) and the
  grid against the 3D pipeline on common seeds (``grid_vs_3d.csv``);
- ``docs/round_robin/``: every pursuer against every evader (``table.csv``) and the
  strategies' goals (``goals.csv``).
"""

from __future__ import annotations

import argparse
import csv
import json
import re
import statistics
import sys
from collections.abc import Callable, Iterable
from decimal import ROUND_HALF_UP, Decimal
from functools import cache
from pathlib import Path

from pegame.report.hypotheses import REASONABLE_RATE

HERE = Path(__file__).resolve().parent
DOCS = HERE.parent
MAPS = ("hall", "enclosed", "brick")
RATIOS = (0.5, 1.0, 2.0)
PAIRINGS = ("R-R", "S-R", "S-S")


@cache
def rows(relative: str) -> list[dict[str, str]]:
    """The rows of a committed CSV under docs/."""
    with (DOCS / relative).open(newline="") as handle:
        return list(csv.DictReader(handle))


@cache
def report(relative: str) -> dict:
    return json.loads((DOCS / relative).read_text())


def rounded(value: float, places: int = 1) -> str:
    """``value`` to ``places`` decimals, halves rounded up (the paper's 23.85% is 23.9,
    which binary floats would make 23.8)."""
    step = Decimal(1).scaleb(-places)
    return str(Decimal(repr(value)).quantize(step, rounding=ROUND_HALF_UP))


def percent(value: str | float, places: int = 1) -> str:
    """A fraction in [0, 1] in % (no sign)."""
    return rounded(float(Decimal(str(value)) * 100), places)


def span(values: Iterable[float]) -> str:
    """'a-b' of fractions, in whole percent or points (one number when they round equal)."""
    values = list(values)
    low, high = percent(min(values), 0), percent(max(values), 0)
    return low if low == high else f"{low}-{high}"


def ratio(value: float) -> str:
    return f"{value:g}"


def cell_key(row: dict[str, str]) -> tuple[str, float, str]:
    return row["map"], float(row["speed_ratio"]), row["pairing"]


# ------------------------------------------------------------------ paper-table1.md


def paper() -> dict[tuple[str, float, str], str]:
    return {cell_key(r): r["paper_mean"] for r in rows("paper_conditions/paper_table1.csv")}


def table1() -> str:
    """Our Table 1 (default conditions) beside the paper's values, %."""
    ours = {cell_key(r): r for r in rows("paper_table1/table1.csv")}
    theirs = paper()
    lines = [
        "| map | v_p/v_e | R-R paper | R-R ours | S-R paper | S-R ours | S-S paper | S-S ours | R-S ours |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for name in MAPS:
        for speed in RATIOS:
            cells = [name, ratio(speed)]
            for pairing in (*PAIRINGS, "R-S"):
                if pairing != "R-S":
                    cells.append(percent(theirs[(name, speed, pairing)]))
                r = ours[(name, speed, pairing)]
                cells.append(f"{percent(r['mean'])} [{percent(r['ci_low'])}, {percent(r['ci_high'])}]")
            lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def hypothesis(name: str, study: str = "paper_table1") -> dict:
    return next(h for h in report(f"{study}/report.json")["hypotheses"] if h["id"] == name)


def holds(name: str) -> str:
    """'N of M' cells where hypothesis ``name`` holds (the report's verdict)."""
    tested = hypothesis(name)["rows"]
    return f"{sum(r['holds'] for r in tested)} of {len(tested)}"


def largest_p_holm(name: str) -> str:
    return f"{max(r['p_holm'] for r in hypothesis(name)['rows']):.2g}"


def h1_gain_at_ratio_1() -> str:
    """S-R minus R-R at v_p/v_e = 1, whole points, hall, enclosed and brick."""
    at_1 = {r["map"]: r for r in hypothesis("H1")["rows"] if r["speed_ratio"] == 1.0}
    gains = [
        percent(at_1[m]["x_stats"]["mean"] - at_1[m]["y_stats"]["mean"], 0) for m in MAPS
    ]
    return f"{gains[0]}, {gains[1]} and {gains[2]}"


def sr_span(speed: float) -> str:
    return span(float(r["mean"]) for r in rows("paper_table1/table1.csv")
                if float(r["speed_ratio"]) == speed and r["pairing"] == "S-R")


def h3_example() -> str:
    """S-S against S-R on enclosed at ratio 1 (the report's means)."""
    row = next(
        r for r in hypothesis("H3")["rows"] if r["map"] == "enclosed" and r["speed_ratio"] == 1.0
    )
    return f"{percent(row['x_stats']['mean'])}% against {percent(row['y_stats']['mean'])}%"


def trend(name: str, study: str = "paper_table1") -> dict:
    return next(t for t in report(f"{study}/report.json")["trends"] if t["id"] == name)


def rises(pairing: str, study: str = "paper_table1", paired: bool = False) -> str:
    """'N of M' environments where T1 (tracking rises with v_p/v_e; Jonckheere-Terpstra,
    or with ``paired`` Page's L on common seeds) holds for ``pairing``, of those tested."""
    tests = [r["paired"] if paired else r for r in trend("T1", study)["rows"] if r["pairing"] == pairing]
    tested = [t for t in tests if t["holds"] is not None]
    return f"{sum(t['holds'] for t in tested)} of {len(tested)}"


def trend_cells(name: str, study: str = "paper_table1", paired: bool = False) -> str:
    """'N of M' rows where trend ``name`` holds (the report's verdict, or the paired one)."""
    summary = trend(name, study)["summary_paired" if paired else "summary"]
    return f"{summary['k']} of {summary['n']}"


def h3_reasonable() -> str:
    tested = hypothesis("H3")["rows"]
    return f"{sum(r['reasonable'] for r in tested)} of {len(tested)}"


def distance(conditions: str) -> list[dict[str, str]]:
    return [r for r in rows("paper_conditions/vs_paper.csv") if r["conditions"] == conditions]


def mean_distance(conditions: str) -> str:
    """Mean |ours - paper| over the 27 cells, points."""
    return percent(statistics.fmean(abs(float(r["difference"])) for r in distance(conditions)))


def inside_ci(conditions: str) -> str:
    cells = distance(conditions)
    return f"{sum(r['paper_inside_ci'] == 'True' for r in cells)} of {len(cells)}"


def conditions_span(pairing: str, table: str = "paper_conditions/table1/table1.csv") -> Callable[..., str]:
    """Our span of ``pairing`` under a table, on ``maps`` (all by default), %."""

    def make(*maps: str) -> str:
        return span(
            float(r["mean"]) for r in rows(table)
            if r["pairing"] == pairing and r["map"] in (maps or MAPS)
        )

    return make


def paper_span(pairing: str, *maps: str) -> str:
    return span(float(v) for (m, _, p), v in paper().items() if p == pairing and m in (maps or MAPS))


def effect(direction: str, factor: str, pairing: str, *maps: str) -> str:
    """Span of |mean paired difference| of one factor's ablation, whole points."""
    return span(
        abs(float(r["mean_difference"])) for r in rows("paper_conditions/factor_table.csv")
        if r["direction"] == direction and r["factor"] == factor and r["pairing"] == pairing
        and r["map"] in (maps or MAPS)
    )


def grid_below_3d() -> str:
    """Span of the 3D pipeline's lead over the grid on common seeds, whole points."""
    return span(-float(r["mean_difference"]) for r in rows("paper_conditions/grid_vs_3d.csv"))


def grid_vs_3d_apart() -> str:
    cells = rows("paper_conditions/grid_vs_3d.csv")
    return f"{sum(float(r['p_holm']) < 0.05 for r in cells)} of {len(cells)}"


def below_paper(pairing: str) -> str:
    """Span of the paper's value minus ours under paper_conditions, whole points."""
    return span(
        float(r["paper"]) - float(r["mean"]) for r in distance("paper_conditions")
        if r["pairing"] == pairing
    )


PAPER_TABLE1_VALUES: dict[str, Callable[[], str]] = {
    "h1_cells": lambda: holds("H1"),
    "h1_p_holm": lambda: largest_p_holm("H1"),
    "h1_gain_1": h1_gain_at_ratio_1,
    "h2_cells": lambda: holds("H2"),
    "sr_at_half": lambda: sr_span(0.5),
    "sr_at_1": lambda: sr_span(1.0),
    "h3_cells": lambda: holds("H3"),
    "h3_threshold": lambda: percent(REASONABLE_RATE, 0),
    "h3_example": h3_example,
    "h3_reasonable": h3_reasonable,
    "t1_sr": lambda: rises("S-R"),
    "t1_ss": lambda: rises("S-S"),
    "t1_rr": lambda: rises("R-R"),
    "t1_paired": lambda: trend_cells("T1", paired=True),
    "t1_rows": lambda: trend_cells("T1"),
    "t2_cells": lambda: trend_cells("T2"),
    "t1_sr_conditions": lambda: rises("S-R", "paper_conditions/table1"),
    "t1_conditions": lambda: trend_cells("T1", "paper_conditions/table1"),
    "t2_conditions": lambda: trend_cells("T2", "paper_conditions/table1"),
    "distance_defaults": lambda: mean_distance("defaults"),
    "distance_conditions": lambda: mean_distance("paper_conditions"),
    "inside_defaults": lambda: inside_ci("defaults"),
    "inside_conditions": lambda: inside_ci("paper_conditions"),
    "ss_hall": lambda: conditions_span("S-S")("hall"),
    "ss_hall_paper": lambda: paper_span("S-S", "hall"),
    "ss_enclosed": lambda: conditions_span("S-S")("enclosed"),
    "ss_enclosed_paper": lambda: paper_span("S-S", "enclosed"),
    "ss_brick": lambda: conditions_span("S-S")("brick"),
    "ss_brick_paper": lambda: paper_span("S-S", "brick"),
    "sr_conditions": lambda: conditions_span("S-R")(),
    "sr_paper": lambda: paper_span("S-R"),
    "rr_conditions": lambda: conditions_span("R-R")(),
    "rr_paper": lambda: paper_span("R-R"),
    "rate_added_sr": lambda: effect("added", "rate", "S-R"),
    "rate_added_ss": lambda: effect("added", "rate", "S-S"),
    "rate_added_ss_hall": lambda: effect("added", "rate", "S-S", "hall"),
    "rate_removed_sr": lambda: effect("removed", "rate", "S-R"),
    "rate_removed_ss": lambda: effect("removed", "rate", "S-S"),
    "command_rate_sr": lambda: effect("added", "command_rate", "S-R"),
    "hide_added_ss": lambda: effect("added", "hide_margin", "S-S", "enclosed", "brick"),
    "hide_removed_ss": lambda: effect("removed", "hide_margin", "S-S"),
    "random_model_sr": lambda: effect("added", "random_model", "S-R"),
    "misses_removed": lambda: span(
        abs(float(r["mean_difference"])) for r in rows("paper_conditions/factor_table.csv")
        if r["direction"] == "removed" and r["factor"] == "misses" and r["pairing"] != "R-R"
    ),
    "distance_3d": lambda: mean_distance("3d_pipeline"),
    "inside_3d": lambda: inside_ci("3d_pipeline"),
    "rr_3d": lambda: conditions_span("R-R", "paper_conditions/table1_3d/table1.csv")(),
    "sr_3d": lambda: conditions_span("S-R", "paper_conditions/table1_3d/table1.csv")(),
    "ss_3d": lambda: conditions_span("S-S", "paper_conditions/table1_3d/table1.csv")(),
    "grid_below_3d": grid_below_3d,
    "grid_vs_3d_apart": grid_vs_3d_apart,
    "sr_below_paper": lambda: below_paper("S-R"),
    "rr_below_paper": lambda: below_paper("R-R"),
}


# ------------------------------------------------------------------ strategies.md


def round_robin() -> str:
    """Mean tracking rate over the three speed ratios, hall / enclosed / brick (%), per
    pursuer (rows) and evader and conditions (columns)."""
    table = rows("round_robin/table.csv")
    means: dict[tuple[str, str, str], list[float]] = {}
    for r in table:
        means.setdefault((r["conditions"], r["pursuer"], r["evader"], r["map"]), []).append(
            float(r["mean"])
        )
    conditions = list(dict.fromkeys(r["conditions"] for r in table))
    pursuers = list(dict.fromkeys(r["pursuer"] for r in table))
    evaders = list(dict.fromkeys(r["evader"] for r in table))
    columns = [(c, e) for c in conditions for e in evaders]
    lines = [
        "| pursuer \\ evader | " + " | ".join(f"{e} ({c})" for c, e in columns) + " |",
        "|---" * (len(columns) + 1) + "|",
    ]
    for p in pursuers:
        cells = [
            " / ".join(percent(statistics.fmean(means[(c, p, e, m)]), 0) for m in MAPS)
            for c, e in columns
        ]
        lines.append(f"| {p} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def signed(value: float) -> str:
    """A difference of fractions in points with its sign."""
    return ("+" if value >= 0 else "-") + percent(abs(value))


def goals() -> str:
    """Each goal of ``docs/round_robin/goals.csv`` by conditions: its cells met, the span of
    the mean paired differences, and its weakest cell: the one whose CI reaches furthest
    towards the other side (lowest lower bound where the differences lean positive,
    highest upper bound where they lean negative)."""
    groups: dict[tuple[str, str], list[dict[str, str]]] = {}
    for r in rows("round_robin/goals.csv"):
        groups.setdefault((r["goal"], r["conditions"]), []).append(r)
    lines = [
        "| goal | conditions | cells met | mean difference (pp) | weakest cell: difference [95% CI] |",
        "|---|---|---|---|---|",
    ]
    for (goal, conditions), cells in groups.items():
        differences = [float(r["mean_difference"]) for r in cells]
        if statistics.fmean(differences) >= 0:
            closest = min(cells, key=lambda r: float(r["ci_low"]))
        else:
            closest = max(cells, key=lambda r: float(r["ci_high"]))
        lines.append(
            f"| {goal} | {conditions} | {sum(r['met'] == 'True' for r in cells)} / {len(cells)} "
            f"| {signed(min(differences))} to {signed(max(differences))} "
            f"| {closest['map']} at {ratio(float(closest['speed_ratio']))}: "
            f"{signed(float(closest['mean_difference']))} [{signed(float(closest['ci_low']))}, "
            f"{signed(float(closest['ci_high']))}] |"
        )
    return "\n".join(lines)


def goals_margin() -> str:
    """The non-inferiority margin of the 'no worse' goals (``goals.csv``), in points."""
    margins = {float(r["margin"]) for r in rows("round_robin/goals.csv") if r["margin"]}
    (margin,) = margins
    return percent(margin, 0)


def round_robin_games() -> str:
    table = rows("round_robin/table.csv")
    return f"{sum(int(r['n']) for r in table)} games in {len(table)} cells"


#: page -> ({table name: generator}, {value name: generator})
PAGES: dict[str, tuple[dict[str, Callable[[], str]], dict[str, Callable[[], str]]]] = {
    "paper-table1.md": ({"table1": table1}, PAPER_TABLE1_VALUES),
    "strategies.md": (
        {"goals": goals, "round_robin": round_robin},
        {"round_robin_games": round_robin_games, "goals_margin": goals_margin},
    ),
}

#: results quoted in prose: a percentage, points or pp, an e-notation p-value, "N of M"
QUOTED = re.compile(
    r"\d+(?:\.\d+)?\s?%(?!\s?(?:bootstrap )?(?:CI|confidence))|\d+(?:\.\d+)?\s?(?:percentage )?(?:points|pp)\b"
    r"|\d(?:\.\d+)?e-\d+|\b\d+ of \d+\b",
    flags=re.IGNORECASE,
)
NOT_PROSE = re.compile(
    r"```.*?```|`[^`\n]*`|<!-- generated: (\w+) -->.*?<!-- end: \1 -->"
    r"|<!-- value: \w+ -->.*?<!-- /value -->|<!--.*?-->|\]\([^)]*\)",
    flags=re.DOTALL,
)


def regenerate(
    text: str, tables: dict[str, Callable[[], str]], values: dict[str, Callable[[], str]]
) -> str:
    """``text`` with every generated table and value replaced by its generator's output.
    ValueError when a generator has no place in the page or the page names an unknown one."""
    for name, make in tables.items():
        pattern = re.compile(
            rf"(<!-- generated: {name} -->\n).*?(\n<!-- end: {name} -->)", flags=re.DOTALL
        )
        if not pattern.search(text):
            raise ValueError(f"no '<!-- generated: {name} -->' block in the page")
        text = pattern.sub(lambda m, make=make: m.group(1) + make() + m.group(2), text)
    unknown = set(re.findall(r"<!-- value: (\w+) -->", text)) - set(values)
    if unknown:
        raise ValueError(f"the page quotes unknown values: {', '.join(sorted(unknown))}")
    return re.sub(
        r"(<!-- value: (\w+) -->).*?(<!-- /value -->)",
        lambda m: m.group(1) + values[m.group(2)]() + m.group(3),
        text,
        flags=re.DOTALL,
    )


def quoted_by_hand(text: str) -> list[str]:
    """Results quoted in the page's prose outside the generated spans (module docstring)."""
    return QUOTED.findall(NOT_PROSE.sub(" ", text))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="exit 1 if a page is out of date")
    args = parser.parse_args(argv)
    problems = []
    for page, (tables, values) in PAGES.items():
        path = HERE / page
        text = path.read_text()
        fresh = regenerate(text, tables, values)
        if fresh != text:
            problems.append(f"{page} is out of date (run python docs/results/tables.py)")
            if not args.check:
                path.write_text(fresh)
        by_hand = quoted_by_hand(fresh)
        if by_hand:
            problems.append(f"{page} quotes by hand: {', '.join(by_hand)}")
    if args.check and problems:
        print("\n".join(problems), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
