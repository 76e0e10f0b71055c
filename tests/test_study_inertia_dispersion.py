"""Dispersing an inertia tensor in a trade study: products of inertia, matrix-shaped dispersions and
the ``principal`` form (moments scaled, principal axes turned), and the sensitivity table's drawn
quantities with their significance.

Oracles independent of the code under test: the drawn tensors' symmetry and eigenvalues
(``numpy.linalg.eigvalsh``), the principal axes' rotation recovered from ``numpy.linalg.eigh``, the
sample statistics of the drawn elements against the requested distribution (seeded, tolerances from
the sampling error of N draws), ``scipy.stats.spearmanr`` and ``scipy.stats.permutation_test``.
"""
from __future__ import annotations

import copy
import math

import numpy as np
import pytest
import yaml
from scipy.stats import permutation_test, rankdata, spearmanr

from scenarios.cli import main
from scenarios.errors import ScenarioError
from scenarios.study.robustness import sensitivity_table
from scenarios.study.spec import parse_study
from tests.test_sweep import BASE as SWEEP_BASE  # the tiny two-row eigenaxis scenario

TENSOR = [[2.0, 0.05, -0.03], [0.05, 3.0, 0.02], [-0.03, 0.02, 4.0]]  # kg m², distinct moments
BASE = {**copy.deepcopy(SWEEP_BASE), "truth": {"spacecraft": {"inertia": copy.deepcopy(TENSOR)}}}
PATH = "truth.spacecraft.inertia"


def study(dispersions, samples=200, seed=5, base=BASE, **parts):
    return parse_study({"study": "inertia", "scenario": copy.deepcopy(base),
                        "monte_carlo": {"samples": samples, "seed": seed, "dispersions": dispersions}, **parts})


def tensors(parsed):
    return np.array([case.scenario["truth"]["spacecraft"]["inertia"] for case in parsed.cases], dtype=float)


def assert_physical(stack):
    assert np.array_equal(stack, stack.transpose(0, 2, 1))  # exactly symmetric
    moments = np.linalg.eigvalsh(stack)
    assert (moments > 0).all()
    assert (moments[:, 0] + moments[:, 1] >= moments[:, 2]).all()


# --- products of inertia ---------------------------------------------------------------------------

def test_an_offset_of_a_product_of_inertia_sets_its_twin_and_has_the_requested_statistics():
    n, std = 400, 0.01
    stack = tensors(study({f"{PATH}[0][1]": {"offset": {"normal": {"mean": 0.0, "std": std}}}}, samples=n))
    assert_physical(stack)
    assert np.array_equal(stack[:, 0, 1], stack[:, 1, 0])
    drawn = stack[:, 0, 1] - TENSOR[0][1]
    assert abs(drawn.mean()) < 4 * std / math.sqrt(n)  # 4 standard errors
    assert drawn.std(ddof=1) == pytest.approx(std, rel=4 / math.sqrt(2 * (n - 1)))
    others = np.ones((3, 3), bool)
    others[0, 1] = others[1, 0] = False
    assert (stack[:, others] == np.array(TENSOR)[others]).all()  # nothing else moves


def test_a_grid_of_a_product_of_inertia_sets_its_twin_too():
    parsed = parse_study({"study": "g", "scenario": copy.deepcopy(BASE), "grid": {f"{PATH}[2][0]": [0.1, -0.2]}})
    stack = tensors(parsed)
    assert stack[:, 0, 2].tolist() == stack[:, 2, 0].tolist() == [0.1, -0.2]


@pytest.mark.parametrize("dispersions, words", [
    ({f"{PATH}[0][1]": {"offset": {"uniform": [0, 0.01]}}, f"{PATH}[1][0]": {"offset": {"uniform": [0, 0.01]}}},
     "same product of inertia"),
    ({f"{PATH}[0]": {"offset": {"normal": {"mean": [0, 0, 0], "std": [0.01, 0.01, 0.01]}}}}, "is a row of a symmetric"),
    ({PATH: {"scale": {"uniform": [0.9, 1.1]}}, f"{PATH}[0][1]": {"offset": {"uniform": [0, 0.01]}}},
     "same inertia tensor"),
    ({f"{PATH}[2][2]": {"scale": {"uniform": [0.9, 1.1]}}, PATH: {"scale": {"uniform": [0.9, 1.1]}}},
     "same inertia tensor"),
])
def test_twin_paths_and_rows_are_refused_at_their_entry(dispersions, words):
    with pytest.raises(ScenarioError, match=words):
        study(dispersions, samples=2)


