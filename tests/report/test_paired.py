"""Paired statistics on common seeds: the Wilcoxon signed-rank tests beside the hypotheses'
Mann-Whitney tests, their zero differences, and the comparison of two values of a factor,
on synthetic sweeps with known answers (fixed seeds)."""

from __future__ import annotations

import csv
import json
import subprocess
import sys

import numpy as np
import pytest
from scipy.stats import wilcoxon

from pegame import report
from pegame.report.compare import STATS, parse_compare
from pegame.report.paired import paired_test
from pegame.testing.reports import config_job, sweep_games, write_job

SEEDS = range(12)


def shifted(shift: float, noise: float = 0.02, seed: int = 3) -> dict:
    """R-R rates spread over [0.2, 0.7] and S-R = R-R + ``shift`` plus a little noise of
    mean zero on the same seeds, in hall and brick at v_p/v_e 1."""
    rng = np.random.default_rng(seed)
    cells = {}
    for m in ("hall", "brick"):
        base = rng.uniform(0.2, 0.7, len(SEEDS))
        cells[(m, 1.0, "R-R")] = base.tolist()
        jitter = rng.normal(0, noise, base.size)
        cells[(m, 1.0, "S-R")] = (base + shift + jitter - jitter.mean()).tolist()
    return cells


def test_a_shift_of_ten_points_on_common_seeds_is_found_by_the_paired_test(tmp_path):
    write_job(tmp_path, "0", sweep_games(shifted(0.10)))
    result = report.write_report(tmp_path, tmp_path / "out")
    h1 = result["hypotheses"][0]
    assert h1["test"] == "Mann-Whitney U"
    assert h1["summary_paired"]["test"] == "Wilcoxon signed-rank on common seeds"
    assert h1["summary_paired"]["verdict"] == "holds"
    for row in h1["rows"]:
        paired = row["paired"]
        assert paired["n_pairs"] == len(SEEDS) and paired["zero_differences"] == 0
        assert paired["ci_low"] < 0.10 < paired["ci_high"]
        assert paired["ci_high"] - paired["ci_low"] < 0.04  # the spawn's variance is gone
        assert paired["mean_difference"] == pytest.approx(0.10)
        assert paired["rank_biserial"] == 1.0 and paired["W"] == 78  # every difference > 0
        assert paired["p_holm"] <= report.ALPHA < row["p_holm"]  # Mann-Whitney misses it
    md = (tmp_path / "out" / "hypotheses.md").read_text()
    assert "## H1: fails (in 0 of 2 cells) by Mann-Whitney U; holds (in 2 of 2 cells) by " in md
    assert "| hall | 1 | 12 | 0 | +" in md and "zero_method='pratt'" in md


def test_without_common_seeds_the_paired_test_is_not_tested(tmp_path):
    cells = shifted(0.10)
    records = sweep_games(cells)
    for record in records:
        if record["pairing"] == "S-R":
            record["seed"] += 100  # other spawns: nothing to pair
    write_job(tmp_path, "0", records)
    h1 = report.write_report(tmp_path)["hypotheses"][0]
    assert h1["summary"]["n"] == 2  # Mann-Whitney still tests both cells
    assert h1["summary_paired"]["text"] == report.UNTESTED
    for row in h1["rows"]:
        assert row["paired"]["n_pairs"] == 0
        assert row["paired"]["p"] is None and row["paired"]["holds"] is None
    unseeded = report.hypotheses(cells)[0]  # rates without seeds: unpaired only
    assert unseeded["summary"]["n"] == 2 and unseeded["summary_paired"]["n"] == 0


@pytest.mark.slow
def test_h3_paired_needs_the_smart_evader_tracked_less_and_above_45_percent(tmp_path):
    rng = np.random.default_rng(5)
    base = rng.uniform(0.6, 0.9, len(SEEDS))
    cells = {
        ("hall", 1.0, "S-R"): base.tolist(),
        ("hall", 1.0, "S-S"): (base - 0.1).tolist(),
        ("brick", 1.0, "S-R"): (base - 0.3).tolist(),
        ("brick", 1.0, "S-S"): (base - 0.4).tolist(),  # tracked less, but below 45%
    }
    write_job(tmp_path, "0", sweep_games(cells))
    h3 = report.write_report(tmp_path)["hypotheses"][2]
    by_map = {row["map"]: row for row in h3["rows"]}
    assert by_map["hall"]["paired"]["holds"] and by_map["brick"]["paired"]["tracked_less"]
    assert not by_map["brick"]["reasonable"] and not by_map["brick"]["paired"]["holds"]
    assert h3["summary_paired"]["text"] == "partly (in 1 of 2 cells)"


