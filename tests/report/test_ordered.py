"""The ordered-alternative tests against references: the Jonckheere-Terpstra statistic's
null mean and tie-corrected variance against the exact permutation distribution of tiny
samples (every assignment of the pooled values to the groups), its p against the exact
permutation p and a published exact result; Page's L against scipy's page_trend_test
without ties and against the exact within-block permutation distribution with ties."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy.stats import page_trend_test

from pegame.report.ordered import jonckheere, page


def assignments(pooled: list[float], sizes: tuple[int, ...]):
    """Every split of ``pooled`` into groups of ``sizes`` (by position), each once."""
    positions = range(len(pooled))
    first, *rest = sizes
    for chosen in itertools.combinations(positions, first):
        left = [pooled[i] for i in positions if i not in chosen]
        head = [pooled[i] for i in chosen]
        if not rest:
            yield [head]
            continue
        for tail in assignments(left, tuple(rest)):
            yield [head, *tail]


def exact_j(groups: list[list[float]]) -> np.ndarray:
    """J of every equally likely assignment under H0."""
    pooled = [v for g in groups for v in g]
    sizes = tuple(len(g) for g in groups)
    return np.array([jonckheere(split)["J"] for split in assignments(pooled, sizes)])


def brute_j(groups: list[list[float]]) -> float:
    """J by its definition: over group pairs i < j, 1 for b > a and 1/2 for b = a."""
    total = 0.0
    for i, j in itertools.combinations(range(len(groups)), 2):
        for a in groups[i]:
            for b in groups[j]:
                total += 1.0 if b > a else 0.5 if b == a else 0.0
    return total


@pytest.mark.parametrize(
    "groups",
    [
        [[0.1, 0.4], [0.2, 0.5, 0.7], [0.3, 0.9]],  # no ties
        [[0.0, 0.5, 1.0], [0.5, 1.0], [1.0, 1.0, 0.0]],  # heavy ties, as rates at 0% / 100%
        [[0.2, 0.2], [0.2, 0.6], [0.6, 0.6, 0.2, 0.9]],
    ],
)
def test_jt_mean_and_tie_corrected_variance_are_those_of_the_permutation_distribution(groups):
    result = jonckheere(groups)
    null = exact_j(groups)
    assert result["J"] == brute_j(groups)
    assert result["mean"] == pytest.approx(null.mean(), abs=1e-9)
    assert result["variance"] == pytest.approx(null.var(), rel=1e-9)


def test_jt_p_is_near_the_exact_permutation_p_on_small_groups():
    groups = [[0.1, 0.3, 0.2, 0.5], [0.4, 0.3, 0.6], [0.7, 0.5, 0.9]]  # ties across groups
    result = jonckheere(groups)
    exact = float(np.mean(exact_j(groups) >= result["J"] - 1e-9))
    assert exact < 0.05  # a real rise, so the tail is the one that matters
    assert result["p"] == pytest.approx(exact, abs=0.01)


def test_jt_matches_statxacts_published_exact_result():
    """Cytel's StatXact example 12 (Ferns & Lang, Ethology 109, 2003: shelducks' plumage
    score, 1-8, at poor, medium and good feeding sites): exact two-sided p 0.0268 for the
    males, 0.0815 for the females. The null distribution of J is symmetric, so the
    two-sided p is twice the one-sided one; the normal approximation is within 0.002."""
    males = {4: (3, 2, 0), 6: (11, 14, 18), 7: (1, 1, 2), 8: (2, 9, 12)}
    females = {
        1: (0, 0, 1),
        2: (0, 3, 1),
        3: (0, 2, 0),
        4: (13, 15, 16),
        5: (0, 3, 5),
        6: (0, 3, 5),
    }
    for table, exact in ((males, 0.0268), (females, 0.0815)):
        groups = [[float(s) for s, c in table.items() for _ in range(c[g])] for g in range(3)]
        assert 2 * jonckheere(groups)["p"] == pytest.approx(exact, abs=0.002)


def test_jt_direction_tau_and_all_ties():
    rising = jonckheere([[0.1, 0.2], [0.3, 0.4], [0.5, 0.6]])
    falling = jonckheere([[0.5, 0.6], [0.3, 0.4], [0.1, 0.2]])
    assert rising["tau"] == 1.0 and falling["tau"] == -1.0
    assert rising["p"] < 0.01 and falling["p"] > 0.99
    tied = jonckheere([[1.0, 1.0], [1.0], [1.0, 1.0]])
    assert tied["z"] is None and tied["p"] == 1.0 and tied["tau"] == 0.0
    with pytest.raises(ValueError, match="two or more"):
        jonckheere([[0.1], []])


def test_page_l_and_p_are_scipys_without_ties():
    rng = np.random.default_rng(0)
    data = rng.normal(size=(15, 3)) + np.array([0.0, 0.3, 0.6])
    result = page(data)
    reference = page_trend_test(data, method="asymptotic")
    assert result["L"] == reference.statistic
    assert result["p"] == pytest.approx(reference.pvalue, rel=1e-12)


def test_page_mean_and_variance_are_the_exact_within_block_permutation_moments_with_ties():
    blocks = [[1.0, 1.0, 0.5], [0.2, 0.9, 0.9], [0.3, 0.3, 0.3], [0.0, 0.4, 1.0]]
    result = page(blocks)
    null = np.array(
        [
            page([list(p) for p in perms])["L"]
            for perms in itertools.product(*(itertools.permutations(b) for b in blocks))
        ]
    )
    assert result["mean"] == pytest.approx(null.mean(), abs=1e-9)
    assert result["variance"] == pytest.approx(null.var(), rel=1e-9)
    assert page([[0.5, 0.5], [1.0, 1.0]])["p"] == 1.0  # every block tied: no evidence
