"""pegame's launcher (hydra_plugins/pegame_launcher, the default ``hydra/launcher``): a
sweep runs as through the joblib launcher, and a worker killed mid-sweep fails only the
job it ran while the other cells finish (issue 26)."""

from __future__ import annotations

import json
import os
import select
import signal
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from pegame import job

CELLS = ["recorder=none", "env=hall", "game.t_max=4", "pursuer=random", "evader=random"]


def start(tmp_path: Path, sweep: Path, *extra: str) -> subprocess.Popen:
    """``python -m pegame -m`` over three speed ratios into ``sweep``, stdout unbuffered."""
    env = {k: v for k, v in os.environ.items() if k != "HYDRA_FULL_ERROR"}
    env["PYTHONUNBUFFERED"] = "1"
    args = [*CELLS, "game.speed_ratio=1,2,3", f"hydra.sweep.dir={sweep}", *extra]
    return subprocess.Popen(
        [sys.executable, "-m", "pegame", "-m", *args],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        start_new_session=True,
    )


def entries(cell: Path) -> list[dict]:
    return list(job.read_lines(cell / job.RESULTS))


def seeds(cell: Path, kind: str = "game") -> list[int]:
    return sorted(e["seed"] for e in entries(cell) if e["kind"] == kind)


def first_game_of(proc: subprocess.Popen, cell: str) -> None:
    """Block until job ``cell`` (e.g. '#0') printed a game: it prints each game's line
    once the game is stored. The rest of stdout is drained by a thread."""
    for line in proc.stdout:
        if line.startswith(f"{cell} ") and " on hall: tracking rate " in line:
            break
    else:
        pytest.fail(f"the sweep ended before {cell} played: {proc.stderr.read()}")
    threading.Thread(target=proc.stdout.read, daemon=True).start()


def holder(cell: Path) -> int:
    """The PID of the process that holds the job directory's lock (its worker)."""
    return int((cell / ".lock").read_text().split()[0])


def wait_exit(pid: int, timeout: float = 300) -> bool:
    """Block until process ``pid`` exited (its pidfd turns readable); whether it did."""
    try:
        fd = os.pidfd_open(pid)
    except ProcessLookupError:
        return True
    try:
        return bool(select.select([fd], [], [], timeout)[0])
    finally:
        os.close(fd)


@pytest.mark.slow
def test_a_killed_worker_fails_its_job_and_the_other_cells_finish(tmp_path):
    # through joblib every job not finished was cancelled and the sweep ended at once
    sweep, trials = tmp_path / "sweep", 150
    proc = start(tmp_path, sweep, f"game.trials={trials}", "hydra.launcher.n_jobs=2")
    first_game_of(proc, "#0")
    victim = holder(sweep / "0")
    os.kill(victim, signal.SIGKILL)
    _, err = proc.communicate(timeout=600)
    assert proc.returncode == 1, err
    killed = [e for e in entries(sweep / "0") if e["kind"] == "failed"]
    assert len(killed) == 1
    assert killed[0]["error"] == "WorkerDied: worker killed by signal 9 (SIGKILL)"
    assert killed[0]["seed"] not in seeds(sweep / "0")  # the game it was playing
    for cell in ("1", "2"):
        assert seeds(sweep / cell) == list(range(trials)), cell
        assert entries(sweep / cell)[-1]["kind"] == "summary"
    report = json.loads((sweep / "report.json").read_text())
    assert [g["seed"] for g in report["failed_games"]] == [killed[0]["seed"]]
    assert report["unfinished_jobs"] == ["0"]
    assert (sweep / "table1.md").is_file()
    assert not list(sweep.glob(".pegame-status-*"))
    resumed = start(tmp_path, sweep, f"game.trials={trials}", "resume=true")
    _, err = resumed.communicate(timeout=600)
    assert resumed.returncode == 0, err
    assert seeds(sweep / "0") == list(range(trials))  # the stored games kept, none twice


def tree(sweep: Path) -> dict[str, object]:
    """The files of a sweep directory; each results.jsonl as its entries without what
    differs from run to run (wall times: none are stored; the launcher: Hydra's files)."""
    return {
        str(path.relative_to(sweep)): entries(path.parent) if path.name == job.RESULTS else None
        for path in sorted(sweep.rglob("*"))
        if path.is_file()
    }


@pytest.mark.slow
def test_a_sweep_gives_the_same_files_and_status_as_through_joblib(tmp_path):
    trees = {}
    for launcher in ("pegame", "joblib"):
        sweep = tmp_path / launcher
        proc = start(tmp_path, sweep, "game.trials=2", f"hydra/launcher={launcher}")
        _, err = proc.communicate(timeout=600)
        assert proc.returncode == 0, err
        trees[launcher] = tree(sweep)
    assert trees["pegame"] == trees["joblib"]
    assert "2/results.jsonl" in trees["pegame"]


@pytest.mark.slow
@pytest.mark.parametrize("how", ["sigterm", "ctrl-c"])
def test_an_interrupt_stops_the_sweep_and_its_workers(tmp_path, how):
    sweep = tmp_path / "sweep"
    proc = start(tmp_path, sweep, "game.trials=400", "hydra.launcher.n_jobs=2")
    first_game_of(proc, "#0")
    worker = holder(sweep / "0")
    if how == "sigterm":
        proc.send_signal(signal.SIGTERM)
    else:
        os.killpg(proc.pid, signal.SIGINT)  # the terminal signals the whole foreground group
    assert proc.wait(timeout=300) == 130
    assert wait_exit(worker), "a worker outlived the sweep"
    assert len(seeds(sweep / "0")) < 400


class FakeTerminal:
    """A stderr that is a terminal: what tqdm draws lands in ``text``."""

    def __init__(self) -> None:
        self.text = ""

    def isatty(self) -> bool:
        return True

    def write(self, text: str) -> int:
        self.text += text
        return len(text)

    def flush(self) -> None:
        pass


def test_the_progress_bar_counts_games_as_they_are_stored(monkeypatch):
    from hydra.core.utils import JobReturn, JobStatus

    from hydra_plugins.pegame_launcher._pool import Progress

    terminal = FakeTerminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    progress = Progress([3, 2])
    assert progress.bar is not None and progress.bar.total == 5 and progress.poll
    progress.running({0: 1, 1: 5})  # a job's count is capped at its trials
    assert progress.bar.n == 3
    progress.running({0: 0})  # never back (a stale read)
    assert progress.bar.n == 3
    finished = JobReturn(status=JobStatus.COMPLETED, _return_value=0)
    progress.done(0, 0, ["env=hall"], finished)  # a resumed job's stored games count at its end
    assert progress.bar.n == 5
    progress.close()
    assert "5/5" in terminal.text and "game" in terminal.text


def test_without_a_terminal_each_cell_prints_a_line_with_the_games(monkeypatch, capsys):
    from hydra.core.utils import JobReturn, JobStatus

    from hydra_plugins.pegame_launcher._pool import Progress

    monkeypatch.setattr(sys.stderr, "isatty", lambda: False, raising=False)
    progress = Progress([4, 4, 2])
    assert progress.bar is None and progress.poll is None  # no polling without a bar
    progress.done(1, 7, ["env=brick"], JobReturn(status=JobStatus.COMPLETED, _return_value=1))
    line = capsys.readouterr().out.strip()
    assert line.startswith("pegame: cell 1 of 3 done (#7 env=brick): exit 1, ")
    assert line.endswith("; games 4 of 10")
