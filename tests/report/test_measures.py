"""The report of any measure of result.json (--metric), the estimator's table and the
stage log, on synthetic job dirs with known answers."""

from __future__ import annotations

import csv
import json
import logging
from types import SimpleNamespace

import numpy as np
import pytest

from pegame import report
from pegame.metrics import TeamMetrics, TrackingMetrics
from pegame.report.measures import MEASURES, measure
from pegame.testing.reports import config_job, game, table_rows, write_job
from pegame.types import Belief, Pose

SMART_R = {"pursuer.name": "smart", "evader.name": "random"}


def test_the_measures_are_the_numeric_fields_of_result_json():
    single = TrackingMetrics(0.1)
    context = SimpleNamespace(control_dt=0.1, grid=SimpleNamespace(blocked=np.zeros((4, 4), bool)))
    team = TeamMetrics(context, 2, 1)  # type: ignore[arg-type]  # the two fields it reads
    belief = Belief(mean=(1.0, 1.0), n_eff=50.0, resampled=True)
    pursuers, evader = (Pose(0, 0), Pose(1, 0)), Pose(2, 0)
    for detected in (True, False, True):
        single.add(pursuers[0], evader, detected, True, belief)
        team.add(pursuers, (evader,), ((None,), (None,)), ((True,), (True,)), (belief,))
    numeric = {
        key
        for summary in (single.summary(), team.summary())
        for key, value in summary.items()
        if not isinstance(value, list)
    }
    assert set(MEASURES) == numeric - {"pursuers", "evaders"}  # the team's sizes are settings


def test_an_unknown_metric_is_one_paragraph_naming_the_measures_and_exit_2(tmp_path, capsys):
    write_job(tmp_path, "0", [game("hall", 1.0, "S-R", 0, 0.5)])
    with pytest.raises(SystemExit) as stop:
        report.main([str(tmp_path), "--metric", "estimation_error"])
    assert stop.value.code == 2
    error = capsys.readouterr().err.splitlines()[-1]
    assert "'estimation_error' is not a measure of result.json (did you mean " in error
    assert "mean_estimation_error, n_eff_mean" in error and "mean_distance" in error
    with pytest.raises(report.MeasureError):
        measure("nope")
    assert not (tmp_path / "table1.md").exists()


@pytest.mark.slow
def test_metric_tables_are_of_that_measure_over_the_games_that_define_it(tmp_path, capsys):
    distances = [{"mean_distance": d} for d in (1.0, 2.0, 3.0, None)]
    config_job(tmp_path, "0", range(4), [0.2, 0.4, 0.6, 0.8], distances, **SMART_R)
    out = tmp_path / "out"
    assert report.main([str(tmp_path), "--out", str(out), "--metric", "mean_distance"]) == 0
    printed = capsys.readouterr().out
    assert "the hypotheses are tested on the tracking rate" in printed
    result = json.loads((out / "report_mean_distance.json").read_text())
    (cell,) = result["cells"]
    assert result["metric"] == "mean_distance"
    assert (cell["n"], cell["mean"], cell["median"]) == (3, 2.0, 2.0)
    assert cell["ci_low"] >= 1.0 and cell["ci_high"] <= 3.0
    md = (out / "table1_mean_distance.md").read_text()
    assert md.startswith("# Table 1: mean distance\n")
    assert "The hypotheses (hypotheses.md) are tested on the tracking rate." in md
    assert table_rows(md)[2] == ["1", f"2.00 m [{cell['ci_low']:.2f}, {cell['ci_high']:.2f}] n=3"]
    (row,) = csv.DictReader((out / "table1_mean_distance.csv").open())
    assert float(row["mean"]) == 2.0 and row["n"] == "3"
    assert "2.00 m {\\scriptsize [" in (out / "table1_mean_distance.tex").read_text()
    assert (out / "fig5a_speed_ratio_mean_distance.png").stat().st_size > 0
    assert not (out / "table1.md").exists()  # the tracking-rate report is not overwritten
    tracking = report.write_report(tmp_path, tmp_path / "rates")
    assert tracking["cells"][0]["mean"] == pytest.approx(0.5)
    assert tracking["hypotheses"] == result["hypotheses"]


