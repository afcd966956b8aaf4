"""Tests for the resampling schemes and the effective-sample-size threshold
(pegame.estimators.resampling): each scheme against filterpy and its own numpy reference,
the kernels against searchsorted, and the threshold wrapper against N_eff < rho N."""

from __future__ import annotations

import filterpy.monte_carlo.resampling as filterpy_resampling
import numpy as np
import pytest

from pegame.estimators.resampling import (
    RESAMPLERS,
    MultinomialResampler,
    ResidualResampler,
    StratifiedResampler,
    SystematicResampler,
    ThresholdResampler,
    _invert,
    _invert_reference,
    _systematic,
    effective_sample_size,
)


class Constant:
    """A stand-in for a Generator whose uniform draws all equal ``value``."""

    def __init__(self, value):
        self.value = value

    def random(self, size=None):
        return self.value if size is None else np.full(size, self.value)


def random_weights(rng, n):
    """Unnormalised weights (n,) with zeros, leading and trailing too, and a positive sum."""
    weights = rng.random(n) ** rng.uniform(0.5, 8.0)
    weights[rng.random(n) < 0.3] = 0.0
    if weights.sum() == 0.0:
        weights[rng.integers(n)] = 1.0
    return weights


def test_the_registry_names_every_scheme_by_its_own_name():
    assert set(RESAMPLERS) == {"systematic", "stratified", "residual", "multinomial"}
    assert all(cls.name == name for name, cls in RESAMPLERS.items())


# --------------------------------------------------------------------------- schemes


@pytest.mark.parametrize(
    "cls", [SystematicResampler, StratifiedResampler, MultinomialResampler], ids=lambda c: c.name
)
@pytest.mark.parametrize("path", ["resample", "resample_reference"])
def test_schemes_match_filterpy(cls, path, monkeypatch):
    weights = np.random.default_rng(9).random(200) ** 3
    weights /= weights.sum()
    monkeypatch.setattr(filterpy_resampling, "random", np.random.default_rng(10).random)
    theirs = getattr(filterpy_resampling, f"{cls.name}_resample")(weights)
    ours = getattr(cls(), path)(weights, np.random.default_rng(10))
    np.testing.assert_array_equal(ours, theirs)


@pytest.mark.parametrize("path", ["resample", "resample_reference"])
def test_residual_keeps_filterpy_copies_and_draws_the_rest_from_n_w(path, monkeypatch):
    """filterpy's deterministic copies, then the published algorithm for the rest (not
    filterpy's, whose residual is w - floor(N w), filterpy issue #290)."""
    n = 200
    weights = np.random.default_rng(11).random(n) ** 3
    weights /= weights.sum()
    monkeypatch.setattr(filterpy_resampling, "random", np.random.default_rng(12).random)
    theirs = filterpy_resampling.residual_resample(weights)
    ours = getattr(ResidualResampler(), path)(weights, np.random.default_rng(12))
    copies = int(np.floor(n * weights).sum())
    np.testing.assert_array_equal(ours[:copies], theirs[:copies])
    # The rest, particle by particle: position u picks the first residual interval past it.
    residual = [n * w - np.floor(n * w) for w in weights]
    total = sum(residual)
    rest = []
    for u in np.random.default_rng(12).random(n - copies):
        running, index = 0.0, 0
        while index < n - 1 and running + residual[index] <= u * total:
            running += residual[index]
            index += 1
        rest.append(index)
    np.testing.assert_array_equal(ours[copies:], rest)


@pytest.mark.parametrize("name", RESAMPLERS)
def test_each_scheme_matches_its_numpy_reference(name):
    scheme = RESAMPLERS[name]()
    rng = np.random.default_rng(40)
    for trial in range(300):
        n = int(rng.integers(1, 400))
        weights = random_weights(rng, n)
        if trial % 7 == 0:
            weights = np.ones(n)  # cumulative weights k / n: positions land on them
        seed = int(rng.integers(2**32))
        fast_rng, slow_rng = np.random.default_rng(seed), np.random.default_rng(seed)
        fast = scheme.resample(weights, fast_rng)
        slow = scheme.resample_reference(weights, slow_rng)
        np.testing.assert_array_equal(fast, slow)
        assert fast.shape == (n,) and fast.dtype == np.int64
        assert fast_rng.bit_generator.state == slow_rng.bit_generator.state  # the same draws


