"""Numba kernels of the batched game: one control tick of many games at once.

Each kernel loops over the games, from PARALLEL_GAMES games on with ``prange`` (numba's
thread pool, across cores: ``NUMBA_NUM_THREADS`` sets how many); inside a game the work
is the single game's, in the same order and with the same float operations, so a game
played here is the game the plain-Python code plays (``tests/test_vector_env.py``
compares them step by step):

- :func:`move` is :class:`pegame.sims.grid.GridSimulator`'s agent move (saturation,
  acceleration limits, exact unicycle arc, the swept collision check
  :func:`pegame.sims.grid._sweep` itself);
- :func:`pegame.vector.camera.sense` is the detector and the ground truth;
- :func:`tally` accumulates :class:`pegame.metrics.TrackingMetrics` as running sums
  (:mod:`pegame.vector.metrics` turns them into its summary);
- :func:`play` plays ticks in the loop's order (:mod:`pegame.vector.game` lays the
  correspondence out); :mod:`pegame.vector.features` builds the observations.
"""

from __future__ import annotations

import math

from numba import njit, prange

from pegame.sims.grid import _sweep
from pegame.vector.camera import sense
from pegame.vector.exact import ceil_of_hypot, hypot, wrap_angle
from pegame.vector.state import (
    A_MAX,
    ALPHA_MAX,
    DETECTED,
    DISTANCE_SUM,
    EVADER,
    EVADER_PATH,
    FIRST_LOSS,
    IN_LOSS,
    IN_VIEW,
    LAST_EX,
    LAST_EY,
    LAST_PX,
    LAST_PY,
    LONGEST_LOSS,
    LOSS_START,
    PARALLEL_GAMES,
    PURSUER,
    PURSUER_PATH,
    REACQUIRE_MAX,
    REACQUIRE_SUM,
    REACQUISITIONS,
    TICKS,
    V_MAX,
    W_MAX,
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
    n = max(1, ceil_of_hypot(tx - x0, ty - y0, world.frame[5]))
    x, y = _sweep(world.masks[role], x0, y0, tx, ty, n, world.frame)
    pose[0], pose[1], pose[2] = x, y, wrap_angle(theta)
    if limited:
        stopped = hypot(tx - x, ty - y) > 1e-9
        state.velocities[game, role, 0] = 0.0 if stopped else v
        state.velocities[game, role, 1] = w


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
