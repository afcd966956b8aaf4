"""The plugin tutorial's third-party example (docs/tutorials/plugin.md) works end to end from the command line:
its entry point registers the pursuer and its pegame.configs entry point its config file.

The distribution is made visible to the subprocesses through a hand-written dist-info on
PYTHONPATH (the ``installed_env`` fixture), without changing the environment."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest


@pytest.mark.slow
def test_the_example_plugin_is_listed_and_plays(tmp_path, installed_env):
    env = installed_env
    listing = subprocess.run(
        [sys.executable, "-m", "pegame.catalog"],
        env=env,
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    assert any(line.split()[:2] == ["spinner", "pegame-spinner"] for line in listing.splitlines())
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "pegame",
            "pursuer=spinner",
            "pursuer.turn_rate=1.2",
            "evader=random",
            "recorder=none",
            "game.t_max=5",
            f"hydra.run.dir={tmp_path / 'run'}",
        ],
        env=env,
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    result = json.loads((tmp_path / "run" / "result.json").read_text())
    assert result["pursuer"] == "spinner" and result["pairing"] == "spinner-R"
    bad = subprocess.run(
        [
            sys.executable,
            "-m",
            "pegame",
            "pursuer=spinner",
            "pursuer.turn_rate=-1",
            "recorder=none",
            f"hydra.run.dir={tmp_path / 'bad'}",
        ],
        env=env,
        cwd=tmp_path,
        capture_output=True,
        text=True,
    )
    assert bad.returncode == 2 and "pursuer.turn_rate" in bad.stderr
