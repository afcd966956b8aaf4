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


def todays_detect(det: OracleDetector, frame: SensorFrame):
    """The oracle's detection before the perception model (its code at the time), as the
    reference that the model with every part off must reproduce bit for bit."""
    from pegame.types import BoundingBox, Detection
    from pegame.visibility import in_view

    cam, evader = frame.camera_pose, frame.evader_truth
    camera, cfg = det.context.camera, det.config
    if evader is None or not in_view(det.context.grid, camera, cam, (evader.x, evader.y)):
        return None
    miss, noise = det.rng.random(), det.rng.normal(0.0, 1.0)
    if miss < cfg.miss_probability:
        return None
    distance = cam.distance_to(evader)
    bearing = math.atan2(evader.y - cam.y, evader.x - cam.x) - cam.theta
    bearing = math.remainder(bearing, 2 * math.pi)
    half = math.asin(min(1.0, det.context.evader.radius / distance))
    left = max(0.0, camera.column_of(bearing + half))
    right = min(float(camera.image_width), camera.column_of(bearing - half))
    depth = max(camera.near, distance * math.cos(bearing) + cfg.range_noise * noise)
    focal, cy = camera.focal_px, 0.5 * camera.image_height
    top = max(0.0, cy - focal * (cfg.evader_height - cfg.camera_height) / depth)
    bottom = min(float(camera.image_height), cy + focal * cfg.camera_height / depth)
    box = BoundingBox(left, top, right - left, bottom - top)
    seen_bearing = camera.bearing_of(box.center_x)
    seen_range = depth / math.cos(seen_bearing)
    heading = cam.theta + seen_bearing
    position = (cam.x + seen_range * math.cos(heading), cam.y + seen_range * math.sin(heading))
    return Detection(box=box, depth=depth, position=position)


@pytest.mark.parametrize("params", [{}, {"range_noise": 0.1, "miss_probability": 0.3}])
def test_with_the_perception_model_off_the_detections_are_todays_bit_for_bit(params):
    new, old = detector(**params), detector(**params)
    poses = np.random.default_rng(1).uniform([0.5, 0.5, -3.0], [7.5, 5.5, 3.0], (400, 3))
    camera = Pose(1.0, 3.0, 0.0)
    for k, (x, y, theta) in enumerate(poses):
        camera = Pose(1.0 + 0.001 * k, 3.0, 0.3 * math.sin(theta)) if k % 2 else camera
        here = SensorFrame(time=0.1 * k, camera_pose=camera, evader_truth=Pose(x, y))
        assert new.detect(here) == todays_detect(old, here)
    assert new.rng.random() == old.rng.random()


def test_nothing_beyond_the_detection_range_is_detected():
    camera = Pose(1.0, 3.0, 0.0)
    near = detector(detection_range=3.0)
    assert near.detect(frame(camera, Pose(3.9, 3.0))) is not None
    assert near.detect(frame(camera, Pose(4.1, 3.0))) is None
    assert detector().detect(frame(camera, Pose(4.1, 3.0))) is not None


def test_a_partly_hidden_evader_is_missed_as_often_as_its_silhouette_is_hidden():
    from pegame.detectors.perception import hidden_fraction

    # The wall's lower end is at y = 2 m: an evader at y = 1.95 m, seen along the wall
    # from beyond it, shows its centre and the half below, not the half behind the wall.
    camera, evader = Pose(7.0, 1.95, math.pi), Pose(4.0, 1.95)
    hidden = hidden_fraction(grid_with_a_wall(), CAMERA, camera, (evader.x, evader.y), 0.25)
    assert 0 < hidden < 1
    n = 4000
    occluded = detector(occlusion_miss=1.0)
    missed = sum(occluded.detect(frame(camera, evader)) is None for _ in range(n))
    assert abs(missed / n - hidden) < 4 * math.sqrt(hidden * (1 - hidden) / n)
    assert hidden_fraction(grid_with_a_wall(), CAMERA, Pose(1.0, 3.0, 0.0), (3.0, 3.0), 0.25) == 0


def test_the_oracle_depth_noise_grows_with_range_and_its_bearing_noise_moves_the_box():
    a, b, n = 0.01, 0.004, 4000
    noisy = detector(range_noise=a, range_noise_growth=b)
    for r in (1.0, 4.0):
        depths = [
            noisy.detect(frame(Pose(0.5, 3.0, 0.0), Pose(0.5 + r, 3.0))).depth for _ in range(n)
        ]
        assert np.std(depths) == pytest.approx(a + b * r**2, rel=4 / math.sqrt(2 * n))
    turned = detector(bearing_noise=0.05)
    seen = [turned.detect(frame(Pose(1.0, 3.0, 0.0), Pose(3.0, 3.0))) for _ in range(n)]
    bearings = [CAMERA.bearing_of(s.box.center_x) for s in seen]
    assert np.std(bearings) == pytest.approx(0.05, rel=4 / math.sqrt(2 * n))
    assert np.mean([math.hypot(s.position[0] - 1.0, s.position[1] - 3.0) for s in seen]) == (
        pytest.approx(2.0, abs=0.01)
    )


def test_the_oracle_runs_at_its_rate_and_resets_its_pipeline():
    slow = detector(rate=1.0)
    camera = Pose(1.0, 3.0, 0.0)
    first = slow.detect(SensorFrame(time=0.0, camera_pose=camera, evader_truth=Pose(3.0, 3.0)))
    held = slow.detect(SensorFrame(time=0.5, camera_pose=camera, evader_truth=Pose(3.0, 3.5)))
    assert held is first
    slow.reset()
    fresh = slow.detect(SensorFrame(time=0.5, camera_pose=camera, evader_truth=Pose(3.0, 3.5)))
    assert fresh.position[1] == pytest.approx(3.5, abs=0.02)
