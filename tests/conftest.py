"""Shared fixtures."""

from __future__ import annotations

import pytest

from pegame.config import compose


@pytest.fixture
def compose_config():
    """compose_config(overrides) -> the DictConfig the app would receive."""
    return compose
