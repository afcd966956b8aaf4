"""The compile notice (pegame.kernel_cache): said once when pegame's kernels compile on a
cold cache, never when they load from a warm one, never for another package's kernel."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from pegame import kernel_cache

#: builds a scenario (as every game and env does), compiles one pegame kernel at its first
#: call, then one of another module
PLAY = """
import numpy as np
from numba import njit
from pegame.config import compose
from pegame.game import Scenario
from pegame.grid.cells import cell_centres
grid = Scenario(compose(["recorder=none"])).context.grid
cell_centres(np.array([1, 2]), grid.width, grid.kernel_frame)
njit(lambda x: x + 1)(1)
"""


def run(cache: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "NUMBA_CACHE_DIR": cache}
    return subprocess.run(
        [sys.executable, "-c", PLAY], env=env, capture_output=True, text=True, timeout=600
    )


@pytest.mark.slow
def test_a_cold_cache_is_announced_once_and_a_warm_one_never(tmp_path):
    cold = run(str(tmp_path / "cache"))
    assert cold.returncode == 0, cold.stderr
    assert cold.stderr.count(kernel_cache.NOTICE) == 1
    warm = run(str(tmp_path / "cache"))
    assert warm.returncode == 0, warm.stderr
    assert kernel_cache.NOTICE not in warm.stderr


def test_only_pegame_functions_are_announced(capsys, monkeypatch):
    notice = kernel_cache.CompileNotice()
    monkeypatch.setattr(kernel_cache.log, "hasHandlers", lambda: False)

    class Event:
        def __init__(self, module: str) -> None:
            self.data = {
                "dispatcher": type("D", (), {"py_func": type("F", (), {"__module__": module})})()
            }

    notice.on_start(Event("numpy_user_module"))
    assert capsys.readouterr().err == ""
    notice.on_start(Event("pegame.sims.grid"))
    notice.on_start(Event("pegame.visibility.rays"))
    assert capsys.readouterr().err.count(kernel_cache.NOTICE) == 1
