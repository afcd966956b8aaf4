"""Fixtures of pegame-vision's tests. Imports no plugin, so that a test module skips
cleanly when OpenCV or pybullet is missing."""

from __future__ import annotations

import pytest

from pegame.api import Context
from pegame.testing import small_context


@pytest.fixture
def context() -> Context:
    """The default bodies and camera on pegame.testing's small map (known walls)."""
    return small_context()
