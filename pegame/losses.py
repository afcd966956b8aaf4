"""Loss causes: why each loss of track happened, and how long it lasted.

A *loss* of the pair (pursuer i, evader j) is a tick at which pursuer i's detector stops
reporting evader j: detected at the tick before, not detected at this one (the search
before a pair's first detection is no loss). Each loss gets one cause, read from the
ground truth at the loss tick: the true poses, the pursuer's command over the tick that
led to it, the map and the camera. The first test that holds, in this precedence, names it:

``missed``
    the evader's centre is in view (inside the FOV wedge, within [near, far], in line of
    sight on the grid: :func:`pegame.visibility.in_view`, the point the oracle detector
    tests), yet no detection: the detector missed a geometrically visible
    evader (the perception model's misses, rate, latency and detection range; a 3D
    detector's miss in its rendered image).
``blocked``
    the pursuer was stopped by an obstacle: over the tick that led to the loss it covered
    less than half the chord its command (saturated to its body's limits, held for one
    control period) asked for (a collision with a wall in the grid simulator).
``turning``
    the pursuer turned in place: it moved less than :data:`STILL` of its top speed's
    distance in the tick while its heading changed (by more than :data:`TURNED`).
``bearing``
    the evader left the field of view sideways: |bearing of its centre| > fov / 2.
``occluded``
    behind an occluder: the line of sight to its centre crosses a blocked cell.
``far``
    beyond the camera's ``far`` range.
``near``
    closer than the camera's ``near`` range.

The geometric causes are disjoint from ``missed`` (the evader is in view or not); the
pursuer's own state comes before the geometry because it says why the camera did not
follow (a pursuer stuck at a wall or spinning on the spot loses an evader that then lies
sideways, behind a wall or out of range). The test is on the evader's centre, as the
oracle's is: a shoulder still showing past a corner (``in_view`` of the game's
ground truth, :func:`pegame.visibility.body_in_view`) does not make the loss a miss.

A loss ends when the pair's detector reports the evader again: its *time to reacquire*
(s) is the time from the loss tick to that detection. A loss still open when the game
ends counts the time up to the game's end in its cause's time lost, and no time to
reacquire. Teams: every (pursuer, evader) pair has its own losses, each counted once;
the counts and times of a game are summed over the pairs (so two pursuers losing the
same evader at once are two losses).

Reference: the paper measures the tracking success rate only (Table 1); the causes
answer its reader's question of which mechanism makes a track fail (pegame issue 29).
Units: times in s, positions in m and angles in rad in the map frame of
:mod:`pegame.grid`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from pegame.types import Body, Camera, Detection, Pose, Velocity, clamp, value_type, wrap_angle

if TYPE_CHECKING:  # pragma: no cover - typing only
    from pegame.api import Context
    from pegame.grid import OccupancyGrid

MISSED, BLOCKED, TURNING = "missed", "blocked", "turning"
BEARING, OCCLUDED, FAR, NEAR = "bearing", "occluded", "far", "near"
#: every cause, in precedence order (module docstring)
CAUSES = (MISSED, BLOCKED, TURNING, BEARING, OCCLUDED, FAR, NEAR)

#: a pursuer that moved less than this fraction of ``v_max * control_dt`` in a tick stood still
STILL = 0.05
#: a pursuer that covered less than this fraction of its command's chord was blocked
BLOCKED_FRACTION = 0.5
#: rad: a heading change above this in a tick is a turn
TURNED = 1e-9


@value_type
class Loss:
    """One loss of track: pursuer ``pursuer`` stopped detecting evader ``evader`` (member
    indices) at control tick ``step``, for ``cause`` (one of :data:`CAUSES`)."""

    pursuer: int
    evader: int
    step: int
    cause: str


def chord(command: Velocity, body: Body, dt: float) -> float:
    """Length (m) of the straight segment a unicycle covers in ``dt`` s holding ``command``
    saturated to ``body``'s limits (the arc of radius v / w seen end to end)."""
    v, w = clamp(command.v, body.v_max), clamp(command.w, body.w_max)
    half_turn = 0.5 * w * dt
    if abs(half_turn) < 1e-9:
        return abs(v) * dt
    return abs(v * dt * math.sin(half_turn) / half_turn)


def loss_cause(
    grid: OccupancyGrid,
    camera: Camera,
    body: Body,
    dt: float,
    before: Pose,
    after: Pose,
    command: Velocity,
    evader_xy: tuple[float, float],
) -> str:
    """The cause (module docstring) of a loss at a tick where the pursuer (``body``) is
    at ``after`` having held ``command`` for ``dt`` s from ``before``, and the evader's
    centre at ``evader_xy`` (map frame, m)."""
    # imported here, at a loss: pegame.api (Tick.losses) and the report import this module
    # without the visibility kernels
    from pegame.visibility import in_view, line_of_sight

    if in_view(grid, camera, after, evader_xy):
        return MISSED
    moved = math.hypot(after.x - before.x, after.y - before.y)
    asked = chord(command, body, dt)
    still = STILL * body.v_max * dt
    if asked > still and moved < BLOCKED_FRACTION * asked:
        return BLOCKED
    if moved <= still and abs(wrap_angle(after.theta - before.theta)) > TURNED:
        return TURNING
    dx, dy = evader_xy[0] - after.x, evader_xy[1] - after.y
    if abs(wrap_angle(math.atan2(dy, dx) - after.theta)) > 0.5 * camera.fov:
        return BEARING
    if not line_of_sight(grid, (after.x, after.y), evader_xy):
        return OCCLUDED
    # in_view failed on none of the above: the range is what is left
    return FAR if math.hypot(dx, dy) > camera.far else NEAR


