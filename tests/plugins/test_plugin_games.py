"""Whole games with the plugins: the built-in strategies, estimators and recorder run
unchanged on sim=pybullet with either detector."""

from __future__ import annotations

import pytest

pytest.importorskip("pybullet")

import json  # noqa: E402

from pegame.config import compose  # noqa: E402
from pegame.game import Game, write_outcome  # noqa: E402


def test_a_short_smart_game_runs_end_to_end_and_is_recorded(tmp_path):
    cfg = compose(["sim=pybullet", "detector=segmentation", "pursuer=smart", "evader=smart",
                   "recorder=rerun", "game.t_max=5"])
    game = Game(cfg)
    outcome = game.play(tmp_path, "game")
    result = outcome.result
    assert result["sim"] == "pybullet" and result["detector"] == "segmentation"
    assert result["ticks"] == 50 and len(outcome.trajectory) == 50
    assert result["tracking_rate"] > 0.5  # the evader spawns in view
    assert game.plugins["sim"]._client is None  # the physics server is released
    assert (tmp_path / "game.rrd").stat().st_size > 0
    write_outcome(outcome, tmp_path)
    assert json.loads((tmp_path / "result.json").read_text())["pairing"] == "S-S"


def test_a_short_game_with_the_vision_detector(tmp_path):
    pytest.importorskip("cv2")
    cfg = compose(["sim=pybullet", "detector=vision", "pursuer=smart", "evader=random",
                   "estimator=kalman", "recorder=none", "game.t_max=5", "game.seed=3"])
    result = Game(cfg).play(tmp_path).result
    assert result["detector"] == "vision" and result["tracking_rate"] > 0.5


def test_the_same_seed_gives_the_same_game(tmp_path):
    overrides = ["sim=pybullet", "detector=segmentation", "recorder=none", "game.t_max=3"]
    first = Game(compose(overrides)).play(tmp_path).trajectory
    assert Game(compose(overrides)).play(tmp_path).trajectory == first
