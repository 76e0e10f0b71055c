"""The certificate of a numerical optimum (ocp.nlp.certificate, planners.collocation.certificate).

Oracles: KKT residuals of small NLPs worked by hand; IPOPT's own reported dual infeasibility at the
same iterate (its ``inf_du``, in its gradient-based scaling); the minimum-time Hamiltonian, which
vanishes along an optimum (Pontryagin), for the sign and size of the co-states recovered from the
collocation multipliers; Bilimoria & Wie's optimum (3.2431, bang-bang) and the eigenaxis saddle
(2 √π = 3.5449, the two other torques singular) for the switching agreement and the verdict.
"""
from __future__ import annotations

import csv
import json

import casadi as ca
import numpy as np
import pytest

from ocp.nlp.certificate import (
    certificate,
    kkt_residuals,
    seed_counts,
    switching_agreement,
)
from ocp.nlp.second_order import second_order_check
from ocp.nlp.solve import solver_options
from planners import PLANNERS
from planners.collocation.certificate import radau_points, switching
from tests.test_collocation import bilimoria_wie_problem


def small_nlp(f, g=None, n=2, max_iterations=200):
    x = ca.SX.sym("x", n)
    problem = {"x": x, "f": f(x)}
    if g is not None:
        problem["g"] = g(x)
    return ca.nlpsol("s", "ipopt", problem, solver_options("ipopt", 1e-12, max_iterations))


def test_kkt_residuals_of_an_equality_constrained_minimum_by_hand():
    # min x² + y² on x + y = 1: x = y = 1/2, ∇f + λ ∇g = (1, 1) + λ (1, 1) = 0 gives λ = −1.
    solver = small_nlp(lambda x: x[0] ** 2 + x[1] ** 2, lambda x: x[0] + x[1])
    exact = kkt_residuals(solver, [0.5, 0.5], [0.0, 0.0], [-1.0], lbg=1.0, ubg=1.0)
    assert exact.unscaled == pytest.approx(0.0, abs=1e-15) and exact.scaled == pytest.approx(0.0, abs=1e-15)
    # (0.6, 0.5) with λ = −1: ∇f + λ ∇g = (1.2 − 1, 1 − 1), and x + y − 1 = 0.1
    moved = kkt_residuals(solver, [0.6, 0.5], [0.0, 0.0], [-1.0], lbg=1.0, ubg=1.0)
    assert moved.stationarity == pytest.approx(0.2) and moved.feasibility == pytest.approx(0.1)
    # the multiplier of the wrong sign: (1, 1) + (1, 1) = 2
    assert kkt_residuals(solver, [0.5, 0.5], [0.0, 0.0], [1.0], lbg=1.0, ubg=1.0).stationarity == pytest.approx(2.0)
    # and the solver's own point reaches the hand-worked one
    solution = solver(x0=[3.0, -1.0], lbg=1.0, ubg=1.0)
    assert float(solution["lam_g"]) == pytest.approx(-1.0, abs=1e-9)


def test_kkt_residuals_of_a_bound_and_its_multiplier_sign_by_hand():
    # min (x − 2)² with x <= 1: x = 1, ∇f = −2, so lam_x = +2 (CasADi: positive on an upper bound).
    solver = small_nlp(lambda x: (x[0] - 2) ** 2, n=1)
    right = kkt_residuals(solver, [1.0], [2.0], [], ubx=1.0)
    assert right.unscaled == pytest.approx(0.0, abs=1e-15)
    # −2 would belong to a lower bound (none here: distance 1): stationarity |−2 − 2| = 4, complementarity 2
    wrong = kkt_residuals(solver, [1.0], [-2.0], [], ubx=1.0)
    assert wrong.stationarity == pytest.approx(4.0) and wrong.complementarity == pytest.approx(2.0)
    # a multiplier on an upper bound 0.5 away: complementarity |λ| × 0.5 = 1
    inside = kkt_residuals(solver, [0.5], [2.0], [], ubx=1.0)
    assert inside.complementarity == pytest.approx(1.0)


