"""The paper's hypotheses: the tests and their verdicts on synthetic rates, and a small
statistical integration test of the first one with fixed seeds (the smart pursuer tracks a
random evader better than the random pursuer does)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import mannwhitneyu

from pegame import report
from pegame.config import compose
from pegame.game import Game
from pegame.testing.reports import separated, sweep_games, write_job

SEEDS = range(8)


def tracking_rates(pursuer: str, tmp_path) -> list[float]:
    return [
        Game(
            compose(
                [
                    f"pursuer={pursuer}",
                    "evader=random",
                    "env=enclosed",
                    "recorder=none",
                    "game.t_max=30",
                    f"game.seed={seed}",
                ]
            )
        )
        .play(tmp_path)
        .result["tracking_rate"]
        for seed in SEEDS
    ]


@pytest.mark.slow
def test_smart_pursuer_tracks_better_than_random(tmp_path):
    smart, random = tracking_rates("smart", tmp_path), tracking_rates("random", tmp_path)
    assert np.mean(smart) - np.mean(random) >= 0.2
    assert mannwhitneyu(smart, random, alternative="greater").pvalue < 0.01


def test_holm_adjusts_in_input_order():
    assert report.holm([0.01, 0.04, 0.03]) == pytest.approx([0.03, 0.06, 0.06])
    assert report.holm([0.5, 0.001]) == pytest.approx([0.5, 0.002])
    assert report.holm([]) == []


def test_h1_holds_when_smart_pursuer_is_better_and_fails_otherwise(tmp_path):
    cells = separated("S-R", "R-R")
    cells[("enclosed", 1.0, "S-R")] = [0.7, 0.8]  # no R-R here: not tested
    h1 = report.hypotheses(cells)[0]
    assert h1["summary"] == {
        "verdict": "holds",
        "k": 4,
        "n": 4,
        "untested": 1,
        "text": "holds (in 4 of 4 cells)",
    }
    assert all(row["p_holm"] <= report.ALPHA for row in h1["rows"] if row["p"] is not None)
    h1 = report.hypotheses(separated("R-R", "S-R"))[0]
    assert h1["summary"]["verdict"] == "fails" and h1["summary"]["k"] == 0

    write_job(tmp_path, "0", sweep_games(cells))
    result = report.write_report(tmp_path, tmp_path / "hyp")
    md = (tmp_path / "hyp" / "hypotheses.md").read_text()
    assert "## H1: holds (in 4 of 4 cells)" in md
    assert "| enclosed | 1 | 75.0% [70.0, 80.0] n=2 | – |" in md and report.UNTESTED in md
    assert result["hypotheses"][0]["summary"]["k"] == 4


def test_h2_tests_the_slow_ratio_and_shows_the_rate_at_equal_speed():
    h2 = report.hypotheses(separated("S-R", "R-R"))[1]
    assert [(row["map"], row["speed_ratio"]) for row in h2["rows"]] == [
        ("hall", 0.5),
        ("brick", 0.5),
    ]
    assert h2["summary"]["verdict"] == "holds"
    assert h2["rows"][0]["x_stats_at_1"]["n"] == 12
    only_equal = {("hall", 1.0, "S-R"): [0.8], ("hall", 1.0, "R-R"): [0.2]}
    h2 = report.hypotheses(only_equal)[1]
    assert h2["rows"][0]["speed_ratio"] == 0.5 and h2["summary"]["text"] == report.UNTESTED


def test_h3_needs_smart_evader_tracked_less_but_above_45_percent():
    rng = np.random.default_rng(2)
    cells = {
        ("hall", 1.0, "S-R"): rng.uniform(0.8, 0.95, 15).tolist(),
        ("hall", 1.0, "S-S"): rng.uniform(0.5, 0.7, 15).tolist(),
        ("brick", 1.0, "S-R"): rng.uniform(0.8, 0.95, 15).tolist(),
        ("brick", 1.0, "S-S"): rng.uniform(0.1, 0.3, 15).tolist(),
    }
    h3 = report.hypotheses(cells)[2]
    by_map = {row["map"]: row for row in h3["rows"]}
    assert by_map["hall"]["holds"] and by_map["hall"]["tracked_less"]
    assert by_map["brick"]["tracked_less"] and not by_map["brick"]["reasonable"]
    assert h3["summary"]["text"] == "partly (in 1 of 2 cells)"
    assert h3["reasonable_cells"] == {"k": 1, "n": 2}
