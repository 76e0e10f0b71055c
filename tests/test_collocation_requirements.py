"""collocation honours the problem's requirements between its mesh points.

Oracles: angles recomputed here from the reference's attitude and the exact (not tabulated)
directions, body rates and wheel torques measured from the reference's samples (momentum
conservation and a numerical derivative of ω, not the planner's controls), the eigenaxis slew and
the unconstrained optimum for the non-vacuity of each case, and CasADi's own derivatives of the
whole NLP.
"""
import copy
import time

import numpy as np
import pytest

from ocp import ReactionWheels, Spacecraft, Torquers, quat
from ocp.geometry import PointingConstraint
from planners import PLANNERS, ManeuverProblem
from planners.collocation.requirements import DENSE_POINTS, Requirements, dense_check


def angle(u, v):
    return np.arccos(np.clip(np.sum(u * v, axis=-1), -1.0, 1.0))


def dense_times(reference, per_interval=200):
    return np.linspace(0.0, reference.duration, per_interval * reference.intervals + 1)


def cubesat(max_torque=3e-3, max_momentum=20e-3):
    """A 12U CubeSat on three orthogonal wheels (the issue's new user)."""
    return Spacecraft(np.diag([0.25, 0.28, 0.12]),
                      wheels=ReactionWheels.from_body_axes(max_torque=max_torque, max_momentum=max_momentum))


# --------------------------------------------------------------------------- the issue's case
def test_the_issue_case_solves_by_default():
    # 120 deg about the z principal axis in 60 s; the star tracker (body y) sweeps the plane the
    # Sun lies in, and the eigenaxis seed passes through the 30 deg keep-out's centre: the problem is
    # symmetric about that plane. Default collocation ran to its iteration limit (15.5 s).
    tracker = np.array([0.0, 1.0, 0.0])
    qf = quat.from_axis_angle([0, 0, 1], np.deg2rad(120.0))
    sun = quat.rotate(quat.from_axis_angle([0, 0, 1], np.deg2rad(60.0)), tracker)
    keep_out = PointingConstraint("sun", tracker, True, np.deg2rad(30.0), directions=[sun], description="sun")
    problem = ManeuverProblem(cubesat(), quat.IDENTITY, np.zeros(3), qf, 60.0, omegaf=np.zeros(3), pointing=(keep_out,))
    eigenaxis = PLANNERS["eigenaxis"]().plan(problem)
    t = np.linspace(0.0, 60.0, 1201)
    assert np.min(np.rad2deg(angle(quat.rotate(eigenaxis.q(t), tracker), sun))) < 0.01  # through the centre
    start = time.perf_counter()
    reference = PLANNERS["collocation"]().plan(problem)
    elapsed = time.perf_counter() - start
    assert reference.ok, reference.message
    t = dense_times(reference)
    least = np.min(np.rad2deg(angle(quat.rotate(reference.q(t), tracker), sun))) - 30.0
    assert least >= 0.0, least
    assert reference.stats["dense_check"]["met"]
    print(f"issue case: {elapsed:.2f} s, {reference.stats['iterations']} iterations, least margin {least:.4f} deg")


# --------------------------------------------------------------------------- the dense check
def random_keep_out(rng):
    """A random rest-to-rest slew whose eigenaxis path crosses a keep-out cone that neither end breaks."""
    while True:
        axis = quat.normalize(rng.normal(size=3))
        slew = rng.uniform(np.deg2rad(60.0), np.deg2rad(150.0))
        boresight = quat.normalize(rng.normal(size=3))
        if min(angle(boresight, axis), angle(boresight, -axis)) < np.deg2rad(30.0):
            continue
        half = rng.uniform(np.deg2rad(10.0), np.deg2rad(30.0))
        crossing = quat.rotate(quat.from_axis_angle(axis, rng.uniform(0.3, 0.7) * slew), boresight)
        offset = rng.normal(size=3)
        offset -= (offset @ crossing) * crossing
        direction = quat.rotate(quat.from_axis_angle(offset, rng.uniform(0.0, 0.6) * half), crossing)
        qf = quat.from_axis_angle(axis, slew)
        if min(angle(boresight, direction), angle(quat.rotate(qf, boresight), direction)) < half + np.deg2rad(2.0):
            continue
        spacecraft = Spacecraft(np.diag(rng.uniform(0.1, 0.3, 3)),
                                wheels=ReactionWheels.from_body_axes(max_torque=0.01, max_momentum=0.05))
        cone = PointingConstraint("keep_out", boresight, True, half, directions=[direction])
        return ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), qf, 60.0, omegaf=np.zeros(3), pointing=(cone,))