def test_a_product_of_inertia_of_principal_moments_asks_for_the_tensor():
    base = {**copy.deepcopy(SWEEP_BASE), "truth": {"spacecraft": {"inertia": [2.0, 3.0, 4.0]}}}
    with pytest.raises(ScenarioError, match="holds 3 principal moments") as error:
        study({f"{PATH}[0][1]": {"offset": {"uniform": [0, 0.01]}}}, samples=2, base=base)
    assert error.value.path == f"monte_carlo.dispersions.{PATH}[0][1]"


def test_a_drawn_tensor_that_is_not_physical_is_refused_naming_the_case_and_path():
    # products of 2 kg m² on moments of 2, 3, 4: some draw is not positive definite or breaks the triangle
    with pytest.raises(ScenarioError) as error:
        study({f"{PATH}[0][1]": {"offset": {"normal": {"mean": 0.0, "std": 2.0}}}}, samples=50)
    assert error.value.path.startswith("case ") and f": {PATH} (set by {PATH}[0][1])" in error.value.path
    assert "positive definite" in error.value.message or "triangle" in error.value.message


# --- matrix-shaped dispersions -----------------------------------------------------------------------

LOW = [[0.9, 0.5, 0.0], [0.5, 0.95, 0.8], [0.0, 0.8, 0.9]]
HIGH = [[1.1, 1.5, 2.0], [1.5, 1.05, 1.2], [2.0, 1.2, 1.1]]


def test_a_symmetric_matrix_scale_draws_each_element_once_with_the_requested_distribution():
    n = 400
    parsed = study({PATH: {"scale": {"uniform": {"low": LOW, "high": HIGH}}}}, samples=n)
    stack = tensors(parsed)
    assert_physical(stack)
    factors = stack / np.array(TENSOR)
    low, high = np.array(LOW), np.array(HIGH)
    assert (factors >= low - 1e-15).all() and (factors <= high + 1e-15).all()
    # uniform: mean (low + high)/2, std (high - low)/sqrt(12); within 4 standard errors
    sigma = (high - low) / math.sqrt(12)
    assert (np.abs(factors.mean(axis=0) - (low + high) / 2) < 4 * sigma / math.sqrt(n)).all()
    # the six upper elements are drawn independently: their sample correlations are near 0
    upper = factors[:, np.triu_indices(3)[0], np.triu_indices(3)[1]]
    correlation = np.corrcoef(upper.T)[np.triu_indices(6, 1)]
    assert np.abs(correlation).max() < 4 / math.sqrt(n)
    # the sensitivity table's parameters: the six drawn factors, not nine elements
    assert list(parsed.parameters) == [f"{PATH}[{i}][{j}]" for i, j in zip(*np.triu_indices(3))]
    assert set(parsed.parameters.values()) == {"scale"}


@pytest.mark.parametrize("dispersion, words", [
    ({"scale": {"uniform": {"low": [[0.9, 0.5, 0.5], [0.6, 0.9, 0.5], [0.5, 0.5, 0.9]], "high": HIGH}}},
     r"needs symmetric parameters .*low\[0\]\[1\] = 0.5 but low\[1\]\[0\] = 0.6"),
    ({"scale": {"uniform": {"low": [0.9] * 9, "high": [1.1] * 9}}}, "9 numbers do not match .* give a 3x3 matrix"),
    ({"scale": {"uniform": {"low": [0.9] * 3, "high": [1.1] * 3}}}, "columns and break its symmetry"),
    ({"offset": {"normal": {"mean": [[0, 0], [0, 0]], "std": [[1, 1], [1, 1]]}}}, "is 3 x 3"),
    ({"scale": {"normal": {"mean": [[1, 0, 0]] * 3, "std": [1, 1, 1]}}}, r"expected the shape of mean \(3 x 3\)"),
])
def test_matrix_dispersions_that_cannot_keep_a_tensor_symmetric_are_refused(dispersion, words):
    with pytest.raises(ScenarioError, match=words):
        study({PATH: dispersion}, samples=2)