@pytest.mark.parametrize("iterations", [2, 3])
def test_scaled_stationarity_is_ipopts_reported_dual_infeasibility(iterations):
    # Gradients far above nlp_scaling_max_gradient = 100 at the start (2, 3): ∇f = (4032, 6000), so
    # IPOPT scales the objective by s_f = 100 / 6000; the rows of g by 100/300 and 1. Stopped after a
    # few iterations (a point far from converged, residuals well above rounding), IPOPT's last
    # reported inf_du (the scaled dual infeasibility) must be s_f times the unscaled stationarity at
    # the returned point and multipliers: the factor is IPOPT's own, reproduced to rounding.
    def f(x):
        return 1000 * (x[0] ** 2 + x[1] ** 2) + x[0] ** 4

    def g(x):
        return ca.vertcat(300 * (x[0] + x[1]), x[0] - x[1] ** 2)

    solver = small_nlp(f, g, max_iterations=iterations)
    x0 = np.array([2.0, 3.0])
    bounds = {"lbx": [-5.0, -5.0], "ubx": [5.0, 0.9], "lbg": [300.0, -0.2], "ubg": [300.0, -0.2]}
    solution = solver(x0=x0, **bounds)
    reported = solver.stats()["iterations"]["inf_du"][-1]
    kkt = kkt_residuals(solver, solution["x"].full(), solution["lam_x"].full(), solution["lam_g"].full(),
                        scaling_point=x0, **bounds)
    assert kkt.objective_scaling == pytest.approx(100.0 / 6000.0)
    assert kkt.stationarity > 10 * reported  # the scaling matters here
    assert kkt.stationarity_scaled == pytest.approx(reported, rel=1e-6)


def test_a_converged_point_meets_ipopts_tolerance_in_its_scaling():
    # Converged to tol = 1e-12 (IPOPT's overall scaled error): the scaled residual is within it,
    # from the scaling at IPOPT's start.
    solver = small_nlp(lambda x: 1000 * (x[0] ** 2 + x[1] ** 2) + x[0] ** 4,
                       lambda x: ca.vertcat(300 * (x[0] + x[1]), x[0] - x[1] ** 2))
    x0 = np.array([2.0, 3.0])
    bounds = {"lbx": [-5.0, -5.0], "ubx": [5.0, 0.9], "lbg": [300.0, -0.2], "ubg": [300.0, -0.2]}
    solution = solver(x0=x0, **bounds)
    assert solver.stats()["return_status"] == "Solve_Succeeded"
    kkt = kkt_residuals(solver, solution["x"].full(), solution["lam_x"].full(), solution["lam_g"].full(),
                        scaling_point=x0, **bounds)
    assert kkt.scaled <= 1e-12


def test_switching_agreement_by_hand():
    # u at +1 with σ < 0 and at −1 with σ > 0 agree; u at +1 with σ > 0 is wrong; an interior u with
    # a large σ is a violation; |σ| below 1e-3 of the largest is a switch or a singular arc.
    u = np.array([[1.0, -1.0], [1.0, 0.2], [0.0, -1.0]])
    sigma = np.array([[-2.0, 3.0], [1.0, 1.5], [1e-5, 4.0]])
    result = switching_agreement(u, -1.0, 1.0, sigma)
    assert (result.agreement, result.wrong, result.interior_large, result.singular) == \
        pytest.approx((3 / 6, 1 / 6, 1 / 6, 1 / 6))


