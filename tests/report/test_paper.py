"""--paper: the packaged paper's Table 1 beside ours, with the difference, on known data."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

from pegame import report
from pegame.report.paper import paper_table
from pegame.testing.reports import config_job, game, table_rows, write_job

DOCS_COPY = Path(__file__).resolve().parents[2] / "docs" / "paper_conditions" / "paper_table1.csv"


def test_the_packaged_table_is_the_papers_27_cells_and_the_docs_read_it():
    table = paper_table()
    assert len(table) == 27
    assert {m for m, _, _ in table} == {"hall", "enclosed", "brick"}
    assert {r for _, r, _ in table} == {0.5, 1.0, 2.0}
    assert {p for _, _, p in table} == {"R-R", "S-R", "S-S"}
    assert table[("hall", 1.0, "S-R")] == 0.7847 and table[("brick", 0.5, "R-R")] == 0.3426
    with DOCS_COPY.open() as handle:
        docs = {
            (r["map"], float(r["speed_ratio"]), r["pairing"]): float(r["paper_mean"])
            for r in csv.DictReader(handle)
        }
    assert docs == table


@pytest.mark.slow
def test_paper_writes_ours_the_papers_and_the_difference_and_lists_what_it_leaves_out(
    tmp_path, capsys
):
    games = [game("hall", 1.0, "S-R", s, 0.7) for s in range(4)]
    games += [game("hall", 1.0, "R-R", s, r) for s, r in enumerate((0.1, 0.2, 0.3, 0.4))]
    games += [game("hall", 1.0, "R-S", s, 0.05) for s in range(4)]
    games += [game("office", 1.0, "S-R", s, 0.5) for s in range(4)]
    write_job(tmp_path, "0", games)
    assert report.main([str(tmp_path), "--paper"]) == 0
    assert "vs paper: 2 cells, mean absolute difference" in capsys.readouterr().out
    result = report.write_report(tmp_path, paper=True)
    rows = {r["pairing"]: r for r in result["vs_paper"]["rows"]}
    assert sorted(rows) == ["R-R", "S-R"]
    assert rows["S-R"]["mean"] == 0.7 and rows["S-R"]["paper_mean"] == 0.7847
    assert rows["S-R"]["difference"] == pytest.approx(0.7 - 0.7847)
    assert rows["S-R"]["paper_inside_ci"] is False  # CI [70, 70]
    low, high = rows["R-R"]["ci_low"], rows["R-R"]["ci_high"]
    assert rows["R-R"]["paper_inside_ci"] is (low <= 0.2385 <= high) and low < 0.2385 < high
    (summary,) = result["vs_paper"]["summaries"]
    assert summary["mean_absolute_difference"] == pytest.approx((0.0847 + 0.0115) / 2)
    assert summary["paper_inside_ci"] == 1 and summary["cells"] == 2
    assert result["vs_paper"]["left_out"] == ["hall, v_p/v_e 1, R-S", "office, v_p/v_e 1, S-R"]
    md = (tmp_path / "vs_paper.md").read_text()
    assert table_rows(md)[2:] == [
        ["hall", "1", "R-R", md_cell(rows["R-R"]), "23.85%", difference(rows["R-R"]), "yes"],
        ["hall", "1", "S-R", "70.0% [70.0, 70.0] n=4", "78.47%", "-8.5 pp", "no"],
    ]
    assert "## Left out (not in the paper's Table 1): 2" in md
    assert "- office, v_p/v_e 1, S-R" in md
    (line,) = [
        r for r in csv.DictReader((tmp_path / "vs_paper.csv").open()) if r["pairing"] == "S-R"
    ]
    assert (line["mean"], line["paper_mean"], line["paper_inside_ci"]) == ("0.7", "0.7847", "False")


def md_cell(row):
    """The table's text of a cell's mean, CI and n."""
    low, high = 100 * row["ci_low"], 100 * row["ci_high"]
    return f"{100 * row['mean']:.1f}% [{low:.1f}, {high:.1f}] n={row['n']}"


def difference(row):
    """The table's text of ours - paper."""
    return f"{100 * row['difference']:+.1f} pp"


@pytest.mark.slow
def test_paper_compares_the_tracking_rate_whatever_the_metric(tmp_path):
    measures = [{"mean_distance": d} for d in (1.0, 2.0)]
    config_job(tmp_path, "0", range(2), [0.6, 0.8], measures, **{"env.name": "hall"})
    result = report.write_report(tmp_path, metric="mean_distance", paper=True)
    (row,) = result["vs_paper"]["rows"]
    assert (row["pairing"], row["mean"], row["paper_mean"]) == ("S-R", 0.7, 0.7847)
    assert result["cells"][0]["mean"] == 1.5