def check_random_keep_outs(count, seed):
    rng = np.random.default_rng(seed)
    least = []
    for _ in range(count):
        problem = random_keep_out(rng)
        cone = problem.pointing[0]
        direction = cone.directions[0]
        t = np.linspace(0.0, problem.duration, 1201)
        eigenaxis = PLANNERS["eigenaxis"]().plan(problem)
        assert np.min(angle(quat.rotate(eigenaxis.q(t), cone.boresight), direction)) < cone.angle  # crosses it
        reference = PLANNERS["collocation"]().plan(problem)
        assert reference.ok, reference.message
        t = dense_times(reference)
        least.append(np.rad2deg(np.min(angle(quat.rotate(reference.q(t), cone.boresight), direction)) - cone.angle))
    assert min(least) >= -0.01, least
    return least


def test_three_random_keep_outs_hold_between_the_nodes():
    check_random_keep_outs(3, seed=7)


@pytest.mark.slow
def test_twenty_random_keep_outs_hold_between_the_nodes():
    # The issue's target: on 20 random keep-out problems, no reference cuts a cone between its
    # nodes by more than 0.01 deg (200 points per interval; the planner checks 20).
    least = check_random_keep_outs(20, seed=2026)
    print(f"least margin over 20 problems: {min(least):.5f} deg")


def test_a_coarse_mesh_is_tightened_until_the_cone_holds_between_the_points():
    # Without a cone margin, on 8 intervals the optimum touches the cone at its points and cuts it
    # between them (0.04 deg): the dense check tightens it and solves again.
    spacecraft = Spacecraft([3.0, 4.0, 5.0], torquers=Torquers(0.2))
    problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.from_axis_angle([0, 0, 1], np.pi * 0.9),
                              60.0, omegaf=np.zeros(3))
    cone = {"boresight": [1, 0, 0], "direction": [0, 1, 0], "angle_deg": 30.0}
    for transcription in ("collocation", "multiple_shooting"):
        options = {"keep_out": [cone], "intervals": 8, "cone_margin_deg": 0.0, "transcription": transcription}
        reference = PLANNERS["collocation"](options).plan(problem)
        assert reference.ok, reference.message
        dense = reference.stats["dense_check"]
        assert dense["rounds"] >= 1 and dense["met"], dense
        assert dense["round_solves"][0]["violations"]["keep_out[0]"] > 0.005  # the first solve did cut it
        t = dense_times(reference)
        least = np.min(np.rad2deg(angle(quat.rotate(reference.q(t), [1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]))))
        assert least >= 30.0, (transcription, least)


# --------------------------------------------------------------------------- moving directions and windows
RATE = 0.06  # rad/s about inertial z: the nadir of a low orbit turns about as fast


def nadir_like(t):
    phase = -np.pi / 3 + RATE * np.asarray(t, dtype=float)
    return np.stack([np.cos(phase), np.sin(phase), np.zeros_like(phase)], axis=-1)


def plane_slew(pointing=()):
    # body x from inertial x to inertial y (90 deg about z) in 60 s, on torquers
    spacecraft = Spacecraft([3.0, 4.0, 5.0], torquers=Torquers(0.2))
    return ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.from_axis_angle([0, 0, 1], np.pi / 2), 60.0,
                           omegaf=np.zeros(3), pointing=tuple(pointing))


