"""Tests for the anticipating pursuer: the map-frame servo on held detections, the look
toward the belief mass, the wedge search against a brute-force reference, its config."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from pegame.api import Context, PursuerObservation
from pegame.grid import FREE, OccupancyGrid
from pegame.pursuers.anticipating import LOOK, AnticipatingPursuer, best_wedge
from pegame.pursuers.smart import SEARCH, SmartPursuer
from pegame.registry import make_config
from pegame.testing import PursuerConformance
from pegame.types import EMPTY_BELIEF, Belief, Body, BoundingBox, Camera, Detection, Pose
from pegame.visibility import MaskRegion

CAMERA = Camera()


@pytest.mark.slow
class TestConformance(PursuerConformance):
    plugin = "anticipating"
    bad_values = {"k_heading": 0, "lead_time": -1, "look_mass": 0, "look_angle_step": 0}


def open_context(size: int = 80, resolution: float = 0.1) -> Context:
    grid = OccupancyGrid(np.full((size, size), FREE, dtype=np.int8), resolution)
    return Context(grid, Body(0.2, 0.5, 1.8), Body(0.25, 0.5, 1.8), CAMERA, 0.1, 1.0)


def make(cls, context: Context, **params):
    pursuer = cls(make_config("pursuer", cls, params), context, np.random.default_rng(0))
    pursuer.reset(Pose(0.0, 0.0))
    return pursuer


def detection_at(pose: Pose, xy) -> Detection:
    """The oracle's detection of an evader at map point ``xy`` seen from ``pose``."""
    dx, dy = xy[0] - pose.x, xy[1] - pose.y
    bearing = math.atan2(dy, dx) - pose.theta
    depth = math.hypot(dx, dy) * math.cos(bearing)
    u = CAMERA.focal_px * math.tan(bearing)
    centre = 0.5 * CAMERA.image_width - u
    return Detection(BoundingBox(centre - 20, 100, 40, 200), depth, (float(xy[0]), float(xy[1])))


def observation(time, pose, detection=None, belief=EMPTY_BELIEF, context=None):
    shape = context.grid.data.shape if context else (1, 1)
    return PursuerObservation(time, pose, detection, belief, MaskRegion(np.zeros(shape, bool)))


def test_servo_stops_turning_once_it_faces_a_held_detection():
    """A detection held over ticks (a 1 Hz detector): the image servo keeps the offset it
    saw and keeps turning after the robot faces the evader; the map-frame servo does not."""
    context = open_context()
    start = Pose(4.0, 4.0, 0.0)
    held = detection_at(start, (6.0, 5.0))  # 26.6 degrees to the left
    facing = Pose(4.0, 4.0, math.atan2(1.0, 2.0))  # turned to face it since
    anticipating = make(AnticipatingPursuer, context, lead_time=0.0)
    smart = make(SmartPursuer, context)
    anticipating.control(observation(0.0, start, held, context=context))
    assert smart.control(observation(0.5, facing, held, context=context)).w > 0.5
    assert abs(anticipating.control(observation(0.5, facing, held, context=context)).w) < 1e-9


def test_lead_follows_the_evader_velocity():
    """Two detections 1 s apart moving +x at 0.4 m/s: the servo aims lead_time ahead."""
    context = open_context()
    pursuer = make(AnticipatingPursuer, context, lead_time=1.0)
    pose = Pose(2.0, 4.0, 0.0)
    pursuer.control(observation(0.0, pose, detection_at(pose, (4.0, 4.0)), context=context))
    pursuer.control(observation(1.0, pose, detection_at(pose, (4.4, 4.0)), context=context))
    x, y = pursuer._predicted(1.0)
    assert x == pytest.approx(4.8) and y == pytest.approx(4.0)


def test_evader_speed_caps_the_velocity_estimate():
    context = open_context()
    pursuer = make(AnticipatingPursuer, context, lead_time=1.0)
    pose = Pose(2.0, 4.0, 0.0)
    pursuer.control(observation(0.0, pose, detection_at(pose, (4.0, 4.0)), context=context))
    pursuer.control(observation(0.1, pose, detection_at(pose, (5.0, 4.0)), context=context))
    assert math.hypot(*pursuer._velocity) == pytest.approx(context.evader.v_max)


def particles_at(xy, n=200, spread=0.05, seed=0) -> Belief:
    rng = np.random.default_rng(seed)
    points = np.column_stack(
        [rng.normal(xy[0], spread, n), rng.normal(xy[1], spread, n), np.zeros(n)]
    )
    return Belief(
        mean=tuple(points[:, :2].mean(axis=0)), particles=points, weights=np.full(n, 1 / n)
    )


def test_lost_evader_in_line_of_sight_beside_the_view_is_looked_at():
    """The belief sits 90 degrees to the left in the open: the pursuer turns left in place
    toward it instead of driving to it."""
    context = open_context()
    pursuer = make(AnticipatingPursuer, context)
    pose = Pose(4.0, 4.0, 0.0)
    lost = observation(1.0, pose, None, particles_at((4.0, 6.0)), context)
    pursuer.decide(lost)
    assert pursuer.mode == LOOK
    assert pursuer._look_heading == pytest.approx(math.pi / 2, abs=0.1)
    command = pursuer.control(lost)
    assert command.v == 0.0 and command.w > 0


