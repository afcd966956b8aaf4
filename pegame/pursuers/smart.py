"""The paper's smart pursuer (paper, Sec. "Smart Pursuer"): a hybrid of a reactive
visual controller while the evader is detected and navigation to the estimator's
estimate while it is not.

Tracking (a detection this control tick): the evader is kept in the centre of the image
and at ``standoff`` metres. The paper's image offset of the bounding box,

    target_offset_x = x_b + w_b / 2 - w_I / 2        (pixels),

with (x_b, y_b, w_b, h_b) the box (top-left corner and size, px) and w_I the image width
(px), is normalised by w_I to u in [-1/2, 1/2] (positive: evader right of the optical
axis) and turned into a turn rate w = -k_w * u (rad/s, map frame CCW positive, so an
evader on the right makes the robot turn clockwise). The forward speed follows the
detection's depth (m, along the optical axis): v = k_v * (depth - standoff) (m/s), so
the robot approaches a far evader and backs off from a near one. Both are saturated to
the body's limits. When the straight motion over a short look-ahead would enter the
pursuer's inflated obstacle cells (``inflate(grid, radius)``, the simulator's collision
mask of the robot's centre), backing off stops (v = 0) and approaching becomes a detour:
the pursuer follows a planned path to the detected position, as move_base would, instead
of standing at the corner that its line of sight grazes (``detour``, not in the paper:
false makes it stop and turn there).

``track`` chooses between two readings of the paper's "We can compute the linear velocity
required to keep at a certain distance from the evader" in 1 Hz nodes that "make use of
move_base package for path planning given a goal location": ``servo`` (the default) is
the reactive controller above, run at every control tick on the latest detection (held
between the detector's results); ``goal`` sends each new detection to move_base as a
goal: the point ``standoff`` m short of the detected position on the line from the
pursuer, planned to once per new detection and followed at the control rate on the
pursuer's own pose (pure pursuit, :class:`pegame.navigation.PathFollower`), turning to
face the detected position once there (docs/trends/README.md).

Searching (no detection): the pursuer plans from its pose to the estimator's estimate,
the weighted mean of the particles (``observation.belief.mean``, map frame, m), and
follows the path; it replans at every decision and at once when it loses the evader.
Once there, or when there is no reachable estimate, it rotates in place to scan for
the evader. A detection switches back to tracking at the next control tick.

The look-ahead collision check runs every tracking tick, so it is a numba kernel
(:func:`_straight_clear`) with the numpy reference ``_straight_clear_reference``.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from pegame.api import Context, Pursuer, PursuerObservation
from pegame.errors import require
from pegame.grid import OccupancyGrid, point_cell
from pegame.navigation import PathFollower, Planner, shared_inflation
from pegame.types import Plan, Pose, Velocity, clamp, wrap_angle

log = logging.getLogger(__name__)

#: s; the collision check looks this far ahead at the commanded speed (at least one radius)
LOOKAHEAD_TIME = 0.5

TRACK, SEARCH, SCAN = "track", "search", "scan"
#: the ``track`` readings (module docstring)
TRACKING = ("servo", "goal")


class SmartPursuer(Pursuer):
    """Centres the detected evader at a standoff distance; when it is lost, drives to the
    estimator's estimate and scans there."""

    description = (
        "Paper's hybrid: centres the seen evader at a standoff, else goes to the estimate."
    )

    @dataclass
    class Config(Pursuer.Config):
        standoff: float = 1.5  # m, distance to keep from the evader along the optical axis
        k_w: float = 4.0  # rad/s per unit of image offset (box centre offset / image width)
        k_v: float = 1.0  # 1/s, forward speed per metre of depth error (depth - standoff)
        scan_rate: float = 1.0  # rad/s, turn rate when scanning in place
        detour: bool = True  # plan around an obstacle the line of sight grazes (false: wait)
        track: str = "servo"  # servo: reactive (v, w) on each tick's detection; goal: each new
        # detection is a move_base goal standoff m short of it, followed on odometry

        def __post_init__(self) -> None:
            super().__post_init__()
            require(self.standoff > 0, "standoff", "a positive distance in m", self.standoff)
            require(self.k_w > 0, "k_w", "a positive gain in rad/s", self.k_w)
            require(self.k_v > 0, "k_v", "a positive gain in 1/s", self.k_v)
            require(self.track in TRACKING, "track", " or ".join(TRACKING), self.track)
            require(
                self.scan_rate > 0,
                "scan_rate",
                "a positive turn rate in rad/s",
                self.scan_rate,
            )

    def __init__(self, config: Config, context: Context, rng: np.random.Generator) -> None:
        super().__init__(config, context, rng)
        self.planner = Planner.shared(context.grid, context.pursuer.radius)
        self.follower = PathFollower(context.pursuer)
        self.blocked = shared_inflation(context.grid, context.pursuer.radius)
        self._frame = context.grid.kernel_frame
        self.reset(Pose(0.0, 0.0))

    def reset(self, pose: Pose) -> None:
        # The game starts with the evader in view, so the pursuer starts out tracking.
        self.mode = TRACK
        self._scan_sign = 1.0  # +1 CCW, -1 CW
        self._goal_of: object = None  # the detection the ``goal`` reading's path was planned for
        self.follower.set_path(np.zeros((0, 2)))

    def decide(self, observation: PursuerObservation) -> Plan:
        """Track a detected evader; otherwise replan to the current estimate."""
        if observation.detection is not None:
            self.mode = TRACK
            return Plan(goal=observation.detection.position, info={"mode": TRACK})
        return self._search(observation)

    def control(self, observation: PursuerObservation) -> Velocity:
        """The reactive command while the evader is detected; else follow the path to the
        estimate, then scan in place."""
        if observation.detection is not None:
            self.mode = TRACK
            if self.config.track == "goal":
                return self._track_goal(observation)
            return self._track(observation)
        self._goal_of = None
        if self.mode == TRACK:
            # Just lost the evader: head for the estimate now rather than at the next decision.
            self._search(observation)
        return self._search_or_scan(observation)

    def _search_or_scan(self, observation: PursuerObservation) -> Velocity:
        """Not tracking: follow the path to the estimate (SEARCH), then turn in place at
        ``scan_rate`` (SCAN) once it is reached."""
        if self.mode == SEARCH:
            command = self.follower.command(observation.pose)
            if not self.follower.done:
                return command
            self._start_scan(observation)
        return Velocity(0.0, self._scan_sign * self.config.scan_rate)

    # -- tracking

    def _track(self, observation: PursuerObservation) -> Velocity:
        """The paper's reactive controller on this tick's detection, made collision-safe."""
        detection, body = observation.detection, self.context.pursuer
        assert detection is not None  # control tracks a detected evader only
        width = self.context.camera.image_width
        offset = (detection.box.x + 0.5 * detection.box.w - 0.5 * width) / width
        w = clamp(-self.config.k_w * offset, body.w_max)
        v = clamp(self.config.k_v * (detection.depth - self.config.standoff), body.v_max)
        reach = math.copysign(max(abs(v) * LOOKAHEAD_TIME, body.radius), v)
        if v != 0.0 and not self._clear(observation.pose, reach):
            blocked_ahead = v > 0 and self.config.detour
            return self._detour(observation, w) if blocked_ahead else Velocity(0.0, w)
        return Velocity(v, w)

    def _track_goal(self, observation: PursuerObservation) -> Velocity:
        """The ``goal`` reading: plan to the point ``standoff`` m short of a new detection's
        position and follow the path on the pursuer's pose; at that point (or when it is
        unreachable or the pursuer is already closer) turn in place to face the detection."""
        detection, pose = observation.detection, observation.pose
        assert detection is not None  # control tracks a detected evader only
        gx, gy = detection.position
        dx, dy = gx - pose.x, gy - pose.y
        if detection is not self._goal_of:  # a new detection: a new goal for move_base
            self._goal_of = detection
            distance = math.hypot(dx, dy)
            path = np.zeros((0, 2))
            if distance > self.config.standoff:
                scale = 1.0 - self.config.standoff / distance
                result = self.planner.plan(
                    (pose.x, pose.y), (pose.x + scale * dx, pose.y + scale * dy)
                )
                path = result.path if result.reachable else path
            self.follower.set_path(path)
        if not self.follower.done:
            return self.follower.command(pose)
        bearing = wrap_angle(math.atan2(dy, dx) - pose.theta)
        return Velocity(0.0, clamp(self.follower.turn_gain * bearing, self.context.pursuer.w_max))

    def _detour(self, observation: PursuerObservation, w: float) -> Velocity:
        """Approaching is blocked (the line of sight grazes an obstacle): follow a planned
        path to the detected position instead, as move_base would; turn in place if none."""
        pose, detection = observation.pose, observation.detection
        assert detection is not None  # a detour while tracking a detected evader only
        result = self.planner.plan((pose.x, pose.y), detection.position)
        if not result.reachable:
            return Velocity(0.0, w)
        self.follower.set_path(result.path)
        return self.follower.command(pose)

    def _clear(self, pose: Pose, distance: float) -> bool:
        """True when moving ``distance`` m straight along the heading (negative: backwards)
        from ``pose`` stays on the grid and out of inflated obstacle cells (see
        :func:`_straight_clear`)."""
        theta = pose.theta
        n = max(1, math.ceil(2 * abs(distance) / self.context.grid.resolution))
        return _straight_clear(
            self.blocked, pose.x, pose.y, math.cos(theta), math.sin(theta), distance, n, self._frame
        )

    # -- searching

    def _search(self, observation: PursuerObservation) -> Plan:
        """Plan to the estimate and follow it (mode SEARCH), or scan when there is none."""
        pose, estimate = observation.pose, observation.belief.mean
        if estimate is None:
            log.info("t=%.1f s: no estimate of the evader; scanning in place", observation.time)
            self._start_scan(observation)
            return Plan(info={"mode": SCAN, "reason": "no estimate"})
        result = self.planner.plan((pose.x, pose.y), estimate)
        if not result.reachable:
            log.info(
                "t=%.1f s: estimate (%.2f, %.2f) m is unreachable (%s); scanning in place",
                observation.time,
                estimate[0],
                estimate[1],
                result.reason,
            )
            self._start_scan(observation)
            return Plan(info={"mode": SCAN, "reason": result.reason})
        self.mode = SEARCH
        self.follower.set_path(result.path)
        return Plan(
            goal=(float(estimate[0]), float(estimate[1])), path=result.path, info={"mode": SEARCH}
        )

    def _start_scan(self, observation: PursuerObservation) -> None:
        """Scan in place, turning toward the estimate when it lies outside the camera's
        field of view; otherwise keep the previous direction so the scan does not dither."""
        self.mode = SCAN
        self.follower.set_path(np.zeros((0, 2)))
        estimate, pose = observation.belief.mean, observation.pose
        if estimate is None:
            return
        dx, dy = estimate[0] - pose.x, estimate[1] - pose.y
        if math.hypot(dx, dy) <= self.follower.goal_tolerance:
            return  # standing on the estimate: its bearing means nothing
        bearing = wrap_angle(math.atan2(dy, dx) - pose.theta)
        if abs(bearing) > 0.5 * self.context.camera.fov:
            self._scan_sign = math.copysign(1.0, bearing)


