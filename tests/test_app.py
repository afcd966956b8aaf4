"""End to end through the Hydra app: outputs, determinism and bad input."""

from __future__ import annotations

import csv
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from pegame.grid import OccupancyGrid, save_map

FAST = ["game.t_max=8", "recorder=none"]


def run_app(tmp_path: Path, *overrides: str, name: str = "run") -> subprocess.CompletedProcess:
    """Run ``python -m pegame`` from an unrelated directory into ``tmp_path / name``."""
    env = {k: v for k, v in os.environ.items() if k != "HYDRA_FULL_ERROR"}
    return subprocess.run(
        [sys.executable, "-m", "pegame", f"hydra.run.dir={tmp_path / name}", *overrides],
        cwd=tmp_path, capture_output=True, text=True, env=env, timeout=300,
    )


def test_one_game_writes_config_result_trajectory_and_log(tmp_path):
    proc = run_app(tmp_path, *FAST, "env=hall", "pursuer=random", "evader=random")
    assert proc.returncode == 0, proc.stderr
    out = tmp_path / "run"
    assert (out / ".hydra" / "config.yaml").exists()
    assert (out / "pegame.log").exists()
    result = json.loads((out / "result.json").read_text())
    assert result["pairing"] == "R-R" and result["map"] == "hall" and result["seed"] == 0
    assert 0.0 <= result["tracking_rate"] <= result["visible_rate"] + 1e-9 <= 1.0 + 1e-9
    rows = list(csv.DictReader((out / "trajectory.csv").open()))
    assert len(rows) == result["ticks"] == 80
    assert result["tracking_rate"] == pytest.approx(np.mean([int(r["detected"]) for r in rows]), abs=1e-6)
    assert "R-R" in proc.stdout and "hall" in proc.stdout and "tracking rate" in proc.stdout


def test_same_seed_gives_byte_identical_files(tmp_path):
    args = (*FAST, "env=enclosed", "game.seed=7")
    for name in ("a", "b"):
        assert run_app(tmp_path, *args, name=name).returncode == 0
    for file in ("result.json", "trajectory.csv"):
        assert (tmp_path / "a" / file).read_bytes() == (tmp_path / "b" / file).read_bytes()
    other = run_app(tmp_path, *FAST, "env=enclosed", "game.seed=8", name="c")
    assert other.returncode == 0
    assert (tmp_path / "c" / "trajectory.csv").read_bytes() != (tmp_path / "a" / "trajectory.csv").read_bytes()


def test_any_ros_map_by_absolute_path(tmp_path):
    data = np.zeros((120, 140), dtype=np.int8)
    data[[0, -1], :] = data[:, [0, -1]] = 100
    save_map(OccupancyGrid(data, 0.05, (1.0, -2.0, 0.0)), tmp_path / "lab.yaml")
    proc = run_app(tmp_path, *FAST, f"env.map={tmp_path / 'lab.yaml'}", "env.name=lab")
    assert proc.returncode == 0, proc.stderr
    assert json.loads((tmp_path / "run" / "result.json").read_text())["map"] == "lab"


@pytest.mark.parametrize(
    "overrides, expected",
    [
        (["pursuer=smrt"], "Available options in 'pursuer'"),
        (["game.t_maxx=3"], "game.t_maxx"),
        (["game.t_max=abc"], "game.t_max"),
        (["evader.v_max=0"], "evader.v_max"),
        (["game.control_hz=-10"], "game.control_hz"),
        (["pursuer.radius=-1"], "pursuer.radius"),
        (["camera.fov=7"], "camera.fov"),
        (["env.map=/nonexistent/map.yaml"], "/nonexistent/map.yaml"),
    ],
)
def test_bad_input_is_one_clear_error_without_traceback_or_result(tmp_path, overrides, expected):
    proc = run_app(tmp_path, *FAST, *overrides)
    assert proc.returncode != 0
    assert expected in proc.stderr
    assert "Traceback" not in proc.stderr
    assert not (tmp_path / "run" / "result.json").exists()


def test_a_map_with_no_valid_spawn_is_reported(tmp_path):
    data = np.full((20, 20), 100, dtype=np.int8)
    data[8:12, 8:12] = 0  # a 0.2 m pocket: too small for either robot
    save_map(OccupancyGrid(data, 0.05), tmp_path / "closet.yaml")
    proc = run_app(tmp_path, *FAST, f"env.map={tmp_path / 'closet.yaml'}")
    assert proc.returncode == 2
    assert "No valid spawn" in proc.stderr and "Traceback" not in proc.stderr
    assert not (tmp_path / "run" / "result.json").exists()
