"""Per-game measures: the paper's tracking success rate and what explains it.

The tracking rate is the fraction of control ticks at which the pursuer's detector
reports the evader (paper, Table 1: "tracking success rate"). A *loss* is a maximal run of
ticks without a detection; it ends in a *reacquisition* when a detection follows. The
visible rate is the fraction of ticks at which any part of the evader's body is in the
pursuer's view (:func:`pegame.visibility.body_in_view`), the ground truth beside it.
"""

from __future__ import annotations

import math

import numpy as np

from pegame.types import Belief, Pose


def _runs(flags: np.ndarray) -> list[tuple[int, int]]:
    """(start, stop) index pairs of the maximal runs of True in a bool array."""
    padded = np.concatenate(([False], flags, [False])).astype(np.int8)
    edges = np.flatnonzero(np.diff(padded))
    return list(zip(edges[::2].tolist(), edges[1::2].tolist()))


def _rounded(value: float | None) -> float | None:
    """Round for the result file (values are deterministic; rounding only shortens them)."""
    return None if value is None or not math.isfinite(value) else round(float(value), 6)


def _path_length(xy: np.ndarray) -> float:
    """Length (m) of the polyline through the (K, 2) points."""
    return float(np.sum(np.linalg.norm(np.diff(xy, axis=0), axis=1)))


class TrackingMetrics:
    """Accumulates one game tick by tick; ``summary()`` gives the result's measures.

    dt: control period (s).
    """

    def __init__(self, dt: float) -> None:
        self.dt = dt
        self.pursuer: list[tuple[float, float]] = []
        self.evader: list[tuple[float, float]] = []
        self.detected: list[bool] = []
        self.in_view: list[bool] = []
        self.estimate_error: list[float] = []  # NaN where detected or no estimate
        self.n_eff: list[float] = []
        self.resamplings = 0
        self.detected_ticks = 0

    def add(
        self, pursuer: Pose, evader: Pose, detected: bool, in_view: bool, belief: Belief
    ) -> None:
        """Record one control tick: true poses, detection, ground-truth visibility, belief."""
        self.pursuer.append((pursuer.x, pursuer.y))
        self.evader.append((evader.x, evader.y))
        self.detected.append(detected)
        self.detected_ticks += detected
        self.in_view.append(in_view)
        error = math.nan
        if not detected and belief.mean is not None:
            error = math.hypot(belief.mean[0] - evader.x, belief.mean[1] - evader.y)
        self.estimate_error.append(error)
        if belief.n_eff is not None:
            self.n_eff.append(belief.n_eff)
        self.resamplings += int(belief.resampled)

    @property
    def tracking_rate(self) -> float:
        """Fraction of ticks so far with the evader detected."""
        return self.detected_ticks / len(self.detected) if self.detected else 0.0

    def summary(self) -> dict[str, float | int | None]:
        """The game's measures: rates in [0, 1], times in s, distances in m."""
        detected = np.asarray(self.detected, dtype=bool)
        losses = _runs(~detected)
        reacquired = [(stop - start) * self.dt for start, stop in losses if stop < detected.size]
        first_loss = losses[0][0] * self.dt if losses else None
        pursuer, evader = np.asarray(self.pursuer), np.asarray(self.evader)
        errors = np.asarray(self.estimate_error)
        errors = errors[np.isfinite(errors)]
        return {
            "tracking_rate": _rounded(detected.mean()),
            "visible_rate": _rounded(np.mean(self.in_view)),
            "time_to_first_loss": _rounded(first_loss),
            "longest_loss": _rounded(max(((b - a) * self.dt for a, b in losses), default=0.0)),
            "reacquisitions": len(reacquired),
            "reacquire_time_mean": _rounded(np.mean(reacquired)) if reacquired else None,
            "reacquire_time_max": _rounded(max(reacquired)) if reacquired else None,
            "mean_distance": _rounded(np.mean(np.linalg.norm(pursuer - evader, axis=1))),
            "pursuer_path_length": _rounded(_path_length(pursuer)),
            "evader_path_length": _rounded(_path_length(evader)),
            "mean_estimation_error": _rounded(errors.mean()) if errors.size else None,
            "n_eff_mean": _rounded(np.mean(self.n_eff)) if self.n_eff else None,
            "n_eff_min": _rounded(min(self.n_eff)) if self.n_eff else None,
            "resamplings": self.resamplings,
        }
