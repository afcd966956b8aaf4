"""A small statistical integration test of the paper's first hypothesis, with fixed seeds:
the smart pursuer tracks a random evader better than the random pursuer does."""

from __future__ import annotations

import numpy as np
from scipy.stats import mannwhitneyu

from pegame.config import compose
from pegame.game import Game

SEEDS = range(8)


def tracking_rates(pursuer: str, tmp_path) -> list[float]:
    return [
        Game(compose([f"pursuer={pursuer}", "evader=random", "env=enclosed", "recorder=none",
                      "game.t_max=30", f"game.seed={seed}"])).play(tmp_path).result["tracking_rate"]
        for seed in SEEDS
    ]


def test_smart_pursuer_tracks_better_than_random(tmp_path):
    smart, random = tracking_rates("smart", tmp_path), tracking_rates("random", tmp_path)
    assert np.mean(smart) - np.mean(random) >= 0.2
    assert mannwhitneyu(smart, random, alternative="greater").pvalue < 0.01
