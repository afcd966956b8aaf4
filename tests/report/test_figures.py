"""A numeric factor drawn as a curve: the lines' points, their CIs and the PNG's pixels."""

from __future__ import annotations

import io

import numpy as np
import pytest
from matplotlib.image import imread

from pegame import report
from pegame.report.cells import group_cells, numeric_factors, other_factors, select
from pegame.report.figures import figure_bytes, figures
from pegame.report.measures import MEASURES
from pegame.testing.reports import config_job

PARTICLES = (2000, 100, 500)
# (pursuer, evader) -> per n_particles the games' tracking rates
RATES = {
    ("smart", "random"): {100: [0.5, 0.7], 500: [0.6, 0.8], 2000: [0.9, 0.9]},
    ("random", "random"): {100: [0.1, 0.3], 500: [0.2, 0.2], 2000: [0.3, 0.5]},
}


def particle_sweep(root, extra=None):
    """Two pairings x three particle counts, two games each, in the enclosed room."""
    job = 0
    for (pursuer, evader), by_n in RATES.items():
        for n in PARTICLES:
            settings = {
                "pursuer.name": pursuer,
                "evader.name": evader,
                "estimator.n_particles": n,
                **(extra or {}),
            }
            config_job(root, str(job), range(2), by_n[n], **settings)
            job += 1


def cells_of(root):
    games = select(report.load_sweep(root).records).games
    return group_cells(games, other_factors(games))


def test_numeric_factors_are_those_with_a_number_in_every_cell(tmp_path):
    particle_sweep(tmp_path / "a")
    kalman = {"estimator.name": "kalman", "estimator.n_particles": None}  # no such setting
    config_job(tmp_path / "a", "9", range(2), [0.5, 0.5], **kalman)
    assert numeric_factors(cells_of(tmp_path / "a")) == []
    particle_sweep(tmp_path / "b")
    assert numeric_factors(cells_of(tmp_path / "b")) == ["estimator.n_particles"]


@pytest.mark.slow
def test_a_numeric_factor_is_a_curve_of_means_with_their_cis(tmp_path):
    particle_sweep(tmp_path)
    cells = cells_of(tmp_path)
    described = [c.summary() for c in cells]
    drawn = figures(cells, described)
    assert sorted(drawn) == [
        "curve_estimator.n_particles",
        "fig5a_speed_ratio",
        "fig5b_environment",
        "fig8_pairing",
    ]
    (ax,) = [ax for ax in drawn["curve_estimator.n_particles"].axes if ax.get_visible()]
    assert ax.get_title() == "Enclosed Room" and ax.get_xscale() == "log"
    lines = {line.get_label(): line for line in ax.get_lines() if line.get_marker() == "o"}
    assert sorted(lines) == ["v_p/v_e 1, R-R", "v_p/v_e 1, S-R"]
    for label, pairing in (
        ("v_p/v_e 1, S-R", ("smart", "random")),
        ("v_p/v_e 1, R-R", ("random", "random")),
    ):
        x, y = lines[label].get_data()
        assert list(x) == [100, 500, 2000]
        expected = [100 * np.mean(RATES[pairing][n]) for n in (100, 500, 2000)]
        assert y == pytest.approx(expected)
    bars = [c for c in ax.collections if len(c.get_segments()) == 3]
    intervals = sorted(
        (seg[0][0], seg[0][1], seg[1][1]) for bar in bars for seg in bar.get_segments()
    )
    expected_bars = [
        (c.factors["estimator.n_particles"], 100 * d["ci_low"], 100 * d["ci_high"])
        for c, d in zip(cells, described)
    ]
    assert np.allclose(np.array(intervals), np.array(sorted(expected_bars)))


@pytest.mark.slow
def test_the_curve_is_drawn_in_the_png_in_both_lines_colours(tmp_path):
    particle_sweep(tmp_path)
    cells = cells_of(tmp_path)
    measure = MEASURES["tracking_rate"]
    fig = figures(cells, [c.summary() for c in cells], measure)["curve_estimator.n_particles"]
    pixels = imread(io.BytesIO(figure_bytes(fig, "png")))[..., :3]
    for colour in ("#1f77b4", "#ff7f0e"):  # C0, C1: one per line
        rgb = np.array([int(colour[i : i + 2], 16) / 255 for i in (1, 3, 5)])
        assert np.sum(np.all(np.abs(pixels - rgb) < 0.02, axis=-1)) > 500


@pytest.mark.slow
def test_the_report_writes_the_curve_of_the_chosen_measure(tmp_path):
    particle_sweep(tmp_path)
    result = report.write_report(tmp_path, metric="visible_rate")
    assert "curve_estimator.n_particles_visible_rate.png" in result["outputs"]
    assert (
        (tmp_path / "curve_estimator.n_particles_visible_rate.svg")
        .read_text()
        .count("visible rate")
    )


def test_a_curve_of_a_measure_no_game_defines_has_no_lines_and_no_legend(tmp_path):
    particle_sweep(tmp_path)
    cells = cells_of(tmp_path)
    handoffs = MEASURES["handoffs"]
    described = [c.summary(handoffs.name) for c in cells]
    fig = figures(cells, described, handoffs)["curve_estimator.n_particles"]
    assert fig.legends == [] and all(not ax.get_lines() for ax in fig.axes)
