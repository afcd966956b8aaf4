"""Numba kernels of the batched game: one control tick of many games at once.

Each kernel loops over the games, from PARALLEL_GAMES games on with ``prange`` (numba's
thread pool, across cores: ``NUMBA_NUM_THREADS`` sets how many); inside a game the work is the single game's, in the
same order and with the same float operations, so a game played here is the game the
plain-Python code plays (``tests/test_vector_env.py`` compares them step by step):

- :func:`move` is :class:`pegame.sims.grid.GridSimulator`'s agent move (saturation,
  acceleration limits, exact unicycle arc, the swept collision check
  :func:`pegame.sims.grid._sweep` itself);
- :func:`point_in_view` and :func:`body_in_view` are :func:`pegame.visibility.in_view` and
  :func:`pegame.visibility.body_in_view`, the line of sight :func:`segment_clear` that of
  :func:`pegame.visibility.sight._segment_clear`;
- :func:`detect` is the oracle detector with every part of the perception model off
  (:class:`pegame.detectors.oracle.OracleDetector`: FOV, range and line of sight of the
  evader's centre, then the pinhole box and the depth back-projection);
- :func:`features` (per game ``_pursuer_row`` and ``_evader_row``) is
  :class:`pegame.envs.observations.PursuerFeatures` and ``EvaderFeatures``, with the crop
  of :func:`pegame.envs.crop._crop` (:func:`crop_into`);
- :func:`tally` accumulates :class:`pegame.metrics.TrackingMetrics` as running sums
  (:mod:`pegame.vector.metrics` turns them into its summary).

Python's ``math.hypot`` and :func:`pegame.types.wrap_angle` come from
:mod:`pegame.vector.exact` (numba's own round differently). Units: SI, map frame.

The fixed numbers of a game are two tuples built by :mod:`pegame.vector.game`:
``world`` (:class:`World`) and ``rules`` (:class:`Rules`); the games' changing state is
one :class:`BatchState` of arrays whose first axis is the game.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit, prange

from pegame.envs.observations import AGE_SCALE
from pegame.sims.grid import _sweep
from pegame.vector.exact import hypot, wrap_angle
from pegame.visibility.sight import SILHOUETTE

PURSUER, EVADER = 0, 1

#: columns of ``rules.bodies``
RADIUS, V_MAX, W_MAX, A_MAX, ALPHA_MAX = range(5)
#: entries of ``rules.camera``
FOV, NEAR, FAR, IMAGE_WIDTH, IMAGE_HEIGHT, FOCAL, DETECTION_RANGE, BODY_HEIGHT, CAMERA_HEIGHT = (
    range(9)
)
#: columns of ``state.detection``: the box (px), the depth (m) and the map position (m)
BOX_X, BOX_Y, BOX_W, BOX_H, DEPTH, SEEN_X, SEEN_Y = range(7)
#: columns of ``state.tally`` (counts are exact in float64)
(
    TICKS,
    DETECTED,
    IN_VIEW,
    IN_LOSS,
    LOSS_START,
    FIRST_LOSS,
    LONGEST_LOSS,
    REACQUISITIONS,
    REACQUIRE_SUM,
    REACQUIRE_MAX,
    DISTANCE_SUM,
    PURSUER_PATH,
    EVADER_PATH,
    LAST_PX,
    LAST_PY,
    LAST_EX,
    LAST_EY,
) = range(17)
TALLY_SIZE = 17

_SILHOUETTE = np.array(SILHOUETTE)

#: batches of at least this many games are spread over numba's threads (prange); below,
#: starting the threads costs more than it saves, most of all on a busy machine
PARALLEL_GAMES = 256


class World(NamedTuple):
    """The map as the kernels read it.

    blocked: the grid's blocked cells; frame: its ``kernel_frame`` as a float64 array (a
    tuple of mixed types cannot enter numba's parallel loops); masks: (2, H, W) the
    grid inflated by the pursuer's and the evader's radius (the simulator's collision
    masks); pooled, crop_x, crop_y, crop_frame: the crop's pooled map, robot-frame cell
    offsets (m) and its map-to-cell numbers (:class:`pegame.envs.crop.LocalCrop`, float64);
    extent: (x0, y0, 2 / width, 2 / height, diagonal) of the observations' normalisation.
    """

    blocked: np.ndarray
    frame: np.ndarray
    masks: np.ndarray
    pooled: np.ndarray
    crop_x: np.ndarray
    crop_y: np.ndarray
    crop_frame: np.ndarray
    extent: np.ndarray


class Rules(NamedTuple):
    """The game's fixed numbers.

    bodies: (2, 5) float64 per role (pursuer, evader): radius (m), v_max (m/s), w_max
    (rad/s), a_max (m/s^2), alpha_max (rad/s^2); camera: float64 (9,) as the constants
    FOV..CAMERA_HEIGHT; control_dt (s); substeps per control tick; decide_every: control
    ticks per decision; ticks: control ticks per game.
    """

    bodies: np.ndarray
    camera: np.ndarray
    control_dt: float
    substeps: int
    decide_every: int
    ticks: int


class BatchState(NamedTuple):
    """The games' state, first axis the game.

    poses (N, 2, 3): (x, y, theta) per role; velocities (N, 2, 2): the current (v, w) of
    bodies with acceleration limits; commands (N, 2, 2): this tick's (v, w) commands;
    steps (N,): control ticks played; detected (N,): the current tick's detection;
    detection (N, 7): its box, depth and position (columns BOX_X..SEEN_Y); in_view (N,);
    seen (N, 3): time (s) and position of the last detection, for the pursuer's
    observation, with has_seen (N,); tally (N, TALLY_SIZE): the metrics' running sums;
    rewards (N,): detections counted in the current env step.
    """

    poses: np.ndarray
    velocities: np.ndarray
    commands: np.ndarray
    steps: np.ndarray
    detected: np.ndarray
    detection: np.ndarray
    in_view: np.ndarray
    seen: np.ndarray
    has_seen: np.ndarray
    tally: np.ndarray
    rewards: np.ndarray


def new_state(num_games: int) -> BatchState:
    """Zeroed state for ``num_games`` games."""
    n = num_games
    return BatchState(
        np.zeros((n, 2, 3)),
        np.zeros((n, 2, 2)),
        np.zeros((n, 2, 2)),
        np.zeros(n, np.int64),
        np.zeros(n, np.bool_),
        np.zeros((n, 7)),
        np.zeros(n, np.bool_),
        np.zeros((n, 3)),
        np.zeros(n, np.bool_),
        np.zeros((n, TALLY_SIZE)),
        np.zeros(n),
    )


@njit(cache=True, inline="always")
def _clamp(value, limit):
    """:func:`pegame.types.clamp`: min(max(value, -limit), limit) with Python's min/max."""
    low = value if value > -limit else -limit
    return low if low < limit else limit