def test_verdicts_from_the_evidence():
    from ocp.nlp.certificate import KKTResiduals, Switching
    small = KKTResiduals(*[1e-9] * 8, 1.0)
    large = KKTResiduals(*[1e-3] * 8, 1.0)
    bang = Switching(0.97, 0.0, 0.01, 0.02, 1e-3)
    singular = Switching(1 / 3, 0.0, 0.0, 2 / 3, 1e-3)
    assert certificate(small, "not checked: big", bang)["verdict"] == "first-order, bang-bang"
    assert certificate(small, "not checked: big", singular)["verdict"] == "first-order"
    assert certificate(large, "strict local minimum", bang)["verdict"] == "not certified"
    # the switching evidence never overrules a second-order check that found negative curvature (a
    # saddle), nor stands in with samples on the side Pontryagin forbids
    from ocp.nlp.second_order import SecondOrderCheck
    saddle = SecondOrderCheck(False, 12, 1e-6, "at most 12 directions of curvature below -1e-06")
    assert certificate(small, saddle, bang)["verdict"] == "first-order"
    # a degenerate point (curvature near zero somewhere, none below -δ) is no saddle: the switching
    # evidence stands in there, and only there with bang-bang controls, as its own verdict, not "certified"
    degenerate = SecondOrderCheck(False, 0, 1e-6, "at most 1 directions of curvature between -1e-06 and 1e-06")
    record = certificate(small, degenerate, bang)
    assert record["verdict"] == "first-order, bang-bang" and record["second_order"].startswith("degenerate: ")
    assert record["summary"].startswith("first-order, bang-bang: KKT 1e-09, SOSC degenerate, switching 97%")
    assert certificate(small, degenerate, singular)["verdict"] == "first-order"
    assert certificate(small, degenerate, None)["verdict"] == "first-order"
    assert certificate(small, SecondOrderCheck(True, 0, 1e-6, "curvature above 1e-06"), None)["verdict"] == "certified"
    assert certificate(small, "not checked: big", Switching(0.92, 0.08, 0.0, 0.0, 1e-3))["verdict"] == "first-order"
    record = certificate(small, "strict local minimum", None, seeds=5, seeds_agreed=4)
    assert record["verdict"] == "certified" and record["summary"] == "certified: KKT 1e-09, SOSC, 4/5 seeds agreed"
    assert json.loads(json.dumps(record)) == record


def test_seed_counts_prefer_the_seeds_record():
    starts = [{"f": 3.0, "converged": True}, {"f": 3.0 + 1e-9, "converged": True}, {"f": 2.0, "converged": False}]
    assert seed_counts({"starts": starts}) == (3, 2)
    assert seed_counts({"coarse": {"starts": starts[:1]}, "starts": starts}) == (1, 1)
    assert seed_counts({"seeds": {"tried": 5, "agreed": 4, "best_from": "eigenaxis"}, "starts": starts}) == (5, 4)
    assert seed_counts({}) == (None, None)


def bilimoria_wie_solution(options):
    problem = bilimoria_wie_problem()
    planner = PLANNERS["collocation"](options)
    ocp = planner._ocp(problem)
    params = np.concatenate([problem.initial_state, problem.qf, np.zeros(3), [problem.duration],
                             problem.model.default_parameters])
    solved = planner._optimum(problem, ocp, planner._starts(problem), params, planner.options.intervals)
    lbx, ubx = solved.transcription.bounds(ocp, solved.nlp, *planner._variable_bounds(problem), problem.duration)
    return problem, solved, params, lbx, ubx


def test_costates_from_the_radau_multipliers_make_the_minimum_time_hamiltonian_vanish():
    # Pontryagin: along a minimum-time optimum H = 1 + pᵀ f = 0. With p = −λ / w_j this holds to the
    # discretisation's accuracy; the opposite sign would give H = 2, a missing step factor far more.
    # switch_refinement 0: the 50-interval solve (by default the exact bang-bang optimum replaces it)
    problem, solved, params, lbx, ubx = bilimoria_wie_solution({"objective": "min_time", "switch_refinement": 0})
    assert float(solved.nlp.unpack(solved.result.x, params)[0]) == pytest.approx(3.2431, abs=2e-4)
    x, u, p, t = radau_points(solved.transcription, problem.model, solved.nlp, solved.result.x, solved.result.lam_g)
    f = np.array([problem.model.rhs(x[k], u[k], t[k], np.zeros(3)).full().ravel() for k in range(t.size)])
    hamiltonian = 1.0 + np.einsum("ki,ki->k", p, f)
    assert np.max(np.abs(hamiltonian)) < 1e-2
    # unit inertia: σ = J⁻ᵀ p_ω = p_ω, and the torques are bang-bang against it
    right = switching(solved.transcription, problem.model, solved.nlp, solved.result.x, solved.result.lam_g,
                      lbx, ubx, params)
    assert right.agreement >= 0.9 and right.wrong == 0.0
    at_bound = np.abs(np.abs(u) - 1.0) < 1e-6
    assert np.all(np.sign(u[at_bound & (np.abs(p[:, 4:7]) > 1e-2)])
                  == -np.sign(p[:, 4:7][at_bound & (np.abs(p[:, 4:7]) > 1e-2)]))
    # the wrong co-state sign must fail the check
    wrong = switching(solved.transcription, problem.model, solved.nlp, solved.result.x, solved.result.lam_g,
                      lbx, ubx, params, costate_sign=-1.0)
    assert wrong.agreement < 0.05 and wrong.wrong >= 0.9


