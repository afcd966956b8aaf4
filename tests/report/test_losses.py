"""The loss-cause table and stacked bars: per cell means of the games' loss_causes."""

from __future__ import annotations

import csv
import json

import pytest

from pegame import report
from pegame.config import compose
from pegame.game import Game
from pegame.losses import CAUSES
from pegame.report.cells import Cell
from pegame.report.losses import cell_losses, losses_figure, losses_table
from pegame.testing.reports import game, write_job


def causes(**given: tuple[int, int, float, float | None]) -> dict:
    """A game's loss_causes: cause=(count, reacquired, time_lost_s, mean_reacquire_s)."""
    zero = (0, 0, 0.0, None)
    return {
        cause: dict(
            zip(("count", "reacquired", "time_lost_s", "mean_reacquire_s"), given.get(cause, zero))
        )
        for cause in CAUSES
    }


def with_causes(seed: int, lost: dict | None, ratio: float = 1.0) -> dict:
    record = game("hall", ratio, "S-R", seed, 0.5)
    if lost is not None:
        record["loss_causes"] = lost
    return record


GAMES = [
    with_causes(0, causes(occluded=(3, 2, 12.0, 4.0), bearing=(1, 1, 2.0, 2.0))),
    with_causes(1, causes(occluded=(1, 0, 30.0, None), missed=(4, 4, 2.0, 0.5))),
    with_causes(2, None),  # an old line without loss causes
]


def test_a_cells_row_is_the_mean_per_game_and_the_pooled_time_to_reacquire():
    row = cell_losses(Cell("hall", 1.0, "S-R", {}, GAMES))
    assert row["games"] == 2
    assert row["losses_per_game"] == 9 / 2
    assert row["occluded"] == {
        "count_per_game": 2.0,
        "time_lost_per_game_s": 21.0,
        "share": 4 / 9,
        "mean_reacquire_s": 4.0,  # two reacquired losses of 4 s; the open one has none
    }
    assert row["missed"]["mean_reacquire_s"] == 0.5
    assert row["bearing"]["count_per_game"] == 0.5
    assert row["far"] == {
        "count_per_game": 0.0,
        "time_lost_per_game_s": 0.0,
        "share": 0.0,
        "mean_reacquire_s": None,
    }
    assert sum(row[c]["share"] for c in CAUSES) == pytest.approx(1.0)


def test_the_report_writes_the_table_and_the_figure_when_games_carry_loss_causes(tmp_path):
    lines = [*GAMES, with_causes(0, causes(near=(2, 2, 1.0, 0.5)), ratio=2.0)]
    write_job(tmp_path, "0", lines)
    result = report.write_report(tmp_path, tmp_path / "out")
    out = tmp_path / "out"
    assert {"losses.md", "losses.csv", "loss_causes.png", "loss_causes.svg"} <= set(
        result["outputs"]
    )
    stored = json.loads((out / "report.json").read_text())["loss_causes"]
    assert [(r["speed_ratio"], r["games"]) for r in stored["rows"]] == [(1.0, 2), (2.0, 1)]
    rows = list(csv.DictReader((out / "losses.csv").open()))
    assert [float(r["losses_per_game"]) for r in rows] == [4.5, 2.0]
    assert float(rows[0]["occluded_time_lost_per_game_s"]) == 21.0
    assert rows[0]["far_mean_reacquire_s"] == ""
    assert float(rows[1]["near_share"]) == 1.0
    text = (out / "losses.md").read_text()
    assert "| hall | 1 | S-R | 2 | 4.50 | 2.00 (1.0 s) |" in text  # missed: 4 losses over 2 games


def test_the_stacked_bars_are_the_tables_means():
    table = losses_table([Cell("hall", 1.0, "S-R", {}, GAMES)])
    fig = losses_figure(table)
    top, bottom = fig.axes[:2]
    counts = [bar.get_height() for bar in top.patches]
    times = [bar.get_height() for bar in bottom.patches]
    row = table["rows"][0]
    assert counts == [row[c]["count_per_game"] for c in CAUSES]  # one segment per cause
    assert times == [row[c]["time_lost_per_game_s"] for c in CAUSES]
    # stacked: each segment starts where the one before ends
    bottoms = [bar.get_y() for bar in top.patches]
    assert bottoms[1:] == pytest.approx([sum(counts[: k + 1]) for k in range(len(counts) - 1)])


def test_no_game_with_loss_causes_writes_no_loss_files(tmp_path):
    write_job(tmp_path, "0", [with_causes(0, None), with_causes(1, None)])
    result = report.write_report(tmp_path)
    assert "losses.md" not in result["outputs"] and "loss_causes" not in result


def test_a_played_games_loss_causes_reach_the_table(tmp_path):
    result = (
        Game(compose(["recorder=none", "game.t_max=20", "pursuer=random", "evader=random"]))
        .play(tmp_path)
        .result
    )
    write_job(tmp_path, "0", [{"kind": "game", **result}])
    (row,) = report.write_report(tmp_path)["loss_causes"]["rows"]
    played = result["loss_causes"]
    assert row["losses_per_game"] == sum(c["count"] for c in played.values()) > 0
    for cause in CAUSES:
        assert row[cause]["time_lost_per_game_s"] == played[cause]["time_lost_s"]


def test_the_command_line_names_the_loss_files(tmp_path, capsys):
    write_job(tmp_path / "sweep", "0", GAMES)
    assert report.main([str(tmp_path / "sweep"), "--out", str(tmp_path / "out")]) == 0
    assert "the loss causes per cell -> losses.md, loss_causes.png" in capsys.readouterr().out
    assert (tmp_path / "out" / "loss_causes.svg").is_file()
