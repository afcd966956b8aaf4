"""Resampling schemes for particle filters, and the effective-sample-size threshold.

A :class:`Resampler` turns N non-negative weights into N indices of the particles that
survive, drawn with probabilities proportional to the weights; one subclass per scheme:

- :class:`SystematicResampler`: one uniform offset u, positions (u + k) / N (Kitagawa
  1996; Hol, Schon and Gustafsson, "On resampling algorithms for particle filters", 2006).
- :class:`StratifiedResampler`: one uniform draw per stratum [k / N, (k + 1) / N) (Hol et
  al. 2006; Douc, Cappe and Moulines, "Comparison of resampling schemes for particle
  filtering", 2005).
- :class:`MultinomialResampler`: N independent uniform positions (Gordon, Salmond and
  Smith 1993; Douc et al. 2005).
- :class:`ResidualResampler`: floor(N w_i) copies of particle i, the rest drawn
  multinomially from the residuals N w_i - floor(N w_i) (Liu and Chen 1998; Douc et al.
  2005).

Each position in [0, 1) picks the particle whose interval of the normalised cumulative
weights holds it. The draws are those of filterpy.monte_carlo's functions fed the same
uniform numbers, but made on the caller's Generator: filterpy's draw from numpy's global
RNG (not reproducible per component), loop in Python and its residual_resample computes
the residual from w instead of N w (filterpy issue #290). The tests compare these with
filterpy's.

:class:`ThresholdResampler` wraps a scheme and resamples only when the weights have
degenerated, N_eff = 1 / sum_i w_i^2 < rho * N (the paper's Eq. for the effective sample
size; Doucet and Johansen, "A tutorial on particle filtering and smoothing", 2009,
Sec. 3.5), as Stone Soup's ESSResampler wraps its resamplers.

Fast path. :meth:`Resampler.resample` inverts the cumulative weights in numba kernels
(systematic positions by counting, without a search); :meth:`Resampler.resample_reference`
does it with plain numpy (np.searchsorted). Both give the same indices from the same
draws, bit for bit.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Callable
from typing import ClassVar

import numpy as np
from numba import njit


def effective_sample_size(weights: np.ndarray) -> float:
    """N_eff = 1 / sum(w^2) of normalised weights (N,) (the paper's Eq.)."""
    return 1.0 / float(np.dot(weights, weights))


#: maps positions in [0, 1) to the indices of the cumulative weights holding them
Invert = Callable[[np.ndarray, np.ndarray], np.ndarray]


class Resampler(ABC):
    """One resampling scheme: N indices drawn from N weights."""

    #: the scheme's name, the value of the filter's ``resampler`` config key
    name: ClassVar[str]

    def resample(self, weights: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """Indices (N,) (int64) of the particles drawn from the non-negative ``weights``
        (N,), which need not sum to 1 but must have a positive sum, with uniform draws
        from ``rng``. Only particles of positive weight are ever drawn."""
        return self._draw(weights / weights.sum(), rng, _invert)

    def resample_reference(self, weights: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """:meth:`resample` in plain numpy: the same draws, the same indices."""
        return self._draw(weights / weights.sum(), rng, _invert_reference)

    @abstractmethod
    def _draw(self, weights: np.ndarray, rng: np.random.Generator, invert: Invert) -> np.ndarray:
        """The indices for the normalised ``weights``; ``invert(weights, positions)``
        maps positions in [0, 1) to the indices of the cumulative weights holding them."""


class _InversionResampler(Resampler):
    """A scheme that draws N positions in [0, 1) and inverts the cumulative weights."""

    @staticmethod
    @abstractmethod
    def positions(n: int, rng: np.random.Generator) -> np.ndarray:
        """n positions (n,) in [0, 1) drawn from ``rng``."""

    def _draw(self, weights: np.ndarray, rng: np.random.Generator, invert: Invert) -> np.ndarray:
        return invert(weights, self.positions(weights.size, rng))


class SystematicResampler(_InversionResampler):
    """Positions (u + k) / N, k = 0..N-1, for one u ~ U[0, 1)."""

    name = "systematic"

    @staticmethod
    def positions(n: int, rng: np.random.Generator) -> np.ndarray:
        return (rng.random() + np.arange(n)) / n

    def resample(self, weights: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        # The kernel counts positions below each cumulative weight instead of searching.
        return _systematic(weights / weights.sum(), rng.random())


class StratifiedResampler(_InversionResampler):
    """Positions (u_k + k) / N with u_k ~ U[0, 1) independent."""

    name = "stratified"

    @staticmethod
    def positions(n: int, rng: np.random.Generator) -> np.ndarray:
        return (rng.random(n) + np.arange(n)) / n


class MultinomialResampler(_InversionResampler):
    """N independent positions u_k ~ U[0, 1)."""

    name = "multinomial"

    @staticmethod
    def positions(n: int, rng: np.random.Generator) -> np.ndarray:
        return rng.random(n)


class ResidualResampler(Resampler):
    """floor(N w_i) copies of each particle i, then the remaining N - sum floor(N w_i)
    drawn multinomially from the residuals N w_i - floor(N w_i)."""

    name = "residual"

    def _draw(self, weights: np.ndarray, rng: np.random.Generator, invert: Invert) -> np.ndarray:
        n = weights.size
        copies = np.floor(n * weights).astype(np.int64)
        kept = np.repeat(np.arange(n), copies)
        rest = n - kept.size
        if rest == 0:
            return kept
        residual = n * weights - copies
        return np.concatenate([kept, invert(residual, MultinomialResampler.positions(rest, rng))])


#: the schemes by name
RESAMPLERS: dict[str, type[Resampler]] = {
    cls.name: cls
    for cls in (SystematicResampler, StratifiedResampler, ResidualResampler, MultinomialResampler)
}


class ThresholdResampler:
    """Resamples with ``scheme`` only when N_eff < rho * N (0 <= rho <= 1; rho = 0 never
    resamples)."""

    def __init__(self, scheme: Resampler, rho: float) -> None:
        self.scheme, self.rho = scheme, rho

    def resample(
        self, weights: np.ndarray, rng: np.random.Generator, n_eff: float | None = None
    ) -> np.ndarray | None:
        """The scheme's indices (N,) for ``weights`` (N,) when they have degenerated,
        else None (keep the particles and their weights; nothing is drawn from ``rng``).

        n_eff: N_eff of the normalised weights when the caller has it (a filter computes
        it while normalising), else computed here.
        """
        return self._resample(weights, rng, n_eff, self.scheme.resample)

    def resample_reference(
        self, weights: np.ndarray, rng: np.random.Generator, n_eff: float | None = None
    ) -> np.ndarray | None:
        """:meth:`resample` with the scheme's plain numpy reference."""
        return self._resample(weights, rng, n_eff, self.scheme.resample_reference)

    def _resample(
        self,
        weights: np.ndarray,
        rng: np.random.Generator,
        n_eff: float | None,
        draw: Callable[[np.ndarray, np.random.Generator], np.ndarray],
    ) -> np.ndarray | None:
        if n_eff is None:
            n_eff = effective_sample_size(weights / weights.sum())
        return draw(weights, rng) if n_eff < self.rho * weights.size else None


# --------------------------------------------------------------------------- kernels


@njit(cache=True)
def _cumulative(weights: np.ndarray) -> tuple[np.ndarray, int]:
    """(cumulative (N,), last): the cumulative sums of the non-negative ``weights`` (N,),
    accumulated in order and normalised by their total, and the index of the last positive
    weight."""
    cumulative = np.empty(weights.size)
    running = 0.0
    for i in range(weights.size):
        running += weights[i]
        cumulative[i] = running
    cumulative /= cumulative[-1]
    last = weights.size - 1
    while weights[last] == 0.0:
        last -= 1
    return cumulative, last


@njit(cache=True)
def _invert(weights: np.ndarray, positions: np.ndarray) -> np.ndarray:
    """For each position in [0, 1), the index whose cumulative-weight interval holds it.

    Numba version of :func:`_invert_reference`, same indices: the cumulative sum is
    accumulated in the same order, and each search returns the first index whose
    normalised cumulative weight exceeds the position, as searchsorted(side="right") does.
    """
    cumulative, last = _cumulative(weights)
    indices = np.empty(positions.size, dtype=np.int64)
    found = 0
    for k in range(positions.size):
        # Systematic and stratified positions increase, so each search starts where the
        # previous one ended and the whole pass is linear; multinomial ones restart at 0.
        if k > 0 and positions[k] < positions[k - 1]:
            found = 0
        found = _upper_bound(cumulative, positions[k], found)
        # Round-off can leave the cumulative sum just below 1, or make the last systematic
        # position exactly 1, and the search then returns N: such positions belong to the
        # last particle of positive weight (never to a trailing zero-weight one).
        indices[k] = min(found, last)
    return indices


@njit(cache=True)
def _systematic(weights: np.ndarray, offset: float) -> np.ndarray:
    """:func:`_invert` of the systematic positions (offset + k) / N, k = 0..N-1, for the
    N ``weights`` and ``offset`` in [0, 1): the same indices, without a search.

    Particle i takes the positions below its normalised cumulative weight C_i and not
    below C_(i-1); there are c_i = ceil(N C_i - offset) positions below C_i (checked
    against the positions themselves, computed as numpy computes them, so round-off
    cannot shift one). Position k's index is then the number of particles with c_i <= k,
    a running count over k: no branch depends on the weights, about twice as fast as the
    search on a real filter's weights.
    """
    n = weights.size
    cumulative, last = _cumulative(weights)
    ending = np.zeros(n + 1, dtype=np.int64)  # ending[c]: particles with c_i == c
    for i in range(n):
        below = min(max(math.ceil(cumulative[i] * n - offset), 0), n)
        while below > 0 and (offset + (below - 1)) / n >= cumulative[i]:
            below -= 1
        while below < n and (offset + below) / n < cumulative[i]:
            below += 1
        ending[below] += 1
    indices = np.empty(n, dtype=np.int64)
    passed = 0
    for k in range(n):
        passed += ending[k]
        # As in _invert, a position that round-off puts past the last positive weight
        # belongs to that particle.
        indices[k] = min(passed, last)
    return indices


@njit(cache=True)
def _upper_bound(values: np.ndarray, value: float, start: int) -> int:
    """First index i >= start of the non-decreasing ``values`` with values[i] > value
    (values.size when none), given values[start - 1] <= value: a galloping search, so
    cheap when the answer is near ``start``."""
    low, step = start, 1
    high = start
    while high < values.size and values[high] <= value:
        low = high + 1
        high = low + step
        step *= 2
    high = min(high, values.size)
    while low < high:
        middle = (low + high) // 2
        if values[middle] <= value:
            low = middle + 1
        else:
            high = middle
    return low


def _invert_reference(weights: np.ndarray, positions: np.ndarray) -> np.ndarray:
    """Plain numpy :func:`_invert`."""
    cumulative = np.cumsum(weights)
    cumulative /= cumulative[-1]
    indices = np.searchsorted(cumulative, positions, side="right")
    return np.minimum(indices, np.flatnonzero(weights)[-1])
