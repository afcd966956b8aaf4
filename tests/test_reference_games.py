"""The games do not change: every built-in plugin on fixed seeds gives the stored measures.

The measures in ``tests/data/reference_games.json`` were recorded by
``python -m pegame.testing.reference_games`` before the redesign of the architecture (the
3D games re-recorded when the pybullet evader became an articulated person and the camera
took the paper's tilt and 320x240, 4c45a4e; the grid games never); a change that alters
any game fails here. Floats are compared exactly: the same seed and config give
the same game, bit for bit.
"""

from __future__ import annotations

import json

import pytest

from pegame.testing.reference_games import CASES, DATA, play

STORED = json.loads(DATA.read_text())
OVERRIDES = dict(CASES)


@pytest.mark.parametrize("game", STORED, ids=[f"{g['label']}-seed{g['seed']}" for g in STORED])
def test_a_reference_game_gives_its_stored_measures(game):
    played = play(OVERRIDES[game["label"]], game["seed"])
    assert {key: played.get(key) for key in game["result"]} == game["result"]
