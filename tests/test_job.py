"""Jobs of several games, sweeps through the launchers, resume, the job lock, failure
tolerance, provenance and interruption."""

from __future__ import annotations

import hashlib
import json
import os
import select
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from pegame import job
from pegame.config import compose
from pegame.errors import JobDirectoryError, ResultsWriteError
from pegame.joblock import JobLock, JobLockedError
from pegame.testing.processes import loky_workers

SHORT = ["game.t_max=4", "recorder=none", "env=hall"]
RANDOM = ["pursuer=random", "evader=random"]


def lines(path: Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text().splitlines()]


def test_trials_append_one_line_per_game_then_the_summary(tmp_path):
    cfg = compose([*SHORT, "game.trials=3", "game.seed=5", *RANDOM])
    run = job.run_job(cfg, tmp_path)
    entries = lines(tmp_path / "results.jsonl")
    assert [e["kind"] for e in entries] == ["game", "game", "game", "summary"]
    assert [e["seed"] for e in entries[:3]] == [5, 6, 7] == [r["seed"] for r in run.played]
    assert entries[-1]["games"] == 3 and entries[-1]["failed"] == 0 and entries[-1]["status"] == 0
    assert not (tmp_path / "result.json").exists()  # per-game files only for one-game jobs


def test_every_game_line_carries_its_config_identity_and_provenance(tmp_path):
    cfg = compose([*SHORT, "game.trials=2", "game.seed=3", *RANDOM])
    job.run_job(cfg, tmp_path, overrides=["env=hall", "game.trials=2"])
    games = [e for e in lines(tmp_path / "results.jsonl") if e["kind"] == "game"]
    assert len(games) == 2
    for entry in games:
        config = entry["config"]
        assert "seed" not in config["game"] and "trials" not in config["game"]
        assert "resume" not in config and "hydra" not in config
        assert config["env"]["name"] == "hall" and config["pursuer"]["name"] == "random"
        assert config["game"]["t_max"] == 4.0
        canonical = json.dumps(config, sort_keys=True, separators=(",", ":")).encode()
        assert entry["config_hash"] == hashlib.sha256(canonical).hexdigest()
        assert entry["overrides"] == ["env=hall", "game.trials=2"]
        prov = entry["provenance"]
        assert set(prov) == {"pegame", "commit", "dirty", "python", "numpy", "numba", "plugins"}
        assert prov["python"] == ".".join(map(str, sys.version_info[:3]))
        assert "pegame" in prov["plugins"]
        assert (prov["commit"] is None) == (prov["dirty"] is None)
    assert games[0]["config_hash"] == games[1]["config_hash"]  # seeds share one config
    other = compose([*SHORT, "game.trials=2", "game.seed=3", "pursuer=random", "evader=smart"])
    job.run_job(other, tmp_path / "other")
    assert lines(tmp_path / "other" / "results.jsonl")[0]["config_hash"] != games[0]["config_hash"]


def test_resume_skips_stored_games_of_the_same_config(tmp_path):
    cfg = compose([*SHORT, "game.trials=2", *RANDOM])
    job.run_job(cfg, tmp_path)
    with (tmp_path / "results.jsonl").open("a") as handle:
        handle.write('{"kind": "game", "seed": 3, "trunc')  # a job killed mid-line
    resumed = compose([*SHORT, "game.trials=4", "resume=true", *RANDOM])
    played = job.run_job(resumed, tmp_path).played
    assert [r["seed"] for r in played] == [2, 3]
    config = next(job.read_lines(tmp_path / "results.jsonl"))["config"]
    assert job.stored_seeds(tmp_path / "results.jsonl", config) == {
        0,
        1,
        2,
        3,
    }  # the fragment stays alone


