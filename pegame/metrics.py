"""Per-game measures: the paper's tracking success rate and what explains it.

The tracking rate is the fraction of control ticks at which the pursuer's detector
reports the evader (paper, Table 1: "tracking success rate"). A *loss* is a maximal run of
ticks without a detection; it ends in a *reacquisition* when a detection follows. The
visible rate is the fraction of ticks at which any part of the evader's body is in the
pursuer's view (:func:`pegame.visibility.body_in_view`), the ground truth beside it.

Teams (:class:`TeamMetrics`): evader j counts as detected at a tick when at least one
pursuer detects it, and as in view when it is in some pursuer's view; ``tracking_rate``
is the mean over the M evaders of their fractions of detected ticks (for one pursuer
and one evader exactly the 1v1 value), and every other per-evader measure is the mean
over the evaders (distances to the nearest pursuer). Beside them: the per-evader and
per-pursuer tracking rates (a pursuer's: the fraction of ticks it detects some evader),
*handoffs* (an evader's custody passing straight from one pursuer to another: its
tracker, the pursuer that has detected it since the others lost it, stops detecting it
while another pursuer does, or the tracker loses it in the very tick another takes it),
and the team's *coverage*, the mean fraction of the map's free cells inside the union of
the pursuers' regions, sampled at decision ticks.

Each loss of track of every (pursuer, evader) pair gets a cause from the ground truth at
its tick (:mod:`pegame.losses`); the summary's ``loss_causes`` gives their counts and the
time lost per cause.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from pegame.types import Belief, Detection, Pose, Region

if TYPE_CHECKING:  # pragma: no cover - typing only
    from pegame.api import Context
    from pegame.losses import LossCauses


def _runs(flags: np.ndarray) -> list[tuple[int, int]]:
    """(start, stop) index pairs of the maximal runs of True in a bool array."""
    padded = np.concatenate(([False], flags, [False])).astype(np.int8)
    edges = np.flatnonzero(np.diff(padded))
    return list(zip(edges[::2].tolist(), edges[1::2].tolist()))


def _rounded(value: float | np.floating | None) -> float | None:
    """Round for the result file (values are deterministic; rounding only shortens them)."""
    return None if value is None or not math.isfinite(value) else round(float(value), 6)


def _path_length(xy: np.ndarray) -> float:
    """Length (m) of the polyline through the (K, 2) points."""
    return float(np.sum(np.linalg.norm(np.diff(xy, axis=0), axis=1)))


class TrackingMetrics:
    """Accumulates one game tick by tick; ``summary()`` gives the result's measures.

    dt: control period (s); losses: the game's loss causes (:mod:`pegame.losses`, fed
    by the tick loop), summarised as ``loss_causes`` when given.
    """

    def __init__(self, dt: float, losses: LossCauses | None = None) -> None:
        self.dt = dt
        self.losses = losses
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

    def summary(self) -> dict[str, Any]:
        """The game's measures: rates in [0, 1], times in s, distances in m; with
        ``losses``, ``loss_causes`` (:meth:`pegame.losses.LossCauses.summary`)."""
        detected = np.asarray(self.detected, dtype=bool)
        losses = _runs(~detected)
        reacquired = [(stop - start) * self.dt for start, stop in losses if stop < detected.size]
        first_loss = losses[0][0] * self.dt if losses else None
        pursuer, evader = np.asarray(self.pursuer), np.asarray(self.evader)
        errors = np.asarray(self.estimate_error)
        errors = errors[np.isfinite(errors)]
        summary: dict[str, Any] = {
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
        if self.losses is not None:
            summary["loss_causes"] = self.losses.summary()
        return summary


class TeamMetrics:
    """Accumulates a team game (module docstring) tick by tick; ``summary()`` gives the
    result's measures, the 1v1 keys (means over the evaders) and the team's.

    context: the game's; pursuers, evaders: the team sizes N and M; losses: the game's
    loss causes, every pair's (:mod:`pegame.losses`), summarised as ``loss_causes``.
    """

    def __init__(
        self, context: Context, pursuers: int, evaders: int, losses: LossCauses | None = None
    ) -> None:
        self.dt = context.control_dt
        self.losses = losses
        self.free = ~context.grid.blocked
        self.free_cells = max(1, int(self.free.sum()))
        self.per_evader = [TrackingMetrics(self.dt) for _ in range(evaders)]
        self.pursuer_paths: list[list[tuple[float, float]]] = [[] for _ in range(pursuers)]
        self.pursuer_detected = [0] * pursuers
        self.ticks = 0
        self.trackers: list[int | None] = [None] * evaders
        self.handoffs = 0
        self.coverage: list[float] = []

    @property
    def detected(self) -> list[bool]:
        """Per tick: whether some evader was detected by some pursuer."""
        columns = [m.detected for m in self.per_evader]
        return [any(flags) for flags in zip(*columns)]

    def add(
        self,
        pursuers: Sequence[Pose],
        evaders: Sequence[Pose],
        detections: Sequence[Sequence[Detection | None]],
        in_view: Sequence[Sequence[bool]],
        beliefs: Sequence[Belief],
        union: Region | None = None,
    ) -> None:
        """Record one control tick: true poses, detections[i][j] and in_view[i][j] of
        pursuer i and evader j, the beliefs per evader and, when given, the union of the
        pursuers' regions (a coverage sample)."""
        self.ticks += 1
        for i, pose in enumerate(pursuers):
            self.pursuer_paths[i].append((pose.x, pose.y))
            self.pursuer_detected[i] += any(d is not None for d in detections[i])
        for j, (evader, metrics) in enumerate(zip(evaders, self.per_evader)):
            seers = [i for i, row in enumerate(detections) if row[j] is not None]
            near = min(range(len(pursuers)), key=lambda i: pursuers[i].distance_to(evader))
            seen_in_view = any(row[j] for row in in_view)
            metrics.add(pursuers[near], evader, bool(seers), seen_in_view, beliefs[j])
            self.handoffs += self._hand(j, seers)
        if union is not None:
            self.coverage.append(float(np.count_nonzero(union.mask & self.free)) / self.free_cells)

    def _hand(self, j: int, seers: list[int]) -> int:
        """Update evader j's tracker from this tick's ``seers``; 1 for a handoff."""
        tracker = self.trackers[j]
        if not seers:
            self.trackers[j] = None
            return 0
        if tracker in seers:
            return 0
        self.trackers[j] = seers[0]
        return int(tracker is not None)

    @property
    def tracking_rate(self) -> float:
        """Mean over the evaders of their fractions of ticks so far detected by some pursuer."""
        return float(np.mean([m.tracking_rate for m in self.per_evader]))

    def summary(self) -> dict[str, Any]:
        """The 1v1 measures as means over the evaders, then the team's (module docstring)."""
        result = team_summary(
            [m.summary() for m in self.per_evader],
            [m.tracking_rate for m in self.per_evader],
            [_path_length(np.asarray(p)) for p in self.pursuer_paths],
            self.pursuer_detected,
            self.ticks,
            self.handoffs,
            self.coverage,
        )
        if self.losses is not None:
            result["loss_causes"] = self.losses.summary()
        return result


