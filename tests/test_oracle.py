"""Tests for the oracle detector: visibility, the synthetic pinhole box, misses and noise."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pegame.api import Context
from pegame.detectors.oracle import OracleDetector
from pegame.grid import FREE, OCCUPIED, OccupancyGrid
from pegame.registry import make_config
from pegame.types import Body, Camera, Pose, SensorFrame

CAMERA = Camera()  # pi/3 FOV, 0.3-5 m, 640 x 480 px
EVADER = Body(radius=0.25, v_max=0.5, w_max=1.8)


def grid_with_a_wall():
    """8 m x 6 m of 0.1 m cells with a wall at x in [5.0, 5.1) m for y in [2, 4) m."""
    data = np.full((60, 80), FREE, dtype=np.int8)
    data[20:40, 50] = OCCUPIED
    return OccupancyGrid(data, 0.1)


def detector(**params):
    context = Context(grid_with_a_wall(), Body(0.2, 0.5, 1.8), EVADER, CAMERA, 0.1, 1.0)
    config = make_config("detector", OracleDetector, params)
    return OracleDetector(config, context, np.random.default_rng(0))


def frame(camera: Pose, evader: Pose | None):
    return SensorFrame(time=0.0, camera_pose=camera, evader_truth=evader)


def test_a_centred_evader_gives_a_centred_box_and_its_position():
    camera, evader = Pose(1.0, 3.0, 0.0), Pose(3.0, 3.0)
    seen = detector().detect(frame(camera, evader))
    assert seen is not None
    assert seen.box.center_x == pytest.approx(CAMERA.image_width / 2)
    assert seen.depth == pytest.approx(2.0)
    assert seen.position == pytest.approx((3.0, 3.0))
    # The box spans the evader's width as a pinhole projects it.
    half = math.asin(EVADER.radius / 2.0)
    assert seen.box.w == pytest.approx(2 * CAMERA.focal_px * math.tan(half))


def test_a_box_left_of_centre_means_an_evader_left_of_the_axis():
    seen = detector().detect(frame(Pose(1.0, 3.0, 0.0), Pose(3.0, 3.5)))
    assert seen is not None and seen.box.center_x < CAMERA.image_width / 2
    # Off the axis the box centre is not quite the centre's bearing: a small error.
    assert seen.position == pytest.approx((3.0, 3.5), abs=0.02)


@pytest.mark.parametrize(
    "evader",
    [
        Pose(6.0, 3.0),  # behind the wall
        Pose(1.2, 3.0),  # closer than near
        Pose(1.0, 5.0),  # outside the field of view
        None,  # no ground truth
    ],
)
def test_an_evader_out_of_view_is_not_detected(evader):
    assert detector().detect(frame(Pose(1.0, 3.0, 0.0), evader)) is None


def test_misses_and_noise_follow_the_config_and_draw_every_time():
    camera, evader = Pose(1.0, 3.0, 0.0), Pose(3.0, 3.0)
    noisy = detector(range_noise=0.1)
    depths = [noisy.detect(frame(camera, evader)).depth for _ in range(200)]
    assert np.std(depths) == pytest.approx(0.1, rel=0.3)
    assert np.mean(depths) == pytest.approx(2.0, abs=0.05)
    # Two numbers are drawn per visible evader, detected or missed, so the stream after a
    # miss is the stream after a detection.
    sure, never = detector(), detector(miss_probability=1.0)
    assert never.detect(frame(camera, evader)) is None
    assert sure.detect(frame(camera, evader)) is not None
    assert never.rng.random() == sure.rng.random()
