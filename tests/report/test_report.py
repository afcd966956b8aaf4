"""The sweep report end to end on synthetic multirun directories with known answers: the
statistics, the table layout, what is missing, failed or unreadable, figures, the CLI."""

from __future__ import annotations

import csv
import errno
import json
import logging
import math
import subprocess
import sys

import numpy as np
import pytest

from pegame import report
from pegame.testing.reports import config_game, config_job, game, separated, sweep_games, write_job


def test_mean_is_the_sample_mean_and_ci_contains_the_population_mean(tmp_path):
    a, b = 6.0, 4.0  # Beta mean 0.6
    values = np.random.default_rng(0).beta(a, b, 200).tolist()
    half = len(values) // 2
    cell = {("hall", 1.0, "S-R"): values}
    records = sweep_games(cell)
    write_job(tmp_path, "0", records[:half])
    write_job(tmp_path, "1", records[half:])
    result = report.write_report(tmp_path)
    (row,) = result["cells"]
    assert row["n"] == 200
    assert row["mean"] == math.fsum(values) / 200
    assert row["ci_low"] < a / (a + b) < row["ci_high"]
    assert row["ci_low"] < row["mean"] < row["ci_high"]
    assert row["median"] == pytest.approx(np.median(values))
    assert row["std"] == pytest.approx(np.std(values, ddof=1))


def test_bootstrap_ci_covers_the_population_mean_about_95_percent_of_the_time():
    covered = 0
    for seed in range(20):
        values = np.random.default_rng(100 + seed).beta(2.0, 3.0, 60).tolist()
        low, high = report.bootstrap_ci(values, resamples=2000)
        covered += low < 0.4 < high
    assert covered >= 17
    assert report.bootstrap_ci([0.3]) == (0.3, 0.3)


def test_table_layout_orders_maps_ratios_and_pairings_like_the_paper(tmp_path):
    cells = {
        (m, r, p): [0.5, 0.6]
        for m in ("office", "brick", "hall", "enclosed")
        for r in (2.0, 0.5, 1.0)
        for p in ("X-Y", "S-S", "R-S", "R-R", "S-R")
    }
    write_job(tmp_path, "0", sweep_games(cells))
    report.write_report(tmp_path, tmp_path / "out")
    out = tmp_path / "out"
    maps = ["hall", "enclosed", "brick", "office"]
    pairings = ["R-R", "S-R", "S-S", "R-S", "X-Y"]
    md = (out / "table1.md").read_text().splitlines()
    header = next(line for line in md if line.startswith("| v_p/v_e"))
    assert (
        header
        == "| " + " | ".join(["v_p/v_e"] + [f"{m} {p}" for m in maps for p in pairings]) + " |"
    )
    body = md[md.index(header) + 2 :]
    assert [line.split(" | ")[0] for line in body[:3]] == ["| 0.5", "| 1", "| 2"]
    assert "55.0% [50.0, 60.0] n=2" in body[0]
    rows = list(csv.DictReader((out / "table1.csv").open()))
    assert list(rows[0]) == [
        "map",
        "speed_ratio",
        "pairing",
        "n",
        "mean",
        "ci_low",
        "ci_high",
        "median",
        "std",
    ]
    expected = [(m, r, p) for m in maps for r in (0.5, 1.0, 2.0) for p in pairings]
    assert [(r["map"], float(r["speed_ratio"]), r["pairing"]) for r in rows] == expected
    assert float(rows[0]["mean"]) == pytest.approx(0.55)
    tex = (out / "table1.tex").read_text()
    assert "\\toprule" in tex and "\\midrule" in tex and "\\bottomrule" in tex
    titles = ["Complex Hall", "Enclosed Room", "Brick Room", "office"]
    assert [tex.index(t) for t in titles] == sorted(tex.index(t) for t in titles)
    assert "\\begin{tabular}{l ccccc ccccc ccccc ccccc}" in tex
    assert "55.0\\% {\\scriptsize [50.0, 60.0] $n$=2}" in tex


def test_missing_job_is_listed_with_its_overrides(tmp_path):
    write_job(tmp_path, "0", [game("hall", 1.0, "S-R", 0, 0.7)])
    (tmp_path / "1" / ".hydra").mkdir(parents=True)
    (tmp_path / "1" / ".hydra" / "overrides.yaml").write_text("- env=brick\n- game.speed_ratio=2\n")
    result = report.write_report(tmp_path)
    assert result["missing_jobs"] == [
        {"job": "1", "overrides": ["env=brick", "game.speed_ratio=2"]}
    ]
    md = (tmp_path / "table1.md").read_text()
    section = md[md.index("## Missing and failed") :]
    assert "job 1: overrides env=brick game.speed_ratio=2" in section


def test_truncated_last_line_is_skipped_and_reported(tmp_path, caplog):
    records = [game("hall", 1.0, "S-R", s, 0.5 + s / 10) for s in range(3)]
    write_job(tmp_path, "0", records, tail='{"kind": "game", "pairing": "S-', summary=False)
    resumed = json.dumps(game("hall", 1.0, "S-R", 9, 0.9)) + "\n"
    write_job(
        tmp_path, "1", [game("hall", 1.0, "S-R", 8, 0.8)], tail=resumed
    )  # killed after resume
    with caplog.at_level(logging.WARNING, logger="pegame.report"):
        result = report.write_report(tmp_path)
    assert result["games"] == 5 and result["cells"][0]["n"] == 5
    (skipped,) = result["skipped_lines"]
    assert skipped["file"] == "0/results.jsonl" and skipped["line"] == 4
    assert "invalid JSON" in skipped["reason"]
    assert result["unfinished_jobs"] == ["0", "1"]
    assert "0/results.jsonl line 4" in (tmp_path / "table1.md").read_text()
    assert "skipping 0/results.jsonl line 4" in caplog.text


