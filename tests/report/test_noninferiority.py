"""Non-inferiority at a stated margin: the decision on constructed paired differences
(clearly inferior, clearly non-inferior, borderline, a small shortfall wholly below zero
but within the margin, a few seeds lost badly), the Holm family, and the command line end
to end on synthetic results."""

from __future__ import annotations

import csv
import json
import subprocess
import sys

import numpy as np
import pytest
from scipy.stats import wilcoxon

from pegame import report
from pegame.report.noninferiority import decide, noninferiority_test
from pegame.testing.reports import config_job

SEEDS = range(40)
MARGIN = 0.02


def paired(shift: float, noise: float, seed: int = 7) -> tuple[dict, dict]:
    """({seed: A's rate}, {seed: B's rate}): B spread over [0.4, 0.9], A = B + ``shift``
    plus noise of standard deviation ``noise`` and mean exactly zero."""
    rng = np.random.default_rng(seed)
    b = rng.uniform(0.4, 0.9, len(SEEDS))
    jitter = rng.normal(0, noise, b.size) if noise else np.zeros(b.size)
    a = b + shift + jitter - jitter.mean()
    return dict(zip(SEEDS, a.tolist())), dict(zip(SEEDS, b.tolist()))


def test_clearly_inferior_is_not_noninferior():
    result = noninferiority_test(*paired(-0.20, 0.05), MARGIN)
    assert result["mean_difference"] == pytest.approx(-0.20)
    assert result["p"] > 0.99
    assert result["lower_bound"] < -MARGIN


def test_clearly_noninferior_has_the_smallest_bootstrap_p():
    result = noninferiority_test(*paired(0.0, 0.01), MARGIN)
    assert result["p"] == pytest.approx(1 / 10_001)
    assert result["lower_bound"] > -MARGIN
    assert result["n_pairs"] == 40


def test_a_mean_shortfall_of_exactly_the_margin_is_not_shown_noninferior():
    result = noninferiority_test(*paired(-MARGIN, 0.03), MARGIN)
    assert result["mean_difference"] == pytest.approx(-MARGIN)
    assert 0.3 < result["p"] < 0.7


def test_a_small_shortfall_wholly_below_zero_is_decided_by_the_margin():
    """The round-robin's case: -0.5 pp with an interval below zero. No worse by more than
    2 points, yes; by more than 0.2 points, no."""
    a, b = paired(-0.005, 0.005)
    within = noninferiority_test(a, b, MARGIN)
    assert within["lower_bound"] < 0 and within["p"] < 0.001
    tight = noninferiority_test(a, b, 0.002)
    assert tight["p"] > 0.99


def test_a_few_seeds_lost_badly_count_in_full():
    """35 seeds 1 point better, 5 seeds 70 points worse: a mean shortfall of 7.9 points,
    not non-inferior (a signed-rank test of d + margin would pass it)."""
    b = dict(zip(SEEDS, [0.9] * 40))
    a = {s: 0.91 if s < 35 else 0.2 for s in SEEDS}
    result = noninferiority_test(a, b, MARGIN)
    assert result["mean_difference"] == pytest.approx((35 * 0.01 - 5 * 0.7) / 40)
    assert result["p"] > 0.5
    shifted = np.array([a[s] - b[s] + MARGIN for s in SEEDS])
    assert wilcoxon(shifted, alternative="greater").pvalue < 0.001


def test_the_bound_and_the_uncorrected_p_agree_and_no_common_seed_is_untested():
    for shift in (-0.04, -0.025, -0.015, 0.0):
        result = noninferiority_test(*paired(shift, 0.04, seed=3), MARGIN)
        if abs(result["p"] - 0.05) > 0.01:
            assert (result["lower_bound"] > -MARGIN) == (result["p"] < 0.05)
    untested = noninferiority_test({0: 0.5}, {1: 0.5}, MARGIN)
    assert untested["n_pairs"] == 0 and untested["p"] is None


def test_holm_decides_the_family():
    rows = [{"p": 0.02}, {"p": 0.03}, {"p": None}, {"p": 0.001}]
    decide(rows)
    assert [r["p_holm"] for r in rows] == pytest.approx([0.04, 0.04, None, 0.003])
    assert [r["noninferior"] for r in rows] == [True, True, None, True]
    rows = [{"p": 0.03}, {"p": 0.04}]
    decide(rows)
    assert [r["noninferior"] for r in rows] == [False, False]


def factor_sweep(tmp_path):
    """miss_probability 0 and 0.3 at v_p/v_e 1 and 2 on common seeds: at 1 the 0.3 games
    track 0.5 points less (non-inferior at 2 points), at 2 they track 15 points less."""
    root = tmp_path / "sweep"
    b = paired(0.0, 0.0)[1]
    for ratio, shift in ((1.0, -0.005), (2.0, -0.15)):
        for miss, rates in ((0.0, list(b.values())), (0.3, [v + shift for v in b.values()])):
            config_job(
                root,
                f"{ratio}_{miss}",
                SEEDS,
                rates,
                **{"game.speed_ratio": ratio, "detector.miss_probability": miss},
            )
    return root


@pytest.mark.slow
def test_cli_noninferior_writes_the_decision_per_cell(tmp_path):
    root = factor_sweep(tmp_path)
    command = [sys.executable, "-m", "pegame.report", str(root), "--out", str(tmp_path / "out")]
    proc = subprocess.run(
        [*command, "--noninferior", "detector.miss_probability=0.3,0", "--margin", "0.02"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    assert (
        "detector.miss_probability: 0.3 no worse than 0 by more than 2 points: non-inferior "
        "in 1 of 2 tested cells -> noninferior_detector.miss_probability.md" in proc.stdout
    )
    with open(tmp_path / "out" / "noninferior_detector.miss_probability.csv") as f:
        rows = list(csv.DictReader(f))
    assert [(r["speed_ratio"], r["noninferior"]) for r in rows] == [
        ("1.0", "True"),
        ("2.0", "False"),
    ]
    assert float(rows[0]["mean_difference"]) == pytest.approx(-0.005)
    saved = json.loads((tmp_path / "out" / "report.json").read_text())
    assert saved["noninferiority"][0]["margin"] == 0.02
    md = (tmp_path / "out" / "noninferior_detector.miss_probability.md").read_text()
    assert "H0 mean(d) <= -2 pp" in md and "| yes |" in md and "| no |" in md


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (["--noninferior", "detector.miss_probability=0.3,0"], "--margin None is not"),
        (["--noninferior", "detector.miss_probability=0.3,0", "--margin", "-1"], "[0, 1)"),
        (["--margin", "0.02"], "give both"),
        (["--noninferior", "detector.miss_probability=0.3", "--margin", "0.02"], "FACTOR=A,B"),
    ],
)
def test_cli_noninferior_bad_input_is_one_error_exit_2(tmp_path, capsys, arguments, message):
    (tmp_path / "sweep").mkdir()
    with pytest.raises(SystemExit) as stop:
        report.main([str(tmp_path / "sweep"), *arguments])
    assert stop.value.code == 2
    assert message in capsys.readouterr().err


def test_noninferior_names_what_the_sweep_has(tmp_path):
    root = factor_sweep(tmp_path)
    with pytest.raises(report.CompareError, match="--noninferior detector.miss_probability: no"):
        report.write_report(
            root,
            tmp_path / "out",
            noninferiors=[("detector.miss_probability", "0.5", "0")],
            margin=0.02,
        )
