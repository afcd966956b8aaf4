"""sim=pybullet's evader: an articulated person whose gait follows the distance it walks,
seen by a camera whose tilt moves the floor in the image."""

from __future__ import annotations

import pytest

pytest.importorskip("pybullet")

import math

import numpy as np

from pegame.api import Velocity
from pegame.types import Pose
from pegame_pybullet.person import JOINTS, STRIDE, gait_angles
from pegame_pybullet.sim import PAPER_TILT, PybulletSimulator


def joint_angles(sim: PybulletSimulator) -> np.ndarray:
    body = sim.labels["evader"]
    return np.array([sim.client.getJointState(body, j)[0] for j in range(len(JOINTS))])


def shin_position(sim: PybulletSimulator) -> np.ndarray:
    """World position (m) of the left shin's frame (the knee)."""
    return np.array(sim.client.getLinkState(sim.labels["evader"], 1)[4])


def test_the_person_has_revolute_hips_knees_shoulders_and_elbows(context):
    sim = PybulletSimulator(PybulletSimulator.Config(), context, np.random.default_rng(0))
    try:
        sim.reset_1v1(Pose(0.3, 1.0, 0.0), Pose(0.9, 1.0, 0.0))
        body = sim.labels["evader"]
        assert sim.client.getNumJoints(body) == len(JOINTS) == 8
        for j in range(len(JOINTS)):
            assert sim.client.getJointInfo(body, j)[2] == 0  # pybullet.JOINT_REVOLUTE
        low, high = sim.client.getAABB(body, -1)
        assert high[2] == pytest.approx(1.70, abs=0.01)  # the head's top
        assert joint_angles(sim) == pytest.approx(gait_angles(0.0))
    finally:
        sim.close()


def test_the_joints_move_with_the_distance_walked_and_stop_with_the_body(context):
    sim = PybulletSimulator(PybulletSimulator.Config(), context, np.random.default_rng(0))
    try:
        sim.reset_1v1(Pose(0.3, 1.0, 0.0), Pose(0.9, 1.0, 0.0))
        still = Velocity(0.0, 0.0)
        sim.step_1v1(still, Velocity(0.35, 0.0), 1.0)  # a quarter of a stride
        assert sim.poses_1v1[1].x == pytest.approx(1.25)
        assert joint_angles(sim) == pytest.approx(gait_angles(0.35))
        assert not np.allclose(joint_angles(sim), gait_angles(0.0))
        knee = shin_position(sim)
        sim.step_1v1(still, Velocity(0.0, 0.5), 1.0)  # turning on the spot: no step taken
        assert joint_angles(sim) == pytest.approx(gait_angles(0.35))
        sim.step_1v1(still, Velocity(-0.35, 0.0), 1.0)  # walking back undoes the stride
        assert joint_angles(sim) == pytest.approx(gait_angles(0.0))
        assert not np.allclose(shin_position(sim), knee)
    finally:
        sim.close()


def test_the_gait_repeats_every_stride_and_the_legs_alternate():
    for distance in (0.0, 0.3, 1.1):
        assert gait_angles(distance + STRIDE) == pytest.approx(gait_angles(distance))
        left_hip, _, right_hip, *_ = gait_angles(distance)
        assert left_hip == pytest.approx(-right_hip)


def floor_rows(tilt: float, context) -> int:
    """The first image row (from the top) where the floor's depth appears, empty room."""
    config = PybulletSimulator.Config(camera_tilt=tilt, width=160, height=120)
    sim = PybulletSimulator(config, context, np.random.default_rng(0))
    try:
        sim.reset_1v1(Pose(0.6, 1.0, 0.0), Pose(0.3, 1.0, 0.0))  # evader behind the camera
        frame = sim.sense_1v1(0.0)
        floor = np.any(frame.segmentation == sim.labels["floor"], axis=1)
        return int(np.argmax(floor))
    finally:
        sim.close()


def test_tilting_the_camera_down_raises_the_floor_in_the_depth_image(context):
    assert PybulletSimulator.Config().camera_tilt == PAPER_TILT == math.pi / 8
    level, tilted = floor_rows(0.0, context), floor_rows(PAPER_TILT, context)
    assert level >= 60  # a level camera sees the floor in the lower half only
    assert tilted < level - 20
