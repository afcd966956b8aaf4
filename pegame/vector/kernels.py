"""Numba kernels of the batched game: one control tick of many games at once.

Each kernel loops over the games with ``prange``, from PARALLEL_GAMES games on on numba's
thread pool (across cores: ``NUMBA_NUM_THREADS`` sets how many), below on one thread
(:func:`threaded`); inside a game the work
is the single game's, in the same order and with the same float operations, so a game
played here is the game the plain-Python code plays (``tests/envs/test_vector.py``
compares them step by step):

- :func:`pegame.sims.grid.move` is the grid simulator's own move kernel (saturation,
  acceleration limits, the unicycle arc, the swept collision check), which its agents
  run on a batch of one;
- :func:`pegame.vector.camera.sense` is the detector and the ground truth;
- :func:`tally` accumulates :class:`pegame.metrics.TrackingMetrics` as running sums
  (:mod:`pegame.vector.metrics` turns them into its summary);
- :func:`play` plays ticks in the loop's order (:mod:`pegame.vector.game` lays the
  correspondence out); :mod:`pegame.vector.features` builds the observations with
  :mod:`pegame.observe.features`' kernels.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numba
import numpy as np
from numba import njit, prange

from pegame.numerics import hypot
from pegame.sims.grid import move
from pegame.vector.camera import sense
from pegame.vector.state import (
    CREW_DETECTED,
    CREW_LAST_X,
    CREW_LAST_Y,
    CREW_PATH,
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
    BatchState,
    Rules,
    World,
)


@njit(cache=True, inline="always")
def tally(
    t: np.ndarray,
    row: int,
    px: float,
    py: float,
    ex: float,
    ey: float,
    detected: bool,
    in_view: bool,
    dt: float,
) -> None:
    """``TrackingMetrics.add`` of one tick, as running sums (no belief), into row ``row``
    of ``t`` (state.tally, an evader's row): the pursuer at (px, py) (m; in a team game the
    one nearest the evader), the evader at (ex, ey), whether it was ``detected`` (by some
    pursuer) and ``in_view`` (of some pursuer)."""
    g = row
    tick = t[g, TICKS]
    if tick > 0:
        dx, dy = px - t[g, LAST_PX], py - t[g, LAST_PY]
        t[g, PURSUER_PATH] += math.sqrt(dx * dx + dy * dy)
        dx, dy = ex - t[g, LAST_EX], ey - t[g, LAST_EY]
        t[g, EVADER_PATH] += math.sqrt(dx * dx + dy * dy)
    t[g, LAST_PX], t[g, LAST_PY], t[g, LAST_EX], t[g, LAST_EY] = px, py, ex, ey
    dx, dy = px - ex, py - ey
    t[g, DISTANCE_SUM] += math.sqrt(dx * dx + dy * dy)
    t[g, IN_VIEW] += in_view
    if detected:
        t[g, DETECTED] += 1.0
        if t[g, IN_LOSS]:
            length = tick - t[g, LOSS_START]
            t[g, LONGEST_LOSS] = max(t[g, LONGEST_LOSS], length)
            t[g, REACQUISITIONS] += 1.0
            t[g, REACQUIRE_SUM] += length * dt
            t[g, REACQUIRE_MAX] = max(t[g, REACQUIRE_MAX], length)
            t[g, IN_LOSS] = 0.0
    elif not t[g, IN_LOSS]:
        t[g, IN_LOSS], t[g, LOSS_START] = 1.0, tick
        if t[g, FIRST_LOSS] < 0:
            t[g, FIRST_LOSS] = tick
    t[g, TICKS] = tick + 1.0


@njit(cache=True, inline="always")
def _measure(rules: Rules, state: BatchState, game: int) -> None:
    """The game's measures of its current tick (the loop's ``_measure``): each evader's
    :func:`tally` with the pursuer nearest it (``TeamMetrics.add``: by distance, the
    lowest among ties), detected and in view if some pursuer detects it (has it in
    view); in a team game also the handoffs (``TeamMetrics._hand``: state.trackers,
    state.handoffs) and each pursuer's detections and path (state.crew)."""
    n_p, n_e = rules.pursuers, rules.evaders
    solo = n_p == 1 and n_e == 1
    poses, detected, in_view, dt = state.poses, state.detected, state.in_view, rules.control_dt
    for j in range(n_e):
        ex, ey = poses[game, n_p + j, 0], poses[game, n_p + j, 1]
        near, best = 0, math.inf
        seen, visible, first = False, False, -1
        for i in range(n_p):
            q = (game * n_p + i) * n_e + j
            if detected[q] and not seen:
                seen, first = True, i
            visible = visible or in_view[q]
            if n_p > 1:
                d = hypot(ex - poses[game, i, 0], ey - poses[game, i, 1])
                if d < best:
                    near, best = i, d
        px, py = poses[game, near, 0], poses[game, near, 1]
        tally(state.tally, game * n_e + j, px, py, ex, ey, seen, visible, dt)
        if not solo:
            trackers, row = state.trackers, game * n_e + j
            tracker = trackers[row]
            if not seen:
                trackers[row] = -1
            elif tracker < 0 or not detected[(game * n_p + tracker) * n_e + j]:
                trackers[row] = first
                state.handoffs[game] += tracker >= 0
    if solo:
        return
    crew = state.crew
    for i in range(n_p):
        member = game * n_p + i
        x, y = poses[game, i, 0], poses[game, i, 1]
        if state.steps[game] > 0:
            dx, dy = x - crew[member, CREW_LAST_X], y - crew[member, CREW_LAST_Y]
            crew[member, CREW_PATH] += math.sqrt(dx * dx + dy * dy)
        crew[member, CREW_LAST_X], crew[member, CREW_LAST_Y] = x, y
        for j in range(n_e):
            if detected[(game * n_p + i) * n_e + j]:
                crew[member, CREW_DETECTED] += 1.0
                break


