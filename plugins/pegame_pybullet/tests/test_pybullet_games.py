"""Whole games on sim=pybullet: the built-in strategies, estimators and recorder run
unchanged with the segmentation detector."""

from __future__ import annotations

import pytest

pytest.importorskip("pybullet")

import json

from pegame.config import compose
from pegame.game import Game, write_outcome


def test_a_short_smart_game_runs_end_to_end_and_is_recorded(tmp_path):
    cfg = compose(
        [
            "sim=pybullet",
            "detector=segmentation",
            "pursuer=smart",
            "evader=smart",
            "recorder=rerun",
            "game.t_max=5",
        ]
    )
    game = Game(cfg)
    outcome = game.play(tmp_path, "game")
    result = outcome.result
    assert result["sim"] == "pybullet" and result["detector"] == "segmentation"
    assert result["ticks"] == 50 and len(outcome.trajectory) == 50
    assert result["tracking_rate"] > 0.5  # the evader spawns in view
    assert game.plugins.sim._client is None  # the physics server is released
    assert (tmp_path / "game.rrd").stat().st_size > 0
    write_outcome(outcome, tmp_path)
    assert json.loads((tmp_path / "result.json").read_text())["pairing"] == "S-S"


def test_the_real_time_factor_benchmark_plays_its_games():
    from pegame_pybullet.bench import rtf

    figures = rtf(t_max=2.0)
    assert figures["rtf"] > 0 and figures["rtf_cpu"] > 0
