"""The percentile bootstrap confidence interval of a mean (Efron & Tibshirani, *An
Introduction to the Bootstrap*, 1993, ch. 13): 10,000 resamples with a fixed seed, so a
report, and a job's closing line, are reproducible. numpy only, so that a job can print
its mean with its CI without importing the report's scipy and matplotlib."""

from __future__ import annotations

import numpy as np

BOOT_RESAMPLES = 10_000
BOOT_LEVEL = 0.95
BOOT_SEED = 0


def bootstrap_means(
    values: list[float], resamples: int = BOOT_RESAMPLES, seed: int = BOOT_SEED
) -> np.ndarray:
    """The means of ``resamples`` resamples (with replacement, the size of ``values``,
    non-empty) drawn with the fixed ``seed``: the bootstrap distribution of the mean."""
    x = np.asarray(values, dtype=float)
    rng = np.random.default_rng(seed)
    chunk = max(1, 2**20 // x.size)  # bounds memory for large samples
    return np.concatenate(
        [
            x[rng.integers(0, x.size, size=(min(chunk, resamples - start), x.size))].mean(axis=1)
            for start in range(0, resamples, chunk)
        ]
    )


def bootstrap_ci(
    values: list[float],
    resamples: int = BOOT_RESAMPLES,
    level: float = BOOT_LEVEL,
    seed: int = BOOT_SEED,
) -> tuple[float, float]:
    """Percentile-bootstrap confidence interval of the mean of ``values`` (non-empty)."""
    means = bootstrap_means(values, resamples, seed)
    low, high = np.percentile(means, [50 * (1 - level), 50 * (1 + level)])
    return float(low), float(high)