def test_resume_into_a_directory_of_another_config_names_the_differing_keys(tmp_path):
    job.run_job(compose([*SHORT, "game.trials=2", *RANDOM]), tmp_path)
    before = (tmp_path / "results.jsonl").read_bytes()
    other = compose(
        ["game.t_max=4", "recorder=none", "env=brick", "game.trials=2", "resume=true", *RANDOM]
    )
    with pytest.raises(JobDirectoryError) as info:
        job.run_job(other, tmp_path)
    assert "env.map" in str(info.value) and "env.name" in str(info.value)
    assert (tmp_path / "results.jsonl").read_bytes() == before  # nothing written


def test_a_second_writer_on_the_same_directory_is_refused(tmp_path):
    cfg = compose([*SHORT, *RANDOM])
    with JobLock(tmp_path):
        with pytest.raises(JobLockedError, match=f"PID {os.getpid()}"):
            job.run_job(cfg, tmp_path)
    assert not (tmp_path / "results.jsonl").exists()
    job.run_job(cfg, tmp_path)  # released with the holder
    assert lines(tmp_path / "results.jsonl")[0]["kind"] == "game"


def test_a_failing_game_is_recorded_and_the_job_goes_on(tmp_path, monkeypatch):
    real_play = job.Game.play

    def flaky(self, out_dir, recording_name="game"):
        if self.seed == 1:
            raise RuntimeError("simulated crash")
        return real_play(self, out_dir, recording_name)

    monkeypatch.setattr(job.Game, "play", flaky)
    cfg = compose([*SHORT, "game.trials=3", *RANDOM])
    run = job.run_job(cfg, tmp_path)
    entries = lines(tmp_path / "results.jsonl")
    assert [e["kind"] for e in entries] == ["game", "failed", "game", "summary"]
    assert entries[1]["error"] == "RuntimeError: simulated crash"
    assert entries[1]["config_hash"] == entries[0]["config_hash"] and "provenance" in entries[1]
    assert "simulated crash" in (tmp_path / "failed_1.txt").read_text()
    assert run.failed == [1] and run.status == 1 == entries[-1]["status"]


def test_a_spawn_error_for_one_seed_is_that_games_failure(tmp_path):
    # a 1e-5 rad camera finds a spawn for seeds 0-5 but not for seed 6
    args = [
        "game.t_max=4",
        "recorder=none",
        "env=enclosed",
        "camera.fov=1e-5",
        "game.trials=8",
        *RANDOM,
    ]
    run = job.run_job(compose(args), tmp_path)
    entries = lines(tmp_path / "results.jsonl")
    failed = [e for e in entries if e["kind"] == "failed"]
    assert [e["seed"] for e in failed] == run.failed == [6]
    assert failed[0]["error"].startswith("SpawnError: No valid spawn")
    assert [e["seed"] for e in entries if e["kind"] == "game"] == [0, 1, 2, 3, 4, 5, 7]
    again = job.run_job(compose([*args, "resume=true"]), tmp_path)  # resume retries only seed 6
    assert again.played == [] and again.failed == [6]


def test_a_full_disk_is_one_error_naming_the_file_and_the_result_is_printed(tmp_path, capsys):
    (tmp_path / "results.jsonl").symlink_to("/dev/full")
    with pytest.raises(ResultsWriteError) as info:
        job.run_job(compose([*SHORT, *RANDOM]), tmp_path)
    assert str(tmp_path / "results.jsonl") in str(info.value) and "No space left" in str(info.value)
    printed = capsys.readouterr().err.splitlines()
    entry = json.loads(
        printed[printed.index(next(p for p in printed if "could not be written" in p)) + 1]
    )
    assert entry["kind"] == "game" and entry["pairing"] == "R-R" and "tracking_rate" in entry


def run_sweep(tmp_path: Path, *overrides: str) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k != "HYDRA_FULL_ERROR"}
    return subprocess.run(
        [
            sys.executable,
            "-m",
            "pegame",
            "-m",
            *SHORT,
            "game.trials=2",
            "pursuer=random,smart",
            "evader=random,smart",
            f"hydra.sweep.dir={tmp_path / 'sweep'}",
            *overrides,
        ],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        env=env,
        timeout=600,
    )