def test_a_whole_tensor_scale_is_one_drawn_quantity():
    parsed = study({PATH: {"scale": {"uniform": [0.9, 1.1]}}}, samples=20)
    assert parsed.parameters == {PATH: "scale"}
    for case, tensor in zip(parsed.cases, tensors(parsed)):
        np.testing.assert_allclose(tensor, case.drawn[PATH] * np.array(TENSOR), rtol=1e-15)


# --- principal moments and axes ----------------------------------------------------------------------

def _ordered_axes(tensor):
    """Eigenvectors ordered by the body axis each is nearest, each pointing along it (the oracle's own)."""
    moments, axes = np.linalg.eigh(tensor)
    order = [int(np.argmax(np.abs(axes[k]))) for k in range(3)]
    axes, moments = axes[:, order], moments[order]
    return moments, axes * np.sign(np.diag(axes))


def test_principal_axes_turn_by_the_drawn_rotation_within_the_requested_bound():
    n, bound = 300, 2.0
    parsed = study({PATH: {"principal": {"axes_deg": {"uniform": [[-bound] * 3, [bound] * 3]}}}}, samples=n)
    stack = tensors(parsed)
    assert_physical(stack)
    base_moments, base_axes = _ordered_axes(np.array(TENSOR))
    angles = []
    for case, tensor in zip(parsed.cases, stack):
        moments, axes = _ordered_axes(tensor)
        np.testing.assert_allclose(moments, base_moments, rtol=1e-12)  # a rotation keeps the moments
        rotation = axes @ base_axes.T
        angle = math.degrees(math.acos(min(1.0, (np.trace(rotation) - 1) / 2)))
        drawn = np.array([case.drawn[f"{PATH}.principal.axes_deg[{k}]"] for k in range(3)])
        assert angle == pytest.approx(np.linalg.norm(drawn), abs=1e-6)
        # and about the drawn axis: the rotation's skew part is along it
        skew = np.array([rotation[2, 1] - rotation[1, 2], rotation[0, 2] - rotation[2, 0],
                         rotation[1, 0] - rotation[0, 1]])
        np.testing.assert_allclose(skew / np.linalg.norm(skew), drawn / np.linalg.norm(drawn), atol=1e-6)
        angles.append(angle)
    angles = np.array(angles)
    assert angles.max() <= bound * math.sqrt(3) and angles.max() > bound  # the box's corners are reached
    # each component uniform on [-2, 2]: mean 0, std 4/sqrt(12)
    components = np.array([[case.drawn[f"{PATH}.principal.axes_deg[{k}]"] for k in range(3)] for case in parsed.cases])
    assert (np.abs(components.mean(axis=0)) < 4 * (2 * bound / math.sqrt(12)) / math.sqrt(n)).all()


def test_principal_moment_factors_scale_the_eigenvalues():
    n = 300
    parsed = study({PATH: {"principal": {"moments_scale": {"uniform": [[0.95, 0.9, 0.97], [1.05, 1.1, 1.03]]}}}},
                   samples=n)
    stack = tensors(parsed)
    assert_physical(stack)
    base_moments, base_axes = _ordered_axes(np.array(TENSOR))
    factors = np.array([_ordered_axes(tensor)[0] / base_moments for tensor in stack])
    low, high = np.array([0.95, 0.9, 0.97]), np.array([1.05, 1.1, 1.03])
    assert (factors >= low - 1e-12).all() and (factors <= high + 1e-12).all()
    assert (np.abs(factors.mean(axis=0) - 1.0) < 4 * (high - low) / math.sqrt(12 * n)).all()
    for tensor in stack:  # the axes stay
        np.testing.assert_allclose(np.abs(_ordered_axes(tensor)[1]), np.abs(base_axes), atol=1e-12)


