"""Smoke tests of pegame.bench's measurements on small inputs (the figures themselves are
measured by ``python -m pegame.bench``, never asserted here)."""

from __future__ import annotations

import math

import pytest

from pegame.bench import bench_decisions, format_report, machine
from pegame.config import resolve_map_path
from pegame.grid import load_map


def test_decision_benchmarks_time_each_part_on_a_paper_map():
    grid = load_map(resolve_map_path("enclosed.yaml"))
    timings = bench_decisions(grid, 3)
    assert set(timings) == {"pursuer_decision_ms", "evader_decision_ms", "pf_step_ms"}
    assert all(math.isfinite(ms) and ms > 0 for ms in timings.values())


def test_report_text_shows_missing_figures_as_dashes():
    report = {
        "machine": machine(),
        "jit_warmup_s": 1.0,
        "maps": {},
        "sim_steps_per_s": 1000.0,
        "map_scaling": [],
    }
    report.update(
        dict.fromkeys(
            (
                "rr_games_per_s",
                "ss_games_per_s",
                "recorder_overhead",
                "rrd_mb_per_game",
                "env_steps_per_s",
                "pybullet_rtf",
                "vision_precision",
                "vision_recall",
                "person_precision",
                "person_recall",
                "person_latency_ms",
            )
        )
    )
    text = format_report(report)
    assert "machine:" in text and "S-S -" in text and "recorder: +-% game time" in text


def test_team_scaling_times_a_game_of_every_team_size(tmp_path):
    from pegame.bench import TEAM_SIZES, team_scaling

    seconds = team_scaling(1, str(tmp_path), t_max=1.0)
    assert list(seconds) == [f"{n}v{m}" for n, m in TEAM_SIZES]
    assert all(value > 0 for value in seconds.values())


@pytest.mark.slow  # eight short games
def test_the_loss_causes_cost_is_measured_on_paired_games_and_inside_the_tracker():
    from pegame.bench import LOSS_GAMES, loss_causes_cost

    cost = loss_causes_cost(1, t_max=1.0)
    assert list(cost) == list(LOSS_GAMES)
    for figures in cost.values():
        assert set(figures) == {"paired", "inside"}
        assert math.isfinite(figures["paired"]) and figures["inside"] > 0
