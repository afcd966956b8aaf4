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

from pegame.sims.grid import move
from pegame.vector.camera import sense
from pegame.vector.state import (
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
    poses: np.ndarray,
    in_view: np.ndarray,
    detected: np.ndarray,
    game: int,
    dt: float,
) -> None:
    """``TrackingMetrics.add`` for ``game``'s current tick, as running sums (no belief),
    into ``t`` = state.tally from the state's poses, in_view and detected."""
    g = game
    px, py = poses[g, PURSUER, 0], poses[g, PURSUER, 1]
    ex, ey = poses[g, EVADER, 0], poses[g, EVADER, 1]
    tick = t[g, TICKS]
    if tick > 0:
        dx, dy = px - t[g, LAST_PX], py - t[g, LAST_PY]
        t[g, PURSUER_PATH] += math.sqrt(dx * dx + dy * dy)
        dx, dy = ex - t[g, LAST_EX], ey - t[g, LAST_EY]
        t[g, EVADER_PATH] += math.sqrt(dx * dx + dy * dy)
    t[g, LAST_PX], t[g, LAST_PY], t[g, LAST_EX], t[g, LAST_EY] = px, py, ex, ey
    dx, dy = px - ex, py - ey
    t[g, DISTANCE_SUM] += math.sqrt(dx * dx + dy * dy)
    t[g, IN_VIEW] += in_view[g]
    if detected[g]:
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
    substeps, the next tick sensed. The arrays are taken out of the NamedTuples once."""
    if not playing[game]:
        return
    masks, frame, bodies = world.masks, world.frame, rules.bodies
    poses, velocities, commands, steps = state.poses, state.velocities, state.commands, state.steps
    dt = rules.control_dt / rules.substeps
    for _ in range(ticks):
        if steps[game] >= rules.ticks:
            break
        if table_role >= 0:
            decision = steps[game] // rules.decide_every
            commands[game, table_role, 0] = table[game, decision, 0]
            commands[game, table_role, 1] = table[game, decision, 1]
        tally(state.tally, poses, state.in_view, state.detected, game, rules.control_dt)
        for _ in range(rules.substeps):
            v, w = commands[game, PURSUER, 0], commands[game, PURSUER, 1]
            move(masks[PURSUER], frame, bodies, poses, velocities, game, PURSUER, v, w, dt)
            v, w = commands[game, EVADER, 0], commands[game, EVADER, 1]
            move(masks[EVADER], frame, bodies, poses, velocities, game, EVADER, v, w, dt)
        steps[game] += 1
        sense(world, rules, state, game)
        state.rewards[game] += state.detected[game]


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
