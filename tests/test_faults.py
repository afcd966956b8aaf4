"""Fault injection: full and read-only disks, racing sweeps, refused runs, misbehaving
plugins and unreadable results (issue 26). Each test is a fault that once lost results
or misled, and what pegame promises for it instead (README, "Exit codes")."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from pegame import files, job
from pegame.config import compose
from pegame.errors import ConfigError
from pegame.observe.observations import ObservationSettings
from pegame.policies import LinearPolicy
from pegame.recorders.files import recording_status
from pegame.sweep import OWNER_FILE
from pegame.testing import chase
from pegame.testing.processes import loky_workers

FAST = ["recorder=none", "env=hall", "game.t_max=2"]
RANDOM = ["pursuer=random", "evader=random"]


def app(cwd: Path, *args: str, env: dict | None = None, timeout: float = 300) -> subprocess.Popen:
    """``python -m pegame *args`` started in ``cwd`` (stdout and stderr piped)."""
    base = {k: v for k, v in os.environ.items() if k != "HYDRA_FULL_ERROR"}
    return subprocess.Popen(
        [sys.executable, "-m", "pegame", *args],
        cwd=cwd,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**base, **(env or {})},
    )


def finished(proc: subprocess.Popen, timeout: float = 300) -> tuple[int, str]:
    """Wait for ``proc``; its exit status and stderr."""
    _, err = proc.communicate(timeout=timeout)
    return proc.returncode, err


def run(cwd: Path, *args: str, env: dict | None = None, timeout: float = 300) -> tuple[int, str]:
    return finished(app(cwd, *args, env=env), timeout)


def games(root: Path) -> list[dict]:
    """Every game line under ``root``."""
    return [
        e
        for path in sorted(root.rglob("results.jsonl"))
        for e in job.read_lines(path)
        if e["kind"] == "game"
    ]


def snapshot(root: Path) -> dict[str, bytes]:
    """Every file under ``root`` (the lock files aside) and its content."""
    return {
        p.relative_to(root).as_posix(): p.read_bytes()
        for p in sorted(root.rglob("*"))
        if p.is_file() and p.name not in (".lock", OWNER_FILE)
    }


@pytest.fixture
def mount(tmp_path: Path) -> Iterator:
    """mount(options) -> a fresh tmpfs mounted with ``options`` (e.g. 'size=2m', 'ro');
    skipped where this process may not mount (not root)."""
    mounted: list[Path] = []

    def make(options: str) -> Path:
        point = tmp_path / f"mnt{len(mounted)}"
        point.mkdir()
        proc = subprocess.run(
            ["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(point)], capture_output=True
        )
        if proc.returncode != 0:
            pytest.skip(f"cannot mount a tmpfs here: {proc.stderr.decode().strip()}")
        mounted.append(point)
        return point

    yield make
    for point in mounted:
        subprocess.run(["umount", "-l", str(point)], capture_output=True)


# --- full and read-only disks -------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("size", ["2m", "1536k"])
def test_a_full_disk_fails_the_game_it_cannot_record_and_leaves_no_broken_recording(
    tmp_path, mount, size
):
    # 2 MB: rerun's file sink wrote a truncated game_2.rrd that was called complete, exit 0;
    # 1.5 MB: the second game hung on rerun's recording stream until killed. A 90 s game
    # on brick records about 1 MB: the three games cannot all fit.
    out = mount(f"size={size}") / "run"
    status, err = run(
        tmp_path,
        "env=brick",
        "game.t_max=90",
        "game.trials=3",
        "recorder=rerun",
        f"hydra.run.dir={out}",
        timeout=180,
    )
    assert status == 1, err
    lines = list(job.read_lines(out / "results.jsonl"))
    failed = [e for e in lines if e["kind"] == "failed"]
    assert failed and all("No space left on device" in e["error"] for e in failed)
    log = (out / "pegame.log").read_text()
    for entry in failed:
        assert (
            f"seed {entry['seed']} failed: Could not write to {out}/game_{entry['seed']}.rrd" in log
        )
    recordings = sorted(p for p in out.iterdir() if recording_status(p))
    assert [recording_status(p) for p in recordings] == ["complete"] * (3 - len(failed))
    for path in recordings:
        verify = subprocess.run(
            [sys.executable, "-m", "rerun", "rrd", "verify", str(path)], capture_output=True
        )
        assert verify.returncode == 0, path


def test_a_recording_that_cannot_be_written_fails_its_game(tmp_path, monkeypatch, caplog):
    real_open = os.open

    def full_for_recordings(path: str, flags: int, *args: int, **options: int) -> int:
        # a recording's partial file opens /dev/full: its write fails with ENOSPC
        if str(path).endswith(".rrd.partial"):
            return real_open("/dev/full", os.O_WRONLY)
        return real_open(path, flags, *args, **options)

    monkeypatch.setattr(files.os, "open", full_for_recordings)
    cfg = compose(["recorder=rerun", "env=hall", "game.t_max=2", "game.trials=2", *RANDOM])
    run_ = job.run_job(cfg, tmp_path)
    assert run_.failed == [0, 1] and run_.status == 1
    failed = [e for e in job.read_lines(tmp_path / "results.jsonl") if e["kind"] == "failed"]
    assert [e["error"].split(":")[0] for e in failed] == ["ResultsWriteError"] * 2
    assert "seed 0 failed: Could not write to" in caplog.text
    assert not [p for p in tmp_path.iterdir() if recording_status(p)]  # no broken file


def test_a_layout_file_that_cannot_be_written_fails_its_game(tmp_path, monkeypatch):
    from pegame.recorders.rerun import blueprint

    def full(path: Path, data: bytes, **options: object) -> None:
        raise files.write_failed(path, OSError(28, "No space left on device"))

    monkeypatch.setattr(blueprint, "write_atomic", full)
    cfg = compose(["recorder=rerun", "env=hall", "game.t_max=2", *RANDOM])
    run_ = job.run_job(cfg, tmp_path)
    assert run_.failed == [0] and run_.status == 1
    (failed,) = [e for e in job.read_lines(tmp_path / "results.jsonl") if e["kind"] == "failed"]
    assert failed["error"].startswith("ResultsWriteError: Could not write to")
    assert "pegame.rbl" in failed["error"]


@pytest.mark.slow
def test_an_unwritable_run_dir_is_one_message_and_exit_2(tmp_path, mount):
    (tmp_path / "a_file").write_text("")
    read_only = mount("ro,size=1m")
    for where in (tmp_path / "a_file", read_only / "run", read_only):
        status, err = run(tmp_path, *FAST, f"hydra.run.dir={where}")
        assert status == 2 and "Traceback" not in err, err
        assert err.startswith(f"pegame: error: Could not write to {where}"), err
    status, err = run(tmp_path, "-m", *FAST, "game.seed=0,1", f"hydra.sweep.dir={read_only}/s")
    assert status == 2 and "Traceback" not in err, err


# --- refused runs leave the directory as it was ----------------------------------------


@pytest.mark.slow
def test_a_refused_run_leaves_the_job_directory_as_it_was(tmp_path):
    out = tmp_path / "run"
    assert run(tmp_path, *FAST, *RANDOM, f"hydra.run.dir={out}")[0] == 0
    before = snapshot(out)
    assert {".hydra/config.yaml", ".hydra/overrides.yaml", "pegame.log"} <= set(before)
    # another config's games are there
    status, err = run(
        tmp_path, *FAST, *RANDOM, "game.t_max=3", "resume=true", f"hydra.run.dir={out}"
    )
    assert status == 2 and "differs in: game.t_max" in err
    assert snapshot(out) == before  # .hydra/config.yaml still says t_max=2, as result.json
    # another process writes there
    from pegame.joblock import JobLock

    with JobLock(out):
        status, err = run(tmp_path, *FAST, *RANDOM, "resume=true", f"hydra.run.dir={out}")
    assert status == 2 and "Another pegame process" in err
    assert snapshot(out) == before


# --- one sweep per sweep directory -----------------------------------------------------


@pytest.mark.slow
def test_a_second_sweep_into_a_sweep_directory_is_refused_naming_the_first(tmp_path):
    sweep = tmp_path / "sweep"
    first = [
        "-m", "recorder=none", "env=hall", "game.t_max=4", "game.trials=40",
        "pursuer=random", "evader=random,smart", f"hydra.sweep.dir={sweep}",
    ]  # fmt: skip
    running = app(tmp_path, *first)
    deadline = time.monotonic() + 240
    while not games(sweep):  # the first sweep owns the directory and plays
        assert running.poll() is None and time.monotonic() < deadline, running.stderr.read()
        time.sleep(0.05)
    status, err = run(tmp_path, *first[:-1], "game.t_max=5", f"hydra.sweep.dir={sweep}")
    assert status == 2 and f"PID {running.pid}" in err, err
    assert finished(running)[0] == 0
    played = games(sweep)
    assert len(played) == 80 and {g["t_max"] for g in played} == {4.0}  # none of the second's
    before = snapshot(sweep)
    status, err = run(tmp_path, *first)  # the same sweep again, after the first ended
    assert status == 2 and "run it again with resume=true" in err and f"PID {running.pid}" in err
    assert snapshot(sweep) == before  # no game doubled, no report rewritten
    status, err = run(tmp_path, *first, "resume=true")
    assert status == 0, err
    assert len(games(sweep)) == 80


# --- misbehaving plugins and bad policy paths -----------------------------------------


@pytest.mark.slow
def test_a_plugin_that_calls_sys_exit_fails_its_game_and_the_sweep_goes_on(tmp_path):
    (tmp_path / "quitter.py").write_text("def policy(observation):\n    raise SystemExit(0)\n")
    sweep = tmp_path / "sweep"
    status, err = run(
        tmp_path,
        "-m",
        *FAST,
        "pursuer=policy",
        "pursuer.path=quitter:policy",
        "evader=random",
        "game.seed=0,5",
        f"hydra.sweep.dir={sweep}",
        env={"PYTHONPATH": str(tmp_path)},
    )
    assert status == 1, err
    cells = sorted(sweep.glob("*/results.jsonl"))
    assert len(cells) == 2
    for path in cells:
        kinds = [(e["kind"], e.get("error")) for e in job.read_lines(path)]
        assert kinds[0] == ("failed", "SystemExit: 0") and kinds[-1][0] == "summary"
    assert (sweep / "report.json").is_file()


def test_a_plugin_that_calls_sys_exit_fails_only_its_game(tmp_path, monkeypatch):
    real_play = job.Game.play

    def exiting(self, out_dir, recording_name="game"):
        if self.seed == 1:
            raise SystemExit(0)
        return real_play(self, out_dir, recording_name)

    monkeypatch.setattr(job.Game, "play", exiting)
    run_ = job.run_job(compose([*FAST, "game.trials=3", *RANDOM]), tmp_path)
    assert run_.failed == [1] and [r["seed"] for r in run_.played] == [0, 2]


def bad_policies(tmp_path: Path) -> dict[str, str]:
    """pursuer.path values that cannot be played, by what is wrong."""
    corrupt = tmp_path / "corrupt.npz"
    corrupt.write_bytes(b"not a zip")
    evaders = tmp_path / "evader.npz"
    LinearPolicy(np.zeros((2, 3)), np.zeros(2), "evader", ObservationSettings()).save(evaders)
    return {
        "missing module": "no_such_module:policy",
        "missing attribute": f"{chase.__module__}:no_such_policy",
        "missing file": str(tmp_path / "none.npz"),
        "corrupt file": str(corrupt),
        "the other role's": str(evaders),
    }


@pytest.mark.parametrize(
    "what",
    ["missing module", "missing attribute", "missing file", "corrupt file", "the other role's"],
)
def test_a_bad_policy_path_is_refused_before_the_first_game(tmp_path, what):
    path = bad_policies(tmp_path)[what]
    cfg = compose([*FAST, "pursuer=policy", f"pursuer.path={path}", "game.trials=3"])
    with pytest.raises(ConfigError, match=r"pursuer\.path|Policy file"):
        job.run_job(cfg, tmp_path / "run")
    assert not (tmp_path / "run" / "results.jsonl").exists()


# --- unreadable results -------------------------------------------------------------


def test_a_results_file_with_bytes_that_are_no_utf8_still_resumes(tmp_path):
    cfg = compose([*FAST, "game.trials=2", *RANDOM])
    job.run_job(cfg, tmp_path)
    with (tmp_path / "results.jsonl").open("ab") as handle:
        handle.write(b'{"kind": "summ\xffary"}\n\xfe\xff\n[1, 2]\n"text"\n')  # no UTF-8, no object
    resumed = compose([*FAST, "game.trials=3", "resume=true", *RANDOM])
    assert [r["seed"] for r in job.run_job(resumed, tmp_path).played] == [2]


# --- a worker killed -----------------------------------------------------------------


@pytest.mark.slow
def test_a_killed_joblib_worker_ends_the_sweep_with_a_report_of_what_finished_and_exit_1(
    tmp_path,
):
    # joblib's TerminatedWorkerError ended the sweep with exit 1, no report, no word on resume;
    # joblib cancels the jobs it had not finished (pegame's launcher fails the killed job
    # only: tests/test_launcher.py)
    sweep = tmp_path / "sweep"
    args = [
        "-m", "recorder=none", "env=hall", "game.t_max=4", "game.trials=60",
        "pursuer=random", "evader=random,smart", "hydra/launcher=joblib",
        "hydra.launcher.n_jobs=2", f"hydra.sweep.dir={sweep}",
    ]  # fmt: skip
    proc = app(tmp_path, *args, env={"PYTHONUNBUFFERED": "1"})
    for line in proc.stdout:  # a job prints each game's line once it is stored
        if " on hall: tracking rate " in line:
            break
    victims = loky_workers(proc.pid)
    assert victims, "no loky worker found"
    os.kill(victims[0], 9)
    status, err = finished(proc)
    assert status == 1, err
    assert "a worker process died" in err and "resume=true" in err
    assert (sweep / "report.json").is_file() and (sweep / "table1.md").is_file()
    assert not list(sweep.glob(".pegame-status-*"))
    status, err = run(tmp_path, *args, "resume=true")  # the sweep's owner let it go
    assert status == 0, err
    assert len(games(sweep)) == 120
