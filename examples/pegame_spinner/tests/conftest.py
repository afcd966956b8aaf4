"""The example's tests see it as installed: unless pegame-spinner is installed already,
its dist-info and package are put on sys.path for the duration of the tests. The dist-info
is hand-written with the example's entry points, which is what `pip install
examples/pegame_spinner` writes."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

from pegame import registry

#: examples/pegame_spinner, the directory that holds the import package ``spinner``
EXAMPLE = Path(__file__).resolve().parents[1]


def write_dist_info(site: Path) -> Path:
    """Write pegame_spinner's dist-info into ``site`` (a directory to put on the path)."""
    info = site / "pegame_spinner-0.1.0.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: pegame-spinner\nVersion: 0.1.0\n")
    (info / "entry_points.txt").write_text(
        "[pegame.pursuers]\nspinner = spinner:Spinner\n\n[pegame.configs]\nspinner = spinner.conf\n"
    )
    return site


@pytest.fixture
def installed_env(tmp_path) -> dict[str, str]:
    """An environment for subprocesses in which pegame-spinner is installed (its
    dist-info and package on PYTHONPATH), without changing this one."""
    site = write_dist_info(tmp_path / "site")
    env = {k: v for k, v in os.environ.items() if k != "HYDRA_FULL_ERROR"}
    env["PYTHONPATH"] = os.pathsep.join([str(site), str(EXAMPLE), env.get("PYTHONPATH", "")])
    return env


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
