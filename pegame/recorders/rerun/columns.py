"""What a recording buffers between sends, and its encoding as Rerun columns.

A control tick is faster than a few ``rr.log`` calls, so the recorder buffers ticks and
sends each entity's rows at once with ``RecordingStream.send_columns``: a tick's numbers
as one :data:`ROW` (see :func:`tick_row`), the particle subsamples in the preallocated
:class:`ParticleRows`, and each other entity's variable-size rows in an
:class:`EntityBuffer`. :func:`time_index` builds the ``step`` and ``sim_time`` index
columns, :func:`strips_array` line strips as one Arrow array; points are float32 (n, 3)
arrays in the map frame (m).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from itertools import chain
from typing import Any, Protocol

import numpy as np
import pyarrow as pa
import rerun as rr
from numpy.typing import ArrayLike

from pegame.api import Tick

STEP, SIM_TIME = "step", "sim_time"

#: the numbers buffered per tick, in this order (NaN where there is nothing)
ROW = (
    "step",
    "time",
    "px",
    "py",
    "ptheta",
    "ex",
    "ey",
    "etheta",
    "det_x",
    "det_y",
    "box_cx",
    "box_cy",
    "box_hw",
    "box_hh",
    "confidence",
    "depth",
    "mean_x",
    "mean_y",
    "n_eff",
    "rate",
)
_NO_DETECTION = (math.nan,) * 8
_NO_MEAN = (math.nan, math.nan)


def tick_row(tick: Tick) -> tuple:
    """What a send needs of the tick's numbers, by reference: (step, time, pursuer pose,
    evader pose, detection or None, belief mean or None, n_eff or None). Taking the numbers
    out waits for the send (:func:`row_columns`): one pass over many rows costs less than
    a call per tick between the game's own work."""
    belief = tick.belief
    return (
        tick.step,
        tick.time,
        tick.pursuer,
        tick.evader,
        tick.detection,
        belief.mean,
        belief.n_eff,
    )


def _numbers(row: tuple) -> tuple:
    """A :func:`tick_row` row's numbers in :data:`ROW` order, the running rate last left NaN."""
    step, time, p, e, det, mean, n_eff = row
    if det is None:
        seen = _NO_DETECTION
    else:
        box = det.box
        seen = (
            det.position[0],
            det.position[1],
            box.x + 0.5 * box.w,
            box.y + 0.5 * box.h,
            0.5 * box.w,
            0.5 * box.h,
            det.confidence,
            det.depth,
        )
    return (
        step,
        time,
        p.x,
        p.y,
        p.theta,
        e.x,
        e.y,
        e.theta,
        *seen,
        *(_NO_MEAN if mean is None else mean),
        math.nan if n_eff is None else n_eff,
        math.nan,
    )


def row_columns(rows: list[tuple], detections: int) -> dict[str, np.ndarray]:
    """Buffered :func:`tick_row` rows as one float array per :data:`ROW` name; ``rate``
    is the running tracking rate, counting ``detections`` detected ticks before the rows."""
    flat = np.fromiter(
        chain.from_iterable(map(_numbers, rows)), dtype=float, count=len(rows) * len(ROW)
    )
    columns = dict(zip(ROW, flat.reshape(len(rows), len(ROW)).T))
    seen = detections + np.cumsum(np.isfinite(columns["det_x"]))
    columns["rate"] = seen / (columns["step"] + 1)
    return columns


class Archetype(Protocol):
    """A Rerun archetype class (``rr.Points3D``, ...): ``columns(**components)`` gives its
    component columns for send_columns."""

    def columns(self, *args: Any, **kwargs: Any) -> Any: ...


class EntityBuffer:
    """Rows of one entity waiting to be sent with ``send_columns``.

    A row is one tick's step and time and, per component, one value per instance: a
    numeric array of shape (n, ...), a list of n strings, or (for ``strips``) a list of
    n (K, 3) arrays. ``kind`` is the archetype (``rr.Points3D``, ``rr.TextLog``, ...).
    """

    def __init__(self, path: str, kind: Archetype) -> None:
        self.path, self.kind = path, kind
        self.steps: list[int] = []
        self.times: list[float] = []
        self.sizes: list[int] = []
        self.values: dict[str, list] = {}

    def add(self, step: int, time: float, **values: Any) -> None:
        self.steps.append(step)
        self.times.append(time)
        self.sizes.append(len(next(iter(values.values()))))
        for key, value in values.items():
            self.values.setdefault(key, []).append(value)

    def send(self, rec: rr.RecordingStream, indexes: dict) -> None:
        """Send the buffered rows as one chunk and empty the buffer; ``indexes`` caches
        time columns (see :func:`time_index`)."""
        if not self.steps:
            return
        columns = {key: _concatenate(key, parts) for key, parts in self.values.items()}
        index = time_index(indexes, np.asarray(self.steps, dtype=np.int64), np.asarray(self.times))
        columns = self.kind.columns(**columns).partition(self.sizes)
        rec.send_columns(self.path, indexes=index, columns=columns, strict=True)
        self.steps, self.times, self.sizes, self.values = [], [], [], {}


def _concatenate(key: str, parts: list) -> Any:
    """One component's values over rows (see :class:`EntityBuffer`)."""
    if key == "strips":
        return strips_array([strip for part in parts for strip in part])
    if isinstance(parts[0], list):
        return [item for part in parts for item in part]
    return np.concatenate(parts)


