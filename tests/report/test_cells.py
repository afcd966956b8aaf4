"""A sweep's cells are its configurations: factors, duplicates, several sweep dirs, old
lines, failed games and provenance warnings."""

from __future__ import annotations

import csv
import logging
import subprocess
import sys

import numpy as np
import pytest
import yaml

from pegame import report
from pegame.testing.reports import PROVENANCE, config_game, config_job, game, table_rows, write_job


def test_an_ablation_gives_one_row_per_value_not_one_merged_cell(tmp_path):
    """Regression: two jobs differing only in detector.miss_probability were merged into one
    cell holding only the later job's games."""
    config_job(
        tmp_path, "0", range(5), [0.9, 0.8, 0.9, 1.0, 0.9], **{"detector.miss_probability": 0.0}
    )
    config_job(
        tmp_path, "1", range(5), [0.5, 0.4, 0.6, 0.5, 0.5], **{"detector.miss_probability": 0.3}
    )
    result = report.write_report(tmp_path)
    assert result["games"] == 10
    assert result["factors"] == ["detector.miss_probability"]
    assert [(c["factors"], c["n"]) for c in result["cells"]] == [
        ({"detector.miss_probability": 0.0}, 5),
        ({"detector.miss_probability": 0.3}, 5),
    ]
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
            config_job(
                tmp_path, str(jobs), range(8), rng.uniform(low, high, 8).tolist(), **settings
            )
            jobs += 1
    result = report.write_report(tmp_path)
    assert result["factors"] == ["estimator.name"]
    assert [(c["factors"]["estimator.name"], c["pairing"], c["n"]) for c in result["cells"]] == [
        ("last_seen", "R-R", 8),
        ("last_seen", "S-R", 8),
        ("particle_filter", "R-R", 8),
        ("particle_filter", "S-R", 8),
    ]
    h1 = [h for h in result["hypotheses"] if h["id"] == "H1"]
    assert [h["factors"] for h in h1] == [
        {"estimator.name": "last_seen"},
        {"estimator.name": "particle_filter"},
    ]
    assert all(h["summary"]["text"] == "holds (in 1 of 1 cells)" for h in h1)
    md = (tmp_path / "hypotheses.md").read_text()
    assert "## H1 (estimator.name=last_seen): holds (in 1 of 1 cells)" in md
    from pegame.report.cells import group_cells, other_factors, select
    from pegame.report.figures import box_figures

    games = select(report.load_sweep(tmp_path).records).games
    panels = box_figures(group_cells(games, other_factors(games)))["fig5a_speed_ratio"].axes
    assert sorted(ax.get_title() for ax in panels) == [
        "estimator.name=last_seen",
        "estimator.name=particle_filter",
    ]


@pytest.mark.slow
def test_settings_that_follow_the_map_or_the_pairing_are_no_extra_factor(tmp_path):
    jobs = 0
    for env in ("enclosed", "brick"):
        for pursuer in ("random", "smart"):
            config_job(
                tmp_path,
                str(jobs),
                range(2),
                [0.5, 0.7],
                **{
                    "env.name": env,
                    "env.map": f"{env}.yaml",
                    "pursuer.name": pursuer,
                    "pursuer.standoff": 1.5 if pursuer == "smart" else None,
                },
            )
            jobs += 1
    result = report.write_report(tmp_path)
    assert result["factors"] == [] and len(result["cells"]) == 4
    assert [(c["map"], c["pairing"]) for c in result["cells"]] == [
        ("enclosed", "R-R"),
        ("enclosed", "S-R"),
        ("brick", "R-R"),
        ("brick", "S-R"),
    ]
    # a pursuer setting swept within one pairing is a factor of its own
    config_job(tmp_path, str(jobs), range(2), [0.5, 0.7], **{"pursuer.standoff": 2.5})
    assert report.write_report(tmp_path)["factors"] == ["pursuer.standoff"]


def test_duplicate_games_count_once_and_the_later_line_wins(tmp_path):
    write_job(
        tmp_path,
        "0",
        [
            game("hall", 1.0, "R-R", 0, 0.1),
            game("hall", 1.0, "R-R", 1, 0.2),
            game("hall", 1.0, "R-R", 0, 0.3),
        ],
    )
    write_job(tmp_path, "10", [game("hall", 1.0, "R-R", 1, 0.5)])
    write_job(tmp_path, "2", [game("hall", 1.0, "R-R", 1, 0.4)])
    (row,) = report.write_report(tmp_path)["cells"]
    assert row["n"] == 2 and row["mean"] == pytest.approx((0.3 + 0.5) / 2)


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