@njit(cache=True, inline="always")
def _ramp(current, target, limit):
    """:func:`pegame.sims.grid._ramp`."""
    if math.isinf(limit):
        return target
    return current + _clamp(target - current, limit)


@njit(cache=True)
def move(world, rules, state, game, role, dt):
    """Move ``role`` of ``game`` by its command for ``dt`` s (the grid simulator's move)."""
    body = rules.bodies[role]
    pose = state.poses[game, role]
    x0, y0, theta0 = pose[0], pose[1], pose[2]
    v = _clamp(state.commands[game, role, 0], body[V_MAX])
    w = _clamp(state.commands[game, role, 1], body[W_MAX])
    limited = not (math.isinf(body[A_MAX]) and math.isinf(body[ALPHA_MAX]))
    if limited:
        v = _ramp(state.velocities[game, role, 0], v, body[A_MAX] * dt)
        w = _ramp(state.velocities[game, role, 1], w, body[ALPHA_MAX] * dt)
    theta = theta0 + w * dt
    if abs(w) < 1e-9:
        dx, dy = v * dt * math.cos(theta0), v * dt * math.sin(theta0)
    else:
        radius = v / w
        dx = radius * (math.sin(theta) - math.sin(theta0))
        dy = -radius * (math.cos(theta) - math.cos(theta0))
    tx, ty = x0 + dx, y0 + dy
    n = max(1, math.ceil(2 * hypot(tx - x0, ty - y0) / world.frame[5]))
    x, y = _sweep(world.masks[role], x0, y0, tx, ty, n, world.frame)
    pose[0], pose[1], pose[2] = x, y, wrap_angle(theta)
    if limited:
        stopped = hypot(tx - x, ty - y) > 1e-9
        state.velocities[game, role, 0] = 0.0 if stopped else v
        state.velocities[game, role, 1] = w


