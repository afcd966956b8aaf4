"""Tests for an ordered alternative: does a measure rise along an ordered factor (the speed
ratio v_p/v_e)?

- :func:`jonckheere`: the Jonckheere-Terpstra test of independent groups (Terpstra,
  *Indagationes Mathematicae* 14, 1952; Jonckheere, *Biometrika* 41, 1954). J counts, over
  every pair of groups i < j and every pair of observations (a from group i, b from group
  j), 1 where b > a and 1/2 where b = a. Under H0 (one distribution for all groups) its mean
  is `(N^2 - sum n_i^2) / 4` and its variance, corrected for ties (Hollander & Wolfe,
  *Nonparametric Statistical Methods*, 2nd ed. 1999, Sec. 6.2), is
  `(N(N-1)(2N+5) - sum n_i(n_i-1)(2n_i+5) - sum t(t-1)(2t+5)) / 72
  + (sum n_i(n_i-1)(n_i-2)) (sum t(t-1)(t-2)) / (36 N(N-1)(N-2))
  + (sum n_i(n_i-1)) (sum t(t-1)) / (8 N(N-1))`
  with t the sizes of the groups of tied values. p is the normal approximation's upper
  tail, P(Z >= z), z = (J - mean) / sd; ``tau`` = 2 J / M - 1 with M = sum_{i<j} n_i n_j, the
  share of concordant minus discordant pairs (+1: every later group above every earlier).
- :func:`page`: the paired form, Page's L test (Page, *JASA* 58, 1963) of blocks (seeds:
  the same spawn poses at every level) x ordered treatments. Within each block the values
  are ranked (ties share their mean rank) and L = sum over blocks of sum_j j r_j. Under H0
  each block's ranks are equally likely in any order, so `E(L) = n k (k+1)^2 / 4` and, for
  a block of ranks r, `Var = (sum_j (j - (k+1)/2)^2) (sum_j (r_j - (k+1)/2)^2) / (k - 1)`:
  the exact permutation variance, which is Page's `n k^2 (k-1) (k+1)^2 / 144` without ties
  and shrinks with them (a block tied at every level adds nothing). p = P(Z >= z).

Values are rounded to 12 decimals before ranking, as in :mod:`pegame.report.paired`, so
float noise does not break ties. Both tests give p = 1 and z = None when the variance is
zero (every value tied: no evidence either way).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from scipy.stats import norm, rankdata

JT_NAME = "Jonckheere-Terpstra"
PAGE_NAME = "Page's L on common seeds"


def tie_sizes(values: np.ndarray) -> np.ndarray:
    """The sizes of the groups of equal values (1 for an untied value)."""
    return np.unique(values, return_counts=True)[1].astype(float)


def upper_tail(statistic: float, mean: float, variance: float) -> tuple[float | None, float]:
    """(z, P(Z >= z)) of the normal approximation; (None, 1) for a zero variance."""
    if variance <= 1e-12:
        return None, 1.0
    z = (statistic - mean) / math.sqrt(variance)
    return z, float(norm.sf(z))


def jonckheere(groups: Sequence[Sequence[float]]) -> dict[str, Any]:
    """The Jonckheere-Terpstra test that the groups, in their order, rise: {J, mean,
    variance, z, p, tau, n} (n: each group's size). Needs two or more non-empty groups."""
    arrays = [np.round(np.asarray(g, dtype=float), 12) for g in groups]
    if len(arrays) < 2 or any(a.size == 0 for a in arrays):
        raise ValueError("the Jonckheere-Terpstra test needs two or more non-empty groups")
    j = 0.0
    for i, lower in enumerate(arrays):
        for upper in arrays[i + 1 :]:
            j += float(np.sum(upper[None, :] > lower[:, None]))
            j += 0.5 * float(np.sum(upper[None, :] == lower[:, None]))
    n = np.array([a.size for a in arrays], dtype=float)
    big = float(n.sum())
    t = tie_sizes(np.concatenate(arrays))
    pairs = (big**2 - float(np.sum(n**2))) / 2  # M = sum_{i<j} n_i n_j
    variance = (
        (
            big * (big - 1) * (2 * big + 5)
            - float(np.sum(n * (n - 1) * (2 * n + 5)))
            - float(np.sum(t * (t - 1) * (2 * t + 5)))
        )
        / 72
        + float(np.sum(n * (n - 1) * (n - 2)))
        * float(np.sum(t * (t - 1) * (t - 2)))
        / (36 * big * (big - 1) * (big - 2))
        + float(np.sum(n * (n - 1))) * float(np.sum(t * (t - 1))) / (8 * big * (big - 1))
    )
    z, p = upper_tail(j, pairs / 2, variance)
    return {
        "J": j,
        "mean": pairs / 2,
        "variance": variance,
        "z": z,
        "p": p,
        "tau": 2 * j / pairs - 1,
        "n": [int(k) for k in n],
    }


def page(blocks: Sequence[Sequence[float]]) -> dict[str, Any]:
    """Page's test that the treatments, in column order, rise within the blocks (rows of
    equal length k >= 2, one per seed): {L, mean, variance, z, p, n_blocks}."""
    values = np.round(np.asarray(blocks, dtype=float), 12)
    if values.ndim != 2 or values.shape[0] == 0 or values.shape[1] < 2:
        raise ValueError("Page's test needs one or more blocks of two or more treatments")
    n, k = values.shape
    ranks = rankdata(values, axis=1)
    weights = np.arange(1, k + 1, dtype=float)
    centre = (k + 1) / 2
    statistic = float(np.sum(ranks * weights))
    spread = float(np.sum((weights - centre) ** 2))
    variance = spread * float(np.sum((ranks - centre) ** 2)) / (k - 1)
    mean = n * k * (k + 1) ** 2 / 4
    z, p = upper_tail(statistic, mean, variance)
    return {"L": statistic, "mean": mean, "variance": variance, "z": z, "p": p, "n_blocks": n}
