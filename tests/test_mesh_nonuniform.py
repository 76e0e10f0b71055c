"""Non-uniform meshes of Radau collocation (ocp.transcription: ``mesh``, ``with_mesh``), the transfer of
multipliers onto them (ocp.transcription.mesh_transfer) and the planner's switch refinement
(``switch_refinement``).

Oracles: a uniform mesh given as nodes is the uniform mesh (same NLP, same optimum); piecewise
polynomials of the transcription's own degree are interpolated exactly, a jump at a node on either
side of it; the fine mesh's own multipliers; XTE's published minimum time (Betts 2010, 28.6304077 s).
"""
from types import SimpleNamespace

import numpy as np
import pytest

import scenarios
from ocp.errors import OptionsError
from ocp.nlp.solve import solve_multistart, solver_options
from ocp.transcription import MultipleShooting, RadauCollocation
from ocp.transcription.mesh_transfer import transfer_multipliers
from planners import PLANNERS
from planners.collocation.reference import seed_sampler
from planners.collocation.requirements import dense_times
from tests.test_collocation_mesh_transfer import bounded_single_axis

STRETCHED = np.array([0.0, 0.05, 0.12, 0.2, 0.35, 0.5, 0.7, 0.85, 1.0])  # 8 intervals, lengths 0.05 ... 0.2


def solved(transcription):
    problem = bounded_single_axis()
    planner = PLANNERS["collocation"]({"intervals": transcription.intervals})
    ocp = planner._ocp(problem)
    nlp = transcription.build(ocp, "ipopt", solver_options("ipopt", 1e-12, 500))
    lbx, ubx = transcription.bounds(ocp, nlp, *planner._variable_bounds(problem), problem.duration)
    seed = transcription.seed(ocp, nlp, seed_sampler(problem, PLANNERS["eigenaxis"]().plan(problem)), problem.duration)
    params = np.concatenate([problem.initial_state, problem.qf, np.zeros(3), [problem.duration],
                             problem.model.default_parameters])
    result = solve_multistart(nlp.solver, [seed], p=params, lbx=lbx, ubx=ubx, lbg=nlp.lbg, ubg=nlp.ubg, agree=1)
    assert result.success, result.message
    return nlp, result


def test_a_uniform_mesh_given_as_nodes_is_the_uniform_mesh():
    _, uniform = solved(RadauCollocation(8))
    _, given = solved(RadauCollocation(8, mesh=np.arange(9) / 8))
    assert given.f == pytest.approx(uniform.f, rel=1e-9)
    np.testing.assert_allclose(given.x, uniform.x, atol=1e-7)


def test_a_non_uniform_mesh_solves_the_same_problem():
    # the same optimum to the discretisation's accuracy (a fine uniform mesh the second method);
    # the mesh's times enter the dynamics: with uniform steps on these nodes the objective is off
    _, fine = solved(RadauCollocation(32))
    _, stretched = solved(RadauCollocation(8, mesh=STRETCHED))
    assert stretched.f == pytest.approx(fine.f, rel=1e-3)
    _, uniform = solved(RadauCollocation(8))
    assert not np.allclose(stretched.x, uniform.x, atol=1e-3)


def test_transfer_with_uniform_nodes_given_is_the_uniform_transfer():
    coarse, coarse_result = solved(RadauCollocation(4))
    fine, _ = solved(RadauCollocation(8))
    expected = transfer_multipliers(coarse, fine, coarse_result.lam_x, coarse_result.lam_g)
    given = transfer_multipliers(coarse, fine, coarse_result.lam_x, coarse_result.lam_g, np.arange(5) / 4,
                                 np.arange(9) / 8)
    for a, b in zip(given, expected):
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-15)


def test_transfer_onto_a_non_uniform_mesh_approaches_its_multipliers():
    # As the uniform transfer (tests/test_collocation_mesh_transfer.py, 8 -> 32: relative errors 0.36
    # and 0.06), here 8 -> 32 intervals, 16 in the first half; each entry at its own time and scaled
    # by its own step. Read as a uniform mesh the errors are 0.59 and 0.44.
    mesh = np.concatenate([np.arange(9) / 16, 0.5 + np.arange(1, 25) / 48])
    coarse, coarse_result = solved(RadauCollocation(8))
    fine, fine_result = solved(RadauCollocation(32, mesh=mesh))
    lam_x, lam_g = transfer_multipliers(coarse, fine, coarse_result.lam_x, coarse_result.lam_g, None, mesh)
    assert np.linalg.norm(fine_result.lam_x) > 1e-3  # the torque bound is active
    for moved, exact, tolerance in ((lam_x, fine_result.lam_x, 0.4), (lam_g, fine_result.lam_g, 0.05)):
        assert np.linalg.norm(moved - exact) < tolerance * np.linalg.norm(exact)


