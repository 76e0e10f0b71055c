"""The study's sensitivity statistics against oracles that do not share their code: Holm's step-down
adjustment worked by hand, exact p-values by enumerating every pairing with SciPy's ``spearmanr``,
the permutation test against the exact enumeration of 9! pairings, the t approximation against
``scipy.stats.spearmanr``'s p-value, Fisher's interval with the Bonett-Wright standard error from the
published formula, and the critical correlations against Zar's table (Biostatistical Analysis,
table B.20: two-tailed 5 %, n = 6 to 12: 0.886, 0.786, 0.738, 0.683, 0.648, 0.618, 0.587), and
the permutation range's critical correlation by Phipson & Smyth's rule worked by hand on 40
constructed pairings."""
import itertools
import math

import numpy as np
import pytest
from scipy.stats import norm, spearmanr

from scenarios.study.robustness import (
    PERMUTATIONS,
    SIGNIFICANCE,
    critical_rho,
    holm,
    rank_significance,
)


def test_holm_by_hand_with_its_step_down_maximum_and_a_missing_value():
    # sorted 0.005, 0.01, 0.03, 0.04 times 4, 3, 2, 1: 0.02, 0.03, 0.06, 0.04 -> the running maximum
    # keeps 0.06 for the largest (an adjusted p-value never falls below a smaller p's)
    assert holm([0.01, 0.04, 0.03, 0.005]) == pytest.approx([0.03, 0.06, 0.06, 0.02], abs=1e-15)
    # None is no member of the family: two p-values, multiplied by 2 and 1
    adjusted = holm([0.01, None, 0.04])
    assert adjusted[1] is None and adjusted[0] == pytest.approx(0.02) and adjusted[2] == pytest.approx(0.04)
    assert holm([0.6, 0.5]) == [1.0, 1.0]  # capped at 1


def _brute_force_p(x: np.ndarray, y: np.ndarray) -> float:
    """Every pairing of y with x, its rho from SciPy: the fraction at least as large in magnitude."""
    observed = abs(spearmanr(x, y).statistic)
    rhos = [abs(spearmanr(x, y[list(order)]).statistic) for order in itertools.permutations(range(len(y)))]
    return float(np.mean(np.asarray(rhos) >= observed - 1e-12))


@pytest.mark.parametrize("y", [[2.0, 1.0, 4.0, 3.0, 6.0, 5.0], [6.0, 4.0, 5.0, 1.0, 3.0, 2.0],
                               [1.0, 2.0, 2.0, 5.0, 4.0, 7.0]])
def test_the_exact_p_value_is_the_two_sided_enumeration(y):
    x = np.array([0.3, 1.1, 2.0, 2.2, 4.5, 5.0])
    y = np.asarray(y)
    rho = spearmanr(x, y).statistic
    assert rank_significance(rho, 6, x, y)["p_value"] == pytest.approx(_brute_force_p(x, y), abs=1e-12)
    # three cases ranked perfectly: two of the six pairings are as extreme (the docstring's 1/3)
    assert rank_significance(1.0, 3, np.arange(3.0), np.arange(3.0))["p_value"] == pytest.approx(1.0 / 3.0)


def test_the_permutation_p_value_against_the_exact_enumeration_of_nine_cases():
    x = np.arange(9.0)
    y = np.array([1.0, 0.0, 3.0, 2.0, 6.0, 4.0, 8.0, 5.0, 7.0])
    rho = spearmanr(x, y).statistic
    pairings = np.array(list(itertools.permutations(range(9))), dtype=np.int8)  # all 362 880
    centred = np.arange(9.0) - 4.0
    null = np.abs((pairings.astype(float) - 4.0) @ centred) / (centred @ centred)
    exact = float(np.mean(null >= abs(rho) - 1e-12))
    p = rank_significance(rho, 9, x, y)["p_value"]
    spread = math.sqrt(exact * (1.0 - exact) / PERMUTATIONS)
    assert abs(p - exact) <= 4.0 * spread + 1.0 / PERMUTATIONS
    # a perfect ranking of 12: no random pairing is as extreme (2 in 12!), only the observed one counts
    assert rank_significance(1.0, 12, np.arange(12.0), np.arange(12.0))["p_value"] == 1.0 / (1.0 + PERMUTATIONS)


