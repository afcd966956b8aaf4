"""The batched games' measures: :class:`pegame.metrics.TrackingMetrics` kept as running
sums per game (a row of ``state.tally``, filled by :func:`pegame.vector.kernels.tally`)
instead of per-tick lists, so that a game's memory does not grow with its length.

Counts, rates, the first loss, the longest loss and the reacquisition maximum are exact;
means and path lengths are sums taken tick by tick where numpy sums pairwise, which can
differ in the last bits before the 6-decimal rounding of the result. No estimator runs in
a batched game: its measures (estimation error, n_eff, resamplings) are None and 0, as
in a single env game without an estimate. A team game's are each evader's, combined as
:func:`pegame.metrics.team_summary` combines them for the single game.
"""

from __future__ import annotations

import numpy as np

from pegame import metrics
from pegame.metrics import _rounded
from pegame.vector import state as k


def new_tally() -> np.ndarray:
    """The tally row of a game before its first tick."""
    row = np.zeros(k.TALLY_SIZE)
    row[k.FIRST_LOSS] = -1.0
    return row


def summary(row: np.ndarray, dt: float) -> dict[str, float | int | None]:
    """``TrackingMetrics.summary`` of the game whose tally is ``row``; ``dt``: the
    control period (s)."""
    ticks = row[k.TICKS]
    longest = row[k.LONGEST_LOSS]
    if row[k.IN_LOSS]:  # a loss running at the end is a loss, not a reacquisition
        longest = max(longest, ticks - row[k.LOSS_START])
    reacquisitions = int(row[k.REACQUISITIONS])
    first_loss = row[k.FIRST_LOSS]
    return {
        "tracking_rate": _rounded(row[k.DETECTED] / ticks),
        "visible_rate": _rounded(row[k.IN_VIEW] / ticks),
        "time_to_first_loss": _rounded(int(first_loss) * dt) if first_loss >= 0 else None,
        "longest_loss": _rounded(int(longest) * dt),
        "reacquisitions": reacquisitions,
        "reacquire_time_mean": (
            _rounded(row[k.REACQUIRE_SUM] / reacquisitions) if reacquisitions else None
        ),
        "reacquire_time_max": _rounded(int(row[k.REACQUIRE_MAX]) * dt) if reacquisitions else None,
        "mean_distance": _rounded(row[k.DISTANCE_SUM] / ticks),
        "pursuer_path_length": _rounded(row[k.PURSUER_PATH]),
        "evader_path_length": _rounded(row[k.EVADER_PATH]),
        "mean_estimation_error": None,
        "n_eff_mean": None,
        "n_eff_min": None,
        "resamplings": 0,
    }


def team_summary(rows: np.ndarray, crew: np.ndarray, handoffs: int, dt: float) -> dict:
    """``TeamMetrics.summary`` (without loss causes) of a team game whose evaders' tally
    rows are ``rows`` (E, TALLY_SIZE) and pursuers' rows of state.crew ``crew`` (P,
    CREW_SIZE), with ``handoffs``; coverage None (it needs the pursuers' regions, which neither the
    batched game nor an env game builds)."""
    ticks = rows[:, k.TICKS]
    rates = np.divide(rows[:, k.DETECTED], ticks, out=np.zeros(ticks.size), where=ticks > 0)
    return metrics.team_summary(
        [summary(row, dt) for row in rows],
        rates.tolist(),
        crew[:, k.CREW_PATH].tolist(),
        [int(n) for n in crew[:, k.CREW_DETECTED]],
        int(ticks[0]),
        handoffs,
        [],
    )