@pytest.mark.slow
@pytest.mark.parametrize("launcher", ["pegame", "joblib"])
def test_a_multirun_writes_every_job_and_the_report(tmp_path, launcher):
    proc = run_sweep(tmp_path, f"hydra/launcher={launcher}")
    assert proc.returncode == 0, proc.stderr
    results = sorted((tmp_path / "sweep").rglob("results.jsonl"))
    assert len(results) == 4
    pairings = {lines(p)[0]["pairing"] for p in results}
    assert pairings == {"R-R", "R-S", "S-R", "S-S"}
    assert not list((tmp_path / "sweep").rglob("*.rrd"))  # no recording in sweeps by default
    assert (tmp_path / "sweep" / "table1.md").exists()
    assert not list((tmp_path / "sweep").glob(".pegame-status-*"))  # collected and removed


@pytest.mark.slow
def test_multirun_through_submitit_local(tmp_path):
    pytest.importorskip("hydra_plugins.hydra_submitit_launcher")
    proc = run_sweep(tmp_path, "hydra/launcher=submitit_local", "hydra.launcher.timeout_min=5")
    assert proc.returncode == 0, proc.stderr
    assert len(list((tmp_path / "sweep").rglob("results.jsonl"))) == 4


# --- interrupting a sweep -------------------------------------------------------------

TRIALS = 50  # enough games that the sweep is still running when it is interrupted
SWEEP = [
    *SHORT,
    "pursuer=random",
    "hydra/launcher=joblib",
    "hydra.launcher.n_jobs=2",
]


def start_sweep(
    tmp_path: Path,
    *extra: str,
    sigint_ignored: bool = False,
    cells: tuple[str, ...] = (f"game.trials={TRIALS}", "evader=random,smart"),
) -> subprocess.Popen:
    """The interrupt tests' sweep of two jobs (``cells``: the overrides that make them),
    its stdout (one summary line per game, unbuffered in every process) and stderr piped;
    ``sigint_ignored``: start it with SIGINT ignored, as a background job or a test
    runner's worker would."""
    env = {k: v for k, v in os.environ.items() if k != "HYDRA_FULL_ERROR"}
    env["PYTHONUNBUFFERED"] = "1"
    ignore = (lambda: signal.signal(signal.SIGINT, signal.SIG_IGN)) if sigint_ignored else None
    return subprocess.Popen(
        [
            sys.executable,
            "-m",
            "pegame",
            "-m",
            *SWEEP,
            *cells,
            f"hydra.sweep.dir={tmp_path / 'sweep'}",
            *extra,
        ],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        start_new_session=True,
        preexec_fn=ignore,
    )


def games_stored(tmp_path: Path) -> list[int]:
    files = sorted((tmp_path / "sweep").glob("*/results.jsonl"))
    return [sum(1 for e in job.read_lines(f) if e.get("kind") == "game") for f in files]


def wait_for_games(proc: subprocess.Popen, per_job: int) -> None:
    """Block until both jobs of the sweep printed ``per_job`` games: a job prints a game's
    summary line after storing it, so this waits on the sweep's own output, not on time.
    The rest of the output is drained by a thread, so that no worker blocks on the pipe."""
    seen: dict[str, int] = {}
    while len(seen) < 2 or min(seen.values()) < per_job:
        line = proc.stdout.readline()
        if not line:
            pytest.fail(f"the sweep ended before playing: {proc.stderr.read()}")
        if " on hall: tracking rate " in line:
            pairing = line.split(" ", 1)[0]
            seen[pairing] = seen.get(pairing, 0) + 1
    threading.Thread(target=proc.stdout.read, daemon=True).start()


def wait_exit(pid: int, timeout: float = 300) -> bool:
    """Block until process ``pid`` has exited (its pidfd turns readable; the timeout only
    keeps a broken run from hanging the suite); whether it did."""
    try:
        fd = os.pidfd_open(pid)
    except ProcessLookupError:
        return True
    try:
        readable, _, _ = select.select([fd], [], [], timeout)
        return bool(readable)
    finally:
        os.close(fd)


