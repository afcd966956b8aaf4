"""Open a run's Rerun recordings: ``python -m pegame.replay <run dir> [--list]``.

Finds every recording under the run directory, recursively (a sweep keeps one directory
per job), sorted by path: ``<game_id>.rrd`` (complete), ``<game_id>.failed.rrd`` (the
game raised; readable up to its failure) and ``<game_id>.rrd.partial`` (the game is
running, or its process was killed); see :mod:`pegame.recorders.files`. It opens the
complete and failed ones together in the Rerun viewer, or with ``--list`` prints each
path, size and status. The viewer is the ``rerun`` CLI of the rerun-sdk installed with
this Python (``python -m rerun``), so it always reads the recordings' format version.
Partial files are listed but not opened: the viewer only loads ``*.rrd`` files, and one
may still be being written; copy one to a ``.rrd`` name to look at it.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

from pegame.errors import PegameError
from pegame.recorders.files import PARTIAL, recording_status


class ReplayError(PegameError):
    """No recordings to replay: the directory is missing or holds none."""


def find_recordings(run_dir: str | Path) -> list[Path]:
    """Every recording file (complete, failed or partial) under ``run_dir``
    (recursively), sorted by path."""
    root = Path(run_dir).expanduser()
    if not root.is_dir():
        raise ReplayError(
            f"'{root}' is not a directory; give a run's output directory (e.g. outputs/<date>/<time>)."
        )
    files = sorted(
        path for path in root.rglob("*.rrd*") if path.is_file() and recording_status(path)
    )
    if not files:
        raise ReplayError(
            f"No Rerun recordings (*.rrd) under '{root}'. Record games with recorder=rerun, "
            "e.g. python -m pegame recorder=rerun."
        )
    return files


def viewer_command(files: list[Path]) -> list[str]:
    """The command that opens ``files`` in one Rerun viewer."""
    return [sys.executable, "-m", "rerun", *(str(path) for path in files)]


def human_size(size: int) -> str:
    """A byte count as '512 B', '3.4 kB' or '12.0 MB' (powers of 1000)."""
    if size < 1000:
        return f"{size} B"
    if size < 1_000_000:
        return f"{size / 1e3:.1f} kB"
    return f"{size / 1e6:.1f} MB"


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point; returns the exit status (2 when there is nothing to replay)."""
    parser = argparse.ArgumentParser(
        prog="python -m pegame.replay",
        description="Open a run's Rerun recordings (*.rrd) in the Rerun viewer.",
    )
    parser.add_argument(
        "run_dir", help="a run's output directory, or any directory above several runs"
    )
    parser.add_argument(
        "--list",
        action="store_true",
        help="list the recordings, their sizes and statuses (complete, failed, partial) instead",
    )
    args = parser.parse_args(argv)
    try:
        files = find_recordings(args.run_dir)
    except ReplayError as exc:
        print(f"pegame.replay: error: {exc}", file=sys.stderr)
        return 2
    if args.list:
        for path in files:
            print(f"{path}  {human_size(path.stat().st_size)}  {recording_status(path)}")
        return 0
    readable = [path for path in files if recording_status(path) != PARTIAL]
    if len(readable) < len(files):
        print(
            f"pegame.replay: {len(files) - len(readable)} partial recording(s) (a game running or killed) "
            "not opened; see --list.",
            file=sys.stderr,
        )
    if not readable:
        return 2
    return subprocess.call(viewer_command(readable))


if __name__ == "__main__":
    sys.exit(main())
