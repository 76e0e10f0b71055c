"""Multipliers carried from a coarse mesh to a fine one (ocp.transcription.mesh_transfer) against the fine mesh's own."""
import numpy as np
import pytest

from ocp import Spacecraft, Torquers, quat
from ocp.nlp.solve import solve_multistart, solver_options
from ocp.transcription import TRANSCRIPTIONS
from ocp.transcription.mesh_transfer import transfer_multipliers
from planners import PLANNERS, ManeuverProblem
from planners.collocation.reference import seed_sampler


def bounded_single_axis():
    # Rest to rest about x in 20 s: the unbounded minimum-energy torque 6 I θ (T − 2t)/T³ peaks at
    # 0.075 N m, so |u| <= 0.06 N m is active near both ends (bound multipliers are not zero).
    spacecraft = Spacecraft([5.0, 4.0, 3.0], torquers=Torquers(0.06))
    return ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.from_axis_angle([1, 0, 0], 1.0), 20.0,
                           omegaf=np.zeros(3))


def solved(name, intervals, order=None):
    problem = bounded_single_axis()
    planner = PLANNERS["collocation"]({"intervals": intervals, "transcription": name})
    ocp = planner._ocp(problem)
    order = order if order is not None else 3 if name == "collocation" else 4  # degree or substeps
    transcription = TRANSCRIPTIONS[name](intervals, order)
    nlp = transcription.build(ocp, "ipopt", solver_options("ipopt", 1e-12, 500))
    lbx, ubx = transcription.bounds(ocp, nlp, *planner._variable_bounds(problem), problem.duration)
    start = PLANNERS["eigenaxis"]().plan(problem)
    seed = transcription.seed(ocp, nlp, seed_sampler(problem, start), problem.duration)
    params = np.concatenate([problem.initial_state, problem.qf, np.zeros(3), [problem.duration],
                             problem.model.default_parameters])
    result = solve_multistart(nlp.solver, [seed], p=params, lbx=lbx, ubx=ubx, lbg=nlp.lbg, ubg=nlp.ubg, agree=1)
    assert result.success, result.message
    return nlp, result