def test_zero_differences_keep_their_pratt_ranks():
    # |d| = 0, 0, .1, .2, .3: Pratt ranks 1.5, 1.5, 3, 4, 5; the zeros' ranks are left out:
    # T+ = 3 + 4 = 7, T- = 5, r = (7 - 5) / 12 (Wilcox's method would rank 1, 2, 3: r = 0)
    x = {0: 0.5, 1: 0.8, 2: 0.6, 3: 0.7, 4: 0.2}
    y = {0: 0.5, 1: 0.8, 2: 0.5, 3: 0.5, 4: 0.5, 9: 0.1}
    test = paired_test(x, y, "greater")
    assert test["n_pairs"] == 5 and test["zero_differences"] == 2
    assert test["W"] == 7 and test["rank_biserial"] == pytest.approx(1 / 6)
    d = [0, 0, 0.1, 0.2, -0.3]
    assert test["p"] == wilcoxon(d, zero_method="pratt", alternative="greater").pvalue


def test_all_zero_differences_are_no_evidence():
    same = {seed: 0.25 * (seed % 4) for seed in SEEDS}
    test = paired_test(same, dict(same), "greater")
    assert (test["p"], test["W"], test["rank_biserial"]) == (1.0, 0.0, 0.0)
    assert test["mean_difference"] == test["ci_low"] == test["ci_high"] == 0.0
    assert test["zero_differences"] == len(SEEDS)


def test_float_noise_does_not_break_ties_between_equal_differences():
    # 0.3 - 0.2 and 0.3 - 0.4 differ in float by 4e-17 in size: tied after rounding, r = 0
    test = paired_test({0: 0.3, 1: 0.3}, {0: 0.2, 1: 0.4}, "two-sided")
    assert test["rank_biserial"] == 0.0 and test["W"] == 1.5


def factor_sweep(root, shift: float = -0.10) -> None:
    """S-R and R-R jobs at detector.miss_probability 0 and 0.3 on the same seeds; 0.3 takes
    ``shift`` off S-R's rates, nothing off R-R's."""
    rng = np.random.default_rng(7)
    for i, (pursuer, base) in enumerate((("smart", 0.7), ("random", 0.3))):
        rates = rng.uniform(base - 0.2, base + 0.2, len(SEEDS))
        for j, miss in enumerate((0.0, 0.3)):
            delta = shift if (pursuer == "smart" and miss) else 0.0
            jitter = rng.normal(0, 0.01, rates.size) * bool(delta)
            noisy = rates + delta + jitter - jitter.mean()  # the mean shift is ``shift``
            config_job(
                root,
                f"{i}{j}",
                SEEDS,
                noisy.tolist(),
                **{"pursuer.name": pursuer, "detector.miss_probability": miss},
            )


