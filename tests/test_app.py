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
    """Run ``python -m pegame`` from an unrelated directory into ``tmp_path / name`` (a
    ``-m`` among the overrides makes it a multirun)."""
    env = {k: v for k, v in os.environ.items() if k != "HYDRA_FULL_ERROR"}
    flags = [o for o in overrides if o == "-m"]
    overrides = tuple(o for o in overrides if o != "-m")
    return subprocess.run(
        [sys.executable, "-m", "pegame", *flags, f"hydra.run.dir={tmp_path / name}", *overrides],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )


@pytest.mark.slow
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
    assert result["tracking_rate"] == pytest.approx(
        np.mean([int(r["detected"]) for r in rows]), abs=1e-6
    )
    assert "R-R" in proc.stdout and "hall" in proc.stdout and "tracking rate" in proc.stdout
    assert proc.stdout.splitlines()[-1] == f"output: {out}"  # where to look, last


@pytest.mark.slow
def test_the_console_names_each_games_cell_and_a_jobs_mean_with_its_ci(tmp_path):
    proc = run_app(
        tmp_path,
        "-m",
        "game.t_max=4",
        "recorder=none",
        "evader=random,smart",
        "game.trials=2",
        f"hydra.sweep.dir={tmp_path / 'sweep'}",
    )
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    for num, evader in ((0, "random"), (1, "smart")):
        cell = f"#{num} game.t_max=4 recorder=none evader={evader} game.trials=2: "
        games = [line for line in lines if line.startswith(cell) and "seed" in line]
        assert len(games) == 2  # every game line names its cell
        rates = [
            json.loads(line)["tracking_rate"]
            for line in (tmp_path / "sweep" / str(num) / "results.jsonl").open()
            if '"kind": "game"' in line
        ]
        mean = next(
            line for line in lines if line.startswith(cell) and "mean tracking rate" in line
        )
        assert f"2 games: mean tracking rate {100 * sum(rates) / 2:.1f}% [" in mean
        assert mean.endswith("(95% bootstrap CI)")
    assert not any(line.startswith("output: ") for line in lines)  # a sweep has its own dir
    progress = [line for line in lines if line.startswith("pegame: cell ")]
    assert [line.split(" done ")[0] for line in progress] == [
        "pegame: cell 1 of 2",
        "pegame: cell 2 of 2",
    ]
    assert all(": exit 0, " in line for line in progress)  # one line per cell, as it ends
    assert [line.split("; ")[-1] for line in progress] == ["games 2 of 4", "games 4 of 4"]


@pytest.mark.slow
def test_same_seed_gives_byte_identical_files(tmp_path):
    args = (*FAST, "env=enclosed", "game.seed=7")
    for name in ("a", "b"):
        assert run_app(tmp_path, *args, name=name).returncode == 0
    for file in ("result.json", "trajectory.csv"):
        assert (tmp_path / "a" / file).read_bytes() == (tmp_path / "b" / file).read_bytes()
    other = run_app(tmp_path, *FAST, "env=enclosed", "game.seed=8", name="c")
    assert other.returncode == 0
    assert (tmp_path / "c" / "trajectory.csv").read_bytes() != (
        tmp_path / "a" / "trajectory.csv"
    ).read_bytes()


@pytest.mark.slow
def test_any_ros_map_by_absolute_path(tmp_path):
    data = np.zeros((120, 140), dtype=np.int8)
    data[[0, -1], :] = data[:, [0, -1]] = 100
    save_map(OccupancyGrid(data, 0.05, (1.0, -2.0, 0.0)), tmp_path / "lab.yaml")
    proc = run_app(tmp_path, *FAST, f"env.map={tmp_path / 'lab.yaml'}", "env.name=lab")
    assert proc.returncode == 0, proc.stderr
    assert json.loads((tmp_path / "run" / "result.json").read_text())["map"] == "lab"


@pytest.mark.parametrize(
    ("overrides", "expected"),
    [
        (["pursuer=smrt"], "Unknown pursuer 'smrt'. Did you mean 'smart'?"),
        (["-m", "evader=smart,smrat"], "Unknown evader 'smrat'. Did you mean 'smart'?"),
        (["+foo=1"], "Unknown key 'foo'"),
        (["+gmae.t_max=5"], "Unknown key 'gmae'. Did you mean 'game'?"),
        (["+camera.bar=2"], "Unknown key 'camera.bar'"),
        (["game.seed=-1"], "game.seed"),
        (["game.t_max=0.01"], "at least one control tick"),
        (["game.decision_hz=3"], "10, 5, 3.33333, 2.5, 2"),
        (["game.t_maxx=3"], "game.t_maxx"),
        (["-m", "game.t_max=5,abc"], "game.t_max"),
        (["game.t_max=[1"], "override_grammar"),
        (["game.t_max=abc"], "game.t_max"),
        (["evader.v_max=0"], "evader.v_max"),
        (["game.control_hz=-10"], "game.control_hz"),
        (["pursuer.radius=-1"], "pursuer.radius"),
        (["camera.fov=7"], "camera.fov"),
        (["env.map=/nonexistent/map.yaml"], "/nonexistent/map.yaml"),
    ],
)
@pytest.mark.slow
def test_bad_input_is_one_clear_error_without_traceback_or_result(tmp_path, overrides, expected):
    proc = run_app(tmp_path, *FAST, *overrides)
    assert proc.returncode == 2
    assert expected in proc.stderr
    assert "Traceback" not in proc.stderr
    assert not (tmp_path / "run" / "result.json").exists()
    assert not (tmp_path / "run" / "results.jsonl").exists()  # failed before the first game