def test_a_moving_direction_is_imposed_at_each_point_s_own_time():
    # A keep-out of 20 deg about a direction turning about z at 0.06 rad/s, from -60 deg: it sweeps
    # through the plane of the slew and meets body x near t = 30 s (both at about 45 deg). Tabulated
    # every 0.25 s (linear interpolation: 0.002 deg); the oracle is the exact direction.
    table = np.arange(0.0, 60.0 + 1e-9, 0.25)
    moving = PointingConstraint("nadir", [1, 0, 0], True, np.deg2rad(20.0), table, nadir_like(table))
    reference = PLANNERS["collocation"]().plan(plane_slew([moving]))
    assert reference.ok, reference.message
    t = dense_times(reference)
    least = np.rad2deg(np.min(angle(quat.rotate(reference.q(t), [1.0, 0.0, 0.0]), nadir_like(t)))) - 20.0
    assert least >= -0.01, least
    # Not vacuous: the unconstrained slew, and a plan that imposes the direction of t = 0 at every
    # point (what wrong point times would do), both cut the moving cone deeply.
    frozen = PointingConstraint("frozen", [1, 0, 0], True, np.deg2rad(20.0), directions=[nadir_like(0.0)])
    for planned in (PLANNERS["collocation"]().plan(plane_slew()), PLANNERS["collocation"]().plan(plane_slew([frozen]))):
        assert planned.ok, planned.message
        t = dense_times(planned)
        assert np.rad2deg(np.min(angle(quat.rotate(planned.q(t), [1.0, 0.0, 0.0]), nadir_like(t)))) < 10.0


def test_a_keep_in_window_is_met_inside_and_ignored_before():
    # Keep body x within 30 deg of inertial y (the final pointing) over [T/2, T] only. The start is
    # 90 deg away (a keep-in over the whole run would be a failed row at once); the unconstrained
    # slew is still 45 deg away at T/2.
    window = (30.0, 60.0)
    keep_in = PointingConstraint("keep_in", [1, 0, 0], False, np.deg2rad(30.0), directions=[[0, 1, 0]], window=window)
    free = PLANNERS["collocation"]().plan(plane_slew())
    reference = PLANNERS["collocation"]().plan(plane_slew([keep_in]))
    assert reference.ok, reference.message
    for planned in (free, reference):
        t = dense_times(planned)
        off = np.rad2deg(angle(quat.rotate(planned.q(t), [1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])))
        inside = (t >= window[0]) & (t <= window[1])
        if planned is free:
            assert np.max(off[inside]) > 40.0  # not vacuous
        else:
            assert np.max(off[inside]) <= 30.0, np.max(off[inside])
            assert np.max(off[t <= 20.0]) > 60.0  # ignored before the window (90 deg at the start)
    always = PointingConstraint("keep_in", [1, 0, 0], False, np.deg2rad(30.0), directions=[[0, 1, 0]])
    failed = PLANNERS["collocation"]().plan(plane_slew([always]))
    assert not failed.ok and "keep_in" in failed.message and "initial attitude" in failed.message, failed.message


def test_an_endpoint_outside_the_window_is_not_a_failure_but_one_inside_is():
    # The final pointing is inertial y: a keep-out of 10 deg about it breaks the final attitude only
    # if its window holds T.
    early = PointingConstraint("early", [1, 0, 0], True, np.deg2rad(10.0), directions=[[0, 1, 0]], window=(0.0, 10.0))
    late = PointingConstraint("late", [1, 0, 0], True, np.deg2rad(10.0), directions=[[0, 1, 0]], window=(50.0, 60.0))
    planner = PLANNERS["collocation"]({"intervals": 20})
    assert planner.plan(plane_slew([early])).ok
    failed = planner.plan(plane_slew([late]))
    assert not failed.ok and "late" in failed.message and "final attitude" in failed.message, failed.message


# --------------------------------------------------------------------------- actuators and rate
def wheel_demand(problem, reference):
    """Peak wheel momentum and torque [N m s, N m] per wheel, from the reference's motion alone: the
    total momentum is zero (rest, no external torque), so the wheels hold h = -I ω (wheels along the
    body axes) and apply -I dω/dt (numerical derivative of the sampled rate)."""
    t = dense_times(reference)
    omega = reference.omega(t)
    momentum = -omega @ problem.spacecraft.inertia.T
    torque = -np.gradient(omega, t, axis=0) @ problem.spacecraft.inertia.T
    return np.max(np.abs(momentum), axis=0), np.max(np.abs(torque), axis=0)