def test_a_principal_factor_scales_the_moment_about_the_axis_nearest_its_body_axis():
    """``moments_scale[k]`` scales the principal moment whose axis is nearest body axis ``k`` (docs),
    whatever order ``eigh`` lists the moments in: with the largest moment about x (4 > 3 > 2, eigh's
    last), a factor of 1.1 on moment 0 scales that eigenpair's value alone and keeps every axis."""
    base = [[4.0, 0.05, 0.0], [0.05, 2.0, 0.02], [0.0, 0.02, 3.0]]
    parsed = study({PATH: {"principal": {"moments_scale": {"uniform": [[1.1, 1.0, 1.0], [1.1, 1.0, 1.0]]}}}},
                   samples=2, base={**copy.deepcopy(SWEEP_BASE), "truth": {"spacecraft": {"inertia": base}}})
    moments, axes = np.linalg.eigh(np.array(base))
    nearest_x = int(np.argmax(np.abs(axes[0])))
    assert nearest_x == 2 and moments[2] > 3.9  # the largest, listed last
    for tensor in tensors(parsed):
        for k in range(3):
            factor = 1.1 if k == nearest_x else 1.0
            np.testing.assert_allclose(tensor @ axes[:, k], factor * moments[k] * axes[:, k], atol=1e-12)


def test_principal_bounds_that_reach_a_tensor_that_is_not_physical_are_refused_at_validation():
    with pytest.raises(ScenarioError, match="triangle inequality") as error:
        study({PATH: {"principal": {"moments_scale": {"uniform": [[1, 1, 0.5], [1, 1, 2.0]]}}}}, samples=2)
    assert error.value.path == f"monte_carlo.dispersions.{PATH}.principal.moments_scale"
    with pytest.raises(ScenarioError, match="must be > 0"):
        study({PATH: {"principal": {"moments_scale": {"uniform": [0.0, 1.1]}}}}, samples=2)
    with pytest.raises(ScenarioError, match="beyond 180 deg"):
        study({PATH: {"principal": {"axes_deg": {"uniform": [[-120] * 3, [120] * 3]}}}}, samples=2)
    # the farthest corner of the box may be its low one: |(-120, -120, -120)| = 120 sqrt(3) = 207.846 deg
    with pytest.raises(ScenarioError, match="207.846 deg, beyond 180 deg"):
        study({PATH: {"principal": {"axes_deg": {"uniform": [[-120] * 3, [0] * 3]}}}}, samples=2)
    with pytest.raises(ScenarioError, match="principal disperses an inertia tensor"):
        study({"spacecraft.wheels.max_torque": {"principal": {"moments_scale": {"uniform": [0.9, 1.1]}}}}, samples=2)


# --- end to end --------------------------------------------------------------------------------------

def test_a_small_sweep_of_products_and_principal_axes_runs_end_to_end(tmp_path):
    data = {"study": "inertia-e2e", "scenario": "base.yaml", "summary": ["cl.final_error_deg", "cl.int_u"],
            "monte_carlo": {"samples": 3, "seed": 2, "dispersions": {
                PATH: {"principal": {"axes_deg": {"normal": {"mean": [0, 0, 0], "std": [1, 1, 1]}},
                                     "moments_scale": {"uniform": [0.95, 1.05]}}}}}}
    (tmp_path / "base.yaml").write_text(yaml.safe_dump(BASE))
    (tmp_path / "study.yaml").write_text(yaml.safe_dump(data))
    out = tmp_path / "out"
    assert main(["sweep", str(tmp_path / "study.yaml"), "--out", str(out), "--workers", "1", "--no-plots"]) == 0
    import pandas as pd
    cases = pd.read_csv(out / "cases.csv")
    assert len(cases) == 6 and set(cases["status"]) <= {"ok", "violated"}
    stack = np.array([yaml.safe_load(v) for v in cases[PATH]], dtype=float)
    assert_physical(stack)
    sensitivity = pd.read_csv(out / "sensitivity.csv")
    assert set(sensitivity["parameter"]) == {f"{PATH}.principal.moments_scale",
                                             *(f"{PATH}.principal.axes_deg[{k}]" for k in range(3))}
    summary = (out / "summary.md").read_text()
    assert "not_ok" in summary and "failures" not in summary
    assert "Note (" in summary and "only 3 cases" in summary  # the small-sample warning


