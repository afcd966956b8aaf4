"""Shared fixtures, and the Hypothesis profiles of the property-based tests."""

from __future__ import annotations

import os

import pytest
from hypothesis import settings

from pegame.config import compose

# ci (the default): the same examples on every run and machine (derandomize, no example
# database), no per-example deadline (numba compiles at a kernel's first call). explore:
# fresh random examples on every run, for hunting bugs by hand
# (HYPOTHESIS_PROFILE=explore python -m pytest tests/...).
settings.register_profile("ci", derandomize=True, database=None, deadline=None)
settings.register_profile("explore", derandomize=False, database=None, deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))


@pytest.fixture
def compose_config():
    """compose_config(overrides) -> the DictConfig the app would receive."""
    return compose


#: a test that takes longer than this (call phase, seconds) belongs to the full suite only
SLOW_S = 3.0
_unmarked_slow: list[tuple[str, float]] = []


def pytest_runtest_logreport(report: pytest.TestReport) -> None:
    """Note tests without the ``slow`` marker that took longer than :data:`SLOW_S`."""
    if report.when == "call" and report.duration > SLOW_S and "slow" not in report.keywords:
        _unmarked_slow.append((report.nodeid, report.duration))


def pytest_terminal_summary(terminalreporter: pytest.TerminalReporter) -> None:
    """List them at the end, so that the quick subset (-m "not slow") stays quick."""
    if _unmarked_slow:
        terminalreporter.section("tests to mark @pytest.mark.slow")
        for nodeid, duration in sorted(_unmarked_slow, key=lambda item: -item[1]):
            terminalreporter.write_line(f"{duration:6.1f} s  {nodeid}")
