"""sim=pybullet: the world matches the map, walls stop the agents, the camera measures
right, frames come at camera_hz, and games release their physics server."""

from __future__ import annotations

import pytest

pytest.importorskip("pybullet")

import dataclasses
import math

import numpy as np
import pybullet

from pegame.api import Velocity
from pegame.errors import ConfigError
from pegame.grid import OccupancyGrid
from pegame.registry import make_config
from pegame.testing import WALL_X, missing_dependency_error
from pegame.types import Pose
from pegame_pybullet.bench import _rss_mb
from pegame_pybullet.sim import PybulletSimulator
from pegame_pybullet.world import merge_rectangles


def make_sim(context, **options) -> PybulletSimulator:
    return PybulletSimulator(PybulletSimulator.Config(**options), context, np.random.default_rng(0))


@pytest.fixture
def sim(context):
    sim = make_sim(context)
    sim.reset_1v1(Pose(0.5, 1.0, 0.0), Pose(3.5, 2.0, 0.0))
    yield sim
    sim.close()


def test_rectangles_cover_the_mask_exactly_without_overlap():
    rng = np.random.default_rng(1)
    for _ in range(20):
        mask = rng.random((int(rng.integers(1, 30)), int(rng.integers(1, 30)))) < rng.random()
        cover = np.zeros(mask.shape, dtype=int)
        for row, col, h, w in merge_rectangles(mask):
            cover[row : row + h, col : col + w] += 1
        assert np.array_equal(cover, mask.astype(int))
    assert len(merge_rectangles(np.ones((300, 300), dtype=bool))) == 1


@pytest.mark.parametrize("origin", [(0.0, 0.0, 0.0), (1.0, -2.0, 0.3)])
def test_walls_are_exactly_where_the_map_has_them(context, origin):
    grid = OccupancyGrid(context.grid.data, context.grid.resolution, origin)
    sim = make_sim(dataclasses.replace(context, grid=grid))
    sim.place(*[Pose(*grid.cell_to_world(5, 5), 0.0)] * 2)
    # A vertical ray from above the 2 m walls down through every cell centre, and through
    # the ring around the grid.
    rows, cols = np.mgrid[-1 : grid.height + 1, -1 : grid.width + 1]
    x, y = grid.cell_to_world(rows.ravel(), cols.ravel())
    starts = np.column_stack([x, y, np.full(x.size, 3.0)])
    ends = starts * [1, 1, 0] + [0, 0, 0.1]
    hits = np.array(
        [
            hit[0]
            for hit in pybullet.rayTestBatch(
                starts.tolist(), ends.tolist(), physicsClientId=sim._client.id
            )
        ]
    )
    walls = np.isin(hits, sim.world.walls).reshape(rows.shape)
    sim.close()
    expected = np.pad(grid.blocked, 1, constant_values=True)
    assert np.array_equal(walls, expected)
    assert len(sim.world.walls) < 10  # merged into a few boxes, not one per cell


def test_the_robot_cannot_pass_through_a_wall(sim, context):
    radius = context.pursuer.radius - 0.5 * context.grid.resolution  # the collision cylinder
    sim.reset_1v1(Pose(1.0, 1.0, 0.0), Pose(3.5, 2.0, 0.0))
    for _ in range(60):  # 1 m/s for 6 s: far past the wall if nothing stopped it
        sim.step_1v1(Velocity(1.0, 0.0), Velocity(0.0, 0.0), 0.1)
    pursuer, _ = sim.poses_1v1
    assert pursuer.x == pytest.approx(WALL_X - radius, abs=0.01)
    sim.step_1v1(Velocity(0.0, 1.0), Velocity(0.0, 0.0), 0.5)  # it may still turn at the wall
    assert sim.poses_1v1[0].theta == pytest.approx(0.5)
    sim.reset_1v1(Pose(1.0, 1.0, 0.0), Pose(WALL_X + 1.0, 1.0, math.pi))
    for _ in range(60):  # the evader from the other side
        sim.step_1v1(Velocity(0.0, 0.0), Velocity(1.0, 0.0), 0.1)
    assert sim.poses_1v1[1].x > WALL_X + 0.1


