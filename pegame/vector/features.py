"""The observations of a batched game, per game: :class:`pegame.observe.observations.
PursuerFeatures` and ``EvaderFeatures`` (no belief part), with the crop of
:func:`pegame.observe.crop._crop` (:func:`crop_into`), the same float operations
(``tests/test_vector_kernels.py`` compares the crop, ``tests/test_vector_env.py`` the
observations). Parallel over games from PARALLEL_GAMES games on.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from pegame.grid.occupancy import COS_YAW, OX, OY, RESOLUTION, ROTATED, SIN_YAW
from pegame.numerics import cell_by_division, hypot, wrap_angle
from pegame.observe.crop import CropLattice, CropScratch, lattice_crop
from pegame.observe.observations import AGE_SCALE
from pegame.vector.state import EVADER, FAR, PARALLEL_GAMES, PURSUER, BatchState, Rules, World


@njit(cache=True, inline="always")
def _unit(value: float) -> float:
    """Python's ``min(1.0, max(-1.0, value))``."""
    low = value if value > -1.0 else -1.0
    return low if low < 1.0 else 1.0


@njit(cache=True, inline="always")
def _pose_features(
    extent: np.ndarray, x: float, y: float, theta: float, out: np.ndarray, at: int
) -> None:
    """``_Features._pose``: normalised position, cos and sin of the heading."""
    x0, y0, sx, sy = extent[0], extent[1], extent[2], extent[3]
    out[at] = _unit((x - x0) * sx - 1.0)
    out[at + 1] = _unit((y - y0) * sy - 1.0)
    out[at + 2] = math.cos(theta)
    out[at + 3] = math.sin(theta)


@njit(cache=True)
def _divided_crop(
    world: World, x: float, y: float, c: float, s: float, out: np.ndarray, at: int
) -> None:
    """The crop's cells by the reference's own operations (:func:`pegame.observe.crop._crop`,
    ``world_to_cell``'s division), into out[at:]."""
    table, off_x, off_y, frame = world.crop_table, world.crop_x, world.crop_y, world.crop_frame
    height, width = world.pooled.shape
    pad = (table.shape[1] - width) // 2
    gx, gy, gc, gs, res = frame[OX], frame[OY], frame[COS_YAW], frame[SIN_YAW], frame[RESOLUTION]
    for k in range(off_x.size):
        dx = x + (c * off_x[k] - s * off_y[k]) - gx
        dy = y + (s * off_x[k] + c * off_y[k]) - gy
        if frame[ROTATED] != 0.0:
            dx, dy = gc * dx + gs * dy, -gs * dx + gc * dy
        cell = cell_by_division(dx, dy, res, height, width)
        if cell == 0:
            out[at + k] = 1.0
        else:
            row, col = (cell - 1) // width, (cell - 1) % width
            out[at + k] = table[row + pad, col + pad]


@njit(cache=True)
def crop_into(
    world: World, x: float, y: float, theta: float, out: np.ndarray, at: int, cells: np.ndarray
) -> bool:
    """The crop of :class:`pegame.observe.crop.LocalCrop` around the pose (x m, y m, theta
    rad) into out[at:], the cells of :func:`pegame.observe.crop._crop` (``cells``: int32
    scratch of the crop's size): from the crop's lattice (:func:`pegame.observe.crop.lattice_crop`), or by
    the division when the lattice does not decide every cell (a pose on cell edges), as
    the features' loop finds them. Returns whether the division was needed.
    ``tests/test_vector_kernels.py`` compares the crop with the reference on random poses
    and on poses whose cells lie on cell edges."""
    c, s = math.cos(theta), math.sin(theta)
    table, centres, frame = world.crop_table, world.crop_centres, world.crop_frame
    lattice = CropLattice(table, centres, frame, world.pooled.shape[1])
    scratch = CropScratch(cells, np.empty((2, centres.size)))
    if lattice_crop(lattice, (x, y, c, s), out, at, scratch):
        return False
    _divided_crop(world, x, y, c, s, out, at)
    return True


