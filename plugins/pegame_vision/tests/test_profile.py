"""pegame_vision.profile: detection probability per bin of each variable, from frames."""

from __future__ import annotations

import pytest

pytest.importorskip("cv2")

from pegame_vision.profile import profile_rows


def record(range_m, found, seen=True, reported=None, error=None, along=None):
    return {
        "range": range_m,
        "bearing": 0.05,
        "visible": 0.8,
        "lateral_speed": 0.2,
        "seen": seen,
        "found": found,
        "reported": found if reported is None else reported,
        "error": error,
        "along": along,
        "across": None if along is None else 0.0,
    }


def test_each_bin_holds_the_fraction_found_of_the_frames_seen_in_it():
    records = [
        record(0.5, True, error=0.1),
        record(0.7, False),
        record(3.5, True, error=0.3),
        record(9.0, False, seen=False, reported=True),  # a false detection
        record(9.0, False, seen=False),
    ]
    rows = {(row[0], row[1]): row[3:] for row in profile_rows(records, [0.002, 0.004])}
    assert rows[("range", 0.0)] == (2, 0.5)
    assert rows[("range", 1.0)] == (0, None)
    assert rows[("range", 3.0)] == (1, 1.0)
    assert rows[("bearing", 0.0)] == (3, pytest.approx(2 / 3))
    assert rows[("false_detection", "")] == (2, 0.5)
    assert rows[("position_error_m", "")] == (2, pytest.approx(0.2))
    assert rows[("cpu_ms", "")] == (2, pytest.approx(3.0))


def test_any_detection_counts_as_a_hit_with_match_any_and_its_error_is_split():
    records = [
        record(0.5, True, error=0.1, along=0.1),
        record(0.7, False, reported=True, error=0.5, along=-0.3),  # reported, IoU < 0.5
        record(0.8, False),
    ]
    found = {(row[0], row[1]): row[3:] for row in profile_rows(records, [0.001])}
    assert found[("range", 0.0)] == (3, pytest.approx(1 / 3))
    assert found[("error_along_mean_m", "")] == (1, pytest.approx(0.1))
    rows = {(row[0], row[1]): row[3:] for row in profile_rows(records, [0.001], "reported")}
    assert rows[("range", 0.0)] == (3, pytest.approx(2 / 3))
    assert rows[("error_along_mean_m", "")] == (2, pytest.approx(-0.1))
    assert rows[("error_along_std_m", "")] == (2, pytest.approx(0.2))
    assert rows[("error_across_std_m", "")] == (2, pytest.approx(0.0))
