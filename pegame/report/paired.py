"""Paired statistics of two sets of games matched by seed.

In a pegame sweep the same seed gives the same spawn poses for every pairing and every
configuration (the spawn stream is drawn first from the seed), so two games with the same
seed are *paired*: their difference removes the spawn's share of the variance. On the
seeds common to both sides this module gives

- the Wilcoxon signed-rank test (Wilcoxon, *Biometrics Bulletin* 1, 1945),
  :func:`scipy.stats.wilcoxon`, with ``zero_method="pratt"`` (Pratt, *JASA* 54, 1959): a
  zero difference (both sides tracked the evader equally on that spawn, often both 100%
  or both 0%, since rates are bounded) is a genuine observation of "no difference". The
  default ``"wilcox"`` drops such pairs before ranking, which shrinks n and overstates the
  evidence when many seeds tie; Pratt's method ranks the zeros with the others (so they
  count as the smallest absolute differences) and then leaves their ranks out of the
  statistic, the conservative choice. All differences zero: W = 0, p = 1 (no evidence);
- the mean paired difference with its percentile-bootstrap confidence interval over
  seeds (:func:`~pegame.bootstrap.bootstrap_ci`: the same fixed seed and 10,000
  resamples as the cells' intervals);
- the matched-pairs rank-biserial correlation (Kerby, *Comprehensive Psychology* 3, 2014)
  r = (T+ - T-) / (T+ + T-), from the same Pratt ranks as the test: +1 when every nonzero
  difference is positive, -1 when every one is negative, 0 when no difference.

Rates and differences are fractions in [0, 1] and [-1, 1] (report.json, CSV); the text
files show them in percent and percentage points. Differences are rounded to 12 decimals
before ranking, so that float noise (0.3 - 0.2 against 0.4 - 0.3) does not break ties.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy.stats import rankdata, wilcoxon

from pegame.bootstrap import bootstrap_ci
from pegame.report.measures import TRACKING, Measure, is_value

ZERO_METHOD = "pratt"
TEST_NAME = "Wilcoxon signed-rank on common seeds"
KEYS = (
    "n_pairs",
    "mean_x",
    "mean_y",
    "mean_difference",
    "ci_low",
    "ci_high",
    "zero_differences",
    "W",
    "p",
    "rank_biserial",
)

BySeed = dict[int, float]  # seed -> the measure (tracking rate: a fraction)


def by_seed(games: list[dict[str, Any]], name: str = "tracking_rate") -> BySeed:
    """{seed: measure ``name``} of a cell's games that define it; a seed played more than
    once in one cell (a cell mixing config hashes, which the report warns about) counts
    with its mean."""
    rates: dict[int, list[float]] = {}
    for game in games:
        if is_value(game.get(name)):
            rates.setdefault(int(game["seed"]), []).append(float(game[name]))
    return {seed: math.fsum(values) / len(values) for seed, values in sorted(rates.items())}


def signed_rank_sums(differences: np.ndarray) -> tuple[float, float]:
    """(T+, T-): the sums of Pratt's ranks of |differences| (zeros ranked, then left out)
    over the positive and over the negative differences."""
    ranks = rankdata(np.abs(differences))
    return float(ranks[differences > 0].sum()), float(ranks[differences < 0].sum())


def rank_biserial(differences: np.ndarray) -> float:
    """Matched-pairs rank-biserial correlation (T+ - T-) / (T+ + T-), 0 without nonzero
    differences."""
    plus, minus = signed_rank_sums(differences)
    return 0.0 if plus + minus == 0 else (plus - minus) / (plus + minus)


def paired_test(x: BySeed, y: BySeed, alternative: str) -> dict[str, Any]:
    """The paired comparison of ``x`` against ``y`` on their common seeds: n_pairs, the
    means of each side there, the mean difference x - y with its bootstrap CI, the number
    of zero differences, Wilcoxon's W = T+ (the sum of the ranks of the positive
    differences, whatever the alternative) and p
    (``alternative``: 'greater', 'less' or 'two-sided', about x - y), and the rank-biserial
    correlation. Every value but n_pairs is None without common seeds (not tested)."""
    seeds = sorted(x.keys() & y.keys())
    if not seeds:
        return {key: 0 if key == "n_pairs" else None for key in KEYS}
    a = np.array([x[s] for s in seeds])
    b = np.array([y[s] for s in seeds])
    differences = np.round(a - b, 12)
    low, high = bootstrap_ci(differences.tolist())
    # scipy's normal approximation divides by zero when every difference is zero
    p = (
        1.0
        if np.all(differences == 0)
        else float(wilcoxon(differences, zero_method=ZERO_METHOD, alternative=alternative).pvalue)
    )
    return {
        "n_pairs": len(seeds),
        "mean_x": math.fsum(a) / len(seeds),
        "mean_y": math.fsum(b) / len(seeds),
        "mean_difference": math.fsum(differences) / len(seeds),
        "ci_low": low,
        "ci_high": high,
        "zero_differences": int(np.sum(differences == 0)),
        "W": signed_rank_sums(differences)[0],
        "p": p,
        "rank_biserial": rank_biserial(differences),
    }


def difference_text(paired: dict[str, Any], measure: Measure = TRACKING) -> str:
    """'+10.0 pp [+8.2, +11.9]' (rates; '+0.52 m [...]' for a distance) for a tested
    comparison, '–' otherwise."""
    if paired["mean_difference"] is None:
        return "–"
    unit = "pp" if measure.is_rate else measure.unit
    low, mean, high = (
        f"{measure.scale * paired[k]:+.{measure.digits}f}"
        for k in ("ci_low", "mean_difference", "ci_high")
    )
    return f"{mean}{' ' + unit if unit else ''} [{low}, {high}]"
