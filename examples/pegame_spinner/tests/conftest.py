"""The example's tests see it as installed: unless pegame-spinner is installed already,
its dist-info and package are put on sys.path for the duration of the tests."""

from __future__ import annotations

import sys

import pytest
from spinner_dist import EXAMPLE, write_dist_info

from pegame import registry


@pytest.fixture(scope="session", autouse=True)
def spinner_installed(tmp_path_factory):
    if "spinner" in registry.available("pursuer"):
        yield
        return
    added = [str(write_dist_info(tmp_path_factory.mktemp("site"))), str(EXAMPLE)]
    sys.path[:0] = added
    registry._entry_points.cache_clear()  # the registry caches what it found
    yield
    for path in added:
        sys.path.remove(path)
    for name in [n for n in sys.modules if n.split(".")[0] == "spinner"]:
        del sys.modules[name]
    registry._entry_points.cache_clear()
