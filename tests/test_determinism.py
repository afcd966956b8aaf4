"""The same seed and config give the same game whatever the CPU's vector width.

Reference games recorded on this machine's CPU (``tests/data/reference_games.json``) are
played again in a fresh process whose numba kernels are compiled for a generic x86-64 CPU
(``NUMBA_CPU_NAME=generic``: no AVX, so no wide vectors and no fused multiply-add) into an
empty kernel cache, and whose numpy runs without its AVX2/AVX-512 loops
(``NPY_DISABLE_CPU_FEATURES``). No kernel that decides a game may reassociate sums
(fastmath), so the measures must be equal, and so must the particle filter's particles
and weights at every tick, bit for bit.
"""

from __future__ import annotations

import json
import os
import platform
import subprocess
import sys

import pytest

from pegame.testing.reference_games import DATA, belief_digest

#: one game per kind of kernel work: the particle filter's weighing and resampling (three
#: schemes), the smart evader's search, the planners and the Kalman filter
LABELS = ("S-S enclosed", "S-S residual", "S-S multinomial", "S-S kalman", "R-S brick")
NUMPY_SIMD = "X86_V3 X86_V4 AVX512_ICL AVX512_SPR"

PLAY = """
import json, sys
from pegame.testing.reference_games import CASES, belief_digest, play
cases = dict(CASES)
games = json.loads(sys.argv[1])
print(json.dumps([[play(cases[g["label"]], g["seed"]) for g in games], belief_digest()]))
"""


@pytest.mark.slow
@pytest.mark.skipif(platform.machine() not in ("x86_64", "AMD64"), reason="x86-64 CPU names")
def test_reference_games_are_the_same_with_kernels_for_a_generic_cpu(tmp_path):
    games = [g for g in json.loads(DATA.read_text()) if g["label"] in LABELS]
    assert len(games) == 2 * len(LABELS)
    env = {
        **os.environ,
        "NUMBA_CPU_NAME": "generic",
        "NUMBA_CACHE_DIR": str(tmp_path / "numba"),
        "NPY_DISABLE_CPU_FEATURES": NUMPY_SIMD,
    }
    done = subprocess.run(
        [sys.executable, "-c", PLAY, json.dumps(games)],
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    played, digest = json.loads(done.stdout.strip().splitlines()[-1])
    assert digest == belief_digest(), "the particle filter's numbers depend on the CPU"
    for game, result in zip(games, played):
        assert {k: result.get(k) for k in game["result"]} == game["result"], game["label"]
