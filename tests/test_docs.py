"""The documentation site builds strictly (mkdocs.yml): every page in the nav exists, no
link or cross-reference is broken, every module of the API reference is found, and the
build needs nothing from the network."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from pegame.api import EvaderObservation, Pose
from pegame.testing import ConformanceError, check_config_errors, small_context

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_the_site_builds_strictly_offline(tmp_path):
    env = {
        **os.environ,
        "NO_MKDOCS_2_WARNING": "1",
        "no_proxy": "*",
        "HTTPS_PROXY": "http://0.0.0.0:9",
    }
    done = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    reference = (tmp_path / "site" / "reference" / "api" / "index.html").read_text()
    assert "pegame.api.Pursuer" in reference  # the API reference came from the docstrings
    assert ":class:`" not in reference  # Sphinx roles were turned into code
    assert reference.count("Parameters:") >= 10  # the interfaces' parameter sections


def check(script: str) -> None:
    """``python docs/<script> --check`` exits 0: the pages it generates are up to date."""
    done = subprocess.run(
        [sys.executable, str(ROOT / "docs" / script), "--check"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr


def test_the_results_pages_tables_are_those_generated_from_the_committed_tables():
    check("results/tables.py")


def test_the_vmas_page_and_readme_table_are_those_generated_from_the_committed_csv():
    check("performance/vmas_side_by_side.py")  # rendered from vmas.csv: no VMAS needed


def test_the_performance_history_page_is_generated_from_its_records():
    check("performance/history.py")
    page = (ROOT / "docs" / "explanation" / "performance-history.md").read_text()
    records = (ROOT / "docs" / "performance" / "history.jsonl").read_text().splitlines()
    assert records  # a row per record, named by its commit
    assert all(f"`{json.loads(line)['commit'][:7]}`" in page for line in records)


def test_a_result_quoted_by_hand_in_a_results_page_is_caught(tmp_path):
    import importlib.util

    spec = importlib.util.spec_from_file_location("tables", ROOT / "docs" / "results" / "tables.py")
    tables = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tables)
    prose = (
        "S-R tracks 97.0% at ratio 1, +3.1 pp over smart, in 8 of 9 cells (p_Holm 9.3e-12); "
        "mean with its 95% bootstrap CI, 40 seeds of 90 s."
    )
    assert tables.quoted_by_hand(prose) == ["97.0%", "3.1 pp", "8 of 9", "9.3e-12"]
    generated = (
        "holds in <!-- value: h1_cells -->9 of 9<!-- /value --> cells, `0.5%` in code, "
        "[a link](../x_10%.md)\n<!-- generated: t -->\n| 12.5% |\n<!-- end: t -->"
    )
    assert tables.quoted_by_hand(generated) == []
    page = "holds in <!-- value: h1_cells -->7 of 9<!-- /value --> cells"
    fresh = tables.regenerate(page, {}, tables.PAPER_TABLE1_VALUES)
    assert fresh == f"holds in <!-- value: h1_cells -->{tables.holds('H1')}<!-- /value --> cells"
    with pytest.raises(ValueError, match="unknown values: nowhere"):
        tables.regenerate("<!-- value: nowhere -->1<!-- /value -->", {}, {})


def tutorial_code(page: str, first_line: str) -> str:
    """The Python block of ``docs/<page>`` that starts with ``first_line``."""
    text = (ROOT / "docs" / page).read_text()
    blocks = text.split("```python\n")[1:]
    return next(block.split("```")[0] for block in blocks if block.startswith(first_line))


def test_the_tutorials_evader_implements_its_interface_and_walks_away(tmp_path, monkeypatch):
    (tmp_path / "fleer.py").write_text(tutorial_code("tutorials/plugin.md", "# fleer.py"))
    monkeypatch.syspath_prepend(str(tmp_path))
    from fleer import Fleer  # the tutorial's module, written above

    check_config_errors("evader", Fleer, {"gain": -1.0})
    with pytest.raises(ConformanceError):
        check_config_errors("evader", Fleer, {"gain": 1.0})  # a valid value is no bad value
    fleer = Fleer(Fleer.Config(), small_context(), np.random.default_rng(0))
    me, pursuer = Pose(2.0, 1.0, 0.0), Pose(3.0, 1.0, 0.0)  # the pursuer straight ahead
    command = fleer.control(EvaderObservation(0.0, me, pursuer))
    assert command.v == fleer.config.v_max
    assert command.w == pytest.approx(fleer.config.gain * math.pi)  # turn round