#: line-of-sight samples whose cells are found together (one vectorised pass)
_CHUNK = 32


@njit(cache=True)
def segment_clear(world, ax, ay, bx, by, step):
    """:func:`pegame.visibility.sight._segment_clear` on the grid: True when no sample of
    the segment from (ax, ay) to (bx, by) (m), ``step`` m apart, lies in a blocked or
    off-grid cell. The same samples and cells (the tests compare the two), found
    _CHUNK at a time in a loop that LLVM vectorises, then looked up; the test stops at
    the first chunk with a blocked cell."""
    frame, blocked = world.frame, world.blocked
    height, width = blocked.shape
    flat = blocked.ravel()
    ox, oy, gc, gs, rotated, res = frame[0], frame[1], frame[2], frame[3], frame[4] != 0.0, frame[5]
    count = max(1, math.ceil(math.hypot(bx - ax, by - ay) / step))
    dx, dy = bx - ax, by - ay
    dt = 1.0 / count
    cells = np.empty(_CHUNK, np.int64)
    for start in range(0, count + 1, _CHUNK):
        size = min(_CHUNK, count + 1 - start)
        for j in range(size):
            k = start + j
            t = 1.0 if k == count else k * dt
            u = ax + t * dx - ox
            v = ay + t * dy - oy
            if rotated:
                u, v = gc * u + gs * v, -gs * u + gc * v
            qc, qr = u / res, v / res
            inside = (qr >= 0.0) & (qr < height) & (qc >= 0.0) & (qc < width)
            cells[j] = np.int64(qr) * width + np.int64(qc) if inside else -1
        for j in range(size):
            cell = cells[j]
            if cell < 0 or flat[cell]:
                return False
    return True


@njit(cache=True)
def point_in_view(world, camera, px, py, ptheta, x, y):
    """:func:`pegame.visibility.in_view` of the map point (x, y) (m) from the camera at
    (px, py, ptheta)."""
    dx, dy = x - px, y - py
    distance = hypot(dx, dy)
    if not camera[NEAR] <= distance <= camera[FAR]:
        return False
    if abs(wrap_angle(math.atan2(dy, dx) - ptheta)) > 0.5 * camera[FOV]:
        return False
    return segment_clear(world, px, py, x, y, 0.5 * world.frame[5])


@njit(cache=True)
def body_in_view(world, camera, px, py, ptheta, x, y, radius, centre):
    """:func:`pegame.visibility.body_in_view`: any SILHOUETTE point of the body of
    ``radius`` m at (x, y) in view; ``centre``: whether its centre (the first point,
    x + 0 = x) is, already known from the detector."""
    if centre:
        return True
    dx, dy = x - px, y - py
    distance = hypot(dx, dy)
    ax, ay = (-dy / distance, dx / distance) if distance > 0.0 else (0.0, 0.0)
    for k in _SILHOUETTE[1:]:
        if point_in_view(world, camera, px, py, ptheta, x + k * radius * ax, y + k * radius * ay):
            return True
    return False


