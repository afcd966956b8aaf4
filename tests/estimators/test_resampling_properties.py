"""Property-based tests of the resampling schemes (pegame.estimators.resampling) on
generated weights (zeros anywhere, any scale): each scheme's kernel against its numpy
reference, N indices of positive-weight particles, the schemes' bounds on the copies of
each particle, unbiased copies (a statistical test with fixed seeds), and the threshold
wrapper resampling exactly when N_eff < rho N."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from pegame.estimators.resampling import (
    RESAMPLERS,
    ThresholdResampler,
    _invert,
    _invert_reference,
    _systematic,
    effective_sample_size,
)

#: unnormalised weights: 1-60 of them, a third zero, the rest over many scales
WEIGHTS = arrays(
    np.float64,
    st.integers(1, 60),
    elements=st.just(0.0) | st.floats(1e-6, 1.0) | st.floats(1.0, 1e6) | st.just(1.0),
).filter(lambda w: w.sum() > 0.0)
SCHEMES = st.sampled_from(sorted(RESAMPLERS))
SEEDS = st.integers(0, 2**32 - 1)


def copies(indices: np.ndarray, n: int) -> np.ndarray:
    """How many times each of the n particles was drawn."""
    return np.bincount(indices, minlength=n)


@settings(max_examples=200)
@given(SCHEMES, WEIGHTS, SEEDS)
def test_kernel_equals_reference_and_draws_n_positive_weight_particles(
    name: str, weights: np.ndarray, seed: int
) -> None:
    scheme = RESAMPLERS[name]()
    fast_rng, slow_rng = np.random.default_rng(seed), np.random.default_rng(seed)
    fast = scheme.resample(weights, fast_rng)
    assert np.array_equal(fast, scheme.resample_reference(weights, slow_rng))
    assert fast_rng.bit_generator.state == slow_rng.bit_generator.state  # the same draws
    assert fast.shape == weights.shape and fast.dtype == np.int64
    assert copies(fast, weights.size).sum() == weights.size
    assert np.all(weights[fast] > 0.0)


@settings(max_examples=100)
@given(WEIGHTS, st.lists(st.floats(0.0, 1.0, exclude_max=True) | st.just(0.0), max_size=80))
def test_inversion_kernel_equals_searchsorted(weights: np.ndarray, drawn: list[float]) -> None:
    positions = np.asarray(drawn, dtype=np.float64)
    for ordered in (positions, np.sort(positions)):  # multinomial, and sorted as the others
        assert np.array_equal(_invert(weights, ordered), _invert_reference(weights, ordered))


@settings(max_examples=100)
@given(WEIGHTS, st.floats(0.0, 1.0, exclude_max=True) | st.sampled_from([0.0, 0.5]))
def test_systematic_kernel_equals_searchsorted(weights: np.ndarray, offset: float) -> None:
    normalised = weights / weights.sum()
    positions = (offset + np.arange(weights.size)) / weights.size
    assert np.array_equal(_systematic(normalised, offset), _invert_reference(normalised, positions))


@settings(max_examples=200)
@given(SCHEMES, WEIGHTS, SEEDS)
def test_copies_keep_to_the_schemes_bounds(name: str, weights: np.ndarray, seed: int) -> None:
    """With N w_i the expected copies of particle i: systematic draws floor or ceil of it
    (|copies - N w_i| < 1), stratified fewer than 2 away (one position per stratum, of
    which at most the two at the ends of i's interval may miss it or fall in it), residual
    at least floor(N w_i); up to round-off (1e-9)."""
    n = weights.size
    expected = n * (weights / weights.sum())
    drawn = copies(RESAMPLERS[name]().resample(weights, np.random.default_rng(seed)), n)
    deviation = np.abs(drawn - expected)
    if name == "systematic":
        assert np.all(deviation < 1.0 + 1e-9)
    if name == "stratified":
        assert np.all(deviation < 2.0 + 1e-9)
    if name == "residual":
        assert np.all(drawn >= np.floor(expected))


#: resamplings per generated case in the test of unbiasedness
REPEATS = 400
#: standard errors of the mean copies allowed by that test
Z = 5.0


@settings(max_examples=25)
@given(SCHEMES, WEIGHTS.filter(lambda w: w.size <= 12), SEEDS)
def test_copies_are_unbiased(name: str, weights: np.ndarray, seed: int) -> None:
    """The mean copies of each particle over REPEATS resamplings lie within Z standard
    errors of N w_i, each copy count's variance bounded by max(N w_i (1 - w_i), 1): the
    multinomial's variance, and at least 1, above the others' (residual < 1, stratified
    <= 1/2, systematic <= 1/4)."""
    n = weights.size
    w = weights / weights.sum()
    scheme, rng = RESAMPLERS[name](), np.random.default_rng(seed)
    total = sum(copies(scheme.resample(weights, rng), n) for _ in range(REPEATS))
    standard_error = np.sqrt(np.maximum(n * w * (1.0 - w), 1.0) / REPEATS)
    assert np.all(np.abs(total / REPEATS - n * w) <= Z * standard_error)


@settings(max_examples=100)
@given(SCHEMES, WEIGHTS, SEEDS, st.floats(0.0, 1.0))
def test_threshold_resamples_exactly_below_rho_n(
    name: str, weights: np.ndarray, seed: int, rho: float
) -> None:
    n_eff = effective_sample_size(weights / weights.sum())
    rng = np.random.default_rng(seed)
    state = rng.bit_generator.state
    drawn = ThresholdResampler(RESAMPLERS[name](), rho).resample(weights, rng)
    if n_eff < rho * weights.size:
        assert drawn is not None and drawn.size == weights.size
    else:
        assert drawn is None and rng.bit_generator.state == state  # nothing drawn
