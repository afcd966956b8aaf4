"""The README's third-party plugin example (examples/pegame_spinner) works end to end:
its entry point registers the pursuer and its pegame.configs entry point its config file.

The distribution is made visible through a hand-written dist-info on PYTHONPATH, which is
what `pip install examples/pegame_spinner` produces, without changing the environment."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "pegame_spinner"


def fake_install(site: Path) -> dict[str, str]:
    info = site / "pegame_spinner-0.1.0.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: pegame-spinner\nVersion: 0.1.0\n")
    (info / "entry_points.txt").write_text(
        "[pegame.pursuers]\nspinner = spinner:Spinner\n\n[pegame.configs]\nspinner = spinner.conf\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "HYDRA_FULL_ERROR"}
    env["PYTHONPATH"] = os.pathsep.join([str(site), str(EXAMPLE), env.get("PYTHONPATH", "")])
    return env


def test_the_example_plugin_is_listed_and_plays(tmp_path):
    env = fake_install(tmp_path / "site")
    listing = subprocess.run([sys.executable, "-m", "pegame.catalog"], env=env, capture_output=True,
                             text=True, check=True).stdout
    assert any(line.split()[:2] == ["spinner", "pegame-spinner"] for line in listing.splitlines())
    proc = subprocess.run(
        [sys.executable, "-m", "pegame", "pursuer=spinner", "pursuer.turn_rate=1.2", "evader=random",
         "recorder=none", "game.t_max=5", f"hydra.run.dir={tmp_path / 'run'}"],
        env=env, cwd=tmp_path, capture_output=True, text=True, timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    result = json.loads((tmp_path / "run" / "result.json").read_text())
    assert result["pursuer"] == "spinner" and result["pairing"] == "spinner-R"
    bad = subprocess.run(
        [sys.executable, "-m", "pegame", "pursuer=spinner", "pursuer.turn_rate=-1", "recorder=none",
         f"hydra.run.dir={tmp_path / 'bad'}"], env=env, cwd=tmp_path, capture_output=True, text=True,
    )
    assert bad.returncode == 2 and "pursuer.turn_rate" in bad.stderr
