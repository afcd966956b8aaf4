"""Open a run's Rerun recordings: ``python -m pegame.replay <run dir> [--list]``, or
draw a game headless: ``--video out.mp4``, ``--png out.png [--at SECONDS]``, ``--series
out.png`` (:mod:`pegame.movie`).

Finds every recording under the run directory, recursively (a sweep keeps one directory
per job), sorted by path: ``<game_id>.rrd`` (complete), ``<game_id>.failed.rrd`` (the
game raised; readable up to its failure) and ``<game_id>.rrd.partial`` (being written
at its game's end, or its process was killed while writing it); see
:mod:`pegame.recorders.files`. It opens the
complete and failed ones together in the Rerun viewer, or with ``--list`` prints each
path, size and status. The viewer is the ``rerun`` CLI of the rerun-sdk installed with
this Python (``python -m rerun``), so it always reads the recordings' format version.
Partial files are listed but not opened: the viewer only loads ``*.rrd`` files, and one
may still be being written; copy one to a ``.rrd`` name to look at it.

The headless outputs need no display: they draw one game (the run's only recording, or
the one ``--game`` names: a part of its path that no other recording's path has; a run
recorded with ``recorder=none`` is drawn from its ``trajectory.csv``). On a remote machine
the viewer itself can also be served to a browser: ``python -m rerun --serve-web
<dir>/pegame.rbl <file.rrd>`` and open the printed address (forward the port over ssh).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

from pegame.errors import PegameError
from pegame.recorders.files import LAYOUT_FILE, PARTIAL, recording_status


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
    """The command that opens ``files`` in one Rerun viewer, after the layout files
    (``pegame.rbl``, :mod:`pegame.recorders.rerun.blueprint`) of their directories."""
    layouts = sorted({path.parent / LAYOUT_FILE for path in files})
    shown = [path for path in layouts if path.is_file()] + files
    return [sys.executable, "-m", "rerun", *(str(path) for path in shown)]


def human_size(size: int) -> str:
    """A byte count as '512 B', '3.4 kB' or '12.0 MB' (powers of 1000)."""
    if size < 1000:
        return f"{size} B"
    if size < 1_000_000:
        return f"{size / 1e3:.1f} kB"
    return f"{size / 1e6:.1f} MB"


def game_source(run_dir: str | Path, game: str | None) -> Path:
    """The recording (or, without one, the job directory with ``trajectory.csv``) that the
    headless outputs draw: the run's only readable recording, or the one whose path holds
    ``game``. ReplayError naming the candidates when that is not exactly one."""
    root = Path(run_dir).expanduser()
    if root.is_file():
        return root
    try:
        files = [p for p in find_recordings(root) if recording_status(p) != PARTIAL]
    except ReplayError:
        if (root / "trajectory.csv").is_file() and game is None:
            return root
        raise
    chosen = [p for p in files if game is None or game in str(p.relative_to(root))]
    if len(chosen) == 1:
        return chosen[0]
    names = ", ".join(str(p.relative_to(root)) for p in (chosen or files)[:8])
    more = " ..." if len(chosen or files) > 8 else ""
    what = f"match --game {game!r}" if game is not None else "are recorded here"
    raise ReplayError(
        f"{len(chosen)} games {what}; name one with --game (a part of its path): {names}{more}"
    )


def draw(args: argparse.Namespace) -> int:
    """Write the headless outputs the arguments ask for (:mod:`pegame.movie`)."""
    from pegame.movie import MovieError, load_game, write_png, write_series, write_video

    try:
        source = game_source(args.run_dir, args.game)
        game = load_game(source)
        if args.size < 16:
            raise ReplayError(f"--size must be at least 16 pixels, not {args.size}")
        if args.video:
            print(f"pegame.replay: {write_video(game, args.video, args.size, args.speed)}")
        if args.png:
            print(f"pegame.replay: {write_png(game, args.png, args.at, args.size)}")
        if args.series:
            print(f"pegame.replay: {write_series(game, args.series, title=str(source))}")
    except (ReplayError, MovieError) as exc:
        print(f"pegame.replay: error: {exc}", file=sys.stderr)
        return 2
    return 0


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
    parser.add_argument("--video", metavar="OUT.mp4", help="write the game as an MP4 video")
    parser.add_argument("--png", metavar="OUT.png", help="write one frame (see --at) as a PNG")
    parser.add_argument(
        "--series",
        metavar="OUT.png",
        help="write the game's detection, distance, estimation error and N_eff against time",
    )
    parser.add_argument(
        "--at", type=float, metavar="SECONDS", help="the --png frame's time (default: the last)"
    )
    parser.add_argument(
        "--game", help="which game of the run to draw: a part of its recording's path"
    )
    parser.add_argument(
        "--speed", type=float, default=1.0, help="video pace, times the game's (default 1)"
    )
    parser.add_argument(
        "--size", type=int, default=480, help="frame's longer side in pixels (default 480)"
    )
    args = parser.parse_args(argv)
    if args.video or args.png or args.series:
        return draw(args)
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
            f"pegame.replay: {len(files) - len(readable)} partial recording(s) (being written, or cut) "
            "not opened; see --list.",
            file=sys.stderr,
        )
    if not readable:
        return 2
    return subprocess.call(viewer_command(readable))


if __name__ == "__main__":
    sys.exit(main())
