"""Sweep aggregation on synthetic multirun directories with known answers."""

from __future__ import annotations

import csv
import errno
import hashlib
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


# ------------------------------------------------ lines as the jobs write them (with config)

PROVENANCE = {"pegame": "0.3.0", "commit": "4f1c2d9e8a7b6c5d4e3f2a1b0c9d8e7f6a5b4c3d", "dirty": False,
              "python": "3.12.3", "numpy": "2.1.3", "numba": "0.60.0",
              "plugins": {"pegame-pybullet": "0.1.0", "pegame-vision": "0.1.0"}}


def job_config(**settings) -> dict:
    """A resolved job config (no game.seed, game.trials, resume, hydra) with dotted
    ``settings`` applied, e.g. ``job_config(**{"detector.miss_probability": 0.3})``; a value
    None removes the key."""
    config = {
        "game": {"t_max": 20.0, "control_hz": 10.0, "decision_hz": 1.0, "speed_ratio": 1.0},
        "env": {"name": "enclosed", "map": "enclosed.yaml"},
        "sim": {"name": "grid"},
        "detector": {"name": "oracle", "range_noise": 0.0, "miss_probability": 0.0},
        "estimator": {"name": "particle_filter", "n_particles": 2000, "resampler": "systematic"},
        "pursuer": {"name": "smart", "radius": 0.2, "standoff": 1.5},
        "evader": {"name": "random", "radius": 0.25, "v_max": 0.5},
        "recorder": {"name": "none"},
    }
    for key, value in settings.items():
        *parents, leaf = key.split(".")
        node = config
        for parent in parents:
            node = node.setdefault(parent, {})
        if value is None:
            node.pop(leaf, None)
        else:
            node[leaf] = value
    return config


def config_game(seed: int, rate: float, overrides: tuple[str, ...] = (),
                provenance: dict | None = PROVENANCE, kind: str = "game", **settings) -> dict:
    """A game (or failed) line of the contract: today's fields plus config, config_hash,
    overrides and provenance."""
    config = job_config(**settings)
    pursuer, evader = config["pursuer"]["name"], config["evader"]["name"]
    line = {"kind": kind, "seed": seed, "pairing": f"{pursuer[0].upper()}-{evader[0].upper()}",
            "map": config["env"]["name"], "speed_ratio": config["game"]["speed_ratio"],
            "config": config,
            "config_hash": hashlib.sha256(json.dumps(config, sort_keys=True,
                                                     separators=(",", ":")).encode()).hexdigest(),
            "overrides": list(overrides), "provenance": provenance}
    if kind == "failed":
        return {**line, "error": "RuntimeError: boom", "traceback_file": f"failed_{seed}.txt"}
    return {**line, "pursuer": pursuer, "evader": evader, "estimator": config["estimator"]["name"],
            "detector": config["detector"]["name"], "sim": config["sim"]["name"],
            "t_max": config["game"]["t_max"], "control_hz": 10.0, "decision_hz": 1.0,
            "tracking_rate": rate, "visible_rate": rate}


def config_job(root: Path, name: str, seeds: range, rates: list[float], **settings) -> Path:
    """A job of the games ``seeds`` with ``rates``, all of one configuration."""
    overrides = [f"{k}={v}" for k, v in settings.items()]
    return write_job(root, name, [config_game(s, r, tuple(overrides), **settings)
                                  for s, r in zip(seeds, rates)], overrides)


def table_rows(md: str) -> list[list[str]]:
    """The body rows of the first Markdown table, as lists of cell texts."""
    lines = md.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("| "))
    rows = []
    for line in lines[start:]:
        if not line.startswith("|"):
            break
        rows.append([cell.strip() for cell in line.strip("|").split("|")])
    return rows


