"""Jobs of several games, sweeps through the launchers, resume and failure tolerance."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from pegame import job
from pegame.config import compose

SHORT = ["game.t_max=4", "recorder=none", "env=hall"]


def lines(path: Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text().splitlines()]


def test_trials_append_one_line_per_game_then_the_summary(tmp_path):
    cfg = compose([*SHORT, "game.trials=3", "game.seed=5", "pursuer=random", "evader=random"])
    results = job.run_job(cfg, tmp_path)
    entries = lines(tmp_path / "results.jsonl")
    assert [e["kind"] for e in entries] == ["game", "game", "game", "summary"]
    assert [e["seed"] for e in entries[:3]] == [5, 6, 7] == [r["seed"] for r in results]
    assert entries[-1]["games"] == 3 and entries[-1]["failed"] == 0
    assert not (tmp_path / "result.json").exists()  # per-game files only for one-game jobs


def test_resume_skips_stored_games(tmp_path):
    cfg = compose([*SHORT, "game.trials=2", "pursuer=random", "evader=random"])
    job.run_job(cfg, tmp_path)
    with (tmp_path / "results.jsonl").open("a") as handle:
        handle.write('{"kind": "game", "seed": 3, "trunc')  # a job killed mid-line
    resumed = compose([*SHORT, "game.trials=4", "resume=true", "pursuer=random", "evader=random"])
    played = job.run_job(resumed, tmp_path)
    assert [r["seed"] for r in played] == [2, 3]
    assert job.stored_seeds(tmp_path / "results.jsonl") == {0, 1, 2, 3}  # the fragment stays alone


def test_a_failing_game_is_recorded_and_the_job_goes_on(tmp_path, monkeypatch):
    real_play = job.Game.play

    def flaky(self, out_dir, recording_name="game"):
        if self.seed == 1:
            raise RuntimeError("simulated crash")
        return real_play(self, out_dir, recording_name)

    monkeypatch.setattr(job.Game, "play", flaky)
    cfg = compose([*SHORT, "game.trials=3", "pursuer=random", "evader=random"])
    job.run_job(cfg, tmp_path)
    entries = lines(tmp_path / "results.jsonl")
    assert [e["kind"] for e in entries] == ["game", "failed", "game", "summary"]
    assert entries[1]["error"] == "RuntimeError: simulated crash"
    assert "simulated crash" in (tmp_path / "failed_1.txt").read_text()


def run_sweep(tmp_path: Path, *overrides: str) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k != "HYDRA_FULL_ERROR"}
    return subprocess.run(
        [sys.executable, "-m", "pegame", "-m", *SHORT, "game.trials=2", "pursuer=random,smart",
         "evader=random,smart", f"hydra.sweep.dir={tmp_path / 'sweep'}", *overrides],
        cwd=tmp_path, capture_output=True, text=True, env=env, timeout=600,
    )


def test_multirun_through_joblib_writes_every_job_and_the_report(tmp_path):
    proc = run_sweep(tmp_path)
    assert proc.returncode == 0, proc.stderr
    results = sorted((tmp_path / "sweep").rglob("results.jsonl"))
    assert len(results) == 4
    pairings = {lines(p)[0]["pairing"] for p in results}
    assert pairings == {"R-R", "R-S", "S-R", "S-S"}
    assert not list((tmp_path / "sweep").rglob("*.rrd"))  # no recording in sweeps by default
    assert (tmp_path / "sweep" / "table1.md").exists()


def test_multirun_through_submitit_local(tmp_path):
    pytest.importorskip("hydra_plugins.hydra_submitit_launcher")
    proc = run_sweep(tmp_path, "hydra/launcher=submitit_local", "hydra.launcher.timeout_min=5")
    assert proc.returncode == 0, proc.stderr
    assert len(list((tmp_path / "sweep").rglob("results.jsonl"))) == 4
