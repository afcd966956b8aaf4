"""pegame_vision.profile: detection probability per bin of each variable, from frames."""

from __future__ import annotations

import pytest

pytest.importorskip("cv2")

from pegame_vision.profile import profile_rows


def record(range_m, found, seen=True, reported=None, error=None):
    return {
        "range": range_m,
        "bearing": 0.05,
        "visible": 0.8,
        "lateral_speed": 0.2,
        "seen": seen,
        "found": found,
        "reported": found if reported is None else reported,
        "error": error,
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