def test_bilimoria_wie_optimum_is_certified_and_the_eigenaxis_saddle_is_not():
    # switch_refinement 0: the 50-interval NLP's certificate (by default the exact bang-bang optimum's,
    # tests/test_collocation_bang_bang.py)
    optimum = PLANNERS["collocation"]({"objective": "min_time", "switch_refinement": 0}).plan(bilimoria_wie_problem())
    assert optimum.duration == pytest.approx(3.2431, abs=2e-4)
    record = optimum.stats["certificate"]
    assert record["verdict"] == "certified", record
    assert record["kkt_scaled"] <= 1e-6 and record["switching"] >= 0.9
    # the full mesh (1908 variables) gets its own second-order check
    assert record["second_order"] == "strict local minimum", record
    assert record["summary"].startswith("certified: KKT ") and ", SOSC, " in record["summary"]
    saddle = PLANNERS["collocation"]({"objective": "min_time", "multistart": 0}).plan(bilimoria_wie_problem())
    assert saddle.duration == pytest.approx(3.5449, abs=1e-3)
    record = saddle.stats["certificate"]
    assert record["verdict"] == "first-order", record
    assert record["second_order"].startswith("not certified: "), record
    assert record["kkt_scaled"] <= 1e-6  # a first-order point all the same
    assert record["switching"] < 0.5  # the two other torques are singular (zero)


def test_a_small_nlp_gets_its_second_order_check():
    # 8 intervals (312 variables), no coarse mesh: the check runs on the only solve; the optimum is a vertex.
    reference = PLANNERS["collocation"]({"objective": "min_time", "intervals": 8, "coarse_intervals": 0}).plan(
        bilimoria_wie_problem())
    record = reference.stats["certificate"]
    assert record["second_order"] == "strict local minimum", record
    assert record["verdict"] == "certified"


def test_the_saddle_on_a_small_mesh_is_not_a_strict_local_minimum():
    problem = bilimoria_wie_problem()
    reference = PLANNERS["collocation"]({"objective": "min_time", "intervals": 8, "multistart": 0}).plan(problem)
    assert reference.duration == pytest.approx(3.5449, abs=1e-3)
    record = reference.stats["certificate"]
    assert record["second_order"].startswith("not certified"), record
    assert record["verdict"] == "first-order"


def test_the_second_order_check_made_here_agrees_with_the_module():
    _, solved, params, lbx, ubx = bilimoria_wie_solution({"objective": "min_time", "intervals": 8,
                                                                "coarse_intervals": 0, "multistart": 0})
    check = second_order_check(solved.nlp.solver, solved.result.x, solved.result.lam_x, solved.result.lam_g,
                               p=params, lbx=lbx, ubx=ubx, lbg=solved.nlp.lbg, ubg=solved.nlp.ubg)
    assert not check.certified and check.negative_curvatures > 0


def test_the_certificate_is_in_a_runs_results(tmp_path):
    from scenarios.cli import main
    out = tmp_path / "run"
    assert main(["run", "scenarios/collocation_min_time.yaml", "--out", str(out), "--no-plots"]) == 0
    rows = json.loads((out / "results.json").read_text())["rows"]
    by_planner = {row["planner"]: row for row in rows}
    assert by_planner["collocation"]["certificate"]["verdict"] == "certified"
    assert by_planner["eigenaxis"]["certificate"] is None
    lines = {line["planner"]: line for line in csv.DictReader((out / "results.csv").open())}
    # the exact bang-bang optimum's certificate (switch_refinement: auto, tests/test_collocation_bang_bang.py)
    assert lines["collocation"]["certificate"].startswith("certified: switch-time shooting, Pontryagin H")
    assert lines["collocation"]["certificate_verdict"] == "certified"
    assert float(lines["collocation"]["certificate_kkt_scaled"]) <= 1e-6
    assert lines["eigenaxis"]["certificate"] == ""
    assert "| certificate | certified: switch-time shooting" in (out / "results.md").read_text()


