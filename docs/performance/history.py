"""pegame's performance over its history: ``python -m pegame.bench --quick --json`` at a
commit, kept one JSON line per run in ``history.jsonl``, and the table of the site's
performance-history page generated from it.

    python docs/performance/history.py record --label "0.1.0 (unreleased)"   # this checkout
    python docs/performance/history.py record --commit bbc9d2b --label "..."  # an older one
    python docs/performance/history.py render    # rewrite the page's table
    python docs/performance/history.py --check   # exit 1 if the page's table is stale

``record --commit`` checks the commit out in a temporary git worktree and runs the bench
there (``PYTHONPATH`` puts the worktree's pegame first; numba compiles its kernels afresh
for it, which the bench times apart as ``jit_warmup_s``). Each line holds the commit, its
date, the label, when and on what machine it was measured, the 1-minute load average
before and after, and the bench's figures. A release adds its line with its version as
the label (docs/development.md, "Releasing"). Figures taken minutes apart on a shared
machine differ by tens of percent; the page says so and gives the load. The 3D plugins are
hidden from these runs (their figures are not part of the history).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import tomllib

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
HISTORY = HERE / "history.jsonl"
PAGE = ROOT / "docs" / "explanation" / "performance-history.md"
BEGIN, END = "<!-- generated: history -->\n", "\n<!-- end: history -->"

#: the figures the page shows: (bench key, column title, format)
FIGURES = (
    ("ss_games_per_s", "S-S games/s", "{:.2f}"),
    ("rr_games_per_s", "R-R games/s", "{:.2f}"),
    ("sim_steps_per_s", "sim steps/s", "{:,.0f}"),
    ("visibility_ms", "visibility ms", "{:.3f}"),
    ("plan_ms", "plan ms", "{:.2f}"),
    ("pf_step_ms", "filter step ms", "{:.3f}"),
    ("recorder_overhead", "recorder overhead", "{:.0%}"),
    ("vector_env_steps_per_s", "batched env steps/s", "{:,.0f}"),
    ("vector_speedup_per_core", "batched / single", "{:.1f}x"),
    ("peak_rss_mb", "peak RSS MB", "{:.0f}"),
)


def git(*args: str, cwd: Path = ROOT) -> str:
    return subprocess.run(
        ["git", *args], cwd=cwd, check=True, capture_output=True, text=True
    ).stdout.strip()


#: the plugin distributions, hidden from the bench: the history follows pegame's core,
#: and an older pegame would import today's plugins
HIDDEN = ("pegame_pybullet", "pegame_vision")


def map_packages(checkout: Path) -> None:
    """Lay out an older checkout as its wheel was: each ``package-dir`` mapping of its
    pyproject (``pegame.maps_data = "maps"``, before the data moved into the package)
    becomes a symlink, so that its pegame imports from the worktree as installed."""
    settings = tomllib.loads((checkout / "pyproject.toml").read_text())
    mapping = settings.get("tool", {}).get("setuptools", {}).get("package-dir", {})
    for package, folder in mapping.items():
        link = checkout.joinpath(*package.split("."))
        if package and not link.exists():
            link.symlink_to((checkout / folder).resolve(), target_is_directory=True)


#: a hidden plugin's package: its submodules (but its empty conf) cannot be imported, even
#: through the editable install's finder, which would find them in this checkout
BLOCKER = """import sys


class Hidden:
    @staticmethod
    def find_spec(name, path=None, target=None):
        if name.startswith("{name}.") and name != "{name}.conf":
            raise ModuleNotFoundError(f"{{name}} is hidden by docs/performance/history.py")
        return None