def test_the_actuator_margin_keeps_the_reference_within_its_share_of_the_limits():
    # 120 deg about body x in 45 s: the minimum-energy slew peaks at 17.5 mN m s of the wheels' 20,
    # within the limit but above 0.8 of it; its torque at 1.55 mN m of 2.
    slew = quat.from_axis_angle([1, 0, 0], np.deg2rad(120.0))

    def problem(margin):
        return ManeuverProblem(cubesat(max_torque=2e-3), quat.IDENTITY, np.zeros(3), slew, 45.0, omegaf=np.zeros(3),
                               actuator_margin=margin)

    free, margined = (PLANNERS["collocation"]().plan(problem(m)) for m in (0.0, 0.2))
    assert free.ok and margined.ok, (free.message, margined.message)
    momentum, torque = wheel_demand(problem(0.0), free)
    assert momentum[0] > 0.85 * 20e-3  # not vacuous: margin 0 uses more than 0.8 of the momentum
    momentum, torque = wheel_demand(problem(0.2), margined)
    assert np.all(momentum <= 0.8 * 20e-3 * (1 + 1e-6)), momentum
    # What the reference asks of the wheels (its controls, saturated at the bounds imposed) stays
    # within 0.8 of the limit everywhere. -I dω/dt between the points follows the state polynomial,
    # whose derivative is not the saturated control where the bound is active: here 1.2e-3 of
    # 0.8 x the limit above it (it was within 4e-4 below while the dense check read the controls'
    # polynomial unsaturated: its overshoot, 1.5e-3, made the planner solve again 2.2e-3 tighter;
    # now only the wheel momentum's 3.5e-5 does, by 5.3e-5).
    commanded = np.max(np.abs(margined.control(dense_times(margined))), axis=0)
    assert np.all(commanded <= 0.8 * 2e-3), commanded
    assert commanded[0] >= 0.8 * 2e-3 * (1 - 1e-4)  # not vacuous: the torque bound is active
    assert np.all(torque <= 0.8 * 2e-3 * (1 + 2e-3)), torque
    assert margined.stats["objective"] > free.stats["objective"]


def test_the_rate_requirement_bounds_the_norm_everywhere():
    # 120 deg about a skew axis in 60 s: the minimum-energy slew peaks at |ω| = 1.5 θ / T = 0.052
    # rad/s; a requirement of 0.04 rad/s on the norm (a box of 0.04 per axis would allow 0.069).
    axis = quat.normalize([1.0, 1.0, 1.0])
    slew = quat.from_axis_angle(axis, np.deg2rad(120.0))
    problem = ManeuverProblem(cubesat(), quat.IDENTITY, np.zeros(3), slew, 60.0, omegaf=np.zeros(3), max_rate=0.04)
    free = PLANNERS["collocation"]().plan(ManeuverProblem(cubesat(), quat.IDENTITY, np.zeros(3), slew, 60.0,
                                                          omegaf=np.zeros(3)))
    assert np.max(np.linalg.norm(free.omega(dense_times(free)), axis=1)) > 0.05
    reference = PLANNERS["collocation"]().plan(problem)
    assert reference.ok, reference.message
    norms = np.linalg.norm(reference.omega(dense_times(reference)), axis=1)
    assert np.max(norms) <= 0.04 * (1 + 1e-6), np.max(norms)
    assert np.max(norms) > 0.04 * (1 - 1e-3)  # the bound is active: a norm, not a box