def team_summary(
    summaries: Sequence[dict[str, Any]],
    tracking_rates: Sequence[float],
    pursuer_paths: Sequence[float],
    pursuer_detected: Sequence[int],
    ticks: int,
    handoffs: int,
    coverage: Sequence[float],
) -> dict[str, Any]:
    """A team game's measures (:meth:`TeamMetrics.summary` but the loss causes) from each
    evader's 1v1 ``summaries`` and unrounded ``tracking_rates``, each pursuer's path
    length (m) and ticks detecting some evader, the ticks played, the handoffs and the
    coverage samples (fractions of the free cells)."""
    result: dict[str, Any] = {}
    for key in summaries[0]:
        values = [v for v in (s[key] for s in summaries) if v is not None]
        result[key] = _rounded(np.mean(values)) if values else None
    ticks = max(1, ticks)
    result["tracking_rate"] = _rounded(float(np.mean(tracking_rates)))
    result["pursuer_path_length"] = _rounded(np.mean(pursuer_paths))
    result.update(
        {
            "pursuers": len(pursuer_paths),
            "evaders": len(summaries),
            "tracking_rate_per_evader": [s["tracking_rate"] for s in summaries],
            "tracking_rate_per_pursuer": [_rounded(n / ticks) for n in pursuer_detected],
            "handoffs": handoffs,
            "coverage": _rounded(np.mean(coverage)) if len(coverage) else None,
        }
    )
    return result