@pytest.mark.parametrize("name", RESAMPLERS)
def test_schemes_are_unbiased_and_skip_zero_weights(name):
    scheme = RESAMPLERS[name]()
    weights = np.array([0.1, 0.0, 0.25, 0.3, 0.35, 0.0])
    rng = np.random.default_rng(13)
    counts = np.zeros(weights.size)
    for _ in range(4000):
        drawn = np.bincount(scheme.resample(weights, rng), minlength=weights.size)
        if name == "residual":
            assert np.all(drawn >= np.floor(weights.size * weights))
        counts += drawn
    assert np.all(counts[weights == 0] == 0)
    np.testing.assert_allclose(counts / 4000, weights.size * weights, atol=0.05)


@pytest.mark.parametrize("path", ["resample", "resample_reference"])
def test_systematic_round_off_edge_case(path, monkeypatch):
    """Weights summing to 1 - 1e-12 and the largest uniform draw below 1: the last
    position lies above the cumulative sum, which runs filterpy past the end."""
    n = 10
    weights = np.random.default_rng(14).random(n)
    weights *= (1.0 - 1e-12) / weights.sum()
    top = Constant(np.nextafter(1.0, 0.0))
    monkeypatch.setattr(filterpy_resampling, "random", top.random)
    with pytest.raises(IndexError):
        filterpy_resampling.systematic_resample(weights)
    resample = getattr(SystematicResampler(), path)
    indices = resample(weights, top)
    assert indices.shape == (n,) and indices.min() >= 0 and indices.max() == n - 1
    trailing = np.append(weights[:-1], 0.0)  # a zero last weight must not catch the overflow
    assert resample(trailing, top).max() == n - 2


# --------------------------------------------------------------------------- kernels


def test_inversion_kernel_matches_searchsorted():
    rng = np.random.default_rng(29)
    for _trial in range(300):
        n = int(rng.integers(1, 400))
        weights = rng.random(n) ** 4
        weights[rng.random(n) < 0.3] = 0.0  # zero weights, leading and trailing too
        if weights.sum() == 0.0:
            weights[rng.integers(n)] = 1.0
        m = int(rng.integers(1, 2 * n + 2))
        sorted_positions = (rng.random() + np.arange(m)) / m
        edges = np.array([0.0, np.nextafter(1.0, 0.0), 1.0, weights[0] / weights.sum()])
        for positions in (sorted_positions, rng.random(m), edges):
            np.testing.assert_array_equal(
                _invert(weights, positions), _invert_reference(weights, positions)
            )


def test_systematic_kernel_matches_searchsorted():
    rng = np.random.default_rng(31)
    for trial in range(400):
        n = int(rng.integers(1, 500))
        weights = random_weights(rng, n)
        if trial % 5 == 0:
            weights = np.ones(n)  # cumulative weights i / n: positions land on them
        weights /= weights.sum()
        for offset in (rng.random(), 0.0, np.nextafter(1.0, 0.0), 0.5):
            positions = (offset + np.arange(n)) / n
            np.testing.assert_array_equal(
                _systematic(weights, offset), _invert_reference(weights, positions)
            )


# --------------------------------------------------------------------------- threshold


@pytest.mark.parametrize("path", ["resample", "resample_reference"])
def test_threshold_resamples_exactly_when_n_eff_is_below_rho_n(path):
    n = 300
    rng = np.random.default_rng(41)
    for _ in range(50):
        weights = random_weights(rng, n)
        n_eff = effective_sample_size(weights / weights.sum())
        assert 1.0 <= n_eff < n
        for rho, expected in (
            (n_eff / n * (1 + 1e-9), True),
            (n_eff / n * (1 - 1e-9), False),
            (0.0, False),
            (1.0, True),
        ):
            scheme = RESAMPLERS[str(rng.choice(list(RESAMPLERS)))]()
            seed = int(rng.integers(2**32))
            wrapped_rng = np.random.default_rng(seed)
            drawn = getattr(ThresholdResampler(scheme, rho), path)(weights, wrapped_rng)
            if expected:
                direct = getattr(scheme, path)(weights, np.random.default_rng(seed))
                np.testing.assert_array_equal(drawn, direct)
            else:
                assert drawn is None
                # Nothing drawn: the Generator is where it was.
                assert (
                    wrapped_rng.bit_generator.state
                    == np.random.default_rng(seed).bit_generator.state
                )


def test_threshold_takes_the_callers_n_eff():
    weights = np.full(64, 1.0 / 64)  # N_eff = N: never degenerate by itself
    threshold = ThresholdResampler(SystematicResampler(), 0.8)
    assert threshold.resample(weights, np.random.default_rng(0)) is None
    drawn = threshold.resample(weights, np.random.default_rng(0), n_eff=0.8 * 64 - 1e-9)
    np.testing.assert_array_equal(drawn, np.arange(64))  # equal weights: one copy each
    assert threshold.resample(weights, np.random.default_rng(0), n_eff=0.8 * 64) is None