def test_the_certificate_is_in_a_one_case_studys_cases_csv(tmp_path):
    import shutil

    from scenarios.cli import main
    shutil.copy("scenarios/collocation_min_time.yaml", tmp_path / "scenario.yaml")
    study = tmp_path / "study.yaml"
    study.write_text("study: one-case\nscenario: scenario.yaml\n")
    assert main(["sweep", str(study), "--out", str(tmp_path / "sweep"), "--workers", "1", "--no-plots"]) == 0
    lines = {line["planner"]: line for line in csv.DictReader((tmp_path / "sweep" / "cases.csv").open())}
    assert lines["collocation"]["certificate_verdict"] == "certified"
    assert float(lines["collocation"]["certificate_kkt_scaled"]) <= 1e-6
    assert float(lines["collocation"]["certificate_kkt_unscaled"]) <= 1e-6
    assert lines["eigenaxis"]["certificate_verdict"] == ""


@pytest.mark.parametrize("tolerance, verdict", [(1e-8, "first-order"), (1e-2, "not certified")])
def test_the_costate_planners_certificate_is_its_boundary_value_residual(tolerance, verdict):
    # solve_bvp's residual at the requested tolerance: first-order (Pontryagin's necessary conditions
    # only); loosened to 1e-2 the residual is far above 1e-6 and the same solution is not certified.
    from tests.test_costate_tpbvp import problem
    reference = PLANNERS["costate_tpbvp"]({"tolerance": tolerance}).plan(problem())
    assert reference.ok, reference.message
    record = reference.stats["certificate"]
    assert record["verdict"] == verdict, record
    assert record["kkt_scaled"] >= reference.stats["max_rms_residual"]
    assert record["second_order"].startswith("not checked") and record["switching"] is None


def test_summary_line_is_rebuilt_with_the_costate_gap_in_its_place():
    from ocp.nlp.certificate import necessary_conditions_certificate, with_costate_gap
    direct = certificate(None, "not checked: no multipliers", seeds=2, seeds_agreed=1)
    updated = with_costate_gap(direct, 4.9e-6)
    assert updated["summary"] == "not certified: KKT not computed, SOSC not checked, co-state gap 5e-06, 1/2 seeds agreed"
    assert direct["costate_gap"] is None and updated["verdict"] == direct["verdict"]  # evidence beside the verdict
    indirect = with_costate_gap(necessary_conditions_certificate(1e-8, "solve_bvp"), 0.25)
    assert indirect["summary"] == ("first-order: solve_bvp residual 1e-08 (Pontryagin's necessary conditions), "
                                   "gap to the direct solution 0.2")


def test_a_run_cross_checks_the_direct_and_the_costate_optimum_of_one_functional(tmp_path):
    # The nano-spacecraft paper's natural-motion problem (the bench's natural_motion_min_energy):
    # collocation's minimum ∫‖u‖² and the co-state TPBVP's minimum ½∫‖M_c‖² are optima of the same
    # functional by two methods (direct transcription; Pontryagin's conditions by solve_bvp): their
    # values agree to a few 1e-6, and each certificate carries that gap. The eigenaxis row, which
    # minimises nothing, and a minimum-time collocation row (another functional) carry none.
    import yaml

    import scenarios
    from scenarios.runner import run
    with open("scenarios/bench/problems/natural_motion_min_energy.yaml") as stream:
        data = yaml.safe_load(stream)
    data["planners"] = [{"name": "collocation", "label": "direct"},
                        {"name": "costate_tpbvp", "label": "indirect"},
                        {"name": "eigenaxis", "label": "eigenaxis", "options": {"profile": "smooth"}}]
    path = tmp_path / "cross.yaml"
    path.write_text(yaml.safe_dump(data))
    rows = {row.label: row for row in run(scenarios.load(path)).rows}
    direct, indirect = rows["direct"], rows["indirect"]
    assert direct.status == indirect.status == "ok"
    j_direct = direct.reference.stats["functional"]["value"]
    j_costate = indirect.reference.stats["functional"]["value"]
    gap = abs(j_direct - j_costate) / j_costate
    assert 0.0 < gap < 1e-4  # two methods agree
    # each planner's value of the functional is its reference's ∫‖u‖² (torquers, no environment torque:
    # the actuators' torque is the body's control torque, measured by the common metric)
    assert j_direct == pytest.approx(direct.reference_metrics["int_u2"], rel=1e-4)
    assert j_costate == pytest.approx(indirect.reference_metrics["int_u2"], rel=1e-4)
    for row in (direct, indirect):
        assert row.reference.stats["certificate"]["costate_gap"] == pytest.approx(gap, rel=1e-12)
    assert "co-state gap" in direct.reference.stats["certificate"]["summary"]
    assert "gap to the direct solution" in indirect.reference.stats["certificate"]["summary"]
    assert rows["eigenaxis"].reference.stats.get("certificate") is None
    # another functional: no cross-check
    data["planners"][0]["options"] = {"objective": "min_l1"}
    path.write_text(yaml.safe_dump(data))
    rows = {row.label: row for row in run(scenarios.load(path)).rows}
    assert rows["direct"].reference.stats["certificate"]["costate_gap"] is None
    assert rows["indirect"].reference.stats["certificate"]["costate_gap"] is None


