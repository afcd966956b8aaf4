"""What the pursuer's camera gives in a batched game, per game: the oracle detector and
the ground truth in_view, the same tests and float operations as the plain code.

- :func:`segment_clear` is :func:`pegame.visibility.sight._segment_clear` (the same
  samples, found in a vectorised pass);
- :func:`point_in_view` and :func:`body_in_view` are :func:`pegame.visibility.in_view` and
  :func:`pegame.visibility.body_in_view`;
- :func:`hidden_fraction` is :func:`pegame.detectors.perception.hidden_fraction`;
- :func:`detect` is the oracle detector's capture
  (:class:`pegame.detectors.oracle.OracleDetector`: FOV, range and line of sight of the
  evader's centre, the range and occlusion misses of the perception model
  (:func:`pegame.detectors.perception.miss_chance`, each game's 'range' stream drawn
  ahead), then the pinhole box and the depth back-projection);
- :func:`sense` is the loop's ``_sense`` (detection, then in_view) with the pursuer
  observation's memory of the last detection; the detection goes through the perception
  model's pipeline (rate and latency: :func:`pegame.detectors.perception.frame_due` and
  :func:`pegame.detectors.perception.deliver_frame`, the kernels the scalar detector runs
  on a batch of one) when it runs.

Python's ``math.hypot`` and :func:`pegame.types.wrap_angle` come from
:mod:`pegame.numerics`. ``tests/vector/test_kernels.py`` compares them with the plain
functions.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from pegame.detectors.perception import deliver_frame, frame_due, miss_chance
from pegame.grid.occupancy import COS_YAW, OX, OY, RESOLUTION, ROTATED, SIN_YAW
from pegame.numerics import (
    cell_by_division,
    cell_by_product,
    hypot,
    hypot_within,
    wrap_angle,
)
from pegame.vector.state import (
    BODY_HEIGHT,
    BOX_H,
    BOX_W,
    BOX_X,
    BOX_Y,
    CAMERA_HEIGHT,
    DEPTH,
    DETECTION_RANGE,
    EVADER,
    FAR,
    FOCAL,
    FOV,
    IMAGE_HEIGHT,
    IMAGE_WIDTH,
    LATENCY,
    MISS_AT_RANGE,
    MISS_START,
    MISSES,
    NEAR,
    OCCLUSION_MISS,
    PERIOD,
    PIPELINE,
    PURSUER,
    RADIUS,
    RATED,
    SEEN_X,
    SEEN_Y,
    BatchState,
    Rules,
    World,
)
from pegame.visibility.sight import SILHOUETTE

_SILHOUETTE = np.array(SILHOUETTE)

#: line-of-sight samples whose cells are found together (one vectorised pass)
_CHUNK = 32


@njit(cache=True, inline="always")
def _sample_cells(
    frame: np.ndarray,
    height: int,
    width: int,
    ax: float,
    ay: float,
    bx: float,
    by: float,
    count: int,
    start: int,
    size: int,
    cells: np.ndarray,
    rotated: bool,
) -> bool:
    """The cells (1 + flat index, 0 off the grid) of samples start..start + size - 1 of
    the segment into ``cells`` by :func:`pegame.numerics.cell_by_product`; returns
    whether all are decided. Inlined with ``rotated`` a constant (no branch in the loop).
    """
    inverse = 1.0 / frame[RESOLUTION]
    decided = True
    for j in range(size):
        u, v = _sample_point(frame, ax, ay, bx, by, start + j, count, rotated)
        cells[j], ok = cell_by_product(u, v, inverse, height, width)
        decided &= ok
    return decided


@njit(cache=True, inline="always")
def _sample_point(
    frame: np.ndarray,
    ax: float,
    ay: float,
    bx: float,
    by: float,
    k: int,
    count: int,
    rotated: bool,
) -> tuple[float, float]:
    """Grid-frame point (u, v) (m) of sample k of count along the segment from (ax, ay)
    to (bx, by), as :func:`pegame.visibility.sight._segment_clear` places it (the last
    one at (bx, by) itself)."""
    t = k * (1.0 / count)
    x, y = (bx, by) if k == count else (ax + t * (bx - ax), ay + t * (by - ay))
    u = x - frame[OX]
    v = y - frame[OY]
    if rotated:
        u, v = frame[COS_YAW] * u + frame[SIN_YAW] * v, -frame[SIN_YAW] * u + frame[COS_YAW] * v
    return u, v


@njit(cache=True)
def segment_clear(
    frame: np.ndarray,
    blocked: np.ndarray,
    values: np.ndarray,
    ax: float,
    ay: float,
    bx: float,
    by: float,
    step: float,
) -> bool:
    """:func:`pegame.visibility.sight._segment_clear` on the grid: True when no sample of
    the segment from (ax, ay) to (bx, by) (m), ``step`` m apart, lies in a blocked or
    off-grid cell. The same samples and cells (the tests compare the two), found
    _CHUNK at a time from products (:func:`pegame.numerics.cell_by_product`; a chunk
    with a sample near a cell edge is found again by the division), then looked up in
    ``values`` = world.sight_values (entry 0: off the grid, blocked); the test stops at
    the first chunk with a blocked cell. ``frame``, ``blocked``: world.frame and
    world.blocked. (The functions here take the world's arrays, not the World: an
    inlined function given a NamedTuple pays a reference count per array.)"""
    height, width = blocked.shape
    rotated = frame[ROTATED] != 0.0
    count = max(1, math.ceil(math.hypot(bx - ax, by - ay) / step))
    cells = np.empty(_CHUNK, np.int64)
    for start in range(0, count + 1, _CHUNK):
        size = min(_CHUNK, count + 1 - start)
        if rotated:
            decided = _sample_cells(
                frame, height, width, ax, ay, bx, by, count, start, size, cells, True
            )
        else:
            decided = _sample_cells(
                frame, height, width, ax, ay, bx, by, count, start, size, cells, False
            )
        if not decided:
            for j in range(size):
                u, v = _sample_point(frame, ax, ay, bx, by, start + j, count, rotated)
                cells[j] = cell_by_division(u, v, frame[RESOLUTION], height, width)
        for j in range(size):
            if values[cells[j]]:
                return False
    return True


@njit(cache=True, inline="always")
def point_in_view(
    frame: np.ndarray,
    blocked: np.ndarray,
    values: np.ndarray,
    camera: np.ndarray,
    px: float,
    py: float,
    ptheta: float,
    x: float,
    y: float,
) -> bool:
    """:func:`pegame.visibility.in_view` of the map point (x, y) (m) from the camera at
    (px, py, ptheta)."""
    dx, dy = x - px, y - py
    if not hypot_within(dx, dy, camera[NEAR], camera[FAR]):
        return False
    if abs(wrap_angle(math.atan2(dy, dx) - ptheta)) > 0.5 * camera[FOV]:
        return False
    return segment_clear(frame, blocked, values, px, py, x, y, 0.5 * frame[RESOLUTION])


@njit(cache=True, inline="always")
def body_in_view(
    frame: np.ndarray,
    blocked: np.ndarray,
    values: np.ndarray,
    camera: np.ndarray,
    px: float,
    py: float,
    ptheta: float,
    x: float,
    y: float,
    radius: float,
    centre: bool,
) -> bool:
    """:func:`pegame.visibility.body_in_view`: any SILHOUETTE point of the body of
    ``radius`` m at (x, y) in view; ``centre``: whether its centre (the first point,
    x + 0 = x) is, already known from the detector."""
    if centre:
        return True
    dx, dy = x - px, y - py
    distance = hypot(dx, dy)
    ax, ay = (-dy / distance, dx / distance) if distance > 0.0 else (0.0, 0.0)
    for k in _SILHOUETTE[1:]:
        if point_in_view(
            frame, blocked, values, camera, px, py, ptheta, x + k * radius * ax, y + k * radius * ay
        ):
            return True
    return False


@njit(cache=True, inline="always")
def hidden_fraction(
    frame: np.ndarray,
    blocked: np.ndarray,
    values: np.ndarray,
    camera: np.ndarray,
    px: float,
    py: float,
    ptheta: float,
    x: float,
    y: float,
    radius: float,
) -> float:
    """:func:`pegame.detectors.perception.hidden_fraction`: the fraction of the SILHOUETTE
    points of the body of ``radius`` m at (x, y) not in view of the camera at (px, py,
    ptheta)."""
    dx, dy = x - px, y - py
    distance = hypot(dx, dy)
    ax, ay = (-dy / distance, dx / distance) if distance > 0.0 else (0.0, 0.0)
    hidden = 0
    for k in _SILHOUETTE:
        if not point_in_view(
            frame, blocked, values, camera, px, py, ptheta, x + k * radius * ax, y + k * radius * ay
        ):
            hidden += 1
    return hidden / _SILHOUETTE.size


@njit(cache=True, inline="always")
def detect(
    frame: np.ndarray,
    blocked: np.ndarray,
    values: np.ndarray,
    camera: np.ndarray,
    perception: np.ndarray,
    radius: float,
    poses: np.ndarray,
    draws: np.ndarray,
    drawn: np.ndarray,
    detected: np.ndarray,
    detection: np.ndarray,
    game: int,
) -> bool:
    """The oracle detector's capture for ``game``'s current poses (state.poses) into
    ``detected`` and ``detection`` (rows of the game; ``camera``: rules.camera,
    ``perception``: rules.perception, ``radius``: the evader's; a range or occlusion miss
    takes the next of the game's ``draws``, counted in ``drawn``). Returns whether the
    evader's centre is in view."""
    cx, cy, ctheta = poses[game, PURSUER, 0], poses[game, PURSUER, 1], poses[game, PURSUER, 2]
    ex, ey = poses[game, EVADER, 0], poses[game, EVADER, 1]
    detected[game] = False
    if not point_in_view(frame, blocked, values, camera, cx, cy, ctheta, ex, ey):
        return False
    distance = hypot(ex - cx, ey - cy)
    if not distance <= camera[DETECTION_RANGE]:
        return True
    if perception[MISSES] != 0.0:
        hidden = 0.0
        if perception[OCCLUSION_MISS] > 0.0:
            hidden = hidden_fraction(frame, blocked, values, camera, cx, cy, ctheta, ex, ey, radius)
        chance = miss_chance(
            distance,
            hidden,
            camera[DETECTION_RANGE],
            perception[MISS_START],
            perception[MISS_AT_RANGE],
            perception[OCCLUSION_MISS],
        )
        draw = draws[game, drawn[game]]
        drawn[game] += 1
        if draw < chance:
            return True
    bearing = wrap_angle(math.atan2(ey - cy, ex - cx) - ctheta)
    depth = distance * math.cos(bearing)
    depth = depth if depth > camera[NEAR] else camera[NEAR]
    # pinhole_box
    width, height, focal = camera[IMAGE_WIDTH], camera[IMAGE_HEIGHT], camera[FOCAL]
    ratio = radius / distance
    half = math.asin(ratio if ratio < 1.0 else 1.0)
    left = 0.5 * width - focal * math.tan(bearing + half)
    left = left if left > 0.0 else 0.0
    right = 0.5 * width - focal * math.tan(bearing - half)
    right = right if right < width else width
    middle = 0.5 * height
    top = middle - focal * (camera[BODY_HEIGHT] - camera[CAMERA_HEIGHT]) / depth
    top = top if top > 0.0 else 0.0
    bottom = middle + focal * camera[CAMERA_HEIGHT] / depth
    bottom = bottom if bottom < height else height
    box_w = right - left
    centre = left + 0.5 * box_w
    seen_bearing = math.atan2(0.5 * width - centre, focal)
    seen_range = depth / math.cos(seen_bearing)
    heading = ctheta + seen_bearing
    out, g = detection, game
    out[g, BOX_X], out[g, BOX_Y], out[g, BOX_W], out[g, BOX_H] = left, top, box_w, bottom - top
    out[g, DEPTH] = depth
    out[g, SEEN_X] = cx + seen_range * math.cos(heading)
    out[g, SEEN_Y] = cy + seen_range * math.sin(heading)
    detected[game] = True
    return True


@njit(cache=True, inline="always")
def sense(world: World, rules: Rules, state: BatchState, game: int) -> None:
    """The loop's ``_sense`` for ``game`` (detection, then ground truth in_view) and the
    pursuer observation's memory of the last detection (``PursuerFeatures.remember``).
    When the perception pipeline runs, a frame is captured only when one is due (into
    state.capture), put in flight, and the result delivered by then goes into
    state.detected and state.detection (the held one stays when none is); else the
    capture is the detection. The caller inlines it once per game, so that the
    NamedTuples' arrays are taken out once (and :func:`detect` is inlined once)."""
    frame, blocked, values = world.frame, world.blocked, world.sight_values
    camera, perception, radius = rules.camera, rules.perception, rules.bodies[EVADER, RADIUS]
    poses, detected, detection = state.poses, state.detected, state.detection
    time = state.steps[game] * rules.control_dt
    pipeline = perception[PIPELINE] != 0.0
    period, rated = perception[PERIOD], perception[RATED] != 0.0
    due = True
    if pipeline:
        due, _ = frame_due(state.pipeline, game, time, period, rated)
    px, py, ptheta = poses[game, PURSUER, 0], poses[game, PURSUER, 1], poses[game, PURSUER, 2]
    ex, ey = poses[game, EVADER, 0], poses[game, EVADER, 1]
    if due:
        out, rows = (state.captured, state.capture) if pipeline else (detected, detection)
        centre = detect(
            frame,
            blocked,
            values,
            camera,
            perception,
            radius,
            poses,
            state.draws,
            state.drawn,
            out,
            rows,
            game,
        )
    else:
        centre = point_in_view(frame, blocked, values, camera, px, py, ptheta, ex, ey)
    if pipeline:
        latency = perception[LATENCY]
        slot_in, slot_out, _ = deliver_frame(
            state.pipeline, game, time, period, rated, latency, due
        )
        if slot_in >= 0:
            state.in_flight_detected[game, slot_in] = state.captured[game]
            state.in_flight[game, slot_in, :] = state.capture[game, :]
        if slot_out >= 0:
            detected[game] = state.in_flight_detected[game, slot_out]
            detection[game, :] = state.in_flight[game, slot_out, :]
    state.in_view[game] = body_in_view(
        frame, blocked, values, camera, px, py, ptheta, ex, ey, radius, centre
    )
    if detected[game]:
        seen = state.seen
        seen[game, 0] = time
        seen[game, 1] = detection[game, SEEN_X]
        seen[game, 2] = detection[game, SEEN_Y]
        state.has_seen[game] = True
