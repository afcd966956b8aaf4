"""Smoke test of the batched env's benchmark on a few games (the figures themselves are
measured by ``python -m pegame.bench``, never asserted here)."""

from __future__ import annotations

import math

import pytest

from pegame.envs.bench import bench_vector_env, format_vector


@pytest.mark.slow
def test_vector_bench_measures_every_figure_in_alternating_rounds():
    report = bench_vector_env(
        seconds=0.2,
        num_envs=6,
        smart_envs=2,
        overrides=["env=enclosed"],
        single_steps=20,
        scaling_base=3,
    )
    assert report["rounds"] >= 1 and report["num_envs"] == 6
    for key in (
        "single_env_steps_per_s",
        "vector_env_steps_per_s",
        "vector_env_steps_per_s_all_cores",
        "vector_env_steps_per_s_smart",
        "vector_env_steps_per_s_smart_paper",
        "vector_reset_ms_per_game",
        "vector_env_array_bytes_per_game",
        "vector_env_steps_per_s_alone",
        "vector_beside_others_ratio",
        "vector_scaling_over_smaller",
    ):
        assert math.isfinite(report[key]) and report[key] > 0, key
    line = format_vector(report)
    assert "(6 games" in line and "x the rate of 3 games" in line
    assert format_vector({}) == "batched env: -"
