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
from pegame.vector.exact import cell_by_division, cell_by_product, hypot, wrap_angle
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


@njit(cache=True, inline="always")
def _fast_cells(world, x, y, c, s, cells, rotate):
    """Every crop cell's flat index in world.crop_values by
    :func:`pegame.vector.exact.cell_by_product` into ``cells``; returns whether all are
    decided. Inlined with ``rotate`` a constant, so that each loop has no branch."""
    height, width = world.pooled.shape
    off_x, off_y = world.crop_x, world.crop_y
    gx, gy, gc, gs = (
        world.crop_frame[0],
        world.crop_frame[1],
        world.crop_frame[2],
        world.crop_frame[3],
    )
    inverse = 1.0 / world.crop_frame[5]
    decided = True
    for k in range(off_x.size):
        dx = x + (c * off_x[k] - s * off_y[k]) - gx
        dy = y + (s * off_x[k] + c * off_y[k]) - gy
        if rotate:
            dx, dy = gc * dx + gs * dy, -gs * dx + gc * dy
        cells[k], ok = cell_by_product(dx, dy, inverse, height, width)
        decided &= ok
    return decided


@njit(cache=True)
def crop_into(world, x, y, theta, out, at, cells):
    """The crop of :class:`pegame.envs.crop.LocalCrop` around the pose (x m, y m, theta
    rad) into out[at:], the cells of :func:`pegame.envs.crop._crop` (same float
    operations; ``cells``: int64 scratch of the crop's size) looked up in
    world.crop_values (entry 0: off the map, blocked). The
    cells come from products (:func:`pegame.vector.exact.cell_by_product`), and from the
    division when any of them is not decided (a pose on cell edges). Returns whether the
    division was needed. ``tests/test_vector_kernels.py`` compares the crop with the
    reference on random poses and on poses whose cells lie on cell edges."""
    c, s = math.cos(theta), math.sin(theta)
    if world.crop_frame[4] != 0.0:
        decided = _fast_cells(world, x, y, c, s, cells, True)
    else:
        decided = _fast_cells(world, x, y, c, s, cells, False)
    if not decided:
        height, width = world.pooled.shape
        off_x, off_y, frame = world.crop_x, world.crop_y, world.crop_frame
        gx, gy, gc, gs, res = frame[0], frame[1], frame[2], frame[3], frame[5]
        for k in range(off_x.size):
            dx = x + (c * off_x[k] - s * off_y[k]) - gx
            dy = y + (s * off_x[k] + c * off_y[k]) - gy
            if frame[4] != 0.0:
                dx, dy = gc * dx + gs * dy, -gs * dx + gc * dy
            cells[k] = cell_by_division(dx, dy, res, height, width)
    values = world.crop_values
    for k in range(cells.size):
        out[at + k] = values[cells[k]]
    return not decided


@njit(cache=True)
def _pursuer_row(world, rules, state, game, row, cells):
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
    crop_into(world, px, py, ptheta, row, 8, cells)


@njit(cache=True)
def _evader_row(world, rules, state, game, row, cells):
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
    crop_into(world, ex, ey, etheta, row, 12, cells)


#: games per block of the features' loop: one crop scratch array per block, since an
#: allocation per game costs about as much as the crop's arithmetic
_BLOCK = 64


@njit(cache=True)
def _features_block(world, rules, state, out, pursuer, block):
    cells = np.empty(world.crop_x.size, np.int64)
    for game in range(block * _BLOCK, min(out.shape[0], (block + 1) * _BLOCK)):
        if pursuer:
            _pursuer_row(world, rules, state, game, out[game], cells)
        else:
            _evader_row(world, rules, state, game, out[game], cells)


@njit(cache=True)
def _features_serial(world, rules, state, out, pursuer):
    for block in range(-(-out.shape[0] // _BLOCK)):
        _features_block(world, rules, state, out, pursuer, block)


@njit(cache=True, parallel=True)
def _features_parallel(world, rules, state, out, pursuer):
    for block in prange(-(-out.shape[0] // _BLOCK)):
        _features_block(world, rules, state, out, pursuer, block)


def features(world, rules, state, out, role):
    """The observation of ``role`` (PURSUER or EVADER) in every game into out (N, size)."""
    kernel = _features_parallel if out.shape[0] >= PARALLEL_GAMES else _features_serial
    kernel(world, rules, state, out, role == PURSUER)