def test_an_ablation_gives_one_row_per_value_not_one_merged_cell(tmp_path):
    """Regression: two jobs differing only in detector.miss_probability were merged into one
    cell holding only the later job's games."""
    config_job(tmp_path, "0", range(5), [0.9, 0.8, 0.9, 1.0, 0.9], **{"detector.miss_probability": 0.0})
    config_job(tmp_path, "1", range(5), [0.5, 0.4, 0.6, 0.5, 0.5], **{"detector.miss_probability": 0.3})
    result = report.write_report(tmp_path)
    assert result["games"] == 10 and result["factors"] == ["detector.miss_probability"]
    assert [(c["factors"], c["n"]) for c in result["cells"]] == [
        ({"detector.miss_probability": 0.0}, 5), ({"detector.miss_probability": 0.3}, 5)]
    assert [c["mean"] for c in result["cells"]] == pytest.approx([0.9, 0.5])
    assert result["duplicates"]["count"] == 0
    header, _, *body = table_rows((tmp_path / "table1.md").read_text())
    assert header == ["detector.miss_probability", "v_p/v_e", "enclosed S-R"]
    assert [row[:2] for row in body] == [["0", "1"], ["0.3", "1"]]
    assert body[1][2].endswith("n=5")
    rows = list(csv.DictReader((tmp_path / "table1.csv").open()))
    assert [(r["detector.miss_probability"], r["n"]) for r in rows] == [("0.0", "5"), ("0.3", "5")]
    tex = (tmp_path / "table1.tex").read_text()
    assert "\\texttt{detector.miss\\_probability} & $v_p/v_e$" in tex
    assert "\\begin{tabular}{ll c}" in tex


def test_a_sweep_over_the_estimator_is_reported_and_tested_per_estimator(tmp_path):
    rng = np.random.default_rng(3)
    jobs = 0
    for estimator in ("particle_filter", "last_seen"):
        for pursuer, low, high in (("smart", 0.6, 0.9), ("random", 0.1, 0.4)):
            settings = {"estimator.name": estimator, "pursuer.name": pursuer}
            if estimator == "last_seen":  # its own settings: none of the filter's
                settings.update({"estimator.n_particles": None, "estimator.resampler": None})
            if pursuer == "random":
                settings["pursuer.standoff"] = None  # a setting of the smart pursuer only
            config_job(tmp_path, str(jobs), range(8), rng.uniform(low, high, 8).tolist(), **settings)
            jobs += 1
    result = report.write_report(tmp_path)
    assert result["factors"] == ["estimator.name"]
    assert [(c["factors"]["estimator.name"], c["pairing"], c["n"]) for c in result["cells"]] == [
        ("last_seen", "R-R", 8), ("last_seen", "S-R", 8),
        ("particle_filter", "R-R", 8), ("particle_filter", "S-R", 8)]
    h1 = [h for h in result["hypotheses"] if h["id"] == "H1"]
    assert [h["factors"] for h in h1] == [{"estimator.name": "last_seen"},
                                          {"estimator.name": "particle_filter"}]
    assert all(h["summary"]["text"] == "holds (in 1 of 1 cells)" for h in h1)
    md = (tmp_path / "hypotheses.md").read_text()
    assert "## H1 (estimator.name=last_seen): holds (in 1 of 1 cells)" in md
    from pegame.report.cells import group_cells, other_factors, select
    from pegame.report.figures import figures

    games = select(report.load_sweep(tmp_path).records).games
    panels = figures(group_cells(games, other_factors(games)))["fig5a_speed_ratio"].axes
    assert sorted(ax.get_title() for ax in panels) == ["estimator.name=last_seen",
                                                       "estimator.name=particle_filter"]


def test_settings_that_follow_the_map_or_the_pairing_are_no_extra_factor(tmp_path):
    jobs = 0
    for env in ("enclosed", "brick"):
        for pursuer in ("random", "smart"):
            config_job(tmp_path, str(jobs), range(2), [0.5, 0.7], **{
                "env.name": env, "env.map": f"{env}.yaml", "pursuer.name": pursuer,
                "pursuer.standoff": 1.5 if pursuer == "smart" else None})
            jobs += 1
    result = report.write_report(tmp_path)
    assert result["factors"] == [] and len(result["cells"]) == 4
    assert [(c["map"], c["pairing"]) for c in result["cells"]] == [
        ("enclosed", "R-R"), ("enclosed", "S-R"), ("brick", "R-R"), ("brick", "S-R")]
    # a pursuer setting swept within one pairing is a factor of its own
    config_job(tmp_path, str(jobs), range(2), [0.5, 0.7], **{"pursuer.standoff": 2.5})
    assert report.write_report(tmp_path)["factors"] == ["pursuer.standoff"]


