"""The observation vectors' float operations, written once: numba kernels of one game.

:class:`pegame.observe.observations.PursuerFeatures` and ``EvaderFeatures`` call
:func:`pursuer_observation` and :func:`evader_observation` for the single game (one
dispatched call per observation: a numba call costs 0.3-1 us to dispatch), and the
batched environments' loop over games (:mod:`pegame.vector.features`) inlines
:func:`pursuer_row`, :func:`evader_row` and :func:`crop_row` per game, so both give the
same vector bit for bit (``tests/envs/test_vector.py`` compares them). What the values
mean is in :mod:`pegame.observe.observations`.

Units and frames: poses are (x m, y m, theta rad) in the map frame; ``extent`` is the
map's normalisation, :func:`extent_numbers`; times are s; ``far`` is the camera's range
(m). The kernels write float64 results into the float32 vector ``out`` (rounded to
nearest, as numpy's item assignment does).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from pegame.grid import OccupancyGrid
from pegame.numerics import hypot, wrap_angle
from pegame.observe.crop import crop_kernel

#: s; detection ages are divided by this and capped at 1
AGE_SCALE = 10.0

#: a map-frame pose as the kernels take it: (x m, y m, theta rad)
XYTheta = tuple[float, float, float]


def extent_numbers(grid: OccupancyGrid) -> np.ndarray:
    """Float64 (5,): (x0, y0, 2 / width, 2 / height, diagonal) of the grid's extent
    (:attr:`OccupancyGrid.extent`, m), the positions' normalisation."""
    x0, x1, y0, y1 = grid.extent
    return np.array([x0, y0, 2.0 / (x1 - x0), 2.0 / (y1 - y0), math.hypot(x1 - x0, y1 - y0)])


@njit(cache=True, inline="always")
def _unit(value: float) -> float:
    """Python's ``min(1.0, max(-1.0, value))`` (NaN gives -1)."""
    low = value if value > -1.0 else -1.0
    return low if low < 1.0 else 1.0


@njit(cache=True, inline="always")
def _pose(extent: np.ndarray, pose: XYTheta, out: np.ndarray, at: int) -> None:
    """The normalised pose (x_n, y_n, cos theta, sin theta) into out[at:at + 4]."""
    x, y, theta = pose
    out[at] = _unit((x - extent[0]) * extent[2] - 1.0)
    out[at + 1] = _unit((y - extent[1]) * extent[3] - 1.0)
    out[at + 2] = math.cos(theta)
    out[at + 3] = math.sin(theta)


@njit(cache=True, inline="always")
def pursuer_row(
    extent: np.ndarray,
    pose: XYTheta,
    detected: bool,
    has_seen: bool,
    seen: XYTheta,
    time: float,
    far: float,
    out: np.ndarray,
) -> None:
    """The pursuer's pose and detection parts into out[0:8] at ``time``: ``detected``
    this tick; ``seen`` the (time, x, y) of the last detection when ``has_seen``."""
    _pose(extent, pose, out, 0)
    out[4] = 1.0 if detected else 0.0
    if not has_seen:
        out[5], out[6], out[7] = 1.0, 0.0, 1.0
        return
    x, y, theta = pose
    seen_at, seen_x, seen_y = seen
    dx, dy = seen_x - x, seen_y - y
    out[5] = min(1.0, hypot(dx, dy) / far)
    out[6] = wrap_angle(math.atan2(dy, dx) - theta) / math.pi
    out[7] = min(1.0, (time - seen_at) / AGE_SCALE)


@njit(cache=True, inline="always")
def evader_row(extent: np.ndarray, pose: XYTheta, pursuer: XYTheta, out: np.ndarray) -> None:
    """The evader's pose, pursuer and relative parts into out[0:12]."""
    _pose(extent, pose, out, 0)
    _pose(extent, pursuer, out, 4)
    x, y, theta = pose
    px, py, ptheta = pursuer
    dx, dy = px - x, py - y
    c, s = math.cos(theta), math.sin(theta)
    diagonal = extent[4]
    out[8] = _unit((c * dx + s * dy) / diagonal)
    out[9] = _unit((-s * dx + c * dy) / diagonal)
    out[10] = math.cos(ptheta - theta)
    out[11] = math.sin(ptheta - theta)


@njit(cache=True, inline="always")
def crop_row(crop: tuple, pose: XYTheta, out: np.ndarray, at: int) -> bool:
    """The crop around ``pose`` into out[at:] (:func:`pegame.observe.crop.crop_kernel`;
    ``crop`` is its (lattice, samples, scratch)); returns whether the division was
    needed."""
    x, y, theta = pose
    lattice, samples, scratch = crop
    return crop_kernel(lattice, samples, scratch, (x, y, math.cos(theta), math.sin(theta)), out, at)


@njit(cache=True)
def pursuer_observation(
    extent: np.ndarray,
    crop: tuple,
    pose: XYTheta,
    detected: bool,
    has_seen: bool,
    seen: XYTheta,
    time: float,
    far: float,
    out: np.ndarray,
    at: int,
) -> None:
    """:func:`pursuer_row` into out[0:8] and the crop into out[at:] (one game)."""
    pursuer_row(extent, pose, detected, has_seen, seen, time, far, out)
    crop_row(crop, pose, out, at)


@njit(cache=True)
def evader_observation(
    extent: np.ndarray, crop: tuple, pose: XYTheta, pursuer: XYTheta, out: np.ndarray, at: int
) -> None:
    """:func:`evader_row` into out[0:12] and the crop into out[at:] (one game)."""
    evader_row(extent, pose, pursuer, out)
    crop_row(crop, pose, out, at)
