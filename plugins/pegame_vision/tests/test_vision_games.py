"""A whole game with detector=vision on sim=pybullet, and its conformance (pegame.testing)."""

from __future__ import annotations

import pytest

pytest.importorskip("cv2")
pytest.importorskip("pybullet")  # the frames are rendered by sim=pybullet

from pegame.config import compose
from pegame.game import Game
from pegame.testing import DetectorConformance


def test_a_short_game_with_the_vision_detector(tmp_path):
    cfg = compose(
        [
            "sim=pybullet",
            "detector=vision",
            "pursuer=smart",
            "evader=random",
            "estimator=kalman",
            "recorder=none",
            "game.t_max=5",
            "game.seed=3",
        ]
    )
    result = Game(cfg).play(tmp_path).result
    assert result["detector"] == "vision" and result["tracking_rate"] > 0.5


class TestVisionDetector(DetectorConformance):
    plugin = "vision"
    overrides = ("sim=pybullet",)
    bad_values = {"colours": ["red"], "hue_tolerance": -1.0, "redetect_every": 0}
