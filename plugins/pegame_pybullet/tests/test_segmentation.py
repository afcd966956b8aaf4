"""detector=segmentation: the evader's exact pixels, its depth and its map position."""

from __future__ import annotations

import pytest

pytest.importorskip("pybullet")

import math

import numpy as np

from pegame.api import SensorFrame
from pegame.errors import ConfigError
from pegame.types import Pose
from pegame_pybullet.segmentation import SegmentationDetector
from pegame_pybullet.sim import PybulletSimulator


@pytest.fixture
def scene(context):
    """(sim, detector) on the small map, with a level camera (the default is the paper's
    pi/8 down, which sees a person's legs only)."""
    config = PybulletSimulator.Config(camera_tilt=0.0)
    sim = PybulletSimulator(config, context, np.random.default_rng(0))
    detector = SegmentationDetector(
        SegmentationDetector.Config(), context, np.random.default_rng(0)
    )
    yield sim, detector
    sim.close()


@pytest.mark.parametrize(
    ("x", "y", "heading"),
    [
        (1.5, 1.0, 0.0),
        (1.2, 1.4, math.pi / 2),
        (1.6, 0.7, 2.0),
        (1.0, 1.0, -1.0),
        (0.8, 1.2, math.pi),
    ],
)
def test_the_evader_in_front_is_found_and_placed_within_10_cm(scene, context, x, y, heading):
    sim, detector = scene
    sim.reset_1v1(Pose(0.3, 1.0, 0.0), Pose(x, y, heading))
    detection = detector.detect(sim.sense_1v1(0.0))
    assert detection is not None
    assert math.hypot(detection.position[0] - x, detection.position[1] - y) < 0.10
    # Depth is along the optical axis to the body's visible surface, in front of its axis.
    assert x - 0.3 - 0.3 < detection.depth < x - 0.3
    # The box is in the pursuer camera's 640 x 480 frame and straddles the evader's bearing.
    camera = context.camera
    column = camera.column_of(math.atan2(y - 1.0, x - 0.3))
    box = detection.box
    assert box.x < column < box.x + box.w
    assert (
        0 <= box.x and box.x + box.w <= camera.image_width and box.y + box.h <= camera.image_height
    )


def test_no_detection_behind_a_wall_behind_the_camera_or_beyond_range(scene, context):
    sim, detector = scene
    for evader in (
        Pose(2.6, 1.0, 0.0),
        Pose(1.5, 2.7, 0.0),
    ):  # behind the wall; pursuer looks at it
        sim.reset_1v1(Pose(0.5, 1.0, 0.0), evader)
        assert detector.detect(sim.sense_1v1(0.0)) is None
    sim.reset_1v1(Pose(1.0, 1.0, math.pi), Pose(1.6, 1.0, 0.0))  # behind the camera
    assert detector.detect(sim.sense_1v1(0.0)) is None


def test_an_evader_beyond_the_camera_range_is_not_detected(context):
    from dataclasses import replace

    near = replace(context, camera=replace(context.camera, far=0.8))
    sim = PybulletSimulator(PybulletSimulator.Config(), near, np.random.default_rng(0))
    detector = SegmentationDetector(SegmentationDetector.Config(), near, np.random.default_rng(0))
    try:
        sim.reset_1v1(Pose(0.3, 1.0, 0.0), Pose(1.7, 1.0, 0.0))
        assert detector.detect(sim.sense_1v1(0.0)) is None
        sim.reset_1v1(Pose(0.3, 1.0, 0.0), Pose(0.9, 1.0, 0.0))
        assert detector.detect(sim.sense_1v1(0.0)) is not None
    finally:
        sim.close()


def test_frames_without_segmentation_are_a_clear_error(context):
    detector = SegmentationDetector(
        SegmentationDetector.Config(), context, np.random.default_rng(0)
    )
    with pytest.raises(ConfigError, match="sim=pybullet"):
        detector.detect(SensorFrame(time=0.0, camera_pose=Pose(0, 0), evader_truth=Pose(1, 0)))


def test_the_perception_model_holds_delays_and_degrades_segmentation_detections(scene, context):
    """Rate 1 Hz and latency 0.2 s at 10 Hz: the frame of tick 0 arrives at tick 2 and is
    held until the frame of tick 10 arrives at tick 12; depth noise moves it along its ray."""
    sim, exact = scene
    config = SegmentationDetector.Config(rate=1.0, latency=0.2, range_noise=0.05)
    slow = SegmentationDetector(config, context, np.random.default_rng(0))
    delivered, raw = [], []
    for k in range(14):
        sim.reset_1v1(Pose(0.3, 1.0, 0.0), Pose(1.2 + 0.02 * k, 1.0, 0.0))
        frame = sim.sense_1v1(0.1 * k)
        delivered.append(slow.detect(frame))
        raw.append(exact.detect(frame))
    assert delivered[:2] == [None, None]
    assert all(d is delivered[2] for d in delivered[2:12]) and delivered[12] is delivered[13]
    assert delivered[12] is not delivered[2]
    for seen, truth in ((delivered[2], raw[0]), (delivered[12], raw[10])):
        assert seen.depth != truth.depth
        bearing = math.atan2(seen.position[1] - 1.0, seen.position[0] - 0.3)
        assert bearing == pytest.approx(
            math.atan2(truth.position[1] - 1.0, truth.position[0] - 0.3)
        )


def test_the_occlusion_miss_is_refused_for_segmentation(context):
    config = SegmentationDetector.Config(occlusion_miss=0.5)
    with pytest.raises(ConfigError, match="detector.occlusion_miss"):
        SegmentationDetector(config, context, np.random.default_rng(0))