@pytest.mark.slow
def test_a_map_with_no_valid_spawn_is_reported(tmp_path):
    data = np.full((20, 20), 100, dtype=np.int8)
    data[8:12, 8:12] = 0  # a 0.2 m pocket: too small for either robot
    save_map(OccupancyGrid(data, 0.05), tmp_path / "closet.yaml")
    proc = run_app(tmp_path, *FAST, f"env.map={tmp_path / 'closet.yaml'}")
    assert proc.returncode == 2
    assert "No valid spawn" in proc.stderr and "Traceback" not in proc.stderr
    assert not (tmp_path / "run" / "result.json").exists()


def lines(path: Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text().splitlines()]


@pytest.mark.slow
def test_a_game_that_fails_exits_1_and_the_others_are_written(tmp_path):
    # a 1e-5 rad camera finds a spawn for seeds 0-5 but not for seed 6
    proc = run_app(
        tmp_path, *FAST, "env=enclosed", "camera.fov=1e-5", "game.seed=5", "game.trials=3"
    )
    assert proc.returncode == 1, proc.stderr
    kinds = [(e["kind"], e.get("seed")) for e in lines(tmp_path / "run" / "results.jsonl")]
    assert kinds == [("game", 5), ("failed", 6), ("game", 7), ("summary", None)]
    assert "seed 6 failed: No valid spawn" in proc.stdout  # Hydra logs to stdout


@pytest.mark.slow
@pytest.mark.parametrize("launcher", ["joblib", "basic"])
def test_a_sweep_whose_games_all_fail_exits_1(tmp_path, launcher):
    proc = run_app(
        tmp_path,
        "-m",
        *FAST,
        "env=enclosed",
        "camera.fov=1e-5",
        "game.seed=6",
        "pursuer=random",
        "evader=random,smart",
        f"hydra/launcher={launcher}",
        f"hydra.sweep.dir={tmp_path / 'sweep'}",
    )
    assert proc.returncode == 1, proc.stderr
    for path in sorted((tmp_path / "sweep").glob("*/results.jsonl")):
        assert [e["kind"] for e in lines(path)] == ["failed", "summary"]


@pytest.mark.slow
def test_one_bad_cell_of_a_sweep_is_reported_and_the_others_run(tmp_path):
    proc = run_app(
        tmp_path,
        "-m",
        *FAST,
        "env=hall",
        "game.speed_ratio=0,1",
        f"hydra.sweep.dir={tmp_path / 'sweep'}",
    )
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr
    bad, good = (lines(tmp_path / "sweep" / cell / "results.jsonl") for cell in ("0", "1"))
    assert bad == [
        {
            "kind": "invalid",
            "error": bad[0]["error"],
            "overrides": [*FAST, "env=hall", "game.speed_ratio=0"],
        }
    ]
    assert "'game.speed_ratio'" in bad[0]["error"]
    assert [e["kind"] for e in good] == ["game", "summary"]
    assert (tmp_path / "sweep" / "table1.md").exists()  # the report ran


@pytest.mark.slow
def test_overrides_are_recorded_with_every_game(tmp_path):
    proc = run_app(tmp_path, *FAST, "env=hall", "pursuer=random")
    assert proc.returncode == 0, proc.stderr
    entry = lines(tmp_path / "run" / "results.jsonl")[0]
    assert entry["overrides"] == [*FAST, "env=hall", "pursuer=random"]
    assert entry["config"]["pursuer"]["name"] == "random"


@pytest.mark.slow
def test_resuming_a_sweep_with_other_cells_is_an_error_naming_the_keys(tmp_path):
    sweep = f"hydra.sweep.dir={tmp_path / 'sweep'}"
    first = run_app(
        tmp_path,
        "-m",
        *FAST,
        "pursuer=random",
        "evader=random",
        "game.trials=2",
        "env=enclosed,brick",
        sweep,
    )
    assert first.returncode == 0, first.stderr
    before = {p: p.read_bytes() for p in (tmp_path / "sweep").glob("*/results.jsonl")}
    again = run_app(
        tmp_path,
        "-m",
        *FAST,
        "pursuer=random",
        "evader=random",
        "game.trials=2",
        "env=brick,hall",
        "resume=true",
        sweep,
    )
    assert again.returncode == 2
    assert "holds games of another config" in again.stderr and "env.name" in again.stderr
    assert {p: p.read_bytes() for p in (tmp_path / "sweep").glob("*/results.jsonl")} == before


@pytest.mark.slow
def test_a_job_directory_has_one_writer(tmp_path):
    from pegame.joblock import JobLock

    with JobLock(tmp_path / "run"):
        proc = run_app(tmp_path, *FAST)
    assert proc.returncode == 2
    assert "Another pegame process" in proc.stderr and "Traceback" not in proc.stderr
    assert not (tmp_path / "run" / "results.jsonl").exists()


@pytest.mark.slow
def test_a_full_disk_is_one_clear_error_and_the_result_is_printed(tmp_path):
    (tmp_path / "run").mkdir()
    (tmp_path / "run" / "results.jsonl").symlink_to("/dev/full")
    proc = run_app(tmp_path, *FAST, "env=hall")
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    assert f"Could not write to {tmp_path / 'run' / 'results.jsonl'}: No space left" in proc.stderr
    printed = [line for line in proc.stderr.splitlines() if line.startswith('{"kind": "game"')]
    assert json.loads(printed[0])["map"] == "hall"
