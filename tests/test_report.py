"""Sweep aggregation on synthetic multirun directories with known answers."""

from __future__ import annotations

import csv
import json
import logging
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from pegame import report

STRATEGY = {"R": "random", "S": "smart"}


def game(map_name: str, ratio: float, pairing: str, seed: int, rate: float) -> dict:
    """A finished-game record as pegame writes it (only the fields the report reads, and some)."""
    pursuer, evader = (STRATEGY.get(letter, letter.lower()) for letter in pairing.split("-"))
    return {"kind": "game", "pairing": pairing, "pursuer": pursuer, "evader": evader,
            "estimator": "last_seen", "detector": "oracle", "sim": "grid", "map": map_name,
            "seed": seed, "speed_ratio": ratio, "t_max": 90.0, "tracking_rate": rate,
            "visible_rate": rate}


def write_job(root: Path, name: str, records: list[dict], overrides: list[str] | None = None,
              tail: str = "", summary: bool = True) -> Path:
    """A job dir with .hydra/overrides.yaml and results.jsonl (``records``, a summary line
    unless ``summary`` is False, then ``tail`` verbatim)."""
    job = root / name
    (job / ".hydra").mkdir(parents=True)
    (job / ".hydra" / "overrides.yaml").write_text("".join(f"- {o}\n" for o in overrides or []))
    ok = [r for r in records if r["kind"] == "game"]
    if summary:
        records = records + [{"kind": "summary", "games": len(ok), "failed": len(records) - len(ok),
                              "tracking_rate_mean": None}]
    lines = "".join(json.dumps(r) + "\n" for r in records)
    (job / "results.jsonl").write_text(lines + tail)
    return job


def sweep_games(rates: dict[tuple[str, float, str], list[float]]) -> list[dict]:
    """Game records for {(map, ratio, pairing): rates}, seeds 0.. within each cell."""
    return [game(m, r, p, seed, v) for (m, r, p), values in rates.items()
            for seed, v in enumerate(values)]


def separated(high: str, low: str, n: int = 12) -> dict:
    """Rates where pairing ``high`` clearly beats ``low`` in 2 maps x 2 speed ratios."""
    rng = np.random.default_rng(1)
    cells = {}
    for m in ("hall", "brick"):
        for r in (0.5, 1.0):
            cells[(m, r, high)] = rng.uniform(0.6, 0.9, n).tolist()
            cells[(m, r, low)] = rng.uniform(0.1, 0.4, n).tolist()
    return cells


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
    cells = {(m, r, p): [0.5, 0.6] for m in ("office", "brick", "hall", "enclosed")
             for r in (2.0, 0.5, 1.0) for p in ("X-Y", "S-S", "R-S", "R-R", "S-R")}
    write_job(tmp_path, "0", sweep_games(cells))
    report.write_report(tmp_path, tmp_path / "out")
    out = tmp_path / "out"
    maps = ["hall", "enclosed", "brick", "office"]
    pairings = ["R-R", "S-R", "S-S", "R-S", "X-Y"]
    md = (out / "table1.md").read_text().splitlines()
    header = next(line for line in md if line.startswith("| v_p/v_e"))
    assert header == "| " + " | ".join(["v_p/v_e"] + [f"{m} {p}" for m in maps for p in pairings]) + " |"
    body = md[md.index(header) + 2:]
    assert [line.split(" | ")[0] for line in body[:3]] == ["| 0.5", "| 1", "| 2"]
    assert "55.0% [50.0, 60.0] n=2" in body[0]
    rows = list(csv.DictReader((out / "table1.csv").open()))
    assert list(rows[0]) == ["map", "speed_ratio", "pairing", "n", "mean", "ci_low", "ci_high",
                             "median", "std"]
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
    assert result["missing_jobs"] == [{"job": "1", "overrides": ["env=brick", "game.speed_ratio=2"]}]
    md = (tmp_path / "table1.md").read_text()
    section = md[md.index("## Missing and failed"):]
    assert "job 1: overrides env=brick game.speed_ratio=2" in section


def test_truncated_last_line_is_skipped_and_reported(tmp_path, caplog):
    records = [game("hall", 1.0, "S-R", s, 0.5 + s / 10) for s in range(3)]
    write_job(tmp_path, "0", records, tail='{"kind": "game", "pairing": "S-', summary=False)
    resumed = json.dumps(game("hall", 1.0, "S-R", 9, 0.9)) + "\n"
    write_job(tmp_path, "1", [game("hall", 1.0, "S-R", 8, 0.8)], tail=resumed)  # killed after resume
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
    write_job(tmp_path, "0", [game("hall", 1.0, "S-R", 0, 0.5)],
              tail='{"kind": "progress"}\n{"kind": "game", "map": "hall"}\n[1, 2]\n')
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


