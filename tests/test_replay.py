"""python -m pegame.replay: finding a run's recordings, their statuses, opening them.

A run directory with one game of each ending is played for real: one that finished, one
whose pursuer raised, and one whose process was killed mid-game (SIGKILL, in a
subprocess), which leaves no recording (it is held in memory until the game ends); a
process killed while writing one leaves its partial file, made here by cutting a copy of
a complete one. The statuses are checked against ``rerun rrd verify``.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from pegame.config import compose
from pegame.game import Game
from pegame.recorders.files import recording_status
from pegame.replay import find_recordings, viewer_command
from pegame.replay import main as replay_main

SHORT = ["recorder=rerun", "game.t_max=3", "env=hall"]

KILLED_GAME = textwrap.dedent("""
    import os, signal, sys
    from pegame.config import compose
    from pegame.game import Game

    game = Game(compose({overrides!r}))
    decide, calls = game.plugins.pursuer.decide, []

    def killed(observation):
        calls.append(observation.time)
        if len(calls) == 3:  # step 20, after two sends of 10 ticks
            os.kill(os.getpid(), signal.SIGKILL)
        return decide(observation)

    game.plugins.pursuer.decide = killed
    game.play(sys.argv[1], "game_2")
""")


def rrd_verify(path: Path) -> int:
    """The exit status of ``rerun rrd verify path``."""
    return subprocess.run(
        [sys.executable, "-m", "rerun", "rrd", "verify", str(path)], capture_output=True, timeout=60
    ).returncode


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    """job0: a finished game, job1: a failed one, job2: a killed one."""
    root = tmp_path_factory.mktemp("run")
    Game(compose(SHORT)).play(root / "job0", "game_0")
    game = Game(compose(SHORT))

    def broken(observation):
        raise RuntimeError("pursuer broke")

    game.plugins.pursuer.decide = broken
    with pytest.raises(RuntimeError):
        game.play(root / "job1", "game_1")
    script = KILLED_GAME.format(overrides=[*SHORT, "recorder.flush_every=10"])
    proc = subprocess.run(
        [sys.executable, "-c", script, str(root / "job2")],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == -9, proc.stderr  # killed
    complete = (root / "job0" / "game_0.rrd").read_bytes()
    (root / "job3").mkdir()
    (root / "job3" / "game_3.rrd.partial").write_bytes(complete[: len(complete) // 2])
    return root


def listed(run_dir: Path, capsys) -> dict[str, str]:
    """{path relative to run_dir: status} from ``--list``."""
    assert replay_main([str(run_dir), "--list"]) == 0
    rows = [line.split("  ") for line in capsys.readouterr().out.splitlines()]
    return {Path(path).relative_to(run_dir).as_posix(): status for path, _size, status in rows}


@pytest.mark.slow
def test_replay_lists_each_recording_with_its_status(run_dir, capsys):
    assert listed(run_dir, capsys) == {
        "job0/game_0.rrd": "complete",
        "job1/game_1.failed.rrd": "failed",
        "job3/game_3.rrd.partial": "partial",
    }


def test_every_recording_listed_as_complete_or_failed_passes_rrd_verify(run_dir, capsys):
    statuses = listed(run_dir, capsys)
    assert "complete" in statuses.values()
    for path, status in statuses.items():
        if status in ("complete", "failed"):
            assert rrd_verify(run_dir / path) == 0, path


def test_a_killed_game_leaves_no_recording_and_a_cut_one_keeps_its_partial_name(run_dir):
    killed = run_dir / "job2"
    assert not killed.exists() or not [p for p in killed.iterdir() if recording_status(p)]
    assert rrd_verify(run_dir / "job3" / "game_3.rrd.partial") != 0  # what the name says


def test_replay_opens_complete_and_failed_recordings_not_partial_ones(run_dir, monkeypatch, capsys):
    opened = []
    monkeypatch.setattr(subprocess, "call", lambda command: opened.append(command) or 0)
    assert replay_main([str(run_dir)]) == 0
    files = [run_dir / "job0" / "game_0.rrd", run_dir / "job1" / "game_1.failed.rrd"]
    assert opened == [viewer_command(files)]
    assert "1 partial recording(s)" in capsys.readouterr().err


def test_replay_finds_recordings_recursively_sorted(tmp_path, capsys):
    for name in (
        "job1/game_2.rrd",
        "job0/game_1.rrd",
        "job0/game_0.rrd",
        "job0/notes.txt",
        "job0/.rrd",
    ):
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_bytes(b"x" * 1500)
    files = find_recordings(tmp_path)
    assert [p.relative_to(tmp_path).as_posix() for p in files] == [
        "job0/game_0.rrd",
        "job0/game_1.rrd",
        "job1/game_2.rrd",
    ]
    assert viewer_command(files) == [sys.executable, "-m", "rerun", *map(str, files)]
    (tmp_path / "job0" / "pegame.rbl").write_bytes(b"layout")  # its directory's layout first
    assert viewer_command(files)[3:] == [str(tmp_path / "job0" / "pegame.rbl"), *map(str, files)]
    assert replay_main([str(tmp_path), "--list"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines == [f"{p}  1.5 kB  complete" for p in files]


def test_replay_without_recordings_is_a_clear_error(tmp_path, capsys):
    assert replay_main([str(tmp_path)]) == 2
    assert "No Rerun recordings (*.rrd)" in capsys.readouterr().err
    assert replay_main([str(tmp_path / "missing")]) == 2
    assert "is not a directory" in capsys.readouterr().err
