"""The report's statistics: a cell's description with a bootstrap confidence interval of
the mean, the one-sided Mann-Whitney U test and the Holm-Bonferroni correction.

- Percentile bootstrap (:mod:`pegame.bootstrap`): 10,000 resamples with a fixed seed, so
  a report is reproducible.
- Mann-Whitney U (Mann & Whitney, 1947), :func:`scipy.stats.mannwhitneyu`.
- Holm's step-down correction (Holm, *Scand. J. Statist.* 6, 1979) of a family of p-values.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy.stats import mannwhitneyu

from pegame.bootstrap import bootstrap_ci

ALPHA = 0.05
DESCRIBED = ("n", "mean", "ci_low", "ci_high", "median", "std")  # describe()'s keys


def describe(values: list[float]) -> dict[str, Any]:
    """n, exact mean (math.fsum, order-independent), bootstrap CI, median and sample std;
    n = 0 and the others None for no values."""
    if not values:
        return {key: 0 if key == "n" else None for key in DESCRIBED}
    low, high = bootstrap_ci(values)
    return {
        "n": len(values),
        "mean": math.fsum(values) / len(values),
        "ci_low": low,
        "ci_high": high,
        "median": float(np.median(values)),
        "std": float(np.std(values, ddof=1)) if len(values) > 1 else None,
    }


def mann_whitney(x: list[float], y: list[float], alternative: str) -> tuple[float, float]:
    """(U of ``x``, p) of the Mann-Whitney U test; ``alternative`` 'greater' or 'less'."""
    result = mannwhitneyu(x, y, alternative=alternative)
    return float(result.statistic), float(result.pvalue)


def holm(pvalues: list[float]) -> list[float]:
    """Holm-Bonferroni adjusted p-values, in input order (reject where <= alpha)."""
    adjusted = [0.0] * len(pvalues)
    running = 0.0
    for rank, index in enumerate(sorted(range(len(pvalues)), key=pvalues.__getitem__)):
        running = max(running, min(1.0, (len(pvalues) - rank) * pvalues[index]))
        adjusted[index] = running
    return adjusted