@pytest.mark.slow
def test_compare_under_a_metric_pairs_that_measure(tmp_path):
    seeds = range(3)
    for name, value, distances in (("0", 0.0, (1.0, 2.0, 3.0)), ("1", 0.3, (2.0, 3.5, 4.5))):
        measures = [{"mean_distance": d} for d in distances]
        config_job(
            tmp_path, name, seeds, [0.5] * 3, measures, **{"detector.miss_probability": value}
        )
    result = report.write_report(
        tmp_path, comparisons=[("detector.miss_probability", "0", "0.3")], metric="mean_distance"
    )
    (row,) = result["comparisons"][0]["rows"]
    assert result["comparisons"][0]["measure"] == "mean_distance"
    assert (row["mean_a"], row["mean_b"], row["mean_difference"]) == (2.0, 10 / 3, 4 / 3)
    md = (tmp_path / "compare_detector.miss_probability_mean_distance.md").read_text()
    assert "| 2.00 m | 3.33 m | +1.33 m [" in md


@pytest.mark.slow
def test_the_estimators_error_n_eff_and_resamplings_are_tabulated_per_cell(tmp_path):
    measures = [
        {"mean_estimation_error": e, "n_eff_mean": n, "resamplings": r}
        for e, n, r in ((1.0, 100.0, 1), (2.0, 200.0, 2), (None, 300.0, 3))
    ]
    config_job(tmp_path, "0", range(3), [0.5, 0.6, 0.7], measures, **SMART_R)
    result = report.write_report(tmp_path)
    (row,) = result["estimation"]["rows"]
    assert row["games"] == 3
    assert (row["mean_estimation_error"]["n"], row["mean_estimation_error"]["mean"]) == (2, 1.5)
    assert (row["n_eff_mean"]["n"], row["n_eff_mean"]["mean"]) == (3, 200.0)
    assert row["resamplings"]["mean"] == 2.0
    (texts,) = table_rows((tmp_path / "estimation.md").read_text())[2:]
    assert texts[:4] == ["enclosed", "1", "S-R", "3"]
    assert texts[4].startswith("1.500 m [") and texts[4].endswith("] n=2")
    assert texts[5].startswith("200.0 [") and texts[6].startswith("2.0 [")
    (line,) = csv.DictReader((tmp_path / "estimation.csv").open())
    assert (line["mean_estimation_error_n"], line["n_eff_mean_mean"]) == ("2", "200.0")


@pytest.mark.slow
def test_no_estimation_table_when_no_game_carries_the_estimators_measures(tmp_path):
    write_job(tmp_path, "0", [game("hall", 1.0, "S-R", s, 0.5) for s in range(2)])
    result = report.write_report(tmp_path)
    assert "estimation" not in result and not (tmp_path / "estimation.md").exists()


@pytest.mark.slow
def test_the_report_logs_each_stage(tmp_path, caplog):
    for job, seeds in (("0", (0, 1)), ("1", (2, 3))):
        write_job(tmp_path, job, [game("hall", 1.0, "S-R", s, 0.5) for s in seeds])
    with caplog.at_level(logging.INFO, logger="pegame.report"):
        report.write_report(tmp_path, tmp_path / "out", paper=True)
    lines = [r.getMessage() for r in caplog.records if r.name == "pegame.report"]
    assert lines[0] == f"loading 2 job dirs below {tmp_path}"
    assert lines[1].startswith("4 games, 1 cells; statistics of tracking_rate")
    assert lines[2:] == [
        "testing hypotheses H1-H3 and the trends T1-T2 on the tracking rate",
        "setting our tracking rates beside the paper's Table 1",
        "drawing the figures (PNG and SVG)",
        f"writing 13 files into {tmp_path / 'out'}",
    ]


@pytest.mark.slow
def test_a_measure_no_game_defines_gives_empty_cells_and_a_warning(tmp_path, caplog):
    write_job(tmp_path, "0", [game("hall", 1.0, "S-R", s, 0.5) for s in range(2)])
    with caplog.at_level(logging.WARNING, logger="pegame.report"):
        result = report.write_report(tmp_path, metric="handoffs")
    assert [c["n"] for c in result["cells"]] == [0]
    assert "no game defines handoffs" in caplog.text
    assert table_rows((tmp_path / "table1_handoffs.md").read_text())[2] == ["1", "–"]