def test_the_t_approximation_and_the_interval_from_their_published_formulas():
    rng = np.random.default_rng(5)
    x = rng.standard_normal(60)
    y = 0.3 * x + rng.standard_normal(60)
    result = spearmanr(x, y)
    out = rank_significance(result.statistic, 60, x, y)
    assert out["p_value"] == pytest.approx(result.pvalue, rel=1e-9)  # two-sided, n - 2 degrees of freedom
    # Fisher's z with Bonett & Wright's (2000) standard error sqrt((1 + rho²/2) / (n - 3))
    rho, z = result.statistic, norm.ppf(0.975)
    half = z * math.sqrt((1.0 + rho**2 / 2.0) / 57.0)
    assert out["rho_low"] == pytest.approx(math.tanh(math.atanh(rho) - half), rel=1e-9)
    assert out["rho_high"] == pytest.approx(math.tanh(math.atanh(rho) + half), rel=1e-9)


def test_critical_correlations_are_zars_table():
    table = {6: 0.886, 7: 0.786, 8: 0.738, 9: 0.683, 10: 0.648, 11: 0.618, 12: 0.587}
    for n, value in table.items():
        assert critical_rho(n) == pytest.approx(value, abs=6e-4), n
    assert critical_rho(4) is None and critical_rho(5) == 1.0


class _Pairings:
    """Stands in for ``np.random.default_rng(0)``: its ``permuted`` returns the pairings given."""

    def __init__(self, pairings: list[tuple[int, ...]]) -> None:
        self.pairings = np.array(pairings)

    def permuted(self, tiled: np.ndarray, axis: int) -> np.ndarray:
        assert axis == 1 and tiled.shape == self.pairings.shape  # PERMUTATIONS rows of the n ranks
        return self.pairings.copy()


# Nine ranks: a pairing's rho is 1 − 6 Σd² / (9 (9² − 1)) = 1 − Σd² / 120.
_SWAP_01 = (1, 0, 2, 3, 4, 5, 6, 7, 8)  # Σd² = 2: rho = 59/60
_SWAP_02 = (2, 1, 0, 3, 4, 5, 6, 7, 8)  # Σd² = 8: rho = 14/15
_REVERSED = tuple(range(8, -1, -1))  # rho = −1, as extreme as the identity two-sided
_UNRELATED = (0, 2, 6, 8, 7, 5, 4, 3, 1)  # d = 0 1 4 5 3 0 2 4 7, Σd² = 120: rho = 0


@pytest.mark.parametrize("first, second, expected", [(_SWAP_01, _SWAP_02, 59.0 / 60.0), (_REVERSED, _SWAP_02, 1.0)])
def test_the_critical_correlation_of_the_permutation_range_counts_the_observed_pairing(monkeypatch, first, second,
                                                                                         expected):
    """From 9 to 49 cases the p-value is Phipson & Smyth's (2010) ``(1 + b) / (1 + m)``, ``b`` of
    the ``m`` random pairings at least as extreme (the observed one counted, so never 0), and
    critical_rho(n) the least null magnitude whose p is at most 5 %. By hand with m = 40 constructed
    pairings of 9 ranks: one of magnitude ``|rho1|``, one of 14/15, 38 of 0. ``|rho1|`` has
    p = (1 + 1) / 41 = 0.049, 14/15 has (1 + 2) / 41 = 0.073: the critical value is ``|rho1|``.
    The rule ``b / m`` would give 2/40 = 0.05 at 14/15 and return 14/15; a one-sided count (rho1 =
    −1 taken as less extreme than 14/15) would too."""
    from scenarios.study import robustness

    assert SIGNIFICANCE == 0.05  # the hand computation's level
    pairings = [first, second] + [_UNRELATED] * 38
    monkeypatch.setattr(robustness, "PERMUTATIONS", len(pairings))
    monkeypatch.setattr(np.random, "default_rng", lambda seed: _Pairings(pairings))
    assert critical_rho(9) == pytest.approx(expected, abs=1e-12)
    # a second pairing as extreme as the first: 3/41 > 5 % already at the largest, nothing significant
    pairings = [first, first, second] + [_UNRELATED] * 37
    assert critical_rho(9) is None