def test_duplicates_need_the_same_config_and_seed_and_are_listed(tmp_path):
    config_job(tmp_path, "0", range(3), [0.1, 0.2, 0.3])
    config_job(tmp_path, "1", range(2, 4), [0.9, 0.4])  # seed 2 again: a duplicate
    config_job(tmp_path, "2", range(3), [0.5, 0.5, 0.5], **{"game.t_max": 30.0})  # other config
    result = report.write_report(tmp_path)
    assert result["factors"] == ["game.t_max"]
    assert [c["n"] for c in result["cells"]] == [4, 3]
    assert result["cells"][0]["mean"] == pytest.approx((0.1 + 0.2 + 0.9 + 0.4) / 4)
    (duplicate,) = result["duplicates"]["games"]
    assert result["duplicates"]["count"] == 1
    assert duplicate["seed"] == 2 and duplicate["kept"] == "1 line 1"
    assert duplicate["dropped"] == ["0 line 3"]
    md = (tmp_path / "table1.md").read_text()
    assert "seed 2: kept 1 line 1, dropped 0 line 3" in md


def test_several_sweep_dirs_are_compared_as_one_study(tmp_path):
    config_job(tmp_path / "a", "0", range(4), [0.9] * 4)
    config_job(tmp_path / "b", "0", range(4), [0.3] * 4, **{"estimator.name": "last_seen"})
    out = tmp_path / "study"
    result = report.write_report([tmp_path / "a", tmp_path / "b"], out)
    assert result["factors"] == ["estimator.name"] and [c["n"] for c in result["cells"]] == [4, 4]
    assert result["sweep_dirs"] == [str(tmp_path / "a"), str(tmp_path / "b")]
    assert (out / "table1.md").exists() and not (tmp_path / "a" / "table1.md").exists()
    with pytest.raises(report.ReportError, match="needs an output directory"):
        report.write_report([tmp_path / "a", tmp_path / "b"])
    proc = subprocess.run([sys.executable, "-m", "pegame.report", str(tmp_path / "a"),
                           str(tmp_path / "b"), "--out", str(tmp_path / "cli")],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "8 games" in proc.stdout and "H1 (estimator.name=last_seen)" in proc.stdout


def test_legacy_lines_load_beside_lines_with_config(tmp_path):
    legacy = [game("enclosed", 1.0, "S-R", s, 0.2) for s in range(3)]  # estimator last_seen
    write_job(tmp_path, "0", legacy)
    write_job(tmp_path, "1", [{k: v for k, v in r.items() if k != "estimator"}
                              for r in [game("enclosed", 1.0, "S-R", s, 0.4) for s in range(2)]])
    config_job(tmp_path, "2", range(3), [0.8] * 3, **{"game.t_max": 90.0})  # particle_filter
    result = report.write_report(tmp_path)
    assert result["factors"] == ["estimator.name"]
    assert [(c["factors"]["estimator.name"], c["n"]) for c in result["cells"]] == [
        ("last_seen", 3), ("particle_filter", 3), (None, 2)]
    versions = [v["version"] for v in result["provenance"]["code_versions"]]
    assert {"pegame": "0.3.0", "commit": PROVENANCE["commit"], "dirty": False} in versions
    assert None in versions  # the old lines carry no provenance
    assert "| – | 1 |" in (tmp_path / "table1.md").read_text()


@pytest.mark.parametrize("field, value", [
    ("seed", "seven"), ("tracking_rate", "high"), ("tracking_rate", 1.5), ("speed_ratio", True),
    ("config", [1, 2]), ("config_hash", 7), ("overrides", "env=hall"), ("provenance", "0.3"),
    ("map", 3),
])
def test_a_line_with_a_wrong_type_is_skipped_and_listed(tmp_path, field, value):
    bad = {**config_game(9, 0.5), field: value}
    write_job(tmp_path, "0", [config_game(0, 0.5), bad, config_game(1, 0.7)])
    result = report.write_report(tmp_path)
    assert result["games"] == 2 and result["cells"][0]["n"] == 2
    (skipped,) = result["skipped_lines"]
    assert skipped["line"] == 2 and f"'{field}' is {value!r}" in skipped["reason"]
    assert "0/results.jsonl line 2: game record with a wrong type" in (tmp_path / "table1.md").read_text()


def test_invalid_cells_are_listed_and_the_others_reported(tmp_path):
    config_job(tmp_path, "0", range(3), [0.5, 0.6, 0.7])
    job = tmp_path / "1"
    (job / ".hydra").mkdir(parents=True)
    error = "Invalid value for 'detector.miss_probability': 1.5. Allowed: a number in [0, 1)."
    (job / "results.jsonl").write_text(json.dumps({
        "kind": "invalid", "error": error, "overrides": ["detector.miss_probability=1.5"]}) + "\n")
    result = report.write_report(tmp_path)
    assert result["games"] == 3 and [c["n"] for c in result["cells"]] == [3]
    (failed,) = result["failed_cells"]
    assert failed["job"] == "1" and failed["error"] == error
    assert result["unfinished_jobs"] == [] and result["missing_jobs"] == []
    md = (tmp_path / "table1.md").read_text()
    assert "### Failed cells (invalid configuration): 1" in md
    assert f"- job 1: overrides detector.miss_probability=1.5: {error}" in md


def test_failed_games_with_config_are_closed_only_by_the_same_configuration(tmp_path):
    write_job(tmp_path, "0", [config_game(4, 0.0, kind="failed"),
                              config_game(5, 0.0, kind="failed", **{"game.t_max": 30.0})])
    config_job(tmp_path, "1", range(4, 6), [0.5, 0.6])  # t_max 20: closes seed 4 only
    result = report.write_report(tmp_path)
    assert [(f["seed"], f["config"]["game"]["t_max"]) for f in result["failed_games"]] == [(5, 30.0)]


def test_a_cell_mixing_code_versions_or_config_hashes_is_warned(tmp_path, caplog):
    config_job(tmp_path, "0", range(3), [0.5] * 3)
    later = {**PROVENANCE, "commit": "0" * 40, "dirty": True}
    write_job(tmp_path, "1", [config_game(s, 0.6, provenance=later) for s in range(3, 5)])
    # a newer pegame added a setting: a key the older configs lack, another config hash
    write_job(tmp_path, "2", [config_game(9, 0.7, **{"detector.latency": 0.0})])
    with caplog.at_level(logging.WARNING, logger="pegame.report"):
        result = report.write_report(tmp_path)
    assert result["factors"] == [] and [c["n"] for c in result["cells"]] == [6]
    (warning,) = result["provenance"]["warnings"]
    assert "enclosed, v_p/v_e 1, S-R mixes code versions and config hashes" in warning
    assert "2 code versions, 2 config hashes" in warning
    assert len(result["provenance"]["config_hashes"]) == 2
    assert len(result["provenance"]["code_versions"]) == 2
    assert sorted(v["dirty"] for v in result["cells"][0]["code_versions"]) == [False, True]
    md = (tmp_path / "table1.md").read_text()
    assert f"- WARNING: {warning}" in md and "commit 000000000000 (dirty)" in md
    assert warning in caplog.text


def test_a_report_that_cannot_be_written_is_one_clear_error(tmp_path, monkeypatch):
    config_job(tmp_path / "sweep", "0", range(2), [0.5, 0.6])
    (tmp_path / "file").write_text("not a directory")
    with pytest.raises(report.ReportError, match="Cannot write the report into"):
        report.write_report(tmp_path / "sweep", tmp_path / "file" / "out")
    proc = subprocess.run([sys.executable, "-m", "pegame.report", str(tmp_path / "sweep"),
                           "--out", str(tmp_path / "file" / "out")],
                          capture_output=True, text=True, timeout=120)
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