def test_interpolation_is_exact_on_a_non_uniform_mesh_with_a_jump_at_a_node():
    mesh = np.array([0.0, 0.3, 0.35, 1.0])
    transcription, T = RadauCollocation(3, 3, mesh), 2.0
    model = SimpleNamespace(nx=2, nu=1)

    def x(t):  # a cubic: the state polynomials' degree
        return np.stack([t ** 3 - t, 2.0 * t ** 2], axis=-1)

    def u(t, left):  # a quadratic up to the node at 0.35 T, another after: a jump there
        before = t < 0.35 * T if not left else t <= 0.35 * T
        return np.where(before, 1.0 + t ** 2, -1.0 - 0.5 * t)[:, None]

    points = (mesh[:-1, None] + transcription.tau[None, :] * np.diff(mesh)[:, None]) * T  # (N, d + 1)
    states = x(points.ravel()).T  # column k (d + 1) + j: point j of interval k
    controls = np.stack([u(points[k, 1:], left=True)[:, 0] for k in range(3)], axis=1)  # (d nu, N)
    t = np.linspace(0.0, T, 41)
    got_x, got_u = transcription.interpolate(model, states, controls, T, t)
    np.testing.assert_allclose(got_x, x(t), atol=1e-12)
    node = np.array([0.35 * T])
    assert transcription.interpolate(model, states, controls, T, node)[1][0, 0] == pytest.approx(-1.0 - 0.35)
    assert transcription.interpolate(model, states, controls, T, node, left=True)[1][0, 0] == pytest.approx(
        1.0 + 0.7 ** 2)
    inside = t[(t != 0.6) & (t != 0.7)]
    np.testing.assert_allclose(transcription.interpolate(model, states, controls, T, inside)[1], u(inside, False),
                               atol=1e-12)
    np.testing.assert_array_equal(transcription.interval_index(T, np.array([0.0, 0.6, 0.65, 0.7, 0.71, 2.0])),
                                  [0, 1, 1, 2, 2, 2])
    np.testing.assert_array_equal(transcription.interval_index(T, np.array([0.6, 0.7]), left=True), [0, 1])
    nodes, inner = transcription.smoothness(T)
    np.testing.assert_allclose(nodes, [0.6, 0.7])
    assert inner.size == 3 * 2 and np.all(np.diff(inner) > 0)


@pytest.mark.parametrize("mesh", [[0.0, 0.5, 1.0], [0.0, 0.6, 0.4, 1.0], [0.1, 0.5, 0.7, 1.0]])
def test_a_mesh_that_is_not_one_is_refused(mesh):
    with pytest.raises(ValueError, match="mesh"):
        RadauCollocation(3, mesh=np.array(mesh))


def test_a_transcription_without_non_uniform_meshes_refuses_one():
    with pytest.raises(ValueError, match="no non-uniform mesh"):
        MultipleShooting(2).with_mesh(np.array([0.0, 0.4, 1.0]))
    refined = RadauCollocation(2).with_mesh(np.array([0.0, 0.2, 0.4, 1.0]))
    assert refined.intervals == 3 and np.array_equal(refined.nodes, [0.0, 0.2, 0.4, 1.0])


XTE = 28.6304077  # Betts 2010, sect. 6.8


def test_switch_refinement_brings_xte_within_its_tolerance():
    problem = scenarios.load("scenarios/bench/problems/xte_150.yaml").problem
    plain = PLANNERS["collocation"]({"objective": "min_time", "switch_refinement": 0}).plan(problem)
    assert plain.ok and plain.duration - XTE > 8e-4 and "switch_refinement" not in plain.stats
    refined = PLANNERS["collocation"]({"objective": "min_time", "switch_refinement": 4}).plan(problem)
    record = refined.stats["switch_refinement"]
    assert refined.ok and abs(refined.duration - XTE) < 1e-4, (refined.duration, record)
    assert record["intervals_split"] >= 3 and record["intervals"] == 50 + 3 * record["intervals_split"]
    assert refined.transcription.mesh is not None and refined.intervals == record["intervals"]
    assert f"refined: {record['intervals_split']} intervals holding a switch split in 4" in refined.message
    certificate = refined.stats["certificate"]
    assert certificate["kkt_scaled"] < 1e-6 and certificate["switching"] > 0.9