# --- what the record says of its seeds and its second-order check (report 51 L1) ---

def test_one_start_is_one_seed_not_an_agreement():
    small = kkt_residuals(small_nlp(lambda x: x[0] ** 2 + x[1] ** 2, lambda x: x[0] + x[1]), [0.5, 0.5], [0.0, 0.0],
                          [-1.0], lbg=1.0, ubg=1.0)
    one = certificate(small, "strict local minimum", None, seeds=1, seeds_agreed=1)
    assert one["summary"].endswith(", SOSC, 1 seed"), one["summary"]
    assert certificate(small, "strict local minimum", None, seeds=1, seeds_agreed=0)["summary"].endswith(
        "1 seed, not converged")
    assert certificate(small, "strict local minimum", None, seeds=2, seeds_agreed=2)["summary"].endswith(
        "2/2 seeds agreed")
    assert certificate(small, "strict local minimum", None, seeds=3)["summary"].endswith(", 3 seeds")
    assert "seed" not in certificate(small, "strict local minimum", None)["summary"]


def test_the_record_keeps_the_second_order_checks_numbers():
    """min x² + y² on x + y = 1 at (1/2, 1/2): H = 2 I on both (free) variables, one active row, so
    the check certifies at δ = CURVATURE_TOLERANCE × ‖H‖∞ = 2e-6 (the curvature on Z is 2)."""
    from ocp.nlp.certificate import certify
    from ocp.nlp.second_order import CURVATURE_TOLERANCE, SecondOrderCheck
    solver = small_nlp(lambda x: x[0] ** 2 + x[1] ** 2, lambda x: x[0] + x[1])
    record = certify(solver, np.array([0.5, 0.5]), np.zeros(2), np.array([-1.0]), lbg=1.0, ubg=1.0)
    assert record["second_order"] == "strict local minimum"
    detail = record["second_order_detail"]
    assert detail["certified"] is True and detail["negative_curvatures"] == 0
    assert detail["curvature_threshold"] == pytest.approx(CURVATURE_TOLERANCE * 2.0, rel=1e-12)
    assert "on 2 free variables and 1 active rows" in detail["message"], detail
    # a check not made keeps no made-up numbers (NaN is no JSON), a text keeps none at all
    small = kkt_residuals(solver, [0.5, 0.5], [0.0, 0.0], [-1.0], lbg=1.0, ubg=1.0)
    unchecked = certificate(small, SecondOrderCheck(False, -1, float("nan"), "no derivatives"))
    assert unchecked["second_order_detail"] == {"certified": False, "negative_curvatures": None,
                                                "curvature_threshold": None, "message": "no derivatives"}
    saddle = certificate(small, SecondOrderCheck(False, 3, 1e-6, "at most 3 directions"))
    assert saddle["second_order_detail"]["negative_curvatures"] == 3
    assert certificate(small, "not checked: no multipliers")["second_order_detail"] is None
    for made in (record, unchecked):
        assert json.loads(json.dumps(made, allow_nan=False)) == made
