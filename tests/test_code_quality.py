"""The code keeps the project's habits: ruff's lint rules and format, and mypy over the whole
package and its plugin distributions, as configured in pyproject.toml ([tool.ruff], [tool.mypy]); the same checks as
.pre-commit-config.yaml, so that README's test command runs them in CI."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def run(tool: str, *args: str) -> subprocess.CompletedProcess[str]:
    """``python -m tool args`` at the repository root; skips when the tool is not installed
    (it comes with the test extras: pip install -e ".[test]")."""
    if importlib.util.find_spec(tool) is None:
        pytest.skip(f"{tool} is not installed (pip install -e '.[test]')")
    return subprocess.run(
        [sys.executable, "-m", tool, *args], cwd=ROOT, capture_output=True, text=True, timeout=600
    )


def test_ruff_lint_finds_nothing():
    proc = run("ruff", "check", "--no-cache", "--output-format", "concise", ".")
    assert proc.returncode == 0, proc.stdout + proc.stderr


@pytest.mark.format
def test_ruff_format_check_finds_nothing_to_reformat():
    """The format check: ``ruff format .`` makes it pass."""
    proc = run("ruff", "format", "--check", "--no-cache", ".")
    assert proc.returncode == 0, proc.stdout + proc.stderr


@pytest.mark.slow
def test_mypy_finds_no_type_errors_in_the_whole_package():
    proc = run("mypy")  # the files and settings of [tool.mypy]: pegame and plugins/
    assert proc.returncode == 0, proc.stdout + proc.stderr