@pytest.mark.parametrize(("options", "named"), [
    ({}, "objective 'min_energy'"),
    ({"objective": "min_time", "transcription": "multiple_shooting"}, "transcription 'multiple_shooting'"),
    ({"objective": "min_time", "solver": "fatrop"}, "solver 'fatrop'"),
    ({"objective": "min_time", "switch_refinement": 1}, "1 piece per interval"),
])
def test_switch_refinement_where_it_does_nothing_is_refused_naming_why(options, named):
    """A reviewer found it accepted and ignored there, without a word in the stats."""
    with pytest.raises(OptionsError, match="switch_refinement") as raised:
        PLANNERS["collocation"]({"switch_refinement": 4, **options})
    assert named in str(raised.value)


def test_the_dense_grid_on_a_non_uniform_mesh_has_its_points_per_interval_and_the_nodes():
    """The dense check spread 20 N points evenly over T: on a refined mesh a split interval got a
    few points and its nodes none."""
    mesh = np.array([0.0, 0.1, 0.125, 0.15, 0.175, 0.2, 1.0])
    reference = SimpleNamespace(duration=8.0, intervals=6, transcription=RadauCollocation(6, mesh=mesh))
    t = dense_times(reference, 20)
    assert t.size == 20 * 6 + 1 and t[0] == 0.0 and t[-1] == 8.0 and np.all(np.diff(t) > 0)
    np.testing.assert_allclose(t[::20], mesh * 8.0, rtol=0, atol=1e-15)  # every node on the grid
    for k in range(6):  # 20 equal steps inside each interval
        np.testing.assert_allclose(np.diff(t[20 * k:20 * (k + 1) + 1]), np.diff(mesh)[k] * 8.0 / 20, rtol=1e-12)
    uniform = SimpleNamespace(duration=8.0, intervals=6, transcription=RadauCollocation(6))
    np.testing.assert_array_equal(dense_times(uniform, 20), np.linspace(0.0, 8.0, 121))


def test_the_uniform_nlp_puts_each_interval_at_its_own_time():
    """A time-dependent problem (a cone switched on over [20, 40] s of 60 s, a gravity gradient along the
    orbit): the NLP of the uniform mesh and of the same mesh given as nodes (times k T / N against the
    nodes' fractions times T) give the same constraints and objective at a random point."""
    import casadi as ca

    from ocp import CircularOrbit, Environment, Spacecraft, Torquers, quat
    from ocp.geometry import PointingConstraint
    from ocp.transcription.stagewise import assemble
    from planners import ManeuverProblem

    windowed = PointingConstraint("keep_in", [0, 0, 1], False, np.deg2rad(60.0), directions=[[0, 0, 1]],
                                  window=(20.0, 40.0))
    spacecraft = Spacecraft([[10, 0.5, 0.2], [0.5, 8, 0.3], [0.2, 0.3, 6]], torquers=Torquers(0.05))
    environment = Environment(CircularOrbit(300e3, 0.9), gravity_gradient=True)
    problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.from_axis_angle([0, 0, 1], 1.0), 60.0,
                              omegaf=np.zeros(3), pointing=(windowed,), environment=environment)
    ocp = PLANNERS["collocation"]({"intervals": 6})._ocp(problem)
    values = []
    rng = np.random.default_rng(5)
    for method in (RadauCollocation(6), RadauCollocation(6, mesh=np.arange(7) / 6)):
        stages = assemble(method, ocp, method.interval(ocp))
        if not values:
            w = rng.normal(size=stages.w.numel())
        p = np.concatenate([problem.initial_state, problem.qf, np.zeros(3), [60.0], np.zeros(3)])
        values.append([v.full().ravel() for v in ca.Function("fg", [stages.w, stages.p], [stages.f, stages.g])(w, p)])
    (f_uniform, g_uniform), (f_nodes, g_nodes) = values
    np.testing.assert_allclose(g_uniform, g_nodes, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(f_uniform, f_nodes, rtol=1e-12)
    assert np.sum(g_uniform == -1.0) > 0  # the window switches the cone off somewhere