# --------------------------------------------------------------------------- what the dense check reads
@pytest.fixture(scope="module")
def bang_bang():
    """Bilimoria & Wie's minimum time on 20 intervals: torques on their bounds, a polynomial that
    overshoots them between the points, controls saturated at the limits themselves."""
    problem = ManeuverProblem(Spacecraft(np.eye(3), torquers=Torquers(1.0)), quat.IDENTITY, np.zeros(3),
                              quat.from_axis_angle([1, 0, 0], np.pi), 10.0, omegaf=np.zeros(3), actuator_margin=0.0)
    # unrefined: on 20 intervals its estimated error of T exceeds mesh_tolerance (switch_refinement: auto)
    reference = PLANNERS["collocation"]({"objective": "min_time", "intervals": 20, "switch_refinement": 0}).plan(problem)
    assert reference.ok, reference.message
    return problem, reference


def sampled_torque_peak(reference):
    """The largest |torque| the reference gives on the dense check's grid, read from both sides of
    each node (its controls as a user reads them)."""
    t = np.linspace(0.0, reference.duration, DENSE_POINTS * reference.intervals + 1)
    return max(float(np.max(np.abs(reference._state_control(t, left=left)[1]))) for left in (False, True))


def test_controls_saturated_within_their_limits_are_met_unsampled(bang_bang, monkeypatch):
    problem, reference = bang_bang
    t = np.linspace(0.0, reference.duration, DENSE_POINTS * reference.intervals + 1)
    assert np.max(np.abs(reference._interpolated(t)[1])) > 1.05  # not vacuous: the polynomial overshoots
    assert sampled_torque_peak(reference) <= 1.0  # what a full sample finds: nothing above the limit
    requirements = Requirements(actuator_margin=0.0)

    def unread(*args, **kwargs):
        raise AssertionError("sampled")

    monkeypatch.setattr(reference, "_state_control", unread)
    monkeypatch.setattr(reference, "_interpolated", unread)
    check = dense_check(problem, reference, requirements)
    assert check.met and check.violations == {} and check.margins_deg == {}
    assert check.points == DENSE_POINTS * reference.intervals + 1


def test_controls_saturated_beyond_their_limits_are_sampled(bang_bang):
    # the same motion held to 90 % of the torque limit (actuator margin 0.1), or read with its
    # saturation bounds twice the limits: the dense check must find what a full sample finds
    problem, reference = bang_bang
    check = dense_check(problem, reference, Requirements(actuator_margin=0.1))
    peak = sampled_torque_peak(reference)
    assert check.violations == pytest.approx({"actuators.torquers": peak / 0.9 - 1.0}, rel=1e-12)
    assert check.violations["actuators.torquers"] > 0.1
    wide = copy.copy(reference)
    wide.control_bounds = tuple(2.0 * bound for bound in reference.control_bounds)
    wide._impulse_offsets = wide._impulse_residuals = None  # found again for the wider bounds
    check = dense_check(problem, wide, Requirements(actuator_margin=0.0))
    peak = sampled_torque_peak(wide)
    assert peak > 1.05  # not vacuous: the wider saturation lets the overshoot through
    assert check.violations == pytest.approx({"actuators.torquers": peak - 1.0}, rel=1e-12)


# --------------------------------------------------------------------------- failures and derivatives
def test_a_failed_solve_with_cones_says_what_to_try():
    problem = plane_slew([PointingConstraint("sun", [1, 0, 0], True, np.deg2rad(20.0), directions=[nadir_like(30.0)])])
    reference = PLANNERS["collocation"]({"max_iterations": 2, "intervals": 10}).plan(problem)
    assert not reference.ok
    assert "multistart" in reference.message and "max_iterations" in reference.message, reference.message


