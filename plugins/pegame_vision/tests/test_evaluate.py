"""pegame_vision.evaluate: frames scored against the reference, named by the detector."""

from __future__ import annotations

import pytest

pytest.importorskip("cv2")

from pegame.types import BoundingBox, Detection, Pose
from pegame_vision.evaluate import _score


def seen(x: float) -> Detection:
    return Detection(BoundingBox(x, 0.0, 10.0, 10.0), 2.0, (1.0, 0.0))


def test_scores_are_named_by_the_detector_and_time_is_per_frame():
    evader = Pose(1.0, 0.0)
    rows = [
        ("positive", seen(0.0), seen(0.0), evader),  # right (IoU 1)
        ("positive", seen(0.0), seen(8.0), evader),  # wrong place (IoU 0.11)
        ("positive", seen(0.0), None, evader),  # missed
        ("negative", None, seen(50.0), evader),  # a false detection
        ("ignored", seen(0.0), seen(30.0), evader),  # neither
    ]
    scores = _score(rows, 0.5, [0.010, 0.030, 0.020], [0.001, 0.003, 0.002], "person")
    assert scores["person_recall"] == pytest.approx(1 / 3)
    assert scores["person_precision"] == pytest.approx(1 / 3)  # 1 right of 3 judged
    assert scores["person_position_error_m"] == pytest.approx(0.0)
    assert scores["person_latency_ms"] == pytest.approx(20.0)
    assert scores["person_cpu_ms"] == pytest.approx(2.0)
    assert (scores["positives"], scores["negatives"], scores["ignored"]) == (3, 1, 1)