def test_records_of_unknown_kind_or_without_required_keys_are_skipped(tmp_path):
    write_job(
        tmp_path,
        "0",
        [game("hall", 1.0, "S-R", 0, 0.5)],
        tail='{"kind": "progress"}\n{"kind": "game", "map": "hall"}\n[1, 2]\n',
    )
    result = report.write_report(tmp_path)
    assert result["games"] == 1 and result["unfinished_jobs"] == []
    reasons = [s["reason"] for s in result["skipped_lines"]]
    assert [s["line"] for s in result["skipped_lines"]] == [3, 4, 5]
    assert reasons[0].startswith("not a record of kind") and reasons[2] == reasons[0]
    assert reasons[1].startswith("game record without speed_ratio, pursuer")


def test_an_empty_directory_gives_an_empty_report(tmp_path):
    result = report.write_report(tmp_path)
    assert result["games"] == 0 and result["cells"] == []
    assert all(h["summary"]["text"] == report.UNTESTED for h in result["hypotheses"])
    assert (tmp_path / "fig8_pairing.png").stat().st_size > 0


def test_figures_are_non_empty_png_and_svg(tmp_path):
    write_job(tmp_path, "0", sweep_games(separated("S-R", "R-R", n=5)))
    result = report.write_report(tmp_path)
    for name in ("fig5a_speed_ratio", "fig5b_environment", "fig8_pairing"):
        assert (tmp_path / f"{name}.png").read_bytes().startswith(b"\x89PNG")
        svg = (tmp_path / f"{name}.svg").read_text()
        assert "<svg" in svg and len(svg) > 1000
        assert f"{name}.png" in result["outputs"]
    json.loads((tmp_path / "report.json").read_text())


@pytest.mark.slow
def test_cli_writes_the_report_into_out(tmp_path):
    write_job(tmp_path / "sweep", "0", sweep_games(separated("S-R", "R-R", n=5)))
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "pegame.report",
            str(tmp_path / "sweep"),
            "--out",
            str(tmp_path / "out"),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    assert "H1: holds" in proc.stdout
    names = {p.name for p in (tmp_path / "out").iterdir()}
    assert {
        "table1.md",
        "table1.csv",
        "table1.tex",
        "hypotheses.md",
        "report.json",
        "fig8_pairing.svg",
    } <= names
    bad = subprocess.run(
        [sys.executable, "-m", "pegame.report", str(tmp_path / "nowhere")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert bad.returncode == 2 and "not a directory" in bad.stderr


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("seed", "seven"),
        ("tracking_rate", "high"),
        ("tracking_rate", 1.5),
        ("speed_ratio", True),
        ("config", [1, 2]),
        ("config_hash", 7),
        ("overrides", "env=hall"),
        ("provenance", "0.3"),
        ("map", 3),
    ],
)
def test_a_line_with_a_wrong_type_is_skipped_and_listed(tmp_path, field, value):
    bad = {**config_game(9, 0.5), field: value}
    write_job(tmp_path, "0", [config_game(0, 0.5), bad, config_game(1, 0.7)])
    result = report.write_report(tmp_path)
    assert result["games"] == 2 and result["cells"][0]["n"] == 2
    (skipped,) = result["skipped_lines"]
    assert skipped["line"] == 2 and f"'{field}' is {value!r}" in skipped["reason"]
    assert (
        "0/results.jsonl line 2: game record with a wrong type"
        in (tmp_path / "table1.md").read_text()
    )


def test_invalid_cells_are_listed_and_the_others_reported(tmp_path):
    config_job(tmp_path, "0", range(3), [0.5, 0.6, 0.7])
    job = tmp_path / "1"
    (job / ".hydra").mkdir(parents=True)
    error = "Invalid value for 'detector.miss_probability': 1.5. Allowed: a number in [0, 1)."
    (job / "results.jsonl").write_text(
        json.dumps(
            {"kind": "invalid", "error": error, "overrides": ["detector.miss_probability=1.5"]}
        )
        + "\n"
    )
    result = report.write_report(tmp_path)
    assert result["games"] == 3 and [c["n"] for c in result["cells"]] == [3]
    (failed,) = result["failed_cells"]
    assert failed["job"] == "1" and failed["error"] == error
    assert result["unfinished_jobs"] == [] and result["missing_jobs"] == []
    md = (tmp_path / "table1.md").read_text()
    assert "### Failed cells (invalid configuration): 1" in md
    assert f"- job 1: overrides detector.miss_probability=1.5: {error}" in md


@pytest.mark.slow
def test_a_report_that_cannot_be_written_is_one_clear_error(tmp_path, monkeypatch):
    config_job(tmp_path / "sweep", "0", range(2), [0.5, 0.6])
    (tmp_path / "file").write_text("not a directory")
    with pytest.raises(report.ReportError, match="Cannot write the report into"):
        report.write_report(tmp_path / "sweep", tmp_path / "file" / "out")
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "pegame.report",
            str(tmp_path / "sweep"),
            "--out",
            str(tmp_path / "file" / "out"),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 2 and "error: Cannot write the report into" in proc.stderr
    assert "Traceback" not in proc.stderr

    def full_disk(path, data):
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    monkeypatch.setattr("pegame.report.write_atomic", full_disk)
    with pytest.raises(report.ReportError, match="No space left on device"):
        report.write_report(tmp_path / "sweep")
    assert report.main([str(tmp_path / "sweep")]) == 2
    with pytest.raises(report.ReportError, match="No such sweep directory"):
        report.write_report(tmp_path / "nowhere")
