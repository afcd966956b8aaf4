"""The cluster path on a real Slurm: a sweep through ``hydra/launcher=slurm`` runs as a job
array on a one-node cluster (:mod:`slurm_cluster`) and gives the same games and the same
Table 1 as the same sweep run locally with ``hydra/launcher=joblib``.

The tests drive only the CLI (``python -m pegame -m ...`` in a subprocess) and read only
what a sweep promises: ``results.jsonl`` lines with kind, seed, map, speed_ratio, pairing
and tracking_rate, and ``table1.csv`` in the sweep dir. They skip, saying why, where the
cluster cannot be brought up (Slurm not installed, not root, a daemon fails).
"""

from __future__ import annotations

import csv
import json
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from pegame.testing.slurm import SlurmCluster, SlurmUnavailable, start_cluster

# One cluster at a time, and the sweeps want both cores: under pytest-xdist
# (--dist loadgroup) these tests share one worker.
pytestmark = pytest.mark.xdist_group("slurm")

#: A reduced Table 1 sweep: 2 maps x 2 pairings, 3 short games per cell.
SWEEP = (
    "+experiment=paper_table1",
    "env=enclosed,brick",
    "game.speed_ratio=1",
    "pursuer=random,smart",
    "evader=smart",
    "game.trials=3",
    "game.t_max=10",
)
CELLS = 2 * 2
GAMES_PER_CELL = 3
SWEEP_TIMEOUT_S = 180.0  # each sweep takes 15-45 s on 2 busy cores; a stuck array must not hang CI


@pytest.fixture(scope="module")
def slurm(tmp_path_factory) -> Iterator[SlurmCluster]:
    """A one-node Slurm cluster for this module, stopped when the module's tests end."""
    pytest.importorskip("hydra_plugins.hydra_submitit_launcher")
    try:
        cluster = start_cluster(tmp_path_factory.mktemp("slurm"))
    except SlurmUnavailable as exc:
        pytest.skip(f"no local Slurm cluster: {exc}")
    yield cluster
    cluster.stop()


def run_sweep(workdir: Path, sweep_dir: Path, *overrides: str, env=None) -> float:
    """Runs the reduced sweep with ``overrides`` from ``workdir``; returns its wall time (s)."""
    workdir.mkdir(parents=True, exist_ok=True)
    command = [sys.executable, "-m", "pegame", "-m", *SWEEP, *overrides,
               f"hydra.sweep.dir={sweep_dir}"]  # fmt: skip
    start = time.monotonic()
    proc = subprocess.run(
        command, cwd=workdir, env=env, capture_output=True, text=True, timeout=SWEEP_TIMEOUT_S
    )
    wall_s = time.monotonic() - start
    assert proc.returncode == 0, (
        f"{' '.join(overrides)} failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
    )
    return wall_s


def tracking_rates(sweep_dir: Path) -> dict[tuple, float]:
    """(map, speed_ratio, pairing, seed) -> tracking rate of every game in the sweep."""
    rates = {}
    for results in sweep_dir.glob("*/results.jsonl"):
        for line in results.read_text().splitlines():
            row = json.loads(line)
            if row.get("kind") == "game":
                key = (row["map"], row["speed_ratio"], row["pairing"], row["seed"])
                assert key not in rates, f"game {key} appears twice in {sweep_dir}"
                rates[key] = row["tracking_rate"]
    return rates


def table1_rows(sweep_dir: Path) -> list[dict[str, str]]:
    """table1.csv of the sweep, rows in a canonical order."""
    with open(sweep_dir / "table1.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    return sorted(rows, key=lambda row: sorted(row.items()))


def test_cluster_runs_a_job(slurm):
    proc = slurm.run(
        "srun", f"--partition={slurm.partition}", "--ntasks=1",
        "bash", "-c", "echo job $SLURM_JOB_ID on $SLURMD_NODENAME",
        timeout_s=60,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr + slurm.logs()
    words = proc.stdout.split()
    assert words[0::2] == ["job", "on"] and words[1].isdigit() and words[3] == slurm.node, words


@pytest.mark.slow
def test_paper_table1_sweep_on_slurm_matches_local(slurm, tmp_path, record_property):
    local_dir, slurm_dir = tmp_path / "local", tmp_path / "slurm"
    local_s = run_sweep(tmp_path / "cwd_local", local_dir, "hydra/launcher=joblib")
    try:
        slurm_s = run_sweep(
            tmp_path / "cwd_slurm", slurm_dir, "hydra/launcher=slurm",
            f"hydra.launcher.partition={slurm.partition}",
            "hydra.launcher.timeout_min=5", "hydra.launcher.mem_gb=1",
            'hydra.launcher.setup=["echo pegame setup on $SLURMD_NODENAME"]',
            env=slurm.env,
        )  # fmt: skip
    except subprocess.TimeoutExpired:
        slurm.run("scancel", "--user=root")
        pytest.fail(
            f"the Slurm sweep did not end in {SWEEP_TIMEOUT_S:.0f} s; squeue:\n"
            f"{slurm.run('squeue').stdout}\n{slurm.logs()}"
        )
    record_property("local_sweep_s", round(local_s, 1))
    record_property("slurm_sweep_s", round(slurm_s, 1))
    print(f"reduced paper_table1 sweep: joblib {local_s:.1f} s, slurm {slurm_s:.1f} s")

    # It went through Slurm as one job array with a task per cell; each ran the setup
    # lines on the node, then its games, to the end.
    submissions = list(slurm_dir.glob(".submitit/*/*_submission.sh"))
    assert len(submissions) == 1, submissions
    assert f"#SBATCH --array=0-{CELLS - 1}" in submissions[0].read_text()
    task_logs = sorted(slurm_dir.glob(".submitit/*_*/*_log.out"))
    assert len(task_logs) == CELLS
    for log in task_logs:
        text = log.read_text()
        assert f"pegame setup on {slurm.node}" in text, text
        assert "Job completed successfully" in text, text
    assert slurm.run("squeue", "-h").stdout.strip() == ""

    # Same seeds, same games: every tracking rate and the report agree with the local run.
    local_rates = tracking_rates(local_dir)
    assert len(local_rates) == CELLS * GAMES_PER_CELL
    assert tracking_rates(slurm_dir) == local_rates
    assert table1_rows(slurm_dir) == table1_rows(local_dir)
