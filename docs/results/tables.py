"""The tables of the results pages, generated from the committed study tables.

    python docs/results/tables.py           # rewrite the tables in the pages
    python docs/results/tables.py --check   # exit 1 if a page's table differs (a test runs it)

Each generated table sits in its page between ``<!-- generated: NAME -->`` and
``<!-- end: NAME -->``; every number in it is read from the committed table it names, so
a page never quotes a figure by hand.

- ``table1`` in ``paper-table1.md``: the default sweep's Table 1
  (``docs/paper_table1/table1.csv``, mean tracking rate with its 95% bootstrap CI, %)
  beside the paper's values (``docs/paper_conditions/paper_table1.csv``, from its .tex).
"""

from __future__ import annotations

import argparse
import csv
import re
import sys
from decimal import ROUND_HALF_UP, Decimal
from collections.abc import Callable
from pathlib import Path

HERE = Path(__file__).resolve().parent
DOCS = HERE.parent
MAPS = ("hall", "enclosed", "brick")
RATIOS = (0.5, 1.0, 2.0)


def rows(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as handle:
        return list(csv.DictReader(handle))


def percent(value: str) -> str:
    """A fraction in [0, 1], as written in the table, in % to one decimal, halves rounded up
    (the paper's 23.85% is 23.9, which binary floats would make 23.8)."""
    return str((Decimal(value) * 100).quantize(Decimal("0.1"), rounding=ROUND_HALF_UP))


def ratio(value: float) -> str:
    return f"{value:g}"


def table1() -> str:
    """Our Table 1 beside the paper's (module docstring)."""
    ours = {
        (r["map"], float(r["speed_ratio"]), r["pairing"]): r
        for r in rows(DOCS / "paper_table1" / "table1.csv")
    }
    paper = {
        (r["map"], float(r["speed_ratio"]), r["pairing"]): r["paper_mean"]
        for r in rows(DOCS / "paper_conditions" / "paper_table1.csv")
    }
    lines = [
        "| map | v_p/v_e | R-R paper | R-R ours | S-R paper | S-R ours | S-S paper | S-S ours | R-S ours |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for name in MAPS:
        for speed in RATIOS:
            cells = [name, ratio(speed)]
            for pairing in ("R-R", "S-R", "S-S", "R-S"):
                if pairing != "R-S":
                    cells.append(percent(paper[(name, speed, pairing)]))
                r = ours[(name, speed, pairing)]
                cells.append(f"{percent(r['mean'])} [{percent(r['ci_low'])}, {percent(r['ci_high'])}]")
            lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


#: page -> {table name: its generator}
PAGES: dict[str, dict[str, Callable[[], str]]] = {"paper-table1.md": {"table1": table1}}


def regenerate(text: str, tables: dict[str, Callable[[], str]]) -> str:
    """``text`` with every generated table replaced by its generator's output."""
    for name, make in tables.items():
        pattern = re.compile(
            rf"(<!-- generated: {name} -->\n).*?(\n<!-- end: {name} -->)", flags=re.DOTALL
        )
        if not pattern.search(text):
            raise ValueError(f"no '<!-- generated: {name} -->' block in the page")
        text = pattern.sub(lambda m: m.group(1) + make() + m.group(2), text)
    return text


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="exit 1 if a page is out of date")
    args = parser.parse_args(argv)
    stale = []
    for page, tables in PAGES.items():
        path = HERE / page
        text = path.read_text()
        fresh = regenerate(text, tables)
        if fresh != text:
            stale.append(page)
            if not args.check:
                path.write_text(fresh)
    if args.check and stale:
        print(f"out of date: {', '.join(stale)} (run python docs/results/tables.py)", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
