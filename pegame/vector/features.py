"""The observations of a batched game: the loop over games (and the state's arrays) around
the kernels of one game of :mod:`pegame.observe.features`, the ones
:class:`pegame.observe.observations.PursuerFeatures` and ``EvaderFeatures`` (no belief
part) call for the single game, so the float operations are the same ones
(``tests/envs/test_vector.py`` compares the observations, ``tests/vector/test_kernels.py``
the crop). Parallel over games from PARALLEL_GAMES games on.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from pegame.observe.crop import CropLattice, CropScratch
from pegame.observe.features import crop_row, evader_row, pursuer_row
from pegame.vector.state import FAR, PARALLEL_GAMES, PURSUER, BatchState, Rules, World


@njit(cache=True)
def crop_into(
    world: World, x: float, y: float, theta: float, out: np.ndarray, at: int, cells: np.ndarray
) -> bool:
    """The crop of :class:`pegame.observe.crop.LocalCrop` around the pose (x m, y m, theta
    rad) into out[at:] as the features' loop writes it (:func:`pegame.observe.features.
    crop_row`; ``cells``: int32 scratch of the crop's size). Returns whether the division
    was needed (a pose on cell edges)."""
    return crop_row(_crop(world, cells), (x, y, theta), out, at)


@njit(cache=True, inline="always")
def _crop(world: World, cells: np.ndarray) -> tuple:
    """:func:`crop_row`'s (lattice, samples, scratch) of the ``world``'s crop, with the
    scratch ``cells`` (int32, the crop's size)."""
    lattice = CropLattice(
        world.crop_table, world.crop_centres, world.crop_frame, world.pooled.shape[1]
    )
    samples = (world.pooled, world.crop_x, world.crop_y)
    return lattice, samples, CropScratch(cells, np.empty((2, world.crop_centres.size)))


#: games per block of the features' loop: one set of crop scratch arrays per block, since
#: an allocation per game costs a reference count and a heap call
_BLOCK = 64


@njit(cache=True)
def _features_block(
    world: World,
    rules: Rules,
    state: BatchState,
    out: np.ndarray,
    pursuer: bool,
    member: int,
    at: int,
    block: int,
) -> None:
    """The rows of the games of ``block`` for pursuer (evader) ``member``: the arrays are
    taken out of the NamedTuples once per block, not per game; the crop goes to
    row[at:]. Pursuer i's detection is
    of its target evader i mod E; evader j's pursuer is the one nearest it (the loop's
    ``nearest``: by squared distance, the lowest among ties)."""
    crop = _crop(world, np.empty(world.crop_x.size, np.int32))
    extent = world.extent
    poses, detected, has_seen = state.poses, state.detected, state.has_seen
    seen, steps = state.seen, state.steps
    far, dt = rules.camera[FAR], rules.control_dt
    n_p, n_e = rules.pursuers, rules.evaders
    agent = member if pursuer else n_p + member
    for game in range(block * _BLOCK, min(out.shape[0], (block + 1) * _BLOCK)):
        row = out[game]
        own = (poses[game, agent, 0], poses[game, agent, 1], poses[game, agent, 2])
        if pursuer:
            mine = game * n_p + member
            last = (seen[mine, 0], seen[mine, 1], seen[mine, 2])
            time = steps[game] * dt
            now = detected[mine * n_e + member % n_e]
            pursuer_row(extent, own, now, has_seen[mine], last, time, far, row)
        else:
            near, best = 0, math.inf
            if n_p > 1:
                for i in range(n_p):
                    dx, dy = poses[game, i, 0] - own[0], poses[game, i, 1] - own[1]
                    d = dx**2 + dy**2
                    if d < best:
                        near, best = i, d
            chaser = (poses[game, near, 0], poses[game, near, 1], poses[game, near, 2])
            evader_row(extent, own, chaser, row)
        crop_row(crop, own, row, at)


@njit(cache=True)
def _features_serial(
    world: World,
    rules: Rules,
    state: BatchState,
    out: np.ndarray,
    pursuer: bool,
    member: int,
    at: int,
) -> None:
    for block in range(-(-out.shape[0] // _BLOCK)):
        _features_block(world, rules, state, out, pursuer, member, at, block)


@njit(cache=True, parallel=True)
def _features_parallel(
    world: World,
    rules: Rules,
    state: BatchState,
    out: np.ndarray,
    pursuer: bool,
    member: int,
    at: int,
) -> None:
    for block in prange(-(-out.shape[0] // _BLOCK)):
        _features_block(world, rules, state, out, pursuer, member, at, block)


def features(
    world: World,
    rules: Rules,
    state: BatchState,
    out: np.ndarray,
    role: int,
    member: int = 0,
    crop: int | None = None,
) -> None:
    """The observation of member ``member`` of ``role`` (PURSUER or EVADER) in every game
    into out (N, size), the crop from column ``crop`` (default: right after the role's
    features; a pursuer's belief part, which the caller fills, comes before it)."""
    at = (8 if role == PURSUER else 12) if crop is None else crop
    kernel = _features_parallel if out.shape[0] >= PARALLEL_GAMES else _features_serial
    kernel(world, rules, state, out, role == PURSUER, member, at)