@pytest.mark.parametrize("transcription", ["collocation", "multiple_shooting"])
@pytest.mark.parametrize("objective", ["min_energy", "min_time"])
def test_block_derivatives_with_moving_windowed_cones_and_a_rate_norm_equal_casadi_ad(transcription, objective):
    # ocp.transcription.stagewise differentiates one interval and scatters the blocks; CasADi's AD
    # of the whole graph is the oracle, with a moving cone (interpolated in time), a windowed one
    # and the rate norm, at a random point with random multipliers.
    import casadi as ca

    from ocp.transcription import TRANSCRIPTIONS
    from ocp.transcription.stagewise import assemble

    table = np.arange(0.0, 61.0, 5.0)
    moving = PointingConstraint("nadir", [1, 0, 0], True, np.deg2rad(20.0), table, nadir_like(table))
    windowed = PointingConstraint("keep_in", [0, 0, 1], False, np.deg2rad(60.0), directions=[[0, 0, 1]],
                                  window=(20.0, 40.0))
    spacecraft = Spacecraft([[10, 0.5, 0.2], [0.5, 8, 0.3], [0.2, 0.3, 6]], torquers=Torquers(0.05))
    problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.from_axis_angle([0, 0, 1], 1.0), 60.0,
                              omegaf=np.zeros(3), pointing=(moving, windowed), max_rate=0.05)
    planner = PLANNERS["collocation"]({"objective": objective, "transcription": transcription})
    ocp = planner._ocp(problem)
    assert ocp.n_path == 3
    method = TRANSCRIPTIONS[transcription](4, **({"degree": 3} if transcription == "collocation" else {}))
    stages = assemble(method, ocp, method.interval(ocp))
    lam_f, lam_g = ca.MX.sym("lam_f"), ca.MX.sym("lam_g", stages.g.numel())
    jacobian = ca.Function("J", [stages.w, stages.p], [ca.jacobian(stages.g, stages.w)])
    hessian = ca.Function("H", [stages.w, stages.p, lam_f, lam_g],
                          [ca.hessian(lam_f * stages.f + ca.dot(lam_g, stages.g), stages.w)[0]])
    rng = np.random.default_rng(3)
    w = rng.normal(size=stages.w.numel())
    p = np.concatenate([problem.initial_state, problem.qf, [0.0, 0.0, 0.0], [60.0], [0.0, 0.0, 0.0]])
    multipliers = (0.7, rng.normal(size=stages.g.numel()))
    np.testing.assert_allclose(stages.jac_g(w, p)[1].full(), jacobian(w, p).full(), rtol=1e-12, atol=1e-12)
    full = hessian(w, p, *multipliers).full()
    np.testing.assert_allclose(stages.hess_lag(w, p, *multipliers).full(), np.triu(full), rtol=1e-10, atol=1e-10)


def test_the_symbolic_constraint_agrees_with_the_margins_inside_and_beyond_its_table():
    # What the NLP imposes (cos θ − cos(limit) <= 0) and what the dense check and the scenario score
    # (the margin θ − limit) must agree in sign everywhere, before and after the direction table too
    # (held there; CasADi's linear interpolant alone would extrapolate).
    import casadi as ca

    table = np.arange(10.0, 50.0 + 1e-9, 5.0)
    cone = PointingConstraint("nadir", [1, 0, 0], True, np.deg2rad(20.0), table, nadir_like(table),
                              growth=np.linspace(0.0, 0.1, table.size))
    q, t = ca.SX.sym("q", 4), ca.SX.sym("t")
    g = ca.Function("g", [q, t], [cone.expression(q, t)])
    rng = np.random.default_rng(5)
    times = np.concatenate([[0.0, 5.0, 55.0, 60.0], rng.uniform(0.0, 60.0, 40)])
    attitudes = quat.random_unit(rng, times.size)
    margins = cone.margins(times, attitudes)
    values = np.array([float(g(a, s)) for a, s in zip(attitudes, times)])
    limits = cone.limit(times)
    # cos θ − cos(limit) against the margin θ − limit, both exact
    np.testing.assert_allclose(values, np.cos(limits + margins) - np.cos(limits), atol=1e-12)


def test_a_free_final_time_imposes_a_window_over_the_whole_run_and_says_so():
    # min_time does not know its points' times before the solve: a windowed keep-in that the start
    # breaks before its window is then refused at once, the message saying why.
    window = PointingConstraint("keep_in", [1, 0, 0], False, np.deg2rad(30.0), directions=[[0, 1, 0]],
                                window=(30.0, 60.0))
    reference = PLANNERS["collocation"]({"objective": "min_time"}).plan(plane_slew([window]))
    assert not reference.ok and "keep_in" in reference.message and "fixed final time" in reference.message
