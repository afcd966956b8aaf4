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


#: |quotient| (cells) below which the multiplied quotient decides the cell (see _cells)
_QUOTIENT_LIMIT = 2.0**20
#: distance (cells) from a cell edge beyond which the multiplied quotient decides it
_EDGE_MARGIN = 2.0**-20


@njit(cache=True)
def _cells(world, x, y, theta, cells):
    """Every crop cell's flat index in world.crop_values (0: off the map, else 1 + the
    pooled map's flat index) for the pose (x m, y m, theta rad) into ``cells`` (int64);
    returns whether the slow route was needed.

    The cell of a map-frame offset d is floor(d / res), the division of
    :func:`pegame.envs.crop._crop`. The fast route multiplies by 1 / res instead, which
    picks the same cell whenever no cell edge lies between the two quotients: with
    u = 2**-53, fl(1 / res) and the product each err by at most u relatively and the
    division by u, so the two quotients differ by at most 3.01 u |q|, below 4e-10 cells
    for |q| < 2**20. A product q whose distance to the nearest whole number,
    | |q - trunc(q)| - 1/2 | away from 1/2 (exact for |q| < 2**20 but for 2**-55), is more
    than 2**-20 therefore lies in the same cell as the division's quotient, and the
    tests 0 <= q < n (whole n) agree, so truncation is the floor where they pass. When
    any cell of the crop misses that test (a pose on a cell edge, far off the map, not
    finite), the whole crop is computed again with the division. The fast route also
    rotates by the grid's yaw when it is 0 (gc = 1, gs = 0: the same offsets but for the
    sign of a zero, which is the same cell), so that its loop has no branch.
    ``tests/test_vector_kernels.py`` compares the crop with the reference on random
    poses and on poses whose cells lie on cell edges (the slow route).
    """
    height, width = world.pooled.shape
    off_x, off_y = world.crop_x, world.crop_y
    c, s = math.cos(theta), math.sin(theta)
    gx, gy, gc, gs = (
        world.crop_frame[0],
        world.crop_frame[1],
        world.crop_frame[2],
        world.crop_frame[3],
    )
    rotate, res = world.crop_frame[4] != 0.0, world.crop_frame[5]
    inverse, near = 1.0 / res, 0.5 - _EDGE_MARGIN
    decided = True
    for k in range(off_x.size):
        dx = x + (c * off_x[k] - s * off_y[k]) - gx
        dy = y + (s * off_x[k] + c * off_y[k]) - gy
        dx, dy = gc * dx + gs * dy, -gs * dx + gc * dy
        qc, qr = dx * inverse, dy * inverse
        col, row = np.int64(qc), np.int64(qr)
        decided &= (
            (abs(abs(qc - col) - 0.5) < near)
            & (abs(abs(qr - row) - 0.5) < near)
            & (max(abs(qc), abs(qr)) < _QUOTIENT_LIMIT)
        )
        inside = (qr >= 0.0) & (qr < height) & (qc >= 0.0) & (qc < width)
        cells[k] = row * width + col + 1 if inside else 0
    if decided:
        return False
    for k in range(off_x.size):
        dx = x + (c * off_x[k] - s * off_y[k]) - gx
        dy = y + (s * off_x[k] + c * off_y[k]) - gy
        if rotate:
            dx, dy = gc * dx + gs * dy, -gs * dx + gc * dy
        qc, qr = dx / res, dy / res
        # a quotient in [0, n) is a cell floor(q) in [0, n), and there truncation floors
        inside = (qr >= 0.0) & (qr < height) & (qc >= 0.0) & (qc < width)
        cells[k] = np.int64(qr) * width + np.int64(qc) + 1 if inside else 0
    return True


@njit(cache=True)
def crop_into(world, x, y, theta, out, at):
    """The crop of :class:`pegame.envs.crop.LocalCrop` around (x, y, theta) into
    out[at:], the cells :func:`pegame.envs.crop._crop` picks (:func:`_cells`), then the
    look-ups in world.crop_values, whose first entry (off the map) is blocked."""
    cells = np.empty(world.crop_x.size, np.int64)
    _cells(world, x, y, theta, cells)
    values = world.crop_values
    for k in range(cells.size):
        out[at + k] = values[cells[k]]


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