def test_compare_two_values_of_a_factor_cell_by_cell(tmp_path):
    factor_sweep(tmp_path)
    result = report.write_report(
        tmp_path, tmp_path / "out", [("detector.miss_probability", "0", "0.3")]
    )
    (comparison,) = result["comparisons"]
    assert (comparison["factor"], comparison["a"], comparison["b"]) == (
        "detector.miss_probability",
        "0",
        "0.3",
    )
    rows = {row["pairing"]: row for row in comparison["rows"]}
    assert sorted(rows) == ["R-R", "S-R"]
    smart, random = rows["S-R"], rows["R-R"]
    assert smart["n_pairs"] == smart["n_a"] == smart["n_b"] == len(SEEDS)
    assert smart["ci_low"] < -0.10 < smart["ci_high"] < 0
    assert smart["mean_difference"] == pytest.approx(-0.10)
    assert smart["mean_b"] - smart["mean_a"] == pytest.approx(smart["mean_difference"])
    assert smart["p_holm"] <= report.ALPHA and smart["rank_biserial"] == -1.0
    assert random["mean_difference"] == 0.0 and random["p"] == random["p_holm"] == 1.0
    assert comparison["summary"] == {"cells": 2, "tested": 2, "significant": 1}

    with open(tmp_path / "out" / "compare_detector.miss_probability.csv") as f:
        table = list(csv.reader(f))
    assert table[0] == ["map", "speed_ratio", "pairing", *STATS]
    assert {line[2] for line in table[1:]} == {"S-R", "R-R"}
    md = (tmp_path / "out" / "compare_detector.miss_probability.md").read_text()
    assert "# detector.miss_probability: 0.3 against 0" in md
    assert "| enclosed | 1 | S-R | 12 (of 12, 12) |" in md and " pp [" in md
    saved = json.loads((tmp_path / "out" / "report.json").read_text())
    assert saved["comparisons"][0]["rows"] == comparison["rows"]
    assert "compare_detector.miss_probability.md" in saved["outputs"]


@pytest.mark.slow
def test_compare_matches_cells_within_each_combination_of_the_other_factors(tmp_path):
    for k, estimator in enumerate(("last_seen", "particle_filter")):
        for j, miss in enumerate((0.0, 0.3)):
            seeds = range(6) if miss else range(3, 9)  # seeds 3, 4, 5 in common
            config_job(
                tmp_path,
                f"{k}{j}",
                seeds,
                [0.5 + 0.1 * k - 0.2 * miss] * 6,
                **{"estimator.name": estimator, "detector.miss_probability": miss},
            )
    comparison = report.write_report(
        tmp_path, tmp_path / "out", [("detector.miss_probability", "0", "0.3")]
    )["comparisons"][0]
    assert comparison["others"] == ["estimator.name"]
    assert [row["factors"] for row in comparison["rows"]] == [
        {"estimator.name": "last_seen"},
        {"estimator.name": "particle_filter"},
    ]
    for row in comparison["rows"]:
        assert row["n_pairs"] == 3 and row["mean_difference"] == pytest.approx(-0.06)
    header = (tmp_path / "out" / "compare_detector.miss_probability.csv").read_text()
    assert header.startswith("estimator.name,map,speed_ratio,pairing,n_a,n_b,n_pairs,")


def test_compare_names_what_the_sweep_has_when_asked_for_what_it_lacks(tmp_path):
    factor_sweep(tmp_path)
    with pytest.raises(report.CompareError, match="Its factors: detector.miss_probability"):
        report.write_report(tmp_path, tmp_path / "out", [("sim.name", "grid", "pybullet")])
    with pytest.raises(report.CompareError, match="values of detector.miss_probability.*0, 0.3"):
        report.write_report(tmp_path, tmp_path / "out", [("detector.miss_probability", "0", "1")])
    with pytest.raises(report.CompareError, match="not FACTOR=A,B"):
        parse_compare("detector.miss_probability=0")
    twice = [("detector.miss_probability", "0", "0.3"), ("detector.miss_probability", "0.3", "0")]
    with pytest.raises(report.CompareError, match="more than once"):
        report.write_report(tmp_path, tmp_path / "out", twice)
    assert not (tmp_path / "out").exists()


@pytest.mark.slow
def test_cli_compare_writes_the_comparison(tmp_path):
    factor_sweep(tmp_path)
    command = [sys.executable, "-m", "pegame.report", str(tmp_path), "--out", str(tmp_path / "o")]
    proc = subprocess.run(
        [*command, "--compare", "detector.miss_probability=0,0.3"],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0, proc.stderr
    assert "detector.miss_probability: 0.3 against 0: significant in 1 of 2" in proc.stdout
    assert (tmp_path / "o" / "compare_detector.miss_probability.md").is_file()
    bad = subprocess.run([*command, "--compare", "nonsense"], capture_output=True, text=True)
    assert bad.returncode == 2 and "not FACTOR=A,B" in bad.stderr