def interrupt_mid_sweep(tmp_path: Path, how, sigint_ignored: bool = False) -> list[int]:
    """Start a two-worker joblib sweep, wait until both jobs stored games, interrupt it with
    ``how(proc)``; return the worker PIDs it had."""
    proc = start_sweep(tmp_path, sigint_ignored=sigint_ignored)
    wait_for_games(proc, per_job=2)
    workers = loky_workers(proc.pid)
    assert len(workers) >= 2
    how(proc)
    proc.wait(timeout=300)
    return workers


def assert_workers_stop(tmp_path: Path, workers: list[int]) -> None:
    """Every worker exits (within one game: they check between games that the sweep's
    process lives), so nothing can append any more, and the sweep stopped short."""
    assert all(wait_exit(pid) for pid in workers), "workers outlived the sweep"
    assert sum(games_stored(tmp_path)) < 2 * TRIALS


@pytest.mark.slow
def test_kill_9_of_the_sweep_parent_stops_its_workers_and_resume_completes(tmp_path):
    workers = interrupt_mid_sweep(tmp_path, lambda proc: proc.send_signal(signal.SIGKILL))
    assert_workers_stop(tmp_path, workers)
    resumed = start_sweep(tmp_path, "resume=true")
    _, err = resumed.communicate(timeout=600)
    assert resumed.returncode == 0, err
    for path in sorted((tmp_path / "sweep").glob("*/results.jsonl")):
        seeds = [e["seed"] for e in job.read_lines(path) if e.get("kind") == "game"]
        assert sorted(seeds) == list(range(TRIALS)), path  # every game once: no race, none lost


@pytest.mark.slow
def test_kill_9_of_the_sweep_parent_ends_a_worker_whose_job_had_ended(tmp_path):
    # a worker whose job had ended waited in loky for the next one, 300 s after the kill
    proc = start_sweep(tmp_path, cells=("game.trials=2,400", "evader=random"))
    threading.Thread(target=proc.stdout.read, daemon=True).start()
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline:
        stored = games_stored(tmp_path)
        if len(stored) == 2 and min(stored) >= 2:
            break
        time.sleep(0.1)
    workers = loky_workers(proc.pid)
    assert len(workers) == 2
    proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=60)
    assert all(wait_exit(pid, timeout=30) for pid in workers), "a worker outlived the sweep"
    assert sum(games_stored(tmp_path)) < 402


@pytest.mark.slow
def test_sigterm_of_the_sweep_parent_stops_its_workers(tmp_path):
    def terminate(proc):
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=300) == 130

    workers = interrupt_mid_sweep(tmp_path, terminate)
    assert_workers_stop(tmp_path, workers)


@pytest.mark.slow
@pytest.mark.parametrize("sigint_ignored", [False, True], ids=["terminal", "started-ignored"])
def test_ctrl_c_stops_the_sweep_and_its_workers(tmp_path, sigint_ignored):
    # started-ignored: a sweep launched with SIGINT ignored (in the background, or by a test
    # runner's worker) ran to the end and exited 0 on an interrupt
    def ctrl_c(proc):
        os.killpg(proc.pid, signal.SIGINT)  # the terminal signals the whole foreground group
        assert proc.wait(timeout=300) == 130

    workers = interrupt_mid_sweep(tmp_path, ctrl_c, sigint_ignored)
    assert_workers_stop(tmp_path, workers)


def test_a_console_line_is_written_in_one_write_with_its_newline(monkeypatch):
    """A sweep's processes share stdout, unbuffered in CI (PYTHONUNBUFFERED): print's two
    writes (the text, then its end) let another process's line land between them, which
    joined a progress line and a log line into one."""
    writes = []

    class Recorder:
        def write(self, text):
            writes.append(text)

        def flush(self):
            pass

    monkeypatch.setattr(sys, "stdout", Recorder())
    job.say("#0 evader=smart: seed 1 tracking 52.0%")
    assert writes == ["#0 evader=smart: seed 1 tracking 52.0%\n"]