def test_belief_behind_a_wall_is_not_looked_at():
    """Particles behind a wall are out of line of sight: the pursuer plans its way there."""
    data = np.full((80, 80), FREE, dtype=np.int8)
    data[50:53, 10:70] = 100  # a wall at y = 5.0-5.3 m
    context = dataclasses.replace(open_context(), grid=OccupancyGrid(data, 0.1))
    pursuer = make(AnticipatingPursuer, context)
    pose = Pose(4.0, 4.0, 0.0)
    assert (
        pursuer.best_look(observation(1.0, pose, None, particles_at((4.0, 6.5)), context))[1] == 0
    )
    pursuer.decide(observation(1.0, pose, None, particles_at((4.0, 6.5)), context))
    assert pursuer.mode != LOOK


def best_wedge_reference(bearings, weights, fov):
    """Brute force: the most weight in a window starting at a bearing, by angle tests."""
    starts = np.mod(bearings, 2 * math.pi)
    return max(weights[np.mod(bearings - s, 2 * math.pi) <= fov + 1e-12].sum() for s in starts)


@pytest.mark.parametrize("seed", range(20))
def test_best_wedge_holds_the_most_weight(seed):
    rng = np.random.default_rng(seed)
    k = int(rng.integers(1, 60))
    bearings = rng.uniform(-math.pi, math.pi, k)
    if seed % 2:
        bearings[: k // 2] = rng.normal(2.9, 0.3, k // 2)  # a cluster across +-pi
    weights = rng.random(k)
    centre, mass = best_wedge(bearings, weights, CAMERA.fov)
    assert mass == pytest.approx(best_wedge_reference(bearings, weights, CAMERA.fov))
    inside = np.abs(np.angle(np.exp(1j * (bearings - centre)))) <= 0.5 * CAMERA.fov + 1e-9
    assert weights[inside].sum() == pytest.approx(mass)


def test_an_evader_that_stops_is_predicted_where_it_stands():
    """Fresh detections of an evader that stopped (new Detection objects, same position):
    the velocity estimate drops to zero, so the prediction does not run off with the speed
    it had before (regression: identical positions were taken for a held result)."""
    context = open_context()
    pursuer = make(AnticipatingPursuer, context, lead_time=0.5)
    pose = Pose(2.0, 4.0, 0.0)
    pursuer.control(observation(0.0, pose, detection_at(pose, (4.0, 4.0)), context=context))
    for k in range(1, 30):
        pursuer.control(observation(0.1 * k, pose, detection_at(pose, (4.4, 4.0)), context=context))
    assert pursuer._predicted(2.9) == pytest.approx((4.4, 4.0))


def corner_context() -> Context:
    """8 m x 8 m open at 0.1 m with a wall block at x = 4.3-4.6 m, y = 3.0-4.1 m, right in
    front of a pursuer at (4, 4) facing +x; the line of sight to (6, 5) passes above it."""
    data = np.full((80, 80), FREE, dtype=np.int8)
    data[30:41, 43:46] = 100
    return dataclasses.replace(open_context(), grid=OccupancyGrid(data, 0.1))


def lose_on_a_detour(pursuer, context):
    """Track an evader at (6, 5) from (4, 4) facing +x, whose straight approach runs into
    the block (the servo detours), then lose it 0.2 s later."""
    pose, evader = Pose(4.0, 4.0, 0.0), (6.0, 5.0)
    pursuer.control(observation(0.0, pose, detection_at(pose, evader), context=context))
    assert len(pursuer.follower.path) > 0  # the approach is blocked: it detours
    lost = observation(0.2, pose, None, particles_at(evader), context)
    assert pursuer.best_look(lost)[1] > pursuer.config.look_mass  # worth a look
    return pursuer.control(lost)


def test_no_look_back_after_a_detour():
    """Regression (brick, v_p/v_e = 1, random evader: 17.7% tracked on seed 22 against the
    smart pursuer's 91.0%): the servo turned away from the evader to detour round the block
    its straight approach runs into, and lost it; looking back at it undid the detour at
    every tick. The pursuer now searches along the path, at the loss and at the next
    decision."""
    context = corner_context()
    pursuer = make(AnticipatingPursuer, context)
    lose_on_a_detour(pursuer, context)
    assert pursuer.mode == SEARCH  # following the path to the estimate, not looking back
    pursuer.decide(observation(1.0, Pose(4.0, 4.0, 0.0), None, particles_at((6.0, 5.0)), context))
    assert pursuer.mode == SEARCH


def test_looks_again_after_a_clear_approach():
    """The hold on the look ends with a tracking tick whose approach is clear."""
    context = corner_context()
    pursuer = make(AnticipatingPursuer, context)
    lose_on_a_detour(pursuer, context)
    open_pose = Pose(4.0, 6.0, 0.0)  # above the block: nothing ahead
    pursuer.control(
        observation(0.5, open_pose, detection_at(open_pose, (6.0, 6.0)), context=context)
    )
    pursuer.control(observation(0.6, open_pose, None, particles_at((4.0, 7.5)), context))
    assert pursuer.mode == LOOK