class LossCauses:
    """Follows every (pursuer, evader) pair of one game tick by tick (module docstring);
    :meth:`summary` gives result.json's ``loss_causes``.

    context: the game's (map, camera, pursuer body, control period); pursuers, evaders:
    the team sizes N and M.
    """

    def __init__(self, context: Context, pursuers: int = 1, evaders: int = 1) -> None:
        self.context = context
        self.dt = context.control_dt
        self.ticks = 0
        self.detected = [[False] * evaders for _ in range(pursuers)]
        # each pursuer's pose and command at the previous tick (None before the first)
        self.before: Sequence[Pose | None] = (None,) * pursuers
        self.commands: Sequence[Velocity | None] = (None,) * pursuers
        self.open: dict[tuple[int, int], tuple[int, str]] = {}  # pair -> (loss tick, cause)
        self.ended: list[tuple[str, int]] = []  # (cause, ticks lost) of the reacquired losses

    def add_one(
        self, pursuer: Pose, evader: Pose, detected: bool, command: Velocity
    ) -> tuple[Loss, ...]:
        """Record one tick of a 1v1 game: the true poses, whether the evader is detected
        and the pursuer's command applied after this tick. Returns the loss begun at this
        tick, if any."""
        row = self.detected[0]
        losses: tuple[Loss, ...] = ()
        if detected != row[0]:  # rare: a loss or a (re)acquisition
            row[0] = detected
            losses = self._change(0, 0, detected, pursuer, evader)
        self.before, self.commands = (pursuer,), (command,)
        self.ticks += 1
        return losses

    def add(
        self,
        pursuers: Sequence[Pose],
        evaders: Sequence[Pose],
        detections: Sequence[Sequence[Detection | None]],
        commands: Sequence[Velocity],
    ) -> tuple[Loss, ...]:
        """Record one tick of a team game: the true poses, detections[i][j] of pursuer i
        and evader j, and the pursuers' commands applied after this tick. Returns the
        losses begun at this tick."""
        losses: tuple[Loss, ...] = ()
        for i, row in enumerate(detections):
            flags = self.detected[i]
            for j, detection in enumerate(row):
                seen = detection is not None
                if seen != flags[j]:
                    flags[j] = seen
                    losses += self._change(i, j, seen, pursuers[i], evaders[j])
        self.before, self.commands = tuple(pursuers), tuple(commands)
        self.ticks += 1
        return losses

    def _change(self, i: int, j: int, seen: bool, pursuer: Pose, evader: Pose) -> tuple[Loss, ...]:
        """Pair (i, j)'s detection changed at the current tick: close its open loss when
        ``seen``, else open a loss with its cause."""
        if seen:
            opened = self.open.pop((i, j), None)
            if opened is not None:
                self.ended.append((opened[1], self.ticks - opened[0]))
            return ()
        before, command = self.before[i], self.commands[i]
        assert before is not None and command is not None  # a loss follows a detected tick
        context = self.context
        cause = loss_cause(
            context.grid,
            context.camera,
            context.pursuer,
            self.dt,
            before,
            pursuer,
            command,
            (evader.x, evader.y),
        )
        self.open[(i, j)] = (self.ticks, cause)
        return (Loss(i, j, self.ticks, cause),)

    def summary(self) -> dict[str, dict[str, Any]]:
        """Per cause in :data:`CAUSES` order: ``count`` (losses), ``reacquired`` (of
        them, those detected again before the game's end), ``time_lost_s`` (s, open
        losses counted to the game's end) and ``mean_reacquire_s`` (s, the mean time to
        reacquire of the reacquired ones; None without any)."""
        lost: dict[str, list[int]] = {cause: [] for cause in CAUSES}
        reacquire: dict[str, list[int]] = {cause: [] for cause in CAUSES}
        for cause, ticks in self.ended:
            lost[cause].append(ticks)
            reacquire[cause].append(ticks)
        for start, cause in self.open.values():
            lost[cause].append(self.ticks - start)
        return {
            cause: {
                "count": len(lost[cause]),
                "reacquired": len(reacquire[cause]),
                "time_lost_s": round(sum(lost[cause]) * self.dt, 6),
                "mean_reacquire_s": (
                    round(sum(reacquire[cause]) * self.dt / len(reacquire[cause]), 6)
                    if reacquire[cause]
                    else None
                ),
            }
            for cause in CAUSES
        }
