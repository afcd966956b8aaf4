"""The per-game measures a report can aggregate: the numeric fields of ``result.json``
(:mod:`pegame.metrics`; a game line of ``results.jsonl`` carries the same), each with
its label, unit and how a table writes it.

Rates are fractions in [0, 1] in report.json and CSV, percentages in text and figures;
distances are in m, times in s, counts plain numbers. A measure a game does not define
(``mean_estimation_error`` when the evader was never out of sight, ``n_eff_mean`` of an
estimator without particles) is None in its line: a cell's statistics of that measure are
over the games that define it, and its n counts them.
"""

from __future__ import annotations

from dataclasses import dataclass
from difflib import get_close_matches
from typing import Any

from pegame.errors import PegameError


@dataclass(frozen=True)
class Measure:
    """One numeric field of result.json.

    name: its key; label: what tables and axes call it (the table's title is 'mean'
    and the label: the mean over the games of the game's value); unit: '%' for rates (stored as
    fractions, shown times 100), 'm', 's' or '' for counts; digits: decimals in text.
    """

    name: str
    label: str
    unit: str
    digits: int

    @property
    def scale(self) -> float:
        """The factor from the stored value to the shown one (100 for rates)."""
        return 100.0 if self.unit == "%" else 1.0

    @property
    def is_rate(self) -> bool:
        """Whether the measure is a fraction in [0, 1]."""
        return self.unit == "%"

    def shown(self, value: float) -> str:
        """A stored value as text in the measure's unit: '61.3%', '3.79 m', '21.0'."""
        number = f"{self.scale * value:.{self.digits}f}"
        return number + ("%" if self.is_rate else f" {self.unit}" if self.unit else "")

    def axis_label(self) -> str:
        """'tracking success rate (%)', 'distance (m)', 'resamplings'."""
        return f"{self.label} ({self.unit})" if self.unit else self.label


MEASURES: dict[str, Measure] = {
    m.name: m
    for m in (
        Measure("tracking_rate", "tracking success rate", "%", 1),
        Measure("visible_rate", "visible rate", "%", 1),
        Measure("time_to_first_loss", "time to first loss", "s", 2),
        Measure("longest_loss", "longest loss", "s", 2),
        Measure("reacquisitions", "reacquisitions", "", 2),
        Measure("reacquire_time_mean", "reacquisition time", "s", 2),
        Measure("reacquire_time_max", "longest reacquisition time", "s", 2),
        Measure("mean_distance", "distance", "m", 2),
        Measure("pursuer_path_length", "pursuer path length", "m", 2),
        Measure("evader_path_length", "evader path length", "m", 2),
        Measure("mean_estimation_error", "estimation error while unseen", "m", 3),
        Measure("n_eff_mean", "N_eff", "", 1),
        Measure("n_eff_min", "minimum N_eff", "", 1),
        Measure("resamplings", "resamplings", "", 1),
        Measure("handoffs", "handoffs", "", 2),
        Measure("coverage", "coverage", "%", 1),
    )
}
TRACKING = MEASURES["tracking_rate"]


class MeasureError(PegameError, ValueError):
    """A report was asked for a measure that result.json does not have."""


def measure(name: str) -> Measure:
    """The measure called ``name``; :class:`MeasureError` listing the allowed names."""
    if name not in MEASURES:
        close = get_close_matches(name, MEASURES, n=1)
        raise MeasureError(
            f"--metric {name!r} is not a measure of result.json"
            + (f" (did you mean {close[0]}?)" if close else "")
            + f". The report aggregates one of its numeric measures: {', '.join(MEASURES)} "
            f"(default tracking_rate; rates in %, distances in m, times in s)."
        )
    return MEASURES[name]


def is_value(value: Any) -> bool:
    """A number (not a bool, not None): a game that defines the measure."""
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def values(games: list[dict[str, Any]], name: str) -> list[float]:
    """The measure ``name`` of each game that defines it, in game order."""
    return [float(g[name]) for g in games if is_value(g.get(name))]
