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
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from pegame.api import Context, EvaderObservation, PursuerObservation
from pegame.errors import require
from pegame.observe.crop import LocalCrop
from pegame.types import Belief, Detection, Pose, wrap_angle

#: s; detection ages are divided by this and capped at 1
AGE_SCALE = 10.0


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
        x0, x1, y0, y1 = context.grid.extent
        self._x0, self._y0 = x0, y0
        self._sx, self._sy = 2.0 / (x1 - x0), 2.0 / (y1 - y0)
        self._diagonal = math.hypot(x1 - x0, y1 - y0)
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
        self._local_crop = LocalCrop(context.grid, settings.crop_cells, settings.crop_resolution)
        self.low = np.array(low, dtype=np.float32)
        self.high = np.array(high, dtype=np.float32)

    def _pose(self, out: np.ndarray, at: int, pose: Pose) -> None:
        """Write the normalised map-frame pose (x_n, y_n, cos, sin) into out[at:at + 4]."""
        out[at] = min(1.0, max(-1.0, (pose.x - self._x0) * self._sx - 1.0))
        out[at + 1] = min(1.0, max(-1.0, (pose.y - self._y0) * self._sy - 1.0))
        out[at + 2] = math.cos(pose.theta)
        out[at + 3] = math.sin(pose.theta)

    def _crop(self, out: np.ndarray, pose: Pose) -> None:
        self._local_crop(pose.x, pose.y, pose.theta, out[self._crop_at :])


class PursuerFeatures(_Features):
    """The pursuer's observation vector. It remembers the last detection, so call
    :meth:`remember` (or ``__call__``) at every control tick and :meth:`reset` per game."""

    def __init__(self, context: Context, settings: ObservationSettings) -> None:
        parts: list[Part] = [("pose", 4, -1.0, 1.0), ("detection", 4, -1.0, 1.0)]
        if settings.belief:
            parts.append(("belief", 4, -1.0, 1.0))
        super().__init__(context, settings, parts)
        self.reset()

    def reset(self) -> None:
        """Forget the last detection (a new game)."""
        self._last: tuple[float, float, float] | None = None  # (time s, x m, y m)
        self._now = False

    def remember(self, time: float, detection: Detection | None) -> None:
        """Record this control tick's detection (or its absence) at ``time`` (s)."""
        self._now = detection is not None
        if detection is not None:
            self._last = (time, float(detection.position[0]), float(detection.position[1]))

    def build(self, time: float, pose: Pose, belief: Belief) -> np.ndarray:
        """The vector at ``time`` (s) for the pursuer at map-frame ``pose``; ``belief`` is
        read only with ``belief=True``. A new float32 array each call."""
        out = np.empty(self.size, dtype=np.float32)
        self._pose(out, 0, pose)
        out[4] = float(self._now)
        if self._last is None:
            out[5:8] = (1.0, 0.0, 1.0)
        else:
            seen_at, x, y = self._last
            dx, dy = x - pose.x, y - pose.y
            out[5] = min(1.0, math.hypot(dx, dy) / self.context.camera.far)
            out[6] = wrap_angle(math.atan2(dy, dx) - pose.theta) / math.pi
            out[7] = min(1.0, (time - seen_at) / AGE_SCALE)
        if self.settings.belief:
            self._belief(out[8:12], pose, belief)
        self._crop(out, pose)
        return out

    def update(self, observation: PursuerObservation) -> None:
        """Remember a strategy observation's detection (call at every control tick)."""
        self.remember(observation.time, observation.detection)

    def __call__(self, observation: PursuerObservation) -> np.ndarray:
        """Remember this tick's detection and build the vector from a strategy observation."""
        self.update(observation)
        return self.build(observation.time, observation.pose, observation.belief)

    def _belief(self, out: np.ndarray, pose: Pose, belief: Belief) -> None:
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
        self._pose(out, 0, pose)
        self._pose(out, 4, pursuer)
        dx, dy = pursuer.x - pose.x, pursuer.y - pose.y
        c, s = math.cos(pose.theta), math.sin(pose.theta)
        d = self._diagonal
        out[8] = min(1.0, max(-1.0, (c * dx + s * dy) / d))
        out[9] = min(1.0, max(-1.0, (-s * dx + c * dy) / d))
        out[10] = math.cos(pursuer.theta - pose.theta)
        out[11] = math.sin(pursuer.theta - pose.theta)
        self._crop(out, pose)
        return out

    def __call__(self, observation: EvaderObservation) -> np.ndarray:
        """Build the vector from a strategy's observation."""
        return self.build(observation.pose, observation.pursuer)
