"""The observations of a batched game, per game: :class:`pegame.envs.observations.
PursuerFeatures` and ``EvaderFeatures`` (no belief part), with the crop of
:func:`pegame.envs.crop._crop` (:func:`crop_into`), the same float operations
(``tests/test_vector_kernels.py`` compares the crop, ``tests/test_vector_env.py`` the
observations). Parallel over games from PARALLEL_GAMES games on.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from pegame.envs.observations import AGE_SCALE
from pegame.vector.exact import hypot, wrap_angle
from pegame.vector.state import EVADER, FAR, PARALLEL_GAMES, PURSUER


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
    gx, gy, gc, gs = (
        world.crop_frame[0],
        world.crop_frame[1],
        world.crop_frame[2],
        world.crop_frame[3],
    )
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