@njit(cache=True, inline="always")
def _pursuer_row(
    extent: np.ndarray,
    poses: np.ndarray,
    detected: np.ndarray,
    has_seen: np.ndarray,
    seen: np.ndarray,
    steps: np.ndarray,
    far: float,
    dt: float,
    game: int,
    row: np.ndarray,
) -> None:
    """``PursuerFeatures.build`` (no belief part, no crop) of ``game`` into ``row``, from
    the state's arrays (a NamedTuple passed to an inlined function costs a reference
    count per array)."""
    px, py, ptheta = poses[game, PURSUER, 0], poses[game, PURSUER, 1], poses[game, PURSUER, 2]
    _pose_features(extent, px, py, ptheta, row, 0)
    row[4] = 1.0 if detected[game] else 0.0
    if not has_seen[game]:
        row[5], row[6], row[7] = 1.0, 0.0, 1.0
    else:
        dx, dy = seen[game, 1] - px, seen[game, 2] - py
        row[5] = min(1.0, hypot(dx, dy) / far)
        row[6] = wrap_angle(math.atan2(dy, dx) - ptheta) / math.pi
        row[7] = min(1.0, (steps[game] * dt - seen[game, 0]) / AGE_SCALE)


@njit(cache=True, inline="always")
def _evader_row(extent: np.ndarray, poses: np.ndarray, game: int, row: np.ndarray) -> None:
    """``EvaderFeatures.build`` (no crop) of ``game`` into ``row``."""
    diagonal = extent[4]
    ex, ey, etheta = poses[game, EVADER, 0], poses[game, EVADER, 1], poses[game, EVADER, 2]
    px, py, ptheta = poses[game, PURSUER, 0], poses[game, PURSUER, 1], poses[game, PURSUER, 2]
    _pose_features(extent, ex, ey, etheta, row, 0)
    _pose_features(extent, px, py, ptheta, row, 4)
    dx, dy = px - ex, py - ey
    c, s = math.cos(etheta), math.sin(etheta)
    row[8] = _unit((c * dx + s * dy) / diagonal)
    row[9] = _unit((-s * dx + c * dy) / diagonal)
    row[10] = math.cos(ptheta - etheta)
    row[11] = math.sin(ptheta - etheta)


#: games per block of the features' loop: one set of crop scratch arrays per block, since
#: an allocation per game costs a reference count and a heap call
_BLOCK = 64


@njit(cache=True)
def _features_block(
    world: World, rules: Rules, state: BatchState, out: np.ndarray, pursuer: bool, block: int
) -> None:
    """The rows of the games of ``block``: the arrays are taken out of the NamedTuples
    once per block, not per game."""
    scratch = CropScratch(
        np.empty(world.crop_x.size, np.int32), np.empty((2, world.crop_centres.size))
    )
    lattice = CropLattice(
        world.crop_table, world.crop_centres, world.crop_frame, world.pooled.shape[1]
    )
    extent = world.extent
    poses, detected, has_seen = state.poses, state.detected, state.has_seen
    seen, steps = state.seen, state.steps
    far, dt = rules.camera[FAR], rules.control_dt
    role, at = (PURSUER, 8) if pursuer else (EVADER, 12)
    for game in range(block * _BLOCK, min(out.shape[0], (block + 1) * _BLOCK)):
        row = out[game]
        if pursuer:
            _pursuer_row(extent, poses, detected, has_seen, seen, steps, far, dt, game, row)
        else:
            _evader_row(extent, poses, game, row)
        x, y, theta = poses[game, role, 0], poses[game, role, 1], poses[game, role, 2]
        c, s = math.cos(theta), math.sin(theta)
        if not lattice_crop(lattice, (x, y, c, s), row, at, scratch):
            _divided_crop(world, x, y, c, s, row, at)


@njit(cache=True)
def _features_serial(
    world: World, rules: Rules, state: BatchState, out: np.ndarray, pursuer: bool
) -> None:
    for block in range(-(-out.shape[0] // _BLOCK)):
        _features_block(world, rules, state, out, pursuer, block)


@njit(cache=True, parallel=True)
def _features_parallel(
    world: World, rules: Rules, state: BatchState, out: np.ndarray, pursuer: bool
) -> None:
    for block in prange(-(-out.shape[0] // _BLOCK)):
        _features_block(world, rules, state, out, pursuer, block)


def features(world: World, rules: Rules, state: BatchState, out: np.ndarray, role: int) -> None:
    """The observation of ``role`` (PURSUER or EVADER) in every game into out (N, size)."""
    kernel = _features_parallel if out.shape[0] >= PARALLEL_GAMES else _features_serial
    kernel(world, rules, state, out, role == PURSUER)
