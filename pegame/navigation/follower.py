"""Path following: a pure-pursuit local controller for a unicycle, move_base's local part.

:class:`PathFollower` drives an agent along a waypoint path (a :class:`pegame.navigation.
Planner` path) by pure pursuit (Coulter, "Implementation of the Pure Pursuit Path Tracking
Algorithm", CMU-RI-TR-92-01, 1992): it steers along the arc through the path point one
lookahead beyond its progress point, and turns in place when that point is far off its
heading. The step on the path is the numba kernel :func:`_follow`, with the plain numpy
reference :func:`_follow_reference` that gives identical floats.

Units and frames: map-frame (x, y) in metres, headings in radians, speeds in m/s and rad/s.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import ArrayLike

from pegame.errors import require
from pegame.numerics import hypot, wrap_angle
from pegame.types import STOP, Body, Pose, Velocity


@njit(cache=True)
def _search_right(values: np.ndarray, x: float) -> int:
    """``np.searchsorted(values, x, side="right")`` for a sorted float array."""
    lo, hi = 0, values.size
    while lo < hi:
        mid = (lo + hi) >> 1
        if values[mid] <= x:
            lo = mid + 1
        else:
            hi = mid
    return lo


@njit(cache=True)
def _follow(
    path: np.ndarray,
    seg_len: np.ndarray,
    arc: np.ndarray,
    progress: float,
    lookahead: float,
    x: float,
    y: float,
) -> tuple[float, float, float, float]:
    """One pure-pursuit step on ``path`` for an agent at (x, y) (map frame, m).

    path: float (K, 2) waypoints (K >= 1); seg_len: (K-1,) segment lengths; arc: (K,) arc
    length at each waypoint; progress: arc length (m) of the agent's progress point.
    Returns (distance to the last waypoint, new progress, lookahead target x, y), all m.

    The progress point moves forward to the closest point on the path nearby: only
    segments starting within two lookaheads of the current progress are searched, so a
    path that passes near itself does not make the agent skip ahead. The target is the
    path point one lookahead beyond it. The arithmetic repeats ``_follow_reference``
    operation for operation (math.hypot here is the C hypot, as np.hypot), so both give
    identical floats.
    """
    last_x, last_y = path[path.shape[0] - 1, 0], path[path.shape[0] - 1, 1]
    to_goal = math.hypot(last_x - x, last_y - y)
    segments = seg_len.size
    if segments > 0:
        first = min(_search_right(arc, progress) - 1, segments - 1)
        last = min(max(_search_right(arc, progress + 2 * lookahead), first + 1), segments)
        best_gap, best_arc = np.inf, 0.0
        for i in range(first, last):
            ax, ay = path[i, 0], path[i, 1]
            dx, dy = path[i + 1, 0] - ax, path[i + 1, 1] - ay
            t = ((x - ax) * dx + (y - ay) * dy) / max(seg_len[i] * seg_len[i], 1e-18)
            t = min(max(t, 0.0), 1.0)
            gap = math.hypot(ax + t * dx - x, ay + t * dy - y)
            if gap < best_gap:  # the first of equal gaps, as np.argmin
                best_gap, best_arc = gap, arc[i] + t * seg_len[i]
        progress = max(progress, best_arc)
    target_arc = progress + lookahead
    if target_arc >= arc[arc.size - 1]:
        return to_goal, progress, last_x, last_y
    i = _search_right(arc, target_arc) - 1
    t = (target_arc - arc[i]) / max(seg_len[i], 1e-18)
    target_x = path[i, 0] + t * (path[i + 1, 0] - path[i, 0])
    target_y = path[i, 1] + t * (path[i + 1, 1] - path[i, 1])
    return to_goal, progress, target_x, target_y


@njit(cache=True)
def follow_command(
    path: tuple, progress: float, gains: tuple, limits: tuple, pose: tuple
) -> tuple[float, float, float, bool]:
    """:meth:`PathFollower.command`'s step for a path not yet done: (v (m/s), w (rad/s),
    new progress (m), done).

    path: (waypoints (K, 2), segment lengths (K-1,), arc lengths (K,)) as
    :meth:`PathFollower.set_path` keeps them; progress: the progress point's arc length
    (m); gains: (lookahead m, goal_tolerance m, rotate_threshold rad, turn_gain 1/s);
    limits: (v_max m/s, w_max rad/s); pose: the agent's (x, y, theta) (m, m, rad). The
    float operations are those of the Python controller it replaced (Python's hypot and
    angle wrap through :mod:`pegame.numerics`), so the commands are the same bits;
    batched strategies call it per game.
    """
    waypoints, seg_len, arc = path
    lookahead, goal_tolerance, rotate_threshold, turn_gain = gains
    v_max, w_max = limits
    x, y, theta = pose
    to_goal, progress, target_x, target_y = _follow(
        waypoints, seg_len, arc, progress, lookahead, x, y
    )
    if to_goal <= goal_tolerance:
        return 0.0, 0.0, progress, True
    dx, dy = target_x - x, target_y - y
    error = wrap_angle(math.atan2(dy, dx) - theta)
    if abs(error) > rotate_threshold:
        return 0.0, _clamp(turn_gain * error, w_max), progress, False
    # Pure pursuit: the arc through the target tangent to the heading has curvature
    # 2 sin(error) / distance.
    curvature = 2.0 * math.sin(error) / max(hypot(dx, dy), 1e-9)
    remaining = arc[arc.size - 1] - progress
    v = v_max * min(1.0, max(remaining, to_goal) / lookahead)
    if abs(curvature) * v > w_max:
        v = w_max / abs(curvature)
    return v, _clamp(curvature * v, w_max), progress, False


@njit(cache=True, inline="always")
def _clamp(value: float, limit: float) -> float:
    """:func:`pegame.types.clamp` in numba code."""
    return min(max(value, -limit), limit)


def _follow_reference(
    path: np.ndarray,
    seg_len: np.ndarray,
    arc: np.ndarray,
    progress: float,
    lookahead: float,
    x: float,
    y: float,
) -> tuple[float, float, float, float]:
    """Plain numpy reference of :func:`_follow`, same arguments and result."""
    xy = np.array([x, y])
    to_goal = float(np.hypot(*(path[-1] - xy)))
    if len(seg_len) > 0:
        first = int(np.searchsorted(arc, progress, side="right")) - 1
        first = min(first, len(seg_len) - 1)
        last = int(np.searchsorted(arc, progress + 2 * lookahead, side="right"))
        last = min(max(last, first + 1), len(seg_len))
        a = path[first:last]
        d = path[first + 1 : last + 1] - a
        lengths = seg_len[first:last]
        t = np.einsum("ij,ij->i", xy - a, d) / np.maximum(lengths**2, 1e-18)
        t = np.clip(t, 0.0, 1.0)
        gap = np.hypot(*(a + t[:, None] * d - xy).T)
        best = int(np.argmin(gap))
        progress = max(progress, float(arc[first + best] + t[best] * lengths[best]))
    target_arc = progress + lookahead
    if target_arc >= arc[-1]:
        target = path[-1]
    else:
        i = int(np.searchsorted(arc, target_arc, side="right")) - 1
        t = (target_arc - arc[i]) / max(seg_len[i], 1e-18)
        target = path[i] + t * (path[i + 1] - path[i])
    return to_goal, progress, float(target[0]), float(target[1])


class PathFollower:
    """Pure-pursuit controller that drives a unicycle along a waypoint path.

    body: the agent's limits (v_max m/s, w_max rad/s). lookahead (m): arc length ahead of
    the agent's progress point that it steers towards. goal_tolerance (m): the path is
    done once the agent is this close to its last waypoint. rotate_threshold (rad): above
    this heading error to the lookahead point the agent turns in place. turn_gain (1/s):
    turn rate per radian of heading error when turning in place.
    """

    def __init__(
        self,
        body: Body,
        lookahead: float = 0.5,
        goal_tolerance: float = 0.15,
        rotate_threshold: float = math.pi / 3,
        turn_gain: float = 2.0,
    ) -> None:
        require(lookahead > 0, "PathFollower.lookahead", "> 0", lookahead)
        require(goal_tolerance >= 0, "PathFollower.goal_tolerance", ">= 0", goal_tolerance)
        self.body = body
        self.lookahead = lookahead
        self.goal_tolerance = goal_tolerance
        self.rotate_threshold = rotate_threshold
        self.turn_gain = turn_gain
        self.set_path(np.zeros((0, 2)))

    def set_path(self, path: ArrayLike) -> None:
        """Follow ``path``, float (K, 2) map-frame waypoints (m); an empty path stops."""
        self.path = np.ascontiguousarray(np.asarray(path, dtype=float).reshape(-1, 2))
        seg = np.diff(self.path, axis=0)
        self._seg_len = np.hypot(seg[:, 0], seg[:, 1])
        self._arc = np.concatenate([[0.0], np.cumsum(self._seg_len)])  # arc length at waypoints
        self._progress = 0.0  # arc length (m) of the agent's progress point; only grows
        self._done = len(self.path) == 0

    @property
    def done(self) -> bool:
        """True once the agent came within goal_tolerance of the last waypoint (or no path)."""
        return self._done

    @property
    def remaining(self) -> float:
        """Path length (m) from the agent's progress point to the end; 0 when done."""
        return 0.0 if self._done else float(self._arc[-1] - self._progress)

    def command(self, pose: Pose) -> Velocity:
        """The velocity command for the agent at ``pose`` (map frame).

        Turns in place (v = 0) when the heading error to the lookahead point exceeds
        rotate_threshold; otherwise drives the pure-pursuit arc through that point at a
        speed reduced within one lookahead of the goal and so that the turn rate stays
        within w_max (the kernel :func:`follow_command`).
        """
        if self._done:
            return STOP
        v, w, self._progress, self._done = follow_command(
            (self.path, self._seg_len, self._arc),
            self._progress,
            (self.lookahead, self.goal_tolerance, self.rotate_threshold, self.turn_gain),
            (self.body.v_max, self.body.w_max),
            (pose.x, pose.y, pose.theta),
        )
        return Velocity(v, w)