@njit(cache=True)
def detect(world, rules, state, game):
    """The oracle detector's capture for ``game``'s current poses, into state.detected
    and state.detection (the pipeline's parts all off). Returns whether the evader's
    centre is in view."""
    camera = rules.camera
    cx, cy, ctheta = state.poses[game, PURSUER]
    ex, ey = state.poses[game, EVADER, 0], state.poses[game, EVADER, 1]
    state.detected[game] = False
    if not point_in_view(world, camera, cx, cy, ctheta, ex, ey):
        return False
    distance = hypot(ex - cx, ey - cy)
    if not distance <= camera[DETECTION_RANGE]:
        return True
    bearing = wrap_angle(math.atan2(ey - cy, ex - cx) - ctheta)
    depth = distance * math.cos(bearing)
    depth = depth if depth > camera[NEAR] else camera[NEAR]
    # pinhole_box
    width, height, focal = camera[IMAGE_WIDTH], camera[IMAGE_HEIGHT], camera[FOCAL]
    ratio = rules.bodies[EVADER, RADIUS] / distance
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
    out = state.detection[game]
    out[BOX_X], out[BOX_Y], out[BOX_W], out[BOX_H] = left, top, box_w, bottom - top
    out[DEPTH] = depth
    out[SEEN_X] = cx + seen_range * math.cos(heading)
    out[SEEN_Y] = cy + seen_range * math.sin(heading)
    state.detected[game] = True
    return True


@njit(cache=True)
def sense(world, rules, state, game):
    """The loop's ``_sense`` for ``game`` (detection, then ground truth in_view) and the
    pursuer observation's memory of the last detection (``PursuerFeatures.remember``)."""
    centre = detect(world, rules, state, game)
    px, py, ptheta = state.poses[game, PURSUER]
    ex, ey = state.poses[game, EVADER, 0], state.poses[game, EVADER, 1]
    state.in_view[game] = body_in_view(
        world, rules.camera, px, py, ptheta, ex, ey, rules.bodies[EVADER, RADIUS], centre
    )
    if state.detected[game]:
        state.seen[game, 0] = state.steps[game] * rules.control_dt
        state.seen[game, 1] = state.detection[game, SEEN_X]
        state.seen[game, 2] = state.detection[game, SEEN_Y]
        state.has_seen[game] = True


@njit(cache=True)
def tally(state, game, dt):
    """``TrackingMetrics.add`` for ``game``'s current tick, as running sums (no belief)."""
    row = state.tally[game]
    px, py = state.poses[game, PURSUER, 0], state.poses[game, PURSUER, 1]
    ex, ey = state.poses[game, EVADER, 0], state.poses[game, EVADER, 1]
    tick = row[TICKS]
    if tick > 0:
        dx, dy = px - row[LAST_PX], py - row[LAST_PY]
        row[PURSUER_PATH] += math.sqrt(dx * dx + dy * dy)
        dx, dy = ex - row[LAST_EX], ey - row[LAST_EY]
        row[EVADER_PATH] += math.sqrt(dx * dx + dy * dy)
    row[LAST_PX], row[LAST_PY], row[LAST_EX], row[LAST_EY] = px, py, ex, ey
    dx, dy = px - ex, py - ey
    row[DISTANCE_SUM] += math.sqrt(dx * dx + dy * dy)
    row[IN_VIEW] += state.in_view[game]
    if state.detected[game]:
        row[DETECTED] += 1.0
        if row[IN_LOSS]:
            length = tick - row[LOSS_START]
            row[LONGEST_LOSS] = max(row[LONGEST_LOSS], length)
            row[REACQUISITIONS] += 1.0
            row[REACQUIRE_SUM] += length * dt
            row[REACQUIRE_MAX] = max(row[REACQUIRE_MAX], length)
            row[IN_LOSS] = 0.0
    elif not row[IN_LOSS]:
        row[IN_LOSS], row[LOSS_START] = 1.0, tick
        if row[FIRST_LOSS] < 0:
            row[FIRST_LOSS] = tick
    row[TICKS] = tick + 1.0


