"""The documentation site builds strictly (mkdocs.yml): every page in the nav exists, no
link or cross-reference is broken, every module of the API reference is found, and the
build needs nothing from the network."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

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


def test_the_results_pages_tables_are_those_generated_from_the_committed_tables():
    done = subprocess.run(
        [sys.executable, str(ROOT / "docs" / "results" / "tables.py"), "--check"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