# --- significance ------------------------------------------------------------------------------------

def _rho_along(a: np.ndarray, b: np.ndarray, axis: int = -1) -> np.ndarray:
    """Spearman's rho of ``a`` and ``b`` along ``axis``: the Pearson correlation of scipy's ranks
    (ties averaged), independent of the product's ranking."""
    ra, rb = rankdata(a, axis=axis), rankdata(b, axis=axis)
    ra = ra - ra.mean(axis=axis, keepdims=True)
    rb = rb - rb.mean(axis=axis, keepdims=True)
    return (ra * rb).sum(axis=axis) / np.sqrt((ra * ra).sum(axis=axis) * (rb * rb).sum(axis=axis))


def test_a_parameter_independent_of_the_metric_is_not_significant_and_a_monotone_one_is():
    n = 40
    parsed = parse_study({"study": "sig", "scenario": copy.deepcopy(SWEEP_BASE), "summary": ["cl.int_u", "cl.max_error_deg"],
                          "monte_carlo": {"samples": n, "seed": 7, "dispersions": {
                              "controller.options.kd": {"uniform": [0.5, 0.7]},
                              "controller.options.kp": {"uniform": [0.1, 0.3]}}}})
    rng = np.random.default_rng(123)
    noise = rng.normal(size=n)
    rows = []
    for case, e in zip(parsed.cases, noise):
        kd = case.scenario["controller"]["options"]["kd"]
        # int_u: a noisy monotone function of kd; max_error: noise alone (independent of both gains)
        rows.append({"case": case.index, "label": "a", "status": "ok", "cl.int_u": math.exp(kd) + 0.02 * e,
                     "cl.max_error_deg": rng.normal()})
    _, table = sensitivity_table(parsed, rows)
    found = {(line["metric"], line["parameter"]): line for line in table}
    assert len(found) == 4
    kd = np.array([case.scenario["controller"]["options"]["kd"] for case in parsed.cases])
    kp = np.array([case.scenario["controller"]["options"]["kp"] for case in parsed.cases])
    for (metric, parameter), line in found.items():
        x = kd if parameter.endswith("kd") else kp
        y = np.array([row[metric] for row in rows])
        assert line["spearman_rho"] == pytest.approx(spearmanr(x, y).statistic, abs=1e-12)
        # scipy's permutation test of Spearman's rho, its statistic vectorised over the resamples
        # (scipy's ranks, a Pearson correlation of them along the last axis: the same pairings and
        # p-value as a loop over spearmanr, whose 5000 calls a pair took 3-4 s of this test's 17)
        exact = permutation_test((x, y), _rho_along, permutation_type="pairings", vectorized=True,
                                 n_resamples=4999, random_state=1).pvalue
        assert line["p_value"] == pytest.approx(exact, abs=0.03)  # both permutation tests, sampling error
    assert found[("cl.int_u", "controller.options.kd")]["significant"] is True
    assert found[("cl.int_u", "controller.options.kd")]["rho_low"] > 0.5
    for key in (("cl.max_error_deg", "controller.options.kd"), ("cl.max_error_deg", "controller.options.kp"),
                ("cl.int_u", "controller.options.kp")):
        assert found[key]["significant"] is False, key
        assert found[key]["rho_low"] < 0 < found[key]["rho_high"], key