@njit(cache=True)
def _play_tick(world, rules, state, game, table, table_role):
    """One control tick of ``game`` in the loop's order (see :mod:`pegame.vector.game`):
    the scripted command, the measures, the simulator's substeps, the next tick sensed."""
    if table_role >= 0:
        decision = state.steps[game] // rules.decide_every
        state.commands[game, table_role, 0] = table[game, decision, 0]
        state.commands[game, table_role, 1] = table[game, decision, 1]
    tally(state, game, rules.control_dt)
    dt = rules.control_dt / rules.substeps
    for _ in range(rules.substeps):
        move(world, rules, state, game, PURSUER, dt)
        move(world, rules, state, game, EVADER, dt)
    state.steps[game] += 1
    sense(world, rules, state, game)
    state.rewards[game] += state.detected[game]


@njit(cache=True)
def _play_game(world, rules, state, game, playing, ticks, table, table_role):
    if playing[game]:
        for _ in range(ticks):
            if state.steps[game] >= rules.ticks:
                break
            _play_tick(world, rules, state, game, table, table_role)


@njit(cache=True)
def _play_serial(world, rules, state, playing, ticks, table, table_role):
    for game in range(playing.size):
        _play_game(world, rules, state, game, playing, ticks, table, table_role)


@njit(cache=True, parallel=True)
def _play_parallel(world, rules, state, playing, ticks, table, table_role):
    for game in prange(playing.size):
        _play_game(world, rules, state, game, playing, ticks, table, table_role)


def play(world, rules, state, playing, ticks, table, table_role):
    """Play up to ``ticks`` control ticks of every game where ``playing`` (bool (N,)) is
    set, each stopping at its last tick; state.rewards counts the detections. ``table``
    (N, decisions, 2): the (v, w) commands of a scripted role ``table_role`` (-1: none) per
    decision. Parallel over games from PARALLEL_GAMES games on."""
    kernel = _play_parallel if playing.size >= PARALLEL_GAMES else _play_serial
    kernel(world, rules, state, playing, ticks, table, table_role)


@njit(cache=True)
def _sense_serial(world, rules, state, games):
    for k in range(games.size):
        sense(world, rules, state, games[k])


@njit(cache=True, parallel=True)
def _sense_parallel(world, rules, state, games):
    for k in prange(games.size):
        sense(world, rules, state, games[k])


def sense_games(world, rules, state, games):
    """:func:`sense` for the games listed in ``games`` (int (K,)), e.g. just reset."""
    kernel = _sense_parallel if games.size >= PARALLEL_GAMES else _sense_serial
    kernel(world, rules, state, games)


@njit(cache=True, inline="always")
def _unit(value):
    """Python's ``min(1.0, max(-1.0, value))``."""
    low = value if value > -1.0 else -1.0
    return low if low < 1.0 else 1.0


@njit(cache=True)
def _pose_features(world, x, y, theta, out, at):
    """``_Features._pose``: normalised position, cos and sin of the heading."""
    x0, y0, sx, sy = world.extent[0], world.extent[1], world.extent[2], world.extent[3]
    out[at] = _unit((x - x0) * sx - 1.0)
    out[at + 1] = _unit((y - y0) * sy - 1.0)
    out[at + 2] = math.cos(theta)
    out[at + 3] = math.sin(theta)