def test_failed_games_are_listed_unless_a_later_run_finished_them(tmp_path):
    failed = [{"kind": "failed", "seed": s, "pairing": "S-S", "map": "brick", "speed_ratio": 2.0,
               "error": f"SpawnError: no valid spawn {s}", "traceback_file": f"failed_{s}.txt"}
              for s in (4, 5)]
    write_job(tmp_path, "0", [game("brick", 2.0, "S-S", 3, 0.4), *failed])
    write_job(tmp_path, "1", [game("brick", 2.0, "S-S", 5, 0.6)])
    result = report.write_report(tmp_path)
    assert [(f["seed"], f["job"]) for f in result["failed_games"]] == [(4, "0")]
    md = (tmp_path / "table1.md").read_text()
    assert "SpawnError: no valid spawn 4 (traceback: 0/failed_4.txt)" in md
    assert "no valid spawn 5" not in md
    assert result["cells"][0]["n"] == 2


def test_duplicate_games_count_once_and_the_later_line_wins(tmp_path):
    write_job(tmp_path, "0", [game("hall", 1.0, "R-R", 0, 0.1), game("hall", 1.0, "R-R", 1, 0.2),
                              game("hall", 1.0, "R-R", 0, 0.3)])
    write_job(tmp_path, "10", [game("hall", 1.0, "R-R", 1, 0.5)])
    write_job(tmp_path, "2", [game("hall", 1.0, "R-R", 1, 0.4)])
    (row,) = report.write_report(tmp_path)["cells"]
    assert row["n"] == 2 and row["mean"] == pytest.approx((0.3 + 0.5) / 2)


def test_holm_adjusts_in_input_order():
    assert report.holm([0.01, 0.04, 0.03]) == pytest.approx([0.03, 0.06, 0.06])
    assert report.holm([0.5, 0.001]) == pytest.approx([0.5, 0.002])
    assert report.holm([]) == []


def test_h1_holds_when_smart_pursuer_is_better_and_fails_otherwise(tmp_path):
    cells = separated("S-R", "R-R")
    cells[("enclosed", 1.0, "S-R")] = [0.7, 0.8]  # no R-R here: not tested
    h1 = report.hypotheses(cells)[0]
    assert h1["summary"] == {"verdict": "holds", "k": 4, "n": 4, "untested": 1,
                             "text": "holds (in 4 of 4 cells)"}
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
    assert [(row["map"], row["speed_ratio"]) for row in h2["rows"]] == [("hall", 0.5), ("brick", 0.5)]
    assert h2["summary"]["verdict"] == "holds"
    assert h2["rows"][0]["x_stats_at_1"]["n"] == 12
    only_equal = {("hall", 1.0, "S-R"): [0.8], ("hall", 1.0, "R-R"): [0.2]}
    h2 = report.hypotheses(only_equal)[1]
    assert h2["rows"][0]["speed_ratio"] == 0.5 and h2["summary"]["text"] == report.UNTESTED


def test_h3_needs_smart_evader_tracked_less_but_above_45_percent():
    rng = np.random.default_rng(2)
    cells = {("hall", 1.0, "S-R"): rng.uniform(0.8, 0.95, 15).tolist(),
             ("hall", 1.0, "S-S"): rng.uniform(0.5, 0.7, 15).tolist(),
             ("brick", 1.0, "S-R"): rng.uniform(0.8, 0.95, 15).tolist(),
             ("brick", 1.0, "S-S"): rng.uniform(0.1, 0.3, 15).tolist()}
    h3 = report.hypotheses(cells)[2]
    by_map = {row["map"]: row for row in h3["rows"]}
    assert by_map["hall"]["holds"] and by_map["hall"]["tracked_less"]
    assert by_map["brick"]["tracked_less"] and not by_map["brick"]["reasonable"]
    assert h3["summary"]["text"] == "partly (in 1 of 2 cells)"
    assert h3["reasonable_cells"] == {"k": 1, "n": 2}


def test_figures_are_non_empty_png_and_svg(tmp_path):
    write_job(tmp_path, "0", sweep_games(separated("S-R", "R-R", n=5)))
    result = report.write_report(tmp_path)
    for name in ("fig5a_speed_ratio", "fig5b_environment", "fig8_pairing"):
        assert (tmp_path / f"{name}.png").read_bytes().startswith(b"\x89PNG")
        svg = (tmp_path / f"{name}.svg").read_text()
        assert "<svg" in svg and len(svg) > 1000
        assert f"{name}.png" in result["outputs"]
    json.loads((tmp_path / "report.json").read_text())


def test_cli_writes_the_report_into_out(tmp_path):
    write_job(tmp_path / "sweep", "0", sweep_games(separated("S-R", "R-R", n=5)))
    proc = subprocess.run([sys.executable, "-m", "pegame.report", str(tmp_path / "sweep"),
                           "--out", str(tmp_path / "out")],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "H1: holds" in proc.stdout
    names = {p.name for p in (tmp_path / "out").iterdir()}
    assert {"table1.md", "table1.csv", "table1.tex", "hypotheses.md", "report.json",
            "fig8_pairing.svg"} <= names
    bad = subprocess.run([sys.executable, "-m", "pegame.report", str(tmp_path / "nowhere")],
                         capture_output=True, text=True, timeout=120)
    assert bad.returncode == 2 and "not a directory" in bad.stderr