@pytest.mark.parametrize("name", sorted(TRANSCRIPTIONS))
def test_transfer_onto_the_same_mesh_is_the_identity(name):
    nlp, result = solved(name, 6)
    lam_x, lam_g = transfer_multipliers(nlp, nlp, result.lam_x, result.lam_g)
    np.testing.assert_allclose(lam_x, result.lam_x, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(lam_g, result.lam_g, rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("name", sorted(TRANSCRIPTIONS))
def test_transferred_multipliers_approach_the_fine_mesh_multipliers(name):
    # A second method: the fine mesh's own optimum. Constraint multipliers tend to the costate
    # (mesh independent), bound multipliers to a density times h: without the h ratio (8 -> 32)
    # the bound multipliers would be 4x too large (relative error 2.2-2.4 instead of 0.36-0.47, which
    # comes from the ends of the active arcs: they move between the meshes).
    coarse, coarse_result = solved(name, 8)
    fine, fine_result = solved(name, 32)
    lam_x, lam_g = transfer_multipliers(coarse, fine, coarse_result.lam_x, coarse_result.lam_g)
    assert np.linalg.norm(fine_result.lam_x) > 1e-3  # the torque bound is active
    for moved, exact, tolerance in ((lam_x, fine_result.lam_x, 0.6), (lam_g, fine_result.lam_g, 0.1)):
        assert np.linalg.norm(moved - exact) < tolerance * np.linalg.norm(exact)


def test_layouts_that_differ_beyond_the_mesh_are_refused():
    nlp, result = solved("collocation", 6)
    other, _ = solved("multiple_shooting", 6)
    assert transfer_multipliers(nlp, other, result.lam_x, result.lam_g) is None


def test_solution_sampler_reads_the_solution_as_the_reference_does():
    # The native seed of a fine mesh (states and controls interpolated by the transcription) against
    # the reference's own evaluation: with torquers only and no environment, the actuator torque is
    # the reference's torque (inverse dynamics of the interpolated states).
    from planners.collocation.reference import solution_sampler

    problem = bounded_single_axis()
    reference = PLANNERS["collocation"]({"intervals": 8}).plan(problem)
    assert reference.status == "ok", reference.message
    t = np.linspace(0.0, problem.duration, 37)
    t = t[np.abs(t / (problem.duration / 8) - np.round(t / (problem.duration / 8))) > 1e-6]  # nodes: below
    x, u, torque = solution_sampler(reference)(t)
    sample = reference.sample(t)
    np.testing.assert_allclose(x[:, 0:4], sample.q, atol=1e-12)
    np.testing.assert_allclose(x[:, 4:7], sample.omega, atol=1e-12)
    # the controls as solved: the reference's own are saturated at the bounds imposed (where the
    # polynomial overshoots them), the seed's are not (IPOPT moves a start into its bounds itself)
    np.testing.assert_allclose(u, reference._interpolated(t)[1], atol=1e-12)
    low, high = reference.control_bounds
    within = np.all((u >= low) & (u <= high), axis=1)
    assert np.any(within) and np.any(~within)  # both kinds are read
    # ... and in an interval where a control leaves its bounds, shifted to keep its impulse
    # (CollocationReference.impulse_offsets): the reference equals the polynomial elsewhere
    k = reference.transcription.interval_index(reference.duration, t)
    within &= np.all(reference.impulse_offsets[k] == 0.0, axis=1)
    assert np.any(within)
    np.testing.assert_allclose(u[within], reference.control(t)[within], atol=1e-12)
    np.testing.assert_allclose(torque[within], np.abs(sample.torque[within]), atol=1e-9)


@pytest.mark.parametrize("name, order", [("collocation", d) for d in range(1, 6)] + [("multiple_shooting", 4)])
def test_every_equality_entry_has_the_fine_mesh_scale(name, order):
    # Entry by entry, not in one norm (where the costate gaps, O(1), hide the small ones): each
    # column of the stage blocks (a gap entry, a collocation equation at one Radau point) carried
    # from 8 to 32 intervals against the fine mesh's own multipliers (a second solve, independent
    # of the transfer), for Radau of every degree. Multiple shooting's control gaps
    # u_{k+1} = c_k balance the control's O(h) stationarity: left unscaled they were 5.4x too
    # large (now 1.35x; the costate entries 0.93-1.12x, the rest is the active arcs' ends moving
    # between the meshes).
    coarse, coarse_result = solved(name, 8, order)
    fine, fine_result = solved(name, 32, order)
    _, lam_g = transfer_multipliers(coarse, fine, coarse_result.lam_x, coarse_result.lam_g)
    nb = fine.n_stage_state + fine.layout["n_path"]
    n_initial = len(fine.lbg) - 32 * nb - fine.layout["n_terminal"]
    rows = np.concatenate([np.arange(nb), nb + n_initial + np.arange(31 * nb)]).reshape(32, nb)
    equality = np.concatenate([np.ones(fine.n_stage_state, bool), fine.layout["path_equality"]])
    checked = 0
    for column in np.flatnonzero(equality):
        exact = np.linalg.norm(fine_result.lam_g[rows[:, column]])
        if exact > 1e-6:
            checked += 1
            assert 0.6 < np.linalg.norm(lam_g[rows[:, column]]) / exact < 1.6, column
    assert checked >= 3 * (order if name == "collocation" else 1)


def bilimoria_wie():
    # Bilimoria & Wie 1993: rest to rest 180° about x, I = 1, |u_i| <= 1 N m; minimum time 3.2431 s.
    return ManeuverProblem(Spacecraft([1.0, 1.0, 1.0], torquers=Torquers(1.0)), quat.IDENTITY, np.zeros(3),
                           quat.from_axis_angle([1, 0, 0], np.pi), 10.0, omegaf=np.zeros(3))


@pytest.mark.parametrize("transfer", [True, False])
def test_the_full_mesh_seed_with_and_without_the_transfer(monkeypatch, transfer):
    # With the coarse multipliers carried over, the full mesh starts from the coarse optimum's own
    # states and controls; when the transfer fails (here: refused, as for layouts that differ), it
    # falls back to that optimum through the inverse dynamics (the seed IPOPT's barrier 1e-4 was
    # tuned on) and still reaches the published optimum, both attempts on the record.
    from planners.collocation import planner as collocation

    used = []
    for name in ("seed_sampler", "solution_sampler"):
        original = getattr(collocation, name)
        monkeypatch.setattr(collocation, name, lambda *args, _f=original, _n=name: used.append(_n) or _f(*args))
    if not transfer:
        monkeypatch.setattr(collocation, "transfer_multipliers", lambda *args: None)
    # switch_refinement 0: the full-mesh solve (by default the exact bang-bang optimum replaces it)
    reference = PLANNERS["collocation"]({"objective": "min_time", "seed_planners": [], "switch_refinement": 0}).plan(
        bilimoria_wie())
    assert reference.ok, reference.message
    assert reference.duration == pytest.approx(3.2431, abs=2e-4)
    # the coarse mesh is seeded from the warm start, then the full mesh from the coarse optimum
    assert used == ["seed_sampler", "solution_sampler" if transfer else "seed_sampler"]
    assert len(reference.stats["starts"]) == 1


@pytest.mark.slow
def test_the_regularised_two_wheel_solve_is_carried_to_the_full_mesh():
    # time_regularization: the coarse regularised optimum and its multipliers seed the full mesh's
    # regularised problem, whose optimum is then polished to plain minimum time (the scenario's
    # 136.64 s). Iteration counts are no oracle here: a relative change of 1e-9 in the full-mesh seed
    # moves them between 14 and 138 (regularised) and 12 and 81 (polish), with the same optimum.
    from dataclasses import asdict
    from pathlib import Path

    import scenarios

    scenario = scenarios.load(Path(__file__).parent.parent / "scenarios" / "horri_palmer_two_wheels.yaml")
    spec = scenario.planners[0]
    reference = PLANNERS[spec.name](asdict(spec.options)).plan(scenario.problem)
    assert reference.ok, reference.message
    assert reference.duration == pytest.approx(136.64, abs=0.01)  # the scenario's minimum time
    coarse, fine = reference.stats["coarse"]["regularized"], reference.stats["regularized"]
    assert len(fine["starts"]) == 1 and fine["objective"] < coarse["objective"]  # a finer mesh, a shorter T


def test_radau_controls_at_a_node_are_the_ending_intervals_point_with_left():
    # Radau's control polynomial of interval k passes through τ_1 … τ_d = 1 only: the left limit at
    # the node t_{k+1} is the decision variable of the point τ_d of interval k; the interval that
    # starts there gives its polynomial extrapolated to τ = 0. Random controls, a duration whose
    # nodes k T / N are not exact in floating point.
    model = bounded_single_axis().model
    N, d, T = 8, 3, 3.2431108282673753
    transcription = TRANSCRIPTIONS["collocation"](N, d)
    rng = np.random.default_rng(1)
    states = rng.normal(size=(model.nx, N * (d + 1)))
    controls = rng.normal(size=(model.nu * d, N))
    nodes = np.arange(1, N) * T / N
    _, u_left = transcription.interpolate(model, states, controls, T, nodes, left=True)
    np.testing.assert_allclose(u_left, controls[(d - 1) * model.nu:, :N - 1].T, rtol=1e-12, atol=1e-12)
    _, u_right = transcription.interpolate(model, states, controls, T, nodes)
    _, u_start = transcription.interpolate(model, states, controls, T, nodes + 1e-12 * T)
    np.testing.assert_allclose(u_right, u_start, atol=1e-9)  # the interval that starts at the node
    assert np.min(np.abs(u_right - u_left)) > 1e-3  # a jump at every node (random controls)
    inner = (np.arange(N) + 0.37) * T / N  # between the nodes both sides read the same interval
    np.testing.assert_array_equal(transcription.interpolate(model, states, controls, T, inner, left=True)[1],
                                  transcription.interpolate(model, states, controls, T, inner)[1])


def test_solution_sampler_reads_a_node_from_the_interval_that_ends_there():
    # The seed of a fine Radau point τ_d = 1 that falls on a coarse node (8 and 50 intervals meet
    # at T/2): the coarse interval ending there, whose own point τ_d = 1 is a decision variable.
    from planners.collocation.reference import solution_sampler

    problem = bounded_single_axis()
    reference = PLANNERS["collocation"]({"intervals": 8}).plan(problem)
    assert reference.status == "ok", reference.message
    _, u, _ = solution_sampler(reference)(np.array([problem.duration / 2]))
    d, nu = reference.transcription.degree, reference.model.nu
    np.testing.assert_allclose(u[0], reference.controls[(d - 1) * nu:d * nu, 3], rtol=1e-12, atol=1e-15)


def test_the_loose_coarse_seed_of_a_fixed_time_leaves_the_optimum(monkeypatch):
    # A fixed final time's coarse solve is only a seed, solved to SEED_TOLERANCE (1e-5, the option's
    # 1e-10 elsewhere); the spin paper's minimum energy from the spin extremal (a 180° flip of a body
    # spinning at 0.2 rad/s: 0.0201 on the coarse mesh, 0.0185 on 50 intervals) must still reach the
    # optimum of the direct 50-interval solve, and the coarse NLP must be built with that tolerance.
    from ocp.transcription import base as transcription_base

    tolerances = []
    build = transcription_base.Transcription.build
    monkeypatch.setattr(transcription_base.Transcription, "build", lambda self, ocp, solver, options:
                        tolerances.append((self.intervals, options[f"{solver}.tol"])) or build(self, ocp, solver, options))
    problem = ManeuverProblem(Spacecraft([19.5, 19.0, 12.6], torquers=Torquers(0.1)), quat.IDENTITY, [0.2, 0, 0],
                              [0, 0, 1, 0], 200.0)
    default = PLANNERS["collocation"]({"warm_start": "spin_extremal"}).plan(problem)
    direct = PLANNERS["collocation"]({"warm_start": "spin_extremal", "coarse_intervals": 0}).plan(problem)
    assert default.ok and direct.ok, (default.message, direct.message)
    assert (8, 1e-5) in tolerances and (50, 1e-10) in tolerances and (8, 1e-10) not in tolerances
    assert default.stats["coarse"]["objective"] > 1.05 * default.stats["objective"]  # the coarse mesh is off
    assert default.stats["objective"] == pytest.approx(direct.stats["objective"], rel=1e-8)
    # the seed was FATROP's (SEED_FATROP), the full mesh IPOPT's from its optimum and multipliers
    assert default.stats["coarse"]["solver"] == "fatrop" and default.stats["solver"] == "ipopt"
    assert default.stats["iterations"] <= 6


def spin_paper_problem():
    return ManeuverProblem(Spacecraft([19.5, 19.0, 12.6], torquers=Torquers(0.1)), quat.IDENTITY, [0.2, 0, 0],
                           [0, 0, 1, 0], 200.0)


def test_ipopt_takes_the_seed_over_when_fatrop_stops(monkeypatch):
    # FATROP's coarse seed stopped (here: one iteration allowed) is not the end: IPOPT solves the
    # seed, the full mesh follows from it, to the optimum of the direct 50-interval solve.
    from planners.collocation import planner as collocation

    monkeypatch.setattr(collocation, "SEED_FATROP", {**collocation.SEED_FATROP, "fatrop.max_iter": 1})
    problem = spin_paper_problem()
    default = PLANNERS["collocation"]({"warm_start": "spin_extremal", "seed_planners": []}).plan(problem)
    direct = PLANNERS["collocation"]({"warm_start": "spin_extremal", "seed_planners": [],
                                      "coarse_intervals": 0}).plan(problem)
    assert default.ok, default.message
    assert default.stats["coarse_fatrop"]["solver_status"] == ["Fatrop_Stopped"]
    assert default.stats["coarse"]["solver"] == "ipopt" and default.stats["coarse"]["iterations"] > 10
    assert default.stats["objective"] == pytest.approx(direct.stats["objective"], rel=1e-8)


@pytest.mark.parametrize("transcription, seed_solver", [("collocation", "fatrop"), ("multiple_shooting", "ipopt")])
def test_the_seed_solver_follows_the_transcription_and_the_objective(transcription, seed_solver):
    # FATROP seeds Radau collocation only (multiple shooting's RK4 stages led it to other optima:
    # SEED_FATROP), and never an L1 objective (FATROP failed on most min_l1 problems).
    problem = spin_paper_problem()
    energy = PLANNERS["collocation"]({"transcription": transcription, "intervals": 20}).plan(problem)
    assert energy.ok, energy.message
    assert energy.stats["coarse"]["solver"] == seed_solver
    if transcription == "collocation":  # multiple shooting takes no L1 cost
        l1 = PLANNERS["collocation"]({"intervals": 20, "objective": "min_l1"}).plan(problem)
        assert l1.ok and l1.stats["coarse"]["solver"] == "ipopt", l1.message


def test_a_shared_cache_keeps_the_fatrop_seed_apart_from_a_fatrop_mesh():
    # A scenario's planners share one SolverCache. The IPOPT option's FATROP seed (SEED_FATROP's
    # mu_init) on 8 intervals and a `solver: fatrop` plan on 8 intervals have the same structure,
    # solver, tolerance and mode: the FATROP plan must not take the seed's NLP (with the seed's
    # options it converged in 20 iterations instead of its own 25).
    from ocp.cache import SolverCache

    fatrop = {"warm_start": "spin_extremal", "solver": "fatrop", "intervals": 8, "coarse_intervals": 0,
              "tolerance": 1e-4}
    alone = PLANNERS["collocation"](fatrop, cache=SolverCache()).plan(spin_paper_problem())
    cache = SolverCache()
    seeded = PLANNERS["collocation"]({"warm_start": "spin_extremal", "tolerance": 1e-4}, cache=cache).plan(
        spin_paper_problem())
    after = PLANNERS["collocation"](fatrop, cache=cache).plan(spin_paper_problem())
    assert alone.ok and seeded.ok and after.ok
    assert seeded.stats["coarse"]["solver"] == "fatrop"
    assert after.stats["iterations"] == alone.stats["iterations"]
    assert after.stats["objective"] == alone.stats["objective"]


def test_seed_fatrop_options_apply_to_the_ipopt_option_seed_only(monkeypatch):
    # SEED_FATROP is documented (the optimal-control guide, its docstring) for the seed FATROP solves in place of the
    # `solver: ipopt` option; a `solver: fatrop` plan's coarse seed keeps FATROP's defaults.
    from ocp.transcription import base as transcription_base

    built = []
    build = transcription_base.Transcription.build
    monkeypatch.setattr(transcription_base.Transcription, "build", lambda self, ocp, solver, options:
                        built.append((self.intervals, solver, options.get("fatrop.mu_init")))
                        or build(self, ocp, solver, options))
    seeds = {}
    for solver in ("ipopt", "fatrop"):
        built.clear()
        reference = PLANNERS["collocation"]({"warm_start": "spin_extremal", "intervals": 20,
                                             "solver": solver}).plan(spin_paper_problem())
        assert reference.ok, reference.message
        assert reference.stats["coarse"]["solver"] == "fatrop"
        seeds[solver] = [mu for intervals, used, mu in built if intervals == 8 and used == "fatrop"]
    assert seeds == {"ipopt": [1e-3], "fatrop": [None]}


@pytest.mark.parametrize("objective, adaptive", [("min_l1", True), ("min_energy", False)])
def test_an_l1_transfer_takes_the_adaptive_barrier(monkeypatch, objective, adaptive):
    # min_l1's optimum is bang-off-bang (torque slacks at their bounds): from the coarse optimum,
    # IPOPT's monotone barrier at 1e-7 crawled here (63 full-mesh iterations, α ~ 1e-3 per step;
    # 212 on the unrounded random problem) where the direct 40-interval solve takes 36. With the
    # adaptive barrier (TRANSFER_L1_BARRIER) 16, to the direct solve's optimum; min_energy keeps
    # the monotone one.
    from ocp.transcription import base as transcription_base

    strategies = []
    build = transcription_base.Transcription.build
    monkeypatch.setattr(transcription_base.Transcription, "build", lambda self, ocp, solver, options: strategies.append(
        options.get("ipopt.mu_strategy")) or build(self, ocp, solver, options))
    problem = ManeuverProblem(Spacecraft([16.605, 19.315, 12.072], torquers=Torquers(0.1)), quat.IDENTITY,
                              [0.1047, 0, 0], quat.from_axis_angle([0.0915, 0.6701, -2.8282], 2.4077), 217.68,
                              omegaf=np.zeros(3))
    default = PLANNERS["collocation"]({"intervals": 40, "objective": objective}).plan(problem)
    assert default.ok and "coarse" in default.stats, default.message
    assert ("adaptive" in strategies) == adaptive
    if adaptive:
        direct = PLANNERS["collocation"]({"intervals": 40, "objective": objective, "coarse_intervals": 0}).plan(problem)
        assert default.stats["objective"] == pytest.approx(direct.stats["objective"], rel=1e-8)
        assert default.stats["iterations"] < 30  # 63 with the monotone barrier


KEEP_OUT = [{"boresight": [0, 0, 1], "direction": [0, 1, 0], "angle_deg": 20.0}]


@pytest.mark.parametrize("options, barrier", [
    ({"objective": "min_l1"}, ("adaptive", None)),
    # free final time with an L1 term: the L1 barrier (the quality-function oracle)
    ({"objective": "weighted", "time_weight": 1.0, "l1_weight": 1.0, "energy_weight": 0.0}, ("adaptive", None)),
    ({"objective": "weighted", "energy_weight": 1.0, "l1_weight": 0.1}, (None, None)),  # 172 iterations against 151
    ({"objective": "min_energy"}, (None, None)),
    # minimum time: the probing oracle (TRANSFER_MIN_TIME_BARRIER; Bilimoria & Wie 7 iterations against 10)
    ({"objective": "min_time"}, ("adaptive", "probing")),
    ({"objective": "min_time", "keep_out": KEEP_OUT}, (None, None)),  # another local minimum on Melton's case
    ({"objective": "weighted", "time_weight": 1.0, "energy_weight": 1.0}, (None, None)),  # 40 against 23 (two wheels)
    ({"objective": "min_l1", "solver": "fatrop"}, None),  # transfer is a cold start for FATROP
])
def test_only_the_transfer_of_an_l1_objective_without_energy_or_of_min_time_changes_the_barrier(monkeypatch, options,
                                                                                              barrier):
    # Pins the conditions of TRANSFER_L1_BARRIER and TRANSFER_MIN_TIME_BARRIER build by build (the
    # end-to-end test above covers min_l1 and min_energy only: dropping its energy or L1 test, or
    # leaving out the time-weighted L1 objective, went unnoticed there): only the full-mesh build
    # started from the coarse optimum takes another barrier, the adaptive one for an L1 term without
    # an energy term, the adaptive one with the probing oracle and the affine corrector for minimum
    # time (no energy or L1 term) without cones.
    from ocp.transcription import base as transcription_base

    strategies = {}
    build = transcription_base.Transcription.build
    monkeypatch.setattr(transcription_base.Transcription, "build", lambda self, ocp, solver, extra: strategies.update(
        {mode: (extra.get("ipopt.mu_strategy"), extra.get("ipopt.mu_oracle"))}) or build(self, ocp, solver, extra))
    problem = bounded_single_axis()
    planner = PLANNERS["collocation"]({"intervals": 4, **options})
    ocp = planner._ocp(problem)
    for mode in ("cold", "warm", "near_optimum", "transfer"):
        planner._nlp(problem, ocp, mode)
    if barrier is None:  # FATROP: near_optimum and transfer are the cold build (a cache hit)
        assert strategies == {"cold": (None, None), "warm": (None, None)}
    else:
        assert strategies == {"cold": (None, None), "warm": (None, None), "near_optimum": (None, None),
                              "transfer": barrier}


def test_the_min_time_transfer_reaches_the_direct_solves_optimum_in_fewer_iterations():
    # Bilimoria & Wie (published 3.2431): the full mesh from the coarse optimum with the probing
    # oracle (TRANSFER_MIN_TIME_BARRIER) 7 IPOPT iterations against 10 with the monotone barrier
    # from 1e-7, to the optimum of the 50-interval solve without the coarse mesh.
    from planners.collocation import planner as planner_module

    problem = ManeuverProblem(Spacecraft([1.0, 1.0, 1.0], torquers=Torquers(1.0)), quat.IDENTITY, np.zeros(3),
                              quat.from_axis_angle([1, 0, 0], np.pi), 10.0, omegaf=np.zeros(3))
    # switch_refinement 0: the transfer (by default the exact bang-bang optimum replaces it)
    default = PLANNERS["collocation"]({"objective": "min_time", "switch_refinement": 0}).plan(problem)
    direct = PLANNERS["collocation"]({"objective": "min_time", "coarse_intervals": 0}).plan(problem)
    assert default.ok and direct.ok and "coarse" in default.stats, default.message
    assert default.duration == pytest.approx(3.2431, abs=2e-4)
    assert default.stats["objective"] == pytest.approx(direct.stats["objective"], rel=1e-8)
    monotone = PLANNERS["collocation"]({"objective": "min_time", "switch_refinement": 0})
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(planner_module, "TRANSFER_MIN_TIME_BARRIER", {})
        before = monotone.plan(problem)
    assert before.stats["objective"] == pytest.approx(default.stats["objective"], rel=1e-8)
    assert default.stats["iterations"] < before.stats["iterations"]


def wheel_slew_30_deg():
    # The 30 deg slew about x in 20 s of the input-hardening base scenario (three 0.05 N m wheels).
    from ocp import ReactionWheels

    spacecraft = Spacecraft([2.0, 3.0, 4.0], wheels=ReactionWheels.from_body_axes(max_torque=0.05))
    return ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.from_axis_angle([1, 0, 0], np.deg2rad(30.0)),
                           20.0, omegaf=np.zeros(3))


def test_no_multiplier_transfer_onto_a_mesh_beyond_its_validated_size(monkeypatch):
    # With the default options (coarse_intervals 8), 300, 400 and 500 intervals on this 30 deg wheel
    # slew ran > 120 s (killed): MUMPS's first factorisation of the IPOPT warm start from the coarse
    # optimum ("INFO(1) = -9 ... reallocating" three times, ~30 s each), with or without the carried
    # multipliers and for mu_init 1e-7 or 1e-4; the same seed without warm_start_init_point
    # converged in 0.9 s, the cold solve from eigenaxis in 3.4 s on 500 intervals.
    from planners.collocation.planner import CollocationPlanner
    from planners.collocation.strategy import TRANSFER_MAX_INTERVALS

    calls = []
    monkeypatch.setattr(CollocationPlanner, "_transfer", lambda self, *args: calls.append(self.options.intervals))
    problem = wheel_slew_30_deg()
    for intervals in (TRANSFER_MAX_INTERVALS, TRANSFER_MAX_INTERVALS + 1):
        PLANNERS["collocation"]({"intervals": intervals}).plan(problem)  # falls back without it
    assert calls == [TRANSFER_MAX_INTERVALS]


def test_a_fine_mesh_beyond_the_transfer_limit_is_solved_from_the_coarse_optimum():
    # 300 intervals (beyond TRANSFER_MAX_INTERVALS): the default plan (coarse seed, then the full
    # mesh from it without multipliers) in seconds, to the optimum of the direct solve from eigenaxis.
    problem = wheel_slew_30_deg()
    default = PLANNERS["collocation"]({"intervals": 300}).plan(problem)
    assert default.ok and "coarse" in default.stats, default.message
    direct = PLANNERS["collocation"]({"intervals": 300, "coarse_intervals": 0}).plan(problem)
    assert direct.ok, direct.message
    assert default.stats["objective"] == pytest.approx(direct.stats["objective"], rel=1e-8)