@pytest.mark.slow
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
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "pegame.report",
            str(tmp_path / "a"),
            str(tmp_path / "b"),
            "--out",
            str(tmp_path / "cli"),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    assert "8 games" in proc.stdout and "H1 (estimator.name=last_seen)" in proc.stdout
    proc = subprocess.run(
        [sys.executable, "-m", "pegame.report", str(tmp_path / "a"), str(tmp_path / "b")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 2 and "several sweep directories need --out" in proc.stderr


def test_failed_games_are_listed_unless_a_later_run_finished_them(tmp_path):
    failed = [
        {
            "kind": "failed",
            "seed": s,
            "pairing": "S-S",
            "map": "brick",
            "speed_ratio": 2.0,
            "error": f"SpawnError: no valid spawn {s}",
            "traceback_file": f"failed_{s}.txt",
        }
        for s in (4, 5)
    ]
    write_job(tmp_path, "0", [game("brick", 2.0, "S-S", 3, 0.4), *failed])
    write_job(tmp_path, "1", [game("brick", 2.0, "S-S", 5, 0.6)])
    result = report.write_report(tmp_path)
    assert [(f["seed"], f["job"]) for f in result["failed_games"]] == [(4, "0")]
    md = (tmp_path / "table1.md").read_text()
    assert "SpawnError: no valid spawn 4 (traceback: 0/failed_4.txt)" in md
    assert "no valid spawn 5" not in md
    assert result["cells"][0]["n"] == 2


def test_failed_games_with_config_are_closed_only_by_the_same_configuration(tmp_path):
    write_job(
        tmp_path,
        "0",
        [
            config_game(4, 0.0, kind="failed"),
            config_game(5, 0.0, kind="failed", **{"game.t_max": 30.0}),
        ],
    )
    config_job(tmp_path, "1", range(4, 6), [0.5, 0.6])  # t_max 20: closes seed 4 only
    result = report.write_report(tmp_path)
    assert [(f["seed"], f["config"]["game"]["t_max"]) for f in result["failed_games"]] == [
        (5, 30.0)
    ]


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


@pytest.mark.slow
def test_legacy_lines_load_beside_lines_with_config(tmp_path):
    legacy = [game("enclosed", 1.0, "S-R", s, 0.2) for s in range(3)]  # estimator last_seen
    write_job(tmp_path, "0", legacy)
    write_job(
        tmp_path,
        "1",
        [
            {k: v for k, v in r.items() if k != "estimator"}
            for r in [game("enclosed", 1.0, "S-R", s, 0.4) for s in range(2)]
        ],
    )
    config_job(tmp_path, "2", range(3), [0.8] * 3, **{"game.t_max": 90.0})  # particle_filter
    result = report.write_report(tmp_path)
    assert result["factors"] == ["estimator.name"]
    assert [(c["factors"]["estimator.name"], c["n"]) for c in result["cells"]] == [
        ("last_seen", 3),
        ("particle_filter", 3),
        (None, 2),
    ]
    versions = [v["version"] for v in result["provenance"]["code_versions"]]
    assert {"pegame": "0.3.0", "commit": PROVENANCE["commit"], "dirty": False} in versions
    assert None in versions  # the old lines carry no provenance
    assert "| – | 1 |" in (tmp_path / "table1.md").read_text()


def test_old_lines_take_the_config_their_job_kept_in_hydra(tmp_path):
    """Lines written before they carried ``config`` are told apart by .hydra/config.yaml."""
    for name, miss in (("0", 0.0), ("1", 0.3)):
        job = write_job(
            tmp_path, name, [game("enclosed", 1.0, "S-R", s, 0.9 - miss) for s in range(5)]
        )
        config = {
            "game": {"seed": 0, "trials": 5, "t_max": 90.0, "speed_ratio": 1.0},
            "env": {"name": "enclosed"},
            "detector": {"name": "oracle", "miss_probability": miss},
            "resume": name == "1",
        }  # seed, trials and resume are no part of the configuration
        (job / ".hydra" / "config.yaml").write_text(yaml.safe_dump(config))
    result = report.write_report(tmp_path)
    assert result["factors"] == ["detector.miss_probability"]
    assert [(c["factors"]["detector.miss_probability"], c["n"]) for c in result["cells"]] == [
        (0.0, 5),
        (0.3, 5),
    ]