@njit(cache=True)
def _straight_clear(
    blocked: np.ndarray,
    x: float,
    y: float,
    cos_theta: float,
    sin_theta: float,
    distance: float,
    n: int,
    frame: tuple,
) -> bool:
    """True when the n samples at ``np.linspace(distance / n, distance, n)`` m along the
    heading (cos_theta, sin_theta) from (x, y) (map frame, m) are all on the grid and, except
    those in the start's own cell, out of the bool (H, W) mask ``blocked``.

    Samples are half a cell apart (the caller's n) so no thin wall is skipped. The start's
    cell does not count: a robot whose centre already touches the inflation zone (possible
    in a continuous simulator) must still be able to move out of it. The sample distances
    repeat np.linspace's arithmetic, so the result equals ``_straight_clear_reference``.
    """
    height, width = blocked.shape
    here = point_cell(x, y, frame)
    start = distance / n
    step = (distance - start) / (n - 1) if n > 1 else 0.0
    for k in range(n):
        s = distance if k == n - 1 else k * step + start
        row, col = point_cell(x + s * cos_theta, y + s * sin_theta, frame)
        if not (0 <= row < height and 0 <= col < width):
            return False
        if (row, col) != here and blocked[row, col]:
            return False
    return True


def _straight_clear_reference(
    grid: OccupancyGrid,
    blocked: np.ndarray,
    x: float,
    y: float,
    theta: float,
    distance: float,
    n: int,
) -> bool:
    """Plain numpy reference of :func:`_straight_clear` (heading ``theta`` rad)."""
    s = np.linspace(distance / n, distance, n)
    rows, cols = grid.world_to_cell(x + s * math.cos(theta), y + s * math.sin(theta))
    if not grid.contains(rows, cols).all():
        return False
    here = grid.world_to_cell(x, y)
    elsewhere = (rows != here[0]) | (cols != here[1])
    return not blocked[rows[elsewhere], cols[elsewhere]].any()
