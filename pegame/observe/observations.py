"""The learning agents' observation vectors, built from what each role may see.

Both the environments (:mod:`pegame.envs`) and the ``policy`` strategies build their
observations here, from the same inputs a strategy gets in a game
(:class:`pegame.api.PursuerObservation`, :class:`pegame.api.EvaderObservation` and the
:class:`pegame.api.Context`), so a policy trained in an env sees the same numbers when it
plays in ``python -m pegame``.

An observation is one flat float32 vector; ``layout`` names its parts as slices (the
crop comes last so that ``obs[layout["crop"]].reshape(cells, cells)`` is an image). All
values lie in [-1, 1]. Normalised positions: x_n = 2 (x - x_min) / (x_max - x_min) - 1
over the map's extent (likewise y; :attr:`OccupancyGrid.extent`, which ignores an origin
yaw), clipped to [-1, 1]. ``D`` is the extent's diagonal (m).

Pursuer (:class:`PursuerFeatures`):

- ``pose`` (4): x_n, y_n, cos(theta), sin(theta) of its own map-frame pose;
- ``detection`` (4): detected this tick (0/1); range (m) / camera.far and bearing (rad,
  robot frame, left positive) / pi of the last detected position from the current pose,
  range capped at 1; its age (s) / ``AGE_SCALE``, capped at 1. Before the first
  detection: 0, 1, 0, 1;
- ``belief`` (4, only with ``belief=True``): has an estimate (0/1); the estimate's
  position in the robot frame / D (x, y); sqrt(trace(covariance)) / D capped at 1 (0
  without a covariance). All 0 without an estimate;
- ``crop`` (cells^2): the egocentric occupancy crop (:mod:`pegame.observe.crop`).

Evader (:class:`EvaderFeatures`), which is told the pursuer's pose as in the paper:

- ``pose`` (4): its own, as above;
- ``pursuer`` (4): the pursuer's pose, as above;
- ``relative`` (4): the pursuer's position in the evader's frame / D (x, y) and
  cos, sin of the pursuer's heading relative to the evader's;
- ``crop`` (cells^2).

The float operations are numba kernels of one game in :mod:`pegame.observe.features`
(one call per vector), shared with the batched environments (:mod:`pegame.vector.features`);
the belief part, which only the single game has, is computed here.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from pegame.api import Context, EvaderObservation, PursuerObservation
from pegame.errors import require
from pegame.observe.crop import LocalCrop
from pegame.observe.features import AGE_SCALE as AGE_SCALE
from pegame.observe.features import evader_observation, extent_numbers, pursuer_observation
from pegame.types import Belief, Detection, Pose


@dataclass(frozen=True)
class ObservationSettings:
    """What goes into an observation vector."""

    crop_cells: int = 32  # cells per side of the local occupancy crop
    crop_resolution: float = 0.2  # m per crop cell
    belief: bool = (
        False  # append the pursuer's estimator summary (costs an estimator update per tick)
    )

    def __post_init__(self) -> None:
        require(
            isinstance(self.crop_cells, int) and self.crop_cells >= 1,
            "crop_cells",
            "a whole number of cells >= 1",
            self.crop_cells,
        )
        require(
            self.crop_resolution > 0 and math.isfinite(self.crop_resolution),
            "crop_resolution",
            "a positive length in m",
            self.crop_resolution,
        )


#: (name, size, low, high) of an observation part
Part = tuple[str, int, float, float]


class _Features:
    """Layout, bounds and map normalisation of one role's observation vector, whose
    ``parts`` come before the crop."""

    def __init__(
        self, context: Context, settings: ObservationSettings, parts: Sequence[Part]
    ) -> None:
        self.context = context
        self.settings = settings
        self._extent = extent_numbers(context.grid)
        self._diagonal = float(self._extent[4])
        parts = [*parts, ("crop", settings.crop_cells**2, 0.0, 1.0)]
        self.layout: dict[str, slice] = {}
        low, high, start = [], [], 0
        for name, size, lo, hi in parts:
            self.layout[name] = slice(start, start + size)
            low += [lo] * size
            high += [hi] * size
            start += size
        self.size = start
        self._crop_at = self.layout["crop"].start
        crop = LocalCrop(context.grid, settings.crop_cells, settings.crop_resolution)
        self._crop = crop.structures
        self.low = np.array(low, dtype=np.float32)
        self.high = np.array(high, dtype=np.float32)


#: the kernels' (time, x, y) of the last detection before there is one (not read)
_NOWHERE = (0.0, 0.0, 0.0)


class PursuerFeatures(_Features):
    """The pursuer's observation vector. It remembers the last detection, so call
    :meth:`remember` (or ``__call__``) at every control tick and :meth:`reset` per game."""

    def __init__(self, context: Context, settings: ObservationSettings) -> None:
        parts: list[Part] = [("pose", 4, -1.0, 1.0), ("detection", 4, -1.0, 1.0)]
        if settings.belief:
            parts.append(("belief", 4, -1.0, 1.0))
        super().__init__(context, settings, parts)
        self._far = float(context.camera.far)
        self.reset()

    def reset(self) -> None:
        """Forget the last detection (a new game)."""
        self._last: tuple[float, float, float] | None = None  # (time s, x m, y m)
        self._now = False

    def remember(self, time: float, detection: Detection | None) -> None:
        """Record this control tick's detection (or its absence) at ``time`` (s)."""
        self._now = detection is not None
        if detection is not None:
            position = detection.position
            self._last = (float(time), float(position[0]), float(position[1]))

    def build(self, time: float, pose: Pose, belief: Belief) -> np.ndarray:
        """The vector at ``time`` (s) for the pursuer at map-frame ``pose``; ``belief`` is
        read only with ``belief=True``. A new float32 array each call."""
        out = np.empty(self.size, dtype=np.float32)
        last = self._last
        pursuer_observation(
            self._extent,
            self._crop,
            (float(pose.x), float(pose.y), float(pose.theta)),
            self._now,
            last is not None,
            _NOWHERE if last is None else last,
            float(time),
            self._far,
            out,
            self._crop_at,
        )
        if self.settings.belief:
            self.belief_part(out[8:12], pose, belief)
        return out

    def update(self, observation: PursuerObservation) -> None:
        """Remember a strategy observation's detection (call at every control tick)."""
        self.remember(observation.time, observation.detection)

    def __call__(self, observation: PursuerObservation) -> np.ndarray:
        """Remember this tick's detection and build the vector from a strategy observation."""
        self.update(observation)
        return self.build(observation.time, observation.pose, observation.belief)

    def belief_part(self, out: np.ndarray, pose: Pose, belief: Belief) -> None:
        """The ``belief`` part (4 values, module docstring) for the pursuer at ``pose``
        into ``out``."""
        if belief.mean is None:
            out[:] = 0.0
            return
        dx, dy = belief.mean[0] - pose.x, belief.mean[1] - pose.y
        c, s = math.cos(pose.theta), math.sin(pose.theta)
        d = self._diagonal
        out[0] = 1.0
        out[1] = min(1.0, max(-1.0, (c * dx + s * dy) / d))
        out[2] = min(1.0, max(-1.0, (-s * dx + c * dy) / d))
        spread = (
            0.0
            if belief.covariance is None
            else math.sqrt(max(0.0, float(np.trace(belief.covariance))))
        )
        out[3] = min(1.0, spread / d)


class EvaderFeatures(_Features):
    """The evader's observation vector (stateless)."""

    def __init__(self, context: Context, settings: ObservationSettings) -> None:
        super().__init__(
            context,
            settings,
            [("pose", 4, -1.0, 1.0), ("pursuer", 4, -1.0, 1.0), ("relative", 4, -1.0, 1.0)],
        )

    def reset(self) -> None:
        """Nothing to forget; the same calls as :class:`PursuerFeatures` work."""

    def update(self, observation: EvaderObservation) -> None:
        """Nothing to remember."""

    def build(self, pose: Pose, pursuer: Pose) -> np.ndarray:
        """The vector for the evader at map-frame ``pose`` and the pursuer at ``pursuer``.
        A new float32 array each call."""
        out = np.empty(self.size, dtype=np.float32)
        evader_observation(
            self._extent,
            self._crop,
            (float(pose.x), float(pose.y), float(pose.theta)),
            (float(pursuer.x), float(pursuer.y), float(pursuer.theta)),
            out,
            self._crop_at,
        )
        return out

    def __call__(self, observation: EvaderObservation) -> np.ndarray:
        """Build the vector from a strategy's observation."""
        return self.build(observation.pose, observation.pursuer)