@njit(cache=True)
def crop_into(world, x, y, theta, out, at):
    """The crop of :class:`pegame.envs.crop.LocalCrop` around (x, y, theta) into
    out[at:], with the float operations of :func:`pegame.envs.crop._crop` (compared with it
    in the tests), in two passes so that LLVM vectorises the first: every cell's flat
    index in the pooled map (-1 off the map), then the look-ups. A quotient q = d / res
    in [0, n) is exactly a cell floor(q) in [0, n), and there truncation is the floor."""
    pooled = world.pooled
    height, width = pooled.shape
    flat = pooled.ravel()
    off_x, off_y = world.crop_x, world.crop_y
    c, s = math.cos(theta), math.sin(theta)
    gx, gy, gc, gs = world.crop_frame[0], world.crop_frame[1], world.crop_frame[2], world.crop_frame[3]
    rotate, res = world.crop_frame[4] != 0.0, world.crop_frame[5]
    cells = np.empty(off_x.size, np.int64)
    for k in range(off_x.size):
        dx = x + (c * off_x[k] - s * off_y[k]) - gx
        dy = y + (s * off_x[k] + c * off_y[k]) - gy
        if rotate:
            dx, dy = gc * dx + gs * dy, -gs * dx + gc * dy
        qc, qr = dx / res, dy / res
        inside = (qr >= 0.0) & (qr < height) & (qc >= 0.0) & (qc < width)
        cells[k] = np.int64(qr) * width + np.int64(qc) if inside else -1
    for k in range(off_x.size):
        cell = cells[k]
        out[at + k] = 1.0 if cell < 0 or flat[cell] else 0.0


@njit(cache=True)
def _pursuer_row(world, rules, state, game, row):
    """``PursuerFeatures.build`` (no belief part) of ``game`` into ``row``."""
    far = rules.camera[FAR]
    px, py, ptheta = state.poses[game, PURSUER]
    _pose_features(world, px, py, ptheta, row, 0)
    row[4] = 1.0 if state.detected[game] else 0.0
    if not state.has_seen[game]:
        row[5], row[6], row[7] = 1.0, 0.0, 1.0
    else:
        dx, dy = state.seen[game, 1] - px, state.seen[game, 2] - py
        row[5] = min(1.0, hypot(dx, dy) / far)
        row[6] = wrap_angle(math.atan2(dy, dx) - ptheta) / math.pi
        row[7] = min(1.0, (state.steps[game] * rules.control_dt - state.seen[game, 0]) / AGE_SCALE)
    crop_into(world, px, py, ptheta, row, 8)


@njit(cache=True)
def _evader_row(world, rules, state, game, row):
    """``EvaderFeatures.build`` of ``game`` into ``row``."""
    diagonal = world.extent[4]
    ex, ey, etheta = state.poses[game, EVADER]
    px, py, ptheta = state.poses[game, PURSUER]
    _pose_features(world, ex, ey, etheta, row, 0)
    _pose_features(world, px, py, ptheta, row, 4)
    dx, dy = px - ex, py - ey
    c, s = math.cos(etheta), math.sin(etheta)
    row[8] = _unit((c * dx + s * dy) / diagonal)
    row[9] = _unit((-s * dx + c * dy) / diagonal)
    row[10] = math.cos(ptheta - etheta)
    row[11] = math.sin(ptheta - etheta)
    crop_into(world, ex, ey, etheta, row, 12)


@njit(cache=True)
def _features_serial(world, rules, state, out, pursuer):
    for game in range(out.shape[0]):
        if pursuer:
            _pursuer_row(world, rules, state, game, out[game])
        else:
            _evader_row(world, rules, state, game, out[game])


@njit(cache=True, parallel=True)
def _features_parallel(world, rules, state, out, pursuer):
    for game in prange(out.shape[0]):
        if pursuer:
            _pursuer_row(world, rules, state, game, out[game])
        else:
            _evader_row(world, rules, state, game, out[game])


def features(world, rules, state, out, role):
    """The observation of ``role`` (PURSUER or EVADER) in every game into out (N, size)."""
    kernel = _features_parallel if out.shape[0] >= PARALLEL_GAMES else _features_serial
    kernel(world, rules, state, out, role == PURSUER)