sys.meta_path.insert(0, Hidden)
"""


def declare(folder: Path, name: str, version: str, groups: dict[str, dict[str, str]]) -> None:
    """Metadata in ``folder`` of a distribution ``name`` declaring the entry points
    ``groups``; ``folder`` comes before site-packages on the path, so importlib.metadata
    finds it first and the installed distribution of that name is not seen."""
    info = folder / f"{name}-{version}.dist-info"
    info.mkdir(parents=True)
    info.joinpath("METADATA").write_text(
        f"Metadata-Version: 2.1\nName: {name}\nVersion: {version}\n"
    )
    info.joinpath("entry_points.txt").write_text(
        "".join(
            f"[{group}]\n" + "".join(f"{key} = {target}\n" for key, target in points.items())
            for group, points in groups.items()
        )
    )


def bench(checkout: Path, scratch: Path) -> dict:
    """The quick bench's JSON, run in ``checkout`` with its own pegame first on the path,
    its own entry points (the installed distribution's may name modules it does not have)
    and the plugins hidden: no entry points, and an empty package of each name with an
    empty ``conf`` for the plugin's Hydra search path."""
    hidden = scratch / "hidden"
    project = tomllib.loads((checkout / "pyproject.toml").read_text())["project"]
    declare(hidden, "pegame", project["version"], project.get("entry-points", {}))
    for name in HIDDEN:
        declare(hidden, name, "0", {})  # no simulators or detectors from it
        (hidden / name / "conf").mkdir(parents=True)
        (hidden / name / "__init__.py").write_text(BLOCKER.format(name=name))
        (hidden / name / "conf" / "__init__.py").touch()
    env = {**os.environ, "PYTHONPATH": os.pathsep.join((str(checkout), str(hidden)))}
    done = subprocess.run(
        [sys.executable, "-m", "pegame.bench", "--quick", "--json"],
        cwd=checkout,
        env=env,
        capture_output=True,
        text=True,
    )
    if done.returncode != 0:
        raise SystemExit(f"the bench failed in {checkout}:\n{done.stderr[-3000:]}")
    # The JSON object is the output's last (pegame prints it on one line, older releases
    # indented); anything before it is not the bench's.
    start = done.stdout.rfind("\n{") + 1
    return json.loads(done.stdout[start:])


def record(label: str, commit: str | None) -> dict:
    """Run the bench at ``commit`` (this checkout when None) and append its line."""
    with tempfile.TemporaryDirectory(prefix="pegame-history-") as scratch:
        if commit is None:
            checkout, sha = ROOT, git("rev-parse", "HEAD")
            dirty = bool(git("status", "--porcelain", "--untracked-files=no"))
        else:
            checkout, sha, dirty = Path(scratch) / "tree", git("rev-parse", commit), False
            git("worktree", "add", "--detach", str(checkout), sha)
            map_packages(checkout)
        try:
            load_before = os.getloadavg()[0]
            figures = bench(checkout, Path(scratch))
            load_after = os.getloadavg()[0]
        finally:
            if commit is not None:
                git("worktree", "remove", "--force", str(checkout))
    line = {
        "label": label,
        "commit": sha[:12],
        "dirty": dirty,
        "commit_date": git("show", "-s", "--format=%cI", sha),
        "measured": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "machine": figures.get("machine"),
        "load_1m": [round(load_before, 2), round(load_after, 2)],
        "figures": {key: figures.get(key) for key, _, _ in FIGURES},
    }
    with HISTORY.open("a") as handle:
        handle.write(json.dumps(line, sort_keys=True) + "\n")
    return line


def table() -> str:
    """The page's table: one row per recorded run, oldest commit first."""
    lines = [json.loads(text) for text in HISTORY.read_text().splitlines() if text.strip()]
    lines.sort(key=lambda line: (line["commit_date"], line["measured"]))
    head = ["label", "commit", "measured (load)"] + [title for _, title, _ in FIGURES]
    out = ["| " + " | ".join(head) + " |", "|---" * len(head) + "|"]
    for line in lines:
        cells = [
            line["label"],
            f"`{line['commit'][:7]}`" + (" (dirty)" if line["dirty"] else ""),
            f"{line['measured'][:10]} ({line['load_1m'][0]:.1f}-{line['load_1m'][1]:.1f})",
        ]
        for key, _, form in FIGURES:
            value = line["figures"].get(key)
            cells.append("n/a" if value is None else form.format(value))
        out.append("| " + " | ".join(cells) + " |")
    return "\n".join(out)


def rendered(text: str) -> str:
    start, end = text.index(BEGIN) + len(BEGIN), text.index(END)
    return text[:start] + table() + text[end:]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="exit 1 if the page is stale")
    commands = parser.add_subparsers(dest="command")
    run = commands.add_parser("record", help="run the bench and append its line")
    run.add_argument("--label", required=True, help="the release or milestone it measures")
    run.add_argument("--commit", help="an older commit (default: this checkout)")
    commands.add_parser("render", help="rewrite the page's table")
    args = parser.parse_args(argv)
    if args.command == "record":
        print(json.dumps(record(args.label, args.commit)))
    text = PAGE.read_text()
    fresh = rendered(text)
    if args.check:
        if fresh != text:
            print(
                f"{PAGE} is stale: run python docs/performance/history.py render", file=sys.stderr
            )
            return 1
        return 0
    if fresh != text:
        PAGE.write_text(fresh)
    return 0


if __name__ == "__main__":
    sys.exit(main())