def time_index(cache: dict, steps: np.ndarray, times: np.ndarray) -> list:
    """The ``step`` and ``sim_time`` index columns of rows at ``steps`` and ``times`` (s),
    cached by steps: most entities have a row at every tick, and building them is not free."""
    key = steps.tobytes()
    if key not in cache:
        # Whole nanoseconds, rounded as set_time rounds them (rerun-sdk would truncate).
        nanos = np.round(times * 1e9).astype(np.int64).astype("timedelta64[ns]")
        cache[key] = [rr.TimeColumn(STEP, sequence=steps), rr.TimeColumn(SIM_TIME, duration=nanos)]
    return cache[key]


def strips_array(
    strips: np.ndarray | Sequence[np.ndarray], lengths: np.ndarray | None = None
) -> pa.ListArray:
    """LineStrip3D arrow array of float32 strips: a list of (K, 3) arrays, an (n, K, 3)
    array, or (M, 3) points one strip after another with the strips' ``lengths`` (n,).
    Built in one go: rerun-sdk's own conversion loops over the strips in Python."""
    if lengths is not None:
        flat = np.asarray(strips)
        offsets = np.zeros(len(lengths) + 1, dtype=np.int32)
        offsets[1:] = np.cumsum(lengths)
    elif isinstance(strips, np.ndarray):
        n, k = strips.shape[:2]
        flat = strips.reshape(n * k, 3)
        offsets = np.arange(0, (n + 1) * k, k, dtype=np.int32) if k else np.zeros(n + 1, np.int32)
    else:
        sizes = [len(strip) for strip in strips]
        flat = np.concatenate(strips) if sizes else np.zeros((0, 3), np.float32)
        offsets = np.zeros(len(sizes) + 1, dtype=np.int32)
        offsets[1:] = np.cumsum(sizes)
    points = rr.encodings.Vec3DBatch(flat).as_arrow_array()
    strip_type = pa.list_(pa.field("item", points.type, nullable=False))
    return pa.ListArray.from_arrays(pa.array(offsets), points, type=strip_type)


def stack_points(x: np.ndarray, y: np.ndarray, z: np.ndarray | float) -> np.ndarray:
    """(n, 3) float32 points from coordinates (m); z is an array or one height."""
    out = np.empty((len(x), 3), dtype=np.float32)
    out[:, 0], out[:, 1], out[:, 2] = x, y, z
    return out


def points_at(xy: ArrayLike, z: float) -> np.ndarray:
    """(n, 3) float32 points at height z (m) from (n, 2) map-frame positions (m); copies."""
    xy = np.asarray(xy, dtype=float).reshape(-1, 2)
    return stack_points(xy[:, 0], xy[:, 1], z)


class ParticleRows:
    """The particle subsamples of up to ``capacity`` ticks, at most ``limit`` particles per
    tick (an evenly strided subsample), in arrays allocated once and touched only where
    rows are written: map-frame positions (m) as float32 points at height ``z``, and their
    weights as float32 (NaN where the estimator gives none; they only set a shade)."""

    def __init__(self, capacity: int, limit: int, z: float) -> None:
        self.limit, self.z = limit, z
        self.xy = np.empty((capacity, limit, 2), dtype=np.float32)
        self.weights = np.empty((capacity, limit), dtype=np.float32)
        self.sizes = np.zeros(capacity, dtype=np.int64)
        self.steps = np.zeros(capacity, dtype=np.int64)
        self.times = np.zeros(capacity)
        self.count = 0
        self.started = False  # rows begin at the first tick with particles

    def add(
        self, step: int, time: float, particles: np.ndarray | None, weights: np.ndarray | None
    ) -> None:
        """A row of (N, >= 2) particles and their (N,) weights; None gives an empty row,
        which clears the particles shown, once there have been some."""
        if particles is None and not self.started:
            return
        self.started = True
        row, size = self.count, 0
        if particles is not None:
            stride = -(-len(particles) // self.limit) or 1
            size = -(-len(particles) // stride)
            self.xy[row, :size] = particles[::stride, :2]
            self.weights[row, :size] = np.nan if weights is None else weights[::stride]
        self.sizes[row], self.steps[row], self.times[row] = size, step, time
        self.count += 1

    def take(self) -> tuple[np.ndarray, ...]:
        """Empty the rows: (steps (T,), times (T,) s, positions (M, 3), sizes (T,), shades
        (S,) uint8, shade counts (T,)), the rows' particles one after the other. A shade
        is 255 * the weight over its tick's largest weight, rounded; 128 where the weight
        is NaN. A row whose particles all have one shade (equal weights, as after a
        resampling) gives that shade once: Rerun repeats a row's last colour over its
        points, so the viewer shows the same colours."""
        n, self.count = self.count, 0
        sizes, weights = self.sizes[:n].copy(), self.weights[:n]
        held = np.arange(self.limit) < sizes[:, None]
        unknown = held & np.isnan(weights)
        # Only the held entries: the rest of a row is whatever the buffer held before.
        known = np.where(held & ~unknown, weights, 0.0)
        top = np.max(known, axis=1, keepdims=True)
        scale = np.divide(255.0, top, out=np.zeros_like(top), where=top > 0)
        shades = np.clip(known * scale + 0.5, 0, 255).astype(np.uint8)
        shades[unknown] = 128
        first = shades[:, :1]
        uniform = np.all((shades == first) | ~held, axis=1) & (sizes > 0)
        coloured = held & ~(uniform[:, None] & (np.arange(self.limit) > 0))
        kept = np.flatnonzero(held)  # take() copies rows several times faster than a bool mask
        positions = np.empty((len(kept), 3), dtype=np.float32)
        positions[:, :2] = np.take(self.xy[:n].reshape(-1, 2), kept, axis=0)
        positions[:, 2] = self.z
        counts = np.where(uniform, 1, sizes)
        steps, times = self.steps[:n].copy(), self.times[:n].copy()
        return steps, times, positions, sizes, shades[coloured], counts