@njit(cache=True)
def _play_game(
    world: World,
    rules: Rules,
    state: BatchState,
    game: int,
    playing: np.ndarray,
    ticks: int,
    table: np.ndarray,
    table_role: int,
) -> None:
    """Up to ``ticks`` control ticks of ``game`` in the loop's order (see
    :mod:`pegame.vector.game`): the scripted command, the measures, the simulator's
    substeps (the pursuers, then the evaders, in member order), the next tick sensed,
    each evader's detections counted. The arrays are taken out of the NamedTuples once."""
    if not playing[game]:
        return
    masks, frame, bodies = world.masks, world.frame, rules.bodies
    poses, velocities, commands, steps = state.poses, state.velocities, state.commands, state.steps
    dt = rules.control_dt / rules.substeps
    n_p, n_e = rules.pursuers, rules.evaders
    for _ in range(ticks):
        if steps[game] >= rules.ticks:
            break
        if table_role >= 0:
            decision = steps[game] // rules.decide_every
            commands[game, table_role, 0] = table[game, decision, 0]
            commands[game, table_role, 1] = table[game, decision, 1]
        _measure(rules, state, game)
        for _ in range(rules.substeps):
            for agent in range(n_p + n_e):
                mask = masks[PURSUER] if agent < n_p else masks[EVADER]
                v, w = commands[game, agent, 0], commands[game, agent, 1]
                move(mask, frame, bodies, poses, velocities, game, agent, v, w, dt)
        steps[game] += 1
        sense(world, rules, state, game)
        for j in range(n_e):
            for i in range(n_p):
                if state.detected[(game * n_p + i) * n_e + j]:
                    state.rewards[game * n_e + j] += 1.0
                    break


@njit(cache=True, parallel=True)
def _play(
    world: World,
    rules: Rules,
    state: BatchState,
    playing: np.ndarray,
    ticks: int,
    table: np.ndarray,
    table_role: int,
) -> None:
    for game in prange(playing.size):
        _play_game(world, rules, state, game, playing, ticks, table, table_role)


@njit(cache=True)
def _sense_game(world: World, rules: Rules, state: BatchState, game: int) -> None:
    """:func:`sense` of one game, a function of its own: inlined into the ``prange`` loop,
    numba's parallel transforms change what it computes (tests/envs/test_vector.py)."""
    sense(world, rules, state, game)


@njit(cache=True, parallel=True)
def _sense(world: World, rules: Rules, state: BatchState, games: np.ndarray) -> None:
    for k in prange(games.size):
        _sense_game(world, rules, state, games[k])


def threaded(kernel: Callable[..., None], games: int, *args: object) -> None:
    """Call the ``prange`` kernel ``kernel`` with ``args``: on numba's threads from
    PARALLEL_GAMES ``games`` on, below on one thread (no thread start-up; the count set is
    the calling thread's). A parallel loop on one thread and not a serial kernel: a
    ``prange`` body does no reference counting, which the same loop in a plain kernel
    pays per array of the NamedTuples per game (the tick, one thread, CPU time: 1.61 us
    per game in a serial loop, 0.92 in the parallel one at 64 games, 2.26 and 1.60 at 8;
    0.3 us more per call at one game, 3 us more with two threads, which are set and reset;
    docs/performance/vmas.md). The count is set here, not in the kernels: numba caches no
    kernel that sets it. (The features' loop takes its arrays out once per block of games:
    a serial loop costs it nothing.)"""
    one = numba.config.NUMBA_NUM_THREADS == 1  # type: ignore[attr-defined]  # no stubs
    if games >= PARALLEL_GAMES or one:
        kernel(*args)
        return
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        kernel(*args)
    finally:
        numba.set_num_threads(threads)


def play(
    world: World,
    rules: Rules,
    state: BatchState,
    playing: np.ndarray,
    ticks: int,
    table: np.ndarray,
    table_role: int,
) -> None:
    """Play up to ``ticks`` control ticks of every game where ``playing`` (bool (N,)) is
    set, each stopping at its last tick; state.rewards counts the detections. ``table``
    (N, decisions, 2): the (v, w) commands of a scripted role ``table_role`` (-1: none) per
    decision. Parallel over games from PARALLEL_GAMES games on."""
    threaded(_play, playing.size, world, rules, state, playing, ticks, table, table_role)


def sense_games(world: World, rules: Rules, state: BatchState, games: np.ndarray) -> None:
    """:func:`sense` for the games listed in ``games`` (int (K,)), e.g. just reset."""
    threaded(_sense, games.size, world, rules, state, games)