def test_a_start_inside_a_wall_is_refused(context):
    sim = make_sim(context)
    try:
        with pytest.raises(ValueError, match="inside a wall"):
            sim.reset_1v1(Pose(WALL_X + 0.05, 1.0, 0.0), Pose(3.5, 2.0, 0.0))
    finally:
        sim.close()


@pytest.mark.parametrize("tilt", [0.0, math.pi / 8])
def test_camera_depth_to_a_wall_and_the_floor(context, tilt):
    sim = make_sim(context, camera_tilt=tilt, width=160, height=120)
    try:
        sim.reset_1v1(Pose(0.5, 1.0, 0.0), Pose(3.5, 2.5, 0.0))
        frame = sim.sense_1v1(0.0)
        height, width = frame.depth.shape
        assert (width, height) == (160, 120) and frame.rgb.shape == (120, 160, 3)
        # Pixel (59, 80) has its centre at the principal point: it looks along the axis.
        assert frame.intrinsics[:2, 2] == pytest.approx([80.5, 59.5])
        if tilt == 0.0:
            expected = WALL_X - 0.5  # the wall, straight ahead
        else:
            expected = 0.4 / math.sin(tilt)  # the axis meets the floor first
        assert frame.depth[59, 80] == pytest.approx(expected, abs=0.02)
        # The optical axis in the map frame points ahead and tilt rad down.
        axis = frame.camera_to_map[:3, 2]
        assert axis == pytest.approx([math.cos(tilt), 0.0, -math.sin(tilt)])
        assert frame.camera_to_map[2, 3] == pytest.approx(0.4)
    finally:
        sim.close()


def test_the_robot_never_sees_itself_and_the_floor_is_labelled(sim):
    frame = sim.sense_1v1(0.0)
    labels = frame.labels
    assert not np.any(frame.segmentation == labels["pursuer"])
    assert np.any(frame.segmentation == labels["floor"])
    assert np.all(np.isfinite(frame.depth[frame.segmentation >= 0]))


def test_frames_are_rendered_at_camera_hz_and_reused_between(context):
    sim = make_sim(context, camera_hz=5.0)
    try:
        sim.reset_1v1(Pose(0.5, 1.0, 0.0), Pose(1.5, 1.2, 0.0))
        first = sim.sense_1v1(0.0)
        sim.step_1v1(Velocity(0.0, 0.5), Velocity(0.0, 0.0), 0.1)
        assert sim.sense_1v1(0.1) is first
        sim.step_1v1(Velocity(0.0, 0.5), Velocity(0.0, 0.0), 0.1)
        second = sim.sense_1v1(0.2)
        assert second is not first and second.time == 0.2
        assert second.camera_pose.theta == pytest.approx(0.1)
    finally:
        sim.close()


def test_bad_options_are_config_errors(context):
    with pytest.raises(ConfigError, match="sim.width"):
        make_config("sim", PybulletSimulator, {"width": 2})
    with pytest.raises(ConfigError, match="sim.camera_height"):
        make_config("sim", PybulletSimulator, {"camera_height": 3.0})
    with pytest.raises(ConfigError, match="collision_inset"):
        make_sim(context, collision_inset=10)


def test_reset_close_cycles_keep_memory_flat(context):
    """Games release their physics server: 30 reset/render/close cycles leave the live
    resident memory flat."""

    def cycle():
        sim = make_sim(context)
        sim.reset_1v1(Pose(0.5, 1.0, 0.0), Pose(1.5, 1.2, 0.0))
        sim.sense_1v1(0.0)
        sim.close()
        assert sim._client is None

    for _ in range(3):
        cycle()
    before = _rss_mb()
    for _ in range(30):
        cycle()
    assert _rss_mb() - before < 5.0


def test_missing_pybullet_is_an_import_error_naming_it():
    error = missing_dependency_error("sim", "pybullet", "pybullet", "pegame_pybullet")
    assert "'pybullet' is not installed" in str(error)
    assert "reinstall the distribution 'pegame-pybullet'" in str(error)
    assert isinstance(error.__cause__, ImportError)