def test_a_perfect_ranking_of_three_cases_is_not_significant():
    """3 cases ranked perfectly: 2 of the 3! pairings reach |rho| = 1, p = 1/3 exactly (scipy's
    permutation test enumerates them too), not "p = 0"."""
    parsed = parse_study({"study": "three", "scenario": copy.deepcopy(SWEEP_BASE), "summary": ["cl.int_u"],
                          "monte_carlo": {"samples": 3, "seed": 1, "dispersions": {
                              "controller.options.kd": {"uniform": [0.5, 0.7]}}}})
    kd = np.array([case.scenario["controller"]["options"]["kd"] for case in parsed.cases])
    rows = [{"case": case.index, "label": "a", "status": "ok", "cl.int_u": 2.0 * value}
            for case, value in zip(parsed.cases, kd)]
    (line,) = sensitivity_table(parsed, rows)[1]
    assert line["spearman_rho"] == pytest.approx(1.0)
    exact = permutation_test((kd, 2.0 * kd), lambda a, b: spearmanr(a, b).statistic,
                             permutation_type="pairings").pvalue
    assert line["p_value"] == pytest.approx(1 / 3) == pytest.approx(exact)
    assert line["significant"] is False and line["rho_low"] is None


def test_the_small_sample_note_reads_the_same_null_distribution_as_the_p_values():
    """Critical values of Spearman's rho, two-sided 5 %, from Zar (1972), "Significance testing of the
    Spearman rank correlation coefficient", JASA 67(339), Table 1: n = 5: 1.000, 6: 0.886, 7: 0.786,
    8: 0.738, 9: 0.700 (0.683 reaches p = 0.05 only within the permutation test's sampling error), 10:
    0.648; up to 4 cases none exists (a perfect ranking has p = 2/n! >= 1/12)."""
    from scenarios.study.robustness import critical_rho

    assert critical_rho(3) is None and critical_rho(4) is None
    assert critical_rho(5) == pytest.approx(1.0)
    assert critical_rho(6) == pytest.approx(0.886, abs=1e-3)
    assert critical_rho(7) == pytest.approx(0.786, abs=1e-3)
    assert critical_rho(8) == pytest.approx(0.738, abs=1e-3)
    assert critical_rho(10) == pytest.approx(0.648, abs=0.02)


MOMENTS = [2.0, 3.0, 4.0]


@pytest.mark.parametrize("base_inertia, scale, low", [
    (TENSOR, {"uniform": [-0.1, 1.1]}, "-0.1"),
    (MOMENTS, {"uniform": [-0.1, 1.1]}, "-0.1"),
    (TENSOR, {"uniform": {"low": 0.0, "high": 1.1}}, "0"),
    (TENSOR, {"uniform": {"low": [[0.9, 0.5, 0.5], [0.5, -0.2, 0.5], [0.5, 0.5, 0.9]], "high": [[1.1] * 3] * 3}},
     "-0.2"),
    (MOMENTS, {"uniform": {"low": [0.9, 0.95, -0.3], "high": [1.1, 1.05, 1.1]}}, "-0.3"),
])
def test_a_scale_whose_bounds_reach_a_factor_of_0_or_less_is_refused_at_validation(base_inertia, scale, low):
    # Refused at its entry whatever the draws: one sample, whichever seed, must not pass validation (a
    # study with a larger `samples` would then fail at the case that draws the factor).
    base = {**copy.deepcopy(SWEEP_BASE), "truth": {"spacecraft": {"inertia": copy.deepcopy(base_inertia)}}}
    for seed in range(3):
        with pytest.raises(ScenarioError, match=f"must be > 0 .*got a low bound of {low} ") as error:
            study({PATH: {"scale": scale}}, samples=1, seed=seed, base=base)
        assert error.value.path == f"monte_carlo.dispersions.{PATH}.scale"


def test_a_scale_of_three_moments_that_can_break_the_triangle_inequality_is_refused_at_validation():
    base = {**copy.deepcopy(SWEEP_BASE), "truth": {"spacecraft": {"inertia": MOMENTS}}}
    with pytest.raises(ScenarioError, match="triangle inequality: moment 2 up to 6 exceeds .* 1 \\+ 3") as error:
        study({PATH: {"scale": {"uniform": [[0.5, 1, 1], [1, 1, 1.5]]}}}, samples=1, base=base)
    assert error.value.path == f"monte_carlo.dispersions.{PATH}.scale"
    # one factor for the three keeps the moments' ratios: any positive bounds are physical
    assert len(study({PATH: {"scale": {"uniform": [0.1, 3.0]}}}, samples=20, base=base).cases) == 20
