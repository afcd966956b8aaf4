"""A plain game never imports gymnasium or pettingzoo, nor does one with the ``policy``
pursuer and evader: observations and actions live in pegame.observe, below both the
strategies and the environments (issue 27). Checked in a fresh interpreter, whose
sys.modules holds only what the app and the games imported."""

from __future__ import annotations

import json
import subprocess
import sys
from importlib.util import find_spec

import pytest

#: the app's module, then games played through pegame.game: the default pairing (smart
#: against smart) and both policy strategies (pegame.testing's chase and flee policies)
SCRIPT = """
import json, sys
import pegame.__main__
from pegame.config import compose
from pegame.game import Game

short = ["env=enclosed", "game.t_max=2", "recorder=none"]
policies = ["pursuer=policy", "pursuer.path=pegame.testing:chase",
            "evader=policy", "evader.path=pegame.testing:flee"]
played = [Game(compose([*short, *extra])).play("unused").result["pairing"]
          for extra in ([], policies)]
loaded = sorted({m.split(".")[0] for m in sys.modules} & {"gymnasium", "pettingzoo"})
print(json.dumps({"played": played, "loaded": loaded}))
"""


@pytest.mark.skipif(
    find_spec("gymnasium") is None and find_spec("pettingzoo") is None,
    reason="neither gymnasium nor pettingzoo is installed: nothing could import them",
)
def test_plain_and_policy_games_import_neither_gymnasium_nor_pettingzoo():
    proc = subprocess.run(
        [sys.executable, "-c", SCRIPT], capture_output=True, text=True, timeout=120
    )
    assert proc.returncode == 0, proc.stderr
    report = json.loads(proc.stdout.strip().splitlines()[-1])
    assert report["played"] == ["S-S", "policy-policy"]
    assert report["loaded"] == []
