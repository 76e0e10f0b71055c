"""The certificate of a collocation optimum: the NLP's evidence (:mod:`ocp.nlp.certificate`) and,
for bang-bang minimum time, Pontryagin's switching functions from the co-states in the multipliers.

Co-states of Legendre-Gauss-Radau collocation. The collocation equation at Radau point ``j`` of
interval ``k`` is ``X_k D_j − h f(x_kj, u_kj) = 0`` (:mod:`ocp.transcription.radau`), with
multiplier ``λ_kj`` (CasADi's ``L = f + λᵀ g``). It is the quadrature ``h w_j (ẋ − f)`` of the
continuous constraint divided by ``h``, and the continuous Lagrangian is ``J + ∫ −pᵀ(ẋ − f) dt``
(``H = L + pᵀ f``), so the co-state there is ``p_kj = −λ_kj / w_j`` (``w_j`` the Radau weights on
[0, 1]). The sign is checked numerically by the tests: with it the minimum-time Hamiltonian
``1 + pᵀ f`` vanishes along Bilimoria & Wie's optimum and the controls minimise ``H``. The
switching functions are ``σ_kj = ∂H/∂u = p_kjᵀ ∂f/∂u (x_kj, u_kj)`` (for ``ω̇ = J⁻¹(u − ω × J ω)``,
``σ = J⁻ᵀ p_ω``), the model's own Jacobian.

The discretisation error of a bang-bang minimum time (:func:`time_error`): the switching
functions' roots, interpolated between the Radau points, are the switch times of a bang-bang
control with the solution's switching structure; Newton's method on those times and ``T`` makes
that control, integrated accurately (RK4, :data:`SHOOTING_STEPS` steps per arc), meet the final
attitude and rate (with more switches than final conditions, ``T`` minimised on them; two switches
of two controls the minimisation makes cross are tied, their order constraint active). Newton's
method stops where the miss and the stationarity at the point it returns are below
:data:`SHOOTING_TOLERANCE`. There the RK4 steps' error of the final miss, by step doubling
(:func:`_rk4_error`: twice the steps, the miss alone), gives one more Newton step, to the optimum
of the same switches flown exactly (Richardson's extrapolation: within 2e-9 s of DOP853's on
Bilimoria & Wie, the full inertia and XTE, whose RK4 optimum is 1.6e-6 s below); where that step
moves ``T`` by more than :data:`SHOOTING_RICHARDSON` of it, the steps per arc are doubled and the
shooting goes on from there. With more switches than final conditions, where ``T`` is flat to
second order along the feasible switch times and the stationarity carries the RK4 Jacobian's own
error, the shooting converges again with twice the steps and the whole point is extrapolated
(``z_2S + (z_2S − z_S)/15``, from a pair whose fewer steps' correction of ``T`` is within
:data:`SHOOTING_RICHARDSON`): a reviewer's six-switch slews had kept switches 2e-7 of ``T`` off with
the miss's error taken off alone; now within 7e-10 of ``T`` of their DOP853 optimum
(``tests/test_bang_bang_six_switches.py``). A σ exactly 0 at a Radau point between a positive and a negative
value is one root. Its ``T`` is that of a trajectory of the continuous problem, so it bounds the
continuous minimum time from above, and, the optimum being stationary on the feasible switch
times, it is within the square of the collocation's switch-time error of it: ``T_N`` minus it is
the discretisation error of ``T_N``, not more than it (a switch the mesh missed makes it less). A
switch or ``T`` moved by more than a mesh interval is another switching structure than the mesh
resolved: no estimate.
"""
from __future__ import annotations

from dataclasses import asdict
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ocp.dynamics.integration import rk4_step
from ocp.dynamics.model import AttitudeModel
from ocp.fast_call import buffered, matrices
from ocp.nlp.certificate import (
    Switching,
    certificate,
    certify,
    seed_counts,
    summary_line,
    switching_agreement,
)
from ocp.nlp.solve import NLPResult
from ocp.transcription import NLP, OptimalControlProblem, Transcription
from ocp.transcription.radau import RadauCollocation
from planners.collocation.reference import _mapped, states_controls
from planners.problem import Array, ManeuverProblem
from planners.reference import Reference

SHOOTING_STEPS = 12
"""RK4 steps per arc of :func:`time_error`'s bang-bang shooting (and :func:`bang_bang_certificate`'s
co-state), doubled where :data:`SHOOTING_RICHARDSON` asks: the RK4 optimum's ``T`` on XTE is
1.6e-6 s below the exact one (28.6304068 s), on Bilimoria & Wie 2.6e-8 s, on the full inertia 2e-7 s
above (taken off by step doubling: :func:`_rk4_error`); 40 steps cost 10x the time a call."""
SHOOTING_TOLERANCE = 1e-10
"""Largest final attitude (quaternion vector part) and rate [rad/s] miss, and stationarity of the
minimisation of ``T`` (more switches than conditions), at which :func:`time_error` accepts a point
of its Newton iteration: both are evaluated at the point returned, whose ``T`` is then that of the
RK4 shooting's exact solution to far below a microsecond (the RK4 steps' own error is then taken
off: :data:`SHOOTING_RICHARDSON`)."""
SHOOTING_ITERATIONS = 10
"""Newton iterations of :func:`time_error` before it gives up."""
SHOOTING_RICHARDSON = 1e-7
"""Largest RK4 correction of ``T`` (the step from the shooting's optimum to that of the same
switches flown exactly, by step doubling: :func:`_rk4_error`), relative to ``T``, that
:func:`time_error` and :func:`bang_bang_certificate` take with their steps per arc; above it the
steps are doubled (up to :data:`SHOOTING_MAX_STEPS`). The correction is Richardson's extrapolation
of RK4's fourth-order error: from 12 and 24 steps it leaves 4e-11 of ``T`` on XTE (correction
5.7e-8 of ``T``) and 2e-10 on the full inertia (2.5e-8, its error at 12 steps 14 times that at 24,
not 16); the switch times within 2e-9 of ``T``. Both are far from the error's asymptote when the
correction is large: above 1e-7 of ``T``, 24 steps and more."""
SHOOTING_MAX_STEPS = 96
"""Most RK4 steps per arc :data:`SHOOTING_RICHARDSON` doubles them to."""
STATE_BOUND_ACTIVE = 1e-6
"""Relative distance of an actuator state from its bound within which :func:`time_error` counts the
bound active (and does not shoot: a bang-bang trajectory with that state constraint active is not
the optimum of the bang-bang problem the shooting solves)."""
SHOOTING_MAX_SWITCHES = 8
"""Most switches :func:`time_error` shoots: a solution whose switching functions change sign more
often is skipped (``skipped``). The minimum times of ``tests/benchmarks/iteration_counts.py`` (rigid
bodies with torquers) have 4 to 10 at the 8-interval optimum, the shot ones 5 or 6 (mt0's 10 were
not shot before the cap either: a switch moved by more than a mesh interval; its plan the same);
with three reaction wheels some slews have
10 to 14 on the 8-interval mesh, where the shooting neither converged nor certified and its Newton
iterations over many arcs (a Hessian of the miss in every switch time, built per arc count) took a
plan from 172 to 1079 ms (2026-12-04)."""


def bound_excess(values: Array, low: Array, high: Array) -> float:
    """The largest excess of ``values (points, n)`` over per-column bounds ``low``, ``high`` (``(n,)``,
    infinite where unbounded), relative to the larger bound's magnitude (absolute where both are zero:
    a failed wheel): positive outside, ``-inf`` where no column has a finite bound.

    Parameters
    ----------
    values : (points, n) ndarray
        The values, a row per point.
    low, high : (n,) ndarray
        Their bounds.

    Returns
    -------
    float
    """
    scale = np.maximum(np.abs(low), np.abs(high))
    scale = np.where(scale > 0, scale, 1.0)
    with np.errstate(invalid="ignore"):
        excess = np.maximum(values - high, low - values) / scale  # nan where both bounds are infinite
    return float(np.max(np.nan_to_num(excess, nan=-np.inf), initial=-np.inf))


def final_conditions(params: Array, nx: int) -> Array:
    """The shooting's final state ``xf``: the final attitude and rate of an NLP's parameters, the
    wheel momenta (free at the end, not read) zero.

    Parameters
    ----------
    params : ndarray
        The NLP's parameters: the initial state (``nx``), then ``[q_f, ω_f]`` (7), ...
    nx : int
        The model's state size (7, plus one per reaction wheel).

    Returns
    -------
    (nx,) ndarray
        ``[q_f, ω_f, 0 …]``.
    """
    return np.concatenate([np.asarray(params, dtype=float)[nx:nx + 7], np.zeros(nx - 7)])


def radau_points(transcription: RadauCollocation, model: AttitudeModel, nlp: NLP, w: Array,
                 lam_g: Array) -> tuple[Array, Array, Array, Array]:
    """States, controls, co-states and times at the Radau points of a collocation solution.

    Parameters
    ----------
    transcription : RadauCollocation
        The transcription of the solution.
    model : AttitudeModel
        The spacecraft model (``nx``, ``nu``).
    nlp : NLP
        The built NLP (its stage sizes, free time).
    w : (n_w,) ndarray
        The decision vector.
    lam_g : ndarray
        The constraint multipliers (CasADi's signs).

    Returns
    -------
    tuple of ndarray
        ``x (N d, nx)``, ``u (N d, nu)``, co-states ``p (N d, nx)`` (``−λ / w_j``, see the module
        docstring) and the points' times ``t (N d,)`` [s] in the NLP's time.
    """
    N, d, nx, nu = transcription.intervals, transcription.degree, model.nx, model.nu
    ns, nc = nlp.n_stage_state, nlp.n_interval
    nz = ns + nc
    stages = np.asarray(w, dtype=float)[:nz * N].reshape(N, nz)
    c = stages[:, ns:]
    x = c[:, :nx * d].reshape(N * d, nx)
    u = c[:, nx * d:nx * d + nu * d].reshape(N * d, nu)
    nb = ns + int(nlp.layout["n_path"])
    lam_g = np.asarray(lam_g, dtype=float)
    starts = [0] + [nb + nx + k * nb for k in range(N - 1)]  # the blocks of ocp.transcription.stagewise
    lam = np.stack([lam_g[start + ns:start + ns + nx * d] for start in starts]).reshape(N, d, nx)
    p = -(lam / transcription.quadrature[None, :, None]).reshape(N * d, nx)
    T = stages[0, ns - 1] if nlp.free_time else None
    times = (np.arange(N)[:, None] + transcription.tau[None, 1:]).ravel() / N
    if transcription.mesh is not None:  # a non-uniform mesh (the planner's switch_refinement)
        times = transcription.fractions(np.arange(N)[:, None], transcription.tau[None, 1:]).ravel()
    return x, u, p, times if T is None else times * T


def _control_jacobian(model: AttitudeModel) -> ca.Function:
    """``∂f/∂u (x, u, t, d)`` of the model's dynamics (mapped over the points and kept with the
    model's recent maps by :func:`switching`)."""
    xs, us, ts, ds = ca.SX.sym("x", model.nx), ca.SX.sym("u", model.nu), ca.SX.sym("t"), ca.SX.sym("d", 3)
    # dense (its structural zeros explicit): read through buffers (ocp.fast_call.matrices)
    return ca.Function("f_u", [xs, us, ts, ds], [ca.densify(ca.jacobian(model.rhs(xs, us, ts, ds), us))])


def switching(transcription: RadauCollocation, model: AttitudeModel, nlp: NLP, w: Array, lam_g: Array,
              lbx: Array, ubx: Array, params: Array, costate_sign: float = 1.0,
              functions: tuple[Array, Array, Array] | None = None) -> Switching:
    """Pontryagin's switching agreement of a minimum-time collocation solution.

    Parameters
    ----------
    transcription, model, nlp, w, lam_g
        As in :func:`radau_points`.
    lbx, ubx : (n_w,) ndarray
        The decision vector's bounds (the controls' bounds are read there).
    params : ndarray
        The NLP's parameters (the disturbance torque [N m] at their end, and ``T`` for a fixed time).
    costate_sign : float
        Multiplies the co-states (1: the convention of the module docstring; −1 only to show that
        a wrong sign fails the check).
    functions : tuple of ndarray, optional
        :func:`switching_functions` of this solution (with ``costate_sign`` 1), already computed.

    Returns
    -------
    ocp.nlp.certificate.Switching
        Agreement of ``sign(u) = −sign(σ)`` over every control at every Radau point.
    """
    _, u, sigma = (functions if functions is not None and costate_sign == 1.0 else
                   switching_functions(transcription, model, nlp, w, lam_g, params, costate_sign))
    N, d, nx, nu = transcription.intervals, transcription.degree, model.nx, model.nu
    nz = nlp.n_stage_state + nlp.n_interval
    offset = nlp.n_stage_state + nx * d
    low = np.asarray(lbx, dtype=float)[:nz * N].reshape(N, nz)[:, offset:offset + nu * d].reshape(N * d, nu)
    high = np.asarray(ubx, dtype=float)[:nz * N].reshape(N, nz)[:, offset:offset + nu * d].reshape(N * d, nu)
    return switching_agreement(u, low, high, sigma)


def switching_functions(transcription: RadauCollocation, model: AttitudeModel, nlp: NLP, w: Array, lam_g: Array,
                        params: Array, costate_sign: float = 1.0) -> tuple[Array, Array, Array]:
    """The switching functions ``σ = ∂H/∂u`` at the Radau points of a collocation solution.

    Parameters
    ----------
    transcription, model, nlp, w, lam_g, params, costate_sign
        As in :func:`switching`.

    Returns
    -------
    tuple of ndarray
        The points' times ``t (N d,)`` [s] (in time order), the controls ``u (N d, nu)`` and
        ``σ (N d, nu)`` there (see the module docstring).
    """
    x, u, p, t = radau_points(transcription, model, nlp, w, lam_g)
    if not nlp.free_time:
        t = t * float(params[model.nx + 7])
    nx, nu = model.nx, model.nu
    mapped = _mapped(model, "switching f_u dense", x.shape[0], lambda: _control_jacobian(model))
    f_u = matrices(mapped, x.T, u.T, t[None, :], np.tile(params[-3:], (x.shape[0], 1)).T)[0]
    f_u = f_u.reshape(nx, x.shape[0], nu).transpose(1, 0, 2)  # (points, nx, nu)
    return t, u, costate_sign * np.einsum("ki,kij->kj", p, f_u)


def collocation_certificate(result: NLPResult, transcription: Transcription, ocp: OptimalControlProblem, nlp: NLP,
                            params: Array, lbx: Array, ubx: Array, solver: str, stats: dict[str, Any],
                            functions: tuple[Array, Array, Array] | None = None) -> dict[str, Any]:
    """``Reference.stats["certificate"]`` of a converged collocation solve.

    Parameters
    ----------
    result : NLPResult
        The converged solve (point and multipliers).
    transcription : Transcription
        Its transcription (switching only for Radau collocation).
    ocp : OptimalControlProblem
        The problem solved (switching only for pure minimum time).
    nlp : NLP
        The built NLP that solved it.
    params, lbx, ubx : ndarray
        The solve's parameters and variable bounds.
    solver : str
        The ``nlpsol`` plugin.
    stats : dict
        The reference's stats so far (``seeds`` or its starts are counted).
    functions : tuple of ndarray, optional
        :func:`switching_functions` of this solution, already computed.

    Returns
    -------
    dict
        The record of :func:`ocp.nlp.certificate.certificate` (``"not certified"``, saying why, for a
        solve without multipliers or a solver without the derivative functions).
    """
    tried, agreed = seed_counts(stats)
    if result.x is None or result.lam_x is None or result.lam_g is None:
        return certificate(None, "not checked: no multipliers", seeds=tried, seeds_agreed=agreed)
    agreement = None
    # Pontryagin's sign(u) = −sign(σ) per control holds for independent box-bounded controls, not
    # with the allocation's equalities among them (planners.collocation.allocation)
    if (ocp.free_time and ocp.energy_weight == 0 and ocp.l1_weight == 0 and isinstance(transcription, RadauCollocation)
            and getattr(transcription, "allocation_rows", None) is None):
        agreement = switching(transcription, ocp.model, nlp, result.x, result.lam_g, lbx, ubx, params,
                              functions=functions)
    try:
        return certify(nlp.solver, result.x, result.lam_x, result.lam_g, p=params, lbx=lbx, ubx=ubx, lbg=nlp.lbg,
                       ubg=nlp.ubg, solver_name=solver, second_order=result.second_order, switching=agreement, seeds=tried,
                       seeds_agreed=agreed)
    except RuntimeError as error:  # a solver plugin without nlp_jac_g / nlp_grad_f
        return certificate(None, f"not checked: {str(error).splitlines()[0]}", agreement, seeds=tried,
                           seeds_agreed=agreed)


def start_violations(problem: ManeuverProblem, reference: Reference, bounds: tuple[Array, Array, Array, Array],
                     max_rate: float | None, pointing: tuple, points: int,
                     tolerance: float, boundary_tolerance: float) -> dict[str, float] | str:
    """How far another planner's reference breaks a collocation problem's constraints: whether it
    is a feasible motion whose duration bounds that problem's minimum time.

    The reference is read at ``points`` equally spaced times over its own duration. Its body
    torque is given to the working wheels as the controllers' allocation gives it (``g = −A⁺ τ``
    over the working wheels, their momenta from the conserved total), or to the torquers alone;
    the states and controls are checked against the variable bounds ``bounds`` (relative excess
    above ``tolerance``), the body-rate norm against ``max_rate``, the pointing constraints'
    margins (not below 0) and the boundary conditions (initial state, final attitude up to sign,
    final rate when fixed; absolute ``boundary_tolerance``). The dynamics hold by construction
    (a reference's torque is its inverse dynamics), so a reference that breaks none of these is a
    feasible slew of the problem.

    Parameters
    ----------
    problem : ManeuverProblem
        The manoeuvre.
    reference : Reference
        The other planner's reference (its own ``duration``).
    bounds : tuple of ndarray
        ``(x_low, x_high, u_low, u_high)`` per point, as the NLP imposes them
        (:func:`~planners.collocation.problem.variable_bounds`).
    max_rate : float or None
        Body-rate norm bound [rad/s]; ``None``: none.
    pointing : tuple of PointingConstraint
        The pointing constraints (their ``margins``, negative inside a keep-out cone).
    points : int
        Times checked.
    tolerance : float
        Relative excess over a bound that counts as broken.
    boundary_tolerance : float
        Absolute miss of a boundary condition that counts as broken.

    Returns
    -------
    dict or str
        The broken constraints and by how much (relative excess, rad of pointing margin, absolute
        boundary miss; ``"not finite"``: how many times hold a NaN or an infinity); empty when the
        reference is feasible. A string says why it cannot be
        checked (actuators other than wheels or torquers alone, environment torques, stored
        momentum with torquers: the actuators' share of the torque is not read from the
        reference alone).
    """
    model, spacecraft, environment = problem.model, problem.spacecraft, problem.environment
    blocks = set(model.control_slices)
    if blocks - {"wheels"} and blocks - {"torquers"}:
        return f"not checked: actuators {sorted(blocks)} (wheels alone or torquers alone are read)"
    if environment.gravity_gradient or environment.magnetic_field is not None or np.any(environment.disturbance_torque):
        return "not checked: environment torques"
    t = np.linspace(0.0, float(reference.duration), max(int(points), 2))
    x, u, sample = states_controls(problem, reference, t)
    bad = ~(np.all(np.isfinite(x), axis=1) & np.all(np.isfinite(u), axis=1)
            & np.all(np.isfinite(sample.torque), axis=1))
    if np.any(bad):  # a NaN compares false with every bound: it would read as feasible
        return {"not finite": float(np.sum(bad))}
    if "wheels" in blocks:
        # what the working wheels cannot give (off their span) and the stored momentum they miss
        demand = sample.torque + np.cross(sample.omega, x[:, 7:] @ spacecraft.wheel_axes.T)
        missed = np.max(np.abs(demand + u[:, model.control_slices["wheels"]] @ spacecraft.wheel_axes.T), initial=0.0)
        if missed > boundary_tolerance:
            return {"torque off the working wheels' span": float(missed)}
    broken: dict[str, float] = {}
    x_low, x_high, u_low, u_high = bounds
    for name, values, low, high in (("states", x, x_low, x_high), ("controls", u, u_low, u_high)):
        worst = bound_excess(values, low, high)
        if worst > tolerance:
            broken[name] = worst
    if max_rate is not None:
        rate_excess = float(np.max(np.linalg.norm(sample.omega, axis=1))) / max_rate - 1.0
        if rate_excess > tolerance:
            broken["rate"] = rate_excess
    for constraint in pointing:
        margin = constraint.margins(t, sample.q)
        if np.any(np.isfinite(margin)) and float(np.nanmin(margin)) < 0.0:
            broken[constraint.name] = -float(np.nanmin(margin))
    assert problem.qf is not None  # collocation refuses a free attitude (Planner.problem_error)
    misses = {"initial state": float(np.max(np.abs(x[0, :7] - problem.initial_state[:7]))),
              "final attitude": float(min(np.max(np.abs(sample.q[-1] - problem.qf)),
                                          np.max(np.abs(sample.q[-1] + problem.qf))))}
    if model.n_wheels:
        misses["initial wheel momentum"] = float(np.max(np.abs(x[0, 7:] - np.asarray(problem.wheel_momentum0, dtype=float))))
    if problem.omegaf is not None:
        misses["final rate"] = float(np.max(np.abs(sample.omega[-1] - problem.omegaf)))
    broken.update({name: miss for name, miss in misses.items() if miss > boundary_tolerance})
    return broken


def switch_intervals(transcription: RadauCollocation, model: AttitudeModel, nlp: NLP, w: Array, lbx: Array,
                     ubx: Array, bound_tolerance: float = 1e-6) -> NDArray[np.bool_]:
    """The mesh intervals of a collocation solution where a bang-bang control switches.

    An interval holds a switch where one of its controls, at its Radau points, is between its
    bounds at one point (by more than ``bound_tolerance`` times ``1 + |bound|``) or at different
    bounds at two: its control polynomial is then no constant at a bound. A switch at a node (the
    intervals on either side at their own bounds) is in neither.

    Parameters
    ----------
    transcription, model, nlp, w
        As in :func:`radau_points`.
    lbx, ubx : (n_w,) ndarray
        The decision vector's bounds (the controls' bounds are read there).
    bound_tolerance : float
        A control within this times ``(1 + |bound|)`` of a bound is at it.

    Returns
    -------
    (N,) ndarray of bool
        Per interval, whether it holds a switch.
    """
    N, d, nx, nu = transcription.intervals, transcription.degree, model.nx, model.nu
    nz = nlp.n_stage_state + nlp.n_interval
    offset = nlp.n_stage_state + nx * d

    def controls(vector: Array) -> Array:
        return np.asarray(vector, dtype=float)[:nz * N].reshape(N, nz)[:, offset:offset + nu * d].reshape(N, d, nu)

    u, low, high = controls(w), controls(lbx), controls(ubx)
    at_low = u - low <= bound_tolerance * (1.0 + np.abs(low))
    at_high = high - u <= bound_tolerance * (1.0 + np.abs(high))
    between = ~at_low & ~at_high
    mixed = np.any(at_low, axis=1) & np.any(at_high, axis=1)
    return np.any(np.any(between, axis=1) | mixed, axis=1)


def _flight(model: AttitudeModel, arcs: int, fixed_rate: bool, steps: int) -> tuple[list[ca.MX], ca.MX]:
    """``([x0, z, U, d, xf], r)``: the symbols and the final miss ``r`` of the bang-bang control
    ``U (nu, arcs)`` from ``x0`` with the switch times and final time ``z = (t_1 … t_{arcs−1}, T)``
    [s] (RK4, ``steps`` steps per arc, disturbance ``d`` [N m]): the vector part of
    ``conj(q_f) ⊗ q(T)`` and, with ``fixed_rate``, ``ω(T) − ω_f`` [rad/s] (``xf = [q_f, ω_f]``)."""
    xt, u, h, d = ca.SX.sym("xt", model.nx + 1), ca.SX.sym("u", model.nu), ca.SX.sym("h"), ca.SX.sym("d", 3)
    x, t = xt[:-1], xt[-1]
    after = rk4_step(lambda state, time: model.rhs(state, u, time, d), x, t, h)
    step = ca.Function("rk4", [xt, u, h, d], [ca.vertcat(after, t + h)])
    arc = step.fold(steps)  # an MX graph of folds: built in milliseconds, unlike its SX expansion
    x0, z, U = ca.MX.sym("x0", model.nx), ca.MX.sym("z", arcs), ca.MX.sym("U", model.nu, arcs)
    disturbance, xf = ca.MX.sym("d", 3), ca.MX.sym("xf", model.nx)
    state, start = ca.vertcat(x0, 0), ca.MX(0)
    for k in range(arcs):
        state = arc(state, ca.repmat(U[:, k], 1, steps), ca.repmat((z[k] - start) / steps, 1, steps),
                    ca.repmat(disturbance, 1, steps))
        start = z[k]
    xs, xfs, miss = _final_miss(model, fixed_rate)
    return [x0, z, U, disturbance, xf], ca.Function("miss", [xs, xfs], [miss])(state[:model.nx], xf)


def _evaluate(function: ca.Function, *args: Array | float) -> list[Array]:
    """Every output of ``function``, whose inputs and outputs are all dense, for the given inputs:
    :func:`ocp.fast_call.matrices` (through its buffers, 2-D arrays of their own in C order)
    without its checks of the sparsities (the shooting's functions are built dense)."""
    outputs = buffered(function).all_outputs(*(np.ravel(arg, order="F") for arg in args))
    return [np.array(flat.reshape(function.size_out(i), order="F"), order="C") for i, flat in enumerate(outputs)]


def _listed(flight: tuple[list[ca.MX], ca.MX]) -> tuple[list[ca.MX], list[ca.MX]]:
    """:func:`_flight`'s inputs and its miss (dense) as the output list of a ``casadi.Function``."""
    return flight[0], [ca.densify(flight[1])]


def _tangent_step(model: AttitudeModel, directions: int) -> ca.Function:
    """``([xt, Ẋ], u, h, d, ḣ) -> [xt⁺, Ẋ⁺]``: one RK4 step of :func:`_flight` (``xt = [x, t]``)
    and its forward derivative in ``directions`` directions ``Ẋ (nx + 1, directions)`` of the state
    and time and ``ḣ (1, directions)`` of the step; ``u`` and ``d``, which no switch time moves,
    without seeds (CasADi's forward mode through :func:`_flight` carries their zeros)."""
    nx = model.nx
    xt, u, h, d = ca.SX.sym("xt", nx + 1), ca.SX.sym("u", model.nu), ca.SX.sym("h"), ca.SX.sym("d", 3)
    x, t = xt[:-1], xt[-1]
    after = ca.vertcat(rk4_step(lambda state, time: model.rhs(state, u, time, d), x, t, h), t + h)
    tangent, h_dot = ca.SX.sym("tangent", nx + 1, directions), ca.SX.sym("h_dot", 1, directions)
    return ca.Function("rk4_tangent", [ca.horzcat(xt, tangent), u, h, d, h_dot],
                       [ca.horzcat(after, ca.jtimes(after, ca.vertcat(xt, h), ca.vertcat(tangent, h_dot)))])


def _shooting(model: AttitudeModel, arcs: int, fixed_rate: bool, steps: int = SHOOTING_STEPS) -> ca.Function:
    """``(x0, z, U, d, xf) -> (r, ∂r/∂z)``: the final miss ``r`` of :func:`_flight` (``steps`` RK4
    steps per arc) and its Jacobian. With more ``arcs`` than conditions, ``(x0, z, U, d, xf, λ) ->
    (r, ∂r/∂z, ∇²_z λᵀ r)``.

    As many arcs as conditions or fewer: the Jacobian by forward sensitivities carried along the
    RK4 steps (:func:`_tangent_step`), on arc ``k`` in the directions of ``z_0 … z_k`` alone (the
    later switches do not move it), each step's nominal and derivative in one call: the same
    arithmetic as CasADi's Jacobian of :func:`_flight` (its forward mode, bit for bit:
    ``tests/test_bang_bang_shooting.py``) without the work on zero seeds, 0.6x its time (0.3x
    on the full inertia)."""
    conditions = 6 if fixed_rate else 3
    if arcs <= conditions:
        nx = model.nx
        x0, z, U = ca.MX.sym("x0", nx), ca.MX.sym("z", arcs), ca.MX.sym("U", model.nu, arcs)
        disturbance, xf = ca.MX.sym("d", 3), ca.MX.sym("xf", nx)
        state, tangent, start = ca.vertcat(x0, 0), ca.MX(nx + 1, 0), ca.MX(0)
        for k in range(arcs):
            step = model.solver_cache.get(("bang-bang rk4 tangent", k + 1), lambda: _tangent_step(model, k + 1))
            h_dot = np.zeros((1, k + 1))  # of h_k = (z_k − z_{k−1}) / steps in the directions z_0 … z_k
            h_dot[0, k] = 1.0 / steps
            if k:
                h_dot[0, k - 1] = -1.0 / steps
            ends = step.fold(steps)(ca.horzcat(state, tangent, ca.MX(nx + 1, 1)), ca.repmat(U[:, k], 1, steps),
                                    ca.repmat((z[k] - start) / steps, 1, steps), ca.repmat(disturbance, 1, steps),
                                    ca.repmat(ca.DM(h_dot), 1, steps))
            state, tangent, start = ends[:, 0], ends[:, 1:], z[k]
        xs, xfs, miss = _final_miss(model, fixed_rate)
        tangents = ca.SX.sym("tangents", nx, arcs)
        final = ca.Function("miss_tangent", [xs, xfs, tangents], [miss, ca.jtimes(miss, xs, tangents)])
        r, jacobian = final(state[:nx], xf, tangent[:nx, :])
        return ca.Function("shooting", [x0, z, U, disturbance, xf], [ca.densify(r), ca.densify(jacobian)])
    inputs, r = _flight(model, arcs, fixed_rate, steps)
    z = inputs[1]
    # more switch times than conditions: T is minimised on them, Newton's method on the KKT
    # conditions, whose Hessian of ``λᵀ r`` this gives too
    multiplier = ca.MX.sym("lambda", r.numel())
    return ca.Function("shooting", [*inputs, multiplier],
                       [ca.densify(m) for m in (r, ca.jacobian(r, z), ca.hessian(ca.dot(multiplier, r), z)[0])])


def _rk4_error(model: AttitudeModel, x0: Array, z: Array, U: Array, disturbance: Array, xf: Array, fixed_rate: bool,
               steps: int, r: Array) -> Array:
    """The error ``e`` of the final miss ``r`` of :func:`_flight` with ``steps`` RK4 steps per arc,
    ``r`` minus that of the same switches flown exactly, by step doubling: RK4's error falls as
    the fourth power of the step, so ``r − r_2S = e (1 − 1/16)`` (``r_2S`` with ``2 steps``, the
    final miss alone)."""
    arcs = len(z)
    flown = _mapped(model, f"switch miss dense {arcs} {fixed_rate} {2 * steps}", 1,
                    lambda: ca.Function("miss", *_listed(_flight(model, arcs, fixed_rate, 2 * steps))))
    finer = _evaluate(flown, x0, z, U, disturbance, xf)[0].ravel()
    return 16.0 / 15.0 * (np.asarray(r, dtype=float).ravel() - finer)


def _newton_step(matrix: Array, rhs: Array, row: int, error: Array) -> Array:
    """The step in ``z`` of the Newton system ``matrix δ = rhs`` of :func:`time_error` (or
    :func:`bang_bang_certificate`) with the RK4 steps' error ``error`` of the final miss, whose
    rows start at ``row``, taken off the miss: from the shooting's optimum to that of the same
    switches flown exactly."""
    shifted = np.array(rhs, dtype=float)
    shifted[row:row + len(error)] += error
    return np.linalg.lstsq(matrix, shifted, rcond=None)[0][:matrix.shape[1] if row == 0 else row]


def _switch_times(t: Array, sigma: Array, low: Array, high: Array) -> tuple[Array, NDArray[np.int_], Array]:
    """The roots of the switching functions ``sigma`` (points, controls) at the times ``t`` [s]:
    linear between consecutive points of opposite signs; a run of exact zeros between a positive
    and a negative value is one root, at the run's middle (between two values of one sign, a touch:
    none). Returns the switch times in time order, the control each switches and the first arc's
    controls (``low`` where the first nonzero σ is positive: the control minimises ``σ u``)."""
    times, owners = [], []
    first = np.where(sigma[0] > 0, low, high)
    for control in range(sigma.shape[1]):
        values = sigma[:, control]
        nonzero = np.flatnonzero(values)
        if nonzero.size and values[0] == 0:  # σ is 0 at the start: the first nonzero value decides
            first[control] = low[control] if values[nonzero[0]] > 0 else high[control]
        a, b = nonzero[:-1], nonzero[1:]  # consecutive nonzero values
        changes = ~(values[a] * values[b] > 0)  # of opposite signs (or NaN)
        a, b = a[changes], b[changes]
        with np.errstate(divide="ignore", invalid="ignore"):
            linear = t[a] + (t[b] - t[a]) * values[a] / (values[a] - values[b])
        # exact zeros in between: the run's middle
        times.append(np.where(b == a + 1, linear, 0.5 * (t[a + 1] + t[b - 1])))
        owners.append(np.full(a.size, control))
    switches = np.concatenate(times)
    order = np.argsort(switches, kind="stable")
    return switches[order], np.concatenate(owners)[order], first


def time_error(transcription: RadauCollocation, model: AttitudeModel, nlp: NLP, w: Array, lbx: Array, ubx: Array,
               params: Array, fixed_rate: bool, functions: tuple[Array, Array, Array]) -> dict[str, Any]:
    """The discretisation error of a bang-bang minimum time: ``T_N`` minus the final time of the
    exact bang-bang trajectory with the solution's switches (see the module docstring).

    Parameters
    ----------
    transcription, model, nlp, w
        As in :func:`radau_points` (a free final time; a rigid body, ``nx`` 7, or with reaction wheels,
        their momenta the states after the rate, free at the end).
    lbx, ubx : (n_w,) ndarray
        The decision vector's bounds (the controls' bounds are read there).
    params : ndarray
        The NLP's parameters: the initial state, final attitude and rate first (the boundary
        conditions), the disturbance torque [N m] at their end.
    fixed_rate : bool
        The final body rate is fixed (a condition of the shooting) or free.
    functions : tuple of ndarray
        :func:`switching_functions` of the solution (the switch times are their roots).

    Returns
    -------
    dict
        ``estimate_s`` (``T_N − T`` [s]), ``shooting_T_s`` (its ``T``: the exact flight's, the RK4
        steps' error taken off), ``switches``, ``miss`` (the final attitude and rate miss of the RK4
        shooting at its optimum), ``stationarity`` (of ``T``'s minimisation; 0 without),
        ``switch_times_s`` (in time order, the exact flight's), ``controls`` (per arc), ``coinciding``
        (tied pairs of switches), ``iterations`` (shooting calls), ``steps_per_arc`` (RK4),
        ``rk4_correction_s`` (``T`` minus the RK4 optimum's [s]) and ``rk4_error`` (the steps' error
        of the final miss there, by step doubling); or ``skipped`` saying why not (controls' bounds
        that vary, a control held at one value, a wheel's momentum at its bound, more switches than
        :data:`SHOOTING_MAX_SWITCHES`, no convergence, switches that change order).
    """
    N, d, nx, nu = transcription.intervals, transcription.degree, model.nx, model.nu
    t, _, sigma = functions
    nz = nlp.n_stage_state + nlp.n_interval
    offset = nlp.n_stage_state + nx * d
    bounds = [np.asarray(b, dtype=float)[:nz * N].reshape(N, nz)[:, offset:offset + nu * d].reshape(N * d, nu)
              for b in (lbx, ubx)]
    low, high = bounds[0][0], bounds[1][0]
    if not all(np.all(b == b[0]) for b in bounds) or not np.all(np.isfinite(low) & np.isfinite(high)):
        return {"skipped": "control bounds that vary along the slew"}
    if np.any(low == high):  # its switching function's roots are no switches
        return {"skipped": "a control held at one value (a failed wheel)"}
    if nx > 7:  # the wheels' momenta: the shooting knows no bound on them
        states = [np.asarray(b, dtype=float)[:nz * N].reshape(N, nz)[:, nlp.n_stage_state:offset].reshape(N * d, nx)
                  for b in (w, lbx, ubx)]
        if bound_excess(states[0][:, 7:], states[1][0, 7:], states[2][0, 7:]) > -STATE_BOUND_ACTIVE:
            return {"skipped": "a wheel's momentum at its bound (a state constraint active)"}
    T = float(np.asarray(w, dtype=float)[nlp.n_stage_state - 1])
    # the boundary conditions as given (the solution meets them to the solver's tolerance)
    params = np.asarray(params, dtype=float)
    x0, xf = params[:nx], final_conditions(params, nx)
    # the roots of σ, linear between consecutive points, and which control each switches
    times, owner, first = _switch_times(t, sigma, low, high)
    if len(times) > SHOOTING_MAX_SWITCHES:
        return {"skipped": f"{len(times)} switches, more than the shooting takes ({SHOOTING_MAX_SWITCHES})"}
    conditions = 6 if fixed_rate else 3
    z, roots = np.append(times, T), np.append(times, T)
    ident = np.arange(len(times))  # each switch's identity, kept through the removals and sorts
    interval = float(np.max(np.diff(transcription.nodes))) * T  # the longest mesh interval [s]
    disturbance = params[-3:]
    multiplier = np.zeros(conditions)
    # pairs of switches of two controls that T's minimisation makes coincide (Bilimoria & Wie 45°):
    # the order constraint between them active, each with its multiplier (>= 0 at a minimum)
    ties: dict[tuple[int, int], float] = {}
    miss = np.inf
    steps, iteration, at_steps = SHOOTING_STEPS, 0, 0
    # the converged point before the steps doubled: z, its switches, its steps, its correction asymptotic
    coarser: tuple[Array, list[int], int, bool] | None = None
    while at_steps < SHOOTING_ITERATIONS:
        iteration, at_steps = iteration + 1, at_steps + 1
        # a switch that Newton's step moved out of the slew is none (a σ root by a node, an arc the
        # mesh made up): the control starts or ends at its other bound
        out = (z[:-1] <= 0) | (z[:-1] >= z[-1])
        for control in owner[z[:-1] <= 0]:
            first[control] = low[control] + high[control] - first[control]
        z, owner, roots = np.append(z[:-1][~out], z[-1]), owner[~out], np.append(roots[:-1][~out], roots[-1])
        ident = ident[~out]
        # the arcs in time order: each switch flips its control between its bounds
        order = np.argsort(z[:-1], kind="stable")
        z[:-1], owner, roots[:-1], ident = z[:-1][order], owner[order], roots[:-1][order], ident[order]
        arcs = len(z)
        position = {int(i): k for k, i in enumerate(ident)}
        ties = {pair: mu for pair, mu in ties.items() if pair[0] in position and pair[1] in position}
        tie_rows = np.zeros((len(ties), arcs))
        for row, (earlier, later) in enumerate(ties):  # z_earlier − z_later <= 0, active
            tie_rows[row, position[earlier]], tie_rows[row, position[later]] = 1.0, -1.0
        mu = np.array(list(ties.values()), dtype=float)
        U = np.repeat(first[:, None], arcs, axis=1)
        for arc, control in enumerate(owner, start=1):
            U[control, arc:] = low[control] + high[control] - U[control, arc - 1]
        shooting = _mapped(model, f"switch shooting dense {arcs} {fixed_rate} {steps}", 1,
                           lambda: _shooting(model, arcs, fixed_rate, steps))
        stationary = 0.0
        outputs = (_evaluate(shooting, x0, z, U, disturbance, xf) if arcs <= conditions else
                   _evaluate(shooting, x0, z, U, disturbance, xf, multiplier))
        if not all(np.all(np.isfinite(m)) for m in outputs):  # an arc far too long: the RK4 steps diverged
            return {"skipped": f"the shooting is not finite ({arcs - 1} switches)"}
        if arcs <= conditions:
            r, J = outputs
            matrix, rhs = J, -r.ravel()
        else:
            r, J, H = outputs
            gradient = np.zeros(arcs)
            gradient[-1] = 1.0  # of T
            residual = gradient + J.T @ multiplier + tie_rows.T @ mu
            stationary = float(np.max(np.abs(residual)))
            constraints = np.vstack([J, tie_rows])
            matrix = np.block([[H, constraints.T], [constraints, np.zeros((len(constraints), len(constraints)))]])
            rhs = -np.concatenate([residual, r.ravel(), tie_rows @ z])
        miss = float(np.max(np.abs(r)))
        if miss < SHOOTING_TOLERANCE and stationary < SHOOTING_TOLERANCE and np.all(mu >= 0):
            # converged at the point evaluated (its switches in order): the RK4 steps' error of its
            # miss by step doubling, and the Newton step to the same switches flown exactly
            error = _rk4_error(model, x0, z, U, disturbance, xf, fixed_rate, steps, r)
            exact = z + _newton_step(matrix, rhs, arcs if arcs > conditions else 0, error)
            if arcs > conditions and steps < SHOOTING_MAX_STEPS:
                # More switches than conditions: the stationarity rows carry the RK4 Jacobian's own
                # error, along the feasible curve where T is flat (a reviewer's 6-switch slews kept
                # switches 2e-7 of T off with the miss's error taken off alone). Converged again with
                # twice the steps, the whole point is extrapolated (Richardson, h⁴: 1/15 of the change),
                # and again with twice those while that moves T by more than SHOOTING_RICHARDSON.
                # (from a pair of step counts where the fewer's own correction of T, by the miss's
                # error, is within SHOOTING_RICHARDSON: RK4's asymptotic error)
                asymptotic = abs(exact[-1] - z[-1]) <= SHOOTING_RICHARDSON * z[-1]
                if not (coarser is not None and coarser[3] and coarser[1] == [int(i) for i in ident]
                        and steps == 2 * coarser[2]):
                    coarser = (z.copy(), [int(i) for i in ident], steps, asymptotic)
                    steps, at_steps = 2 * steps, 0
                    continue
                exact = z + (z - coarser[0]) / 15.0
            elif abs(exact[-1] - z[-1]) > SHOOTING_RICHARDSON * z[-1] and steps < SHOOTING_MAX_STEPS:
                # too far from RK4's asymptotic error to extrapolate it: again with twice the steps
                z, steps, at_steps = exact, 2 * steps, 0
                continue
            return {"estimate_s": T - float(exact[-1]), "shooting_T_s": float(exact[-1]), "switches": arcs - 1,
                    "miss": miss, "stationarity": stationary, "switch_times_s": [float(v) for v in exact[:-1]],
                    "controls": U.T.tolist(), "coinciding": len(ties), "iterations": iteration,
                    "steps_per_arc": steps, "rk4_correction_s": float(exact[-1] - z[-1]),
                    "rk4_error": float(np.max(np.abs(error)))}
        try:
            solution = np.linalg.lstsq(matrix, rhs, rcond=None)[0]
        except np.linalg.LinAlgError as error:
            return {"skipped": f"the shooting's Newton step: {error}"}
        step = solution[:arcs]
        if arcs > conditions:
            multiplier = multiplier + solution[arcs:arcs + conditions]
            mu = mu + solution[arcs + conditions:]
            # a tie whose multiplier is negative is released: T falls with the two switches apart
            ties = {pair: float(m) for pair, m in zip(ties, mu) if m >= 0}
        z = z + step
        if not np.all(np.isfinite(z)) or np.max(np.abs(z - roots)) > interval:
            return {"skipped": f"the shooting moves a switch or T by more than a mesh interval ({len(z) - 1} "
                               f"switches): another switching structure"}
        if arcs > conditions:  # two switches of two controls the step crosses: tied, from their middle
            for k in range(arcs - 2):
                pair = (int(ident[k]), int(ident[k + 1]))
                if z[k] > z[k + 1] and owner[k] != owner[k + 1] and pair not in ties:
                    ties[pair] = 0.0
                    z[k] = z[k + 1] = 0.5 * (z[k] + z[k + 1])
    return {"skipped": f"the shooting does not converge ({len(z) - 1} switches; miss {miss:.1e})"}


BANG_BANG_MISS = 1e-8
"""Largest final attitude (quaternion vector part) and rate [rad/s] miss of a trajectory
:func:`bang_bang_certificate` accepts as feasible, flown exactly (its RK4 steps' error taken off:
:func:`_rk4_error`): 1e-13 at :func:`time_error`'s optimum, 1.4e-10 flown by DOP853 on XTE; a switch
time moved by 1e-6 s misses by about 1e-6, and XTE's RK4 optimum (1.6e-6 s below) by 1e-7."""
BANG_BANG_STATIONARITY = 1e-5
"""Largest residual ``‖e_T + Jᵀ ν‖∞`` of the multipliers of :func:`bang_bang_certificate` (with
more switches than final conditions, the least-squares ``ν``): the measure of
:data:`BANG_BANG_HAMILTONIAN` (its ``T`` row is ``H(T)``). About 1e-15 at the converged shootings;
a tie of two switches (Bilimoria & Wie 45°) leaves its order constraint's multiplier there
(3e-8), and a switch moved by 1e-3 s leaves 1e-3."""
BANG_BANG_HAMILTONIAN = 1e-5
"""Largest ``|H(t)| = |1 + pᵀ f|`` along the trajectory (``H`` is already relative: the cost's
multiplier is 1). With the discrete co-state of the RK4 shooting it is 1e-7 on Bilimoria & Wie
and 1e-6 on the full inertia and XTE: the RK4 steps' error (:data:`SHOOTING_STEPS`), ten times
below (more steps where :data:`SHOOTING_RICHARDSON` asks). Above it :func:`bang_bang_certificate`
doubles its steps once (up to :data:`SHOOTING_MAX_STEPS`) before it refuses: a discrete co-state's
own error falls 16-fold, a trajectory's that is no optimum does not (0.1 s the first time a model
needs the finer co-state, 10-30 ms a call)."""
BANG_BANG_ZERO = 1e-5
"""Largest ``|σ_i|`` at a switch of control ``i``, relative to ``max|σ_i|`` over the slew: 3e-7 on
Bilimoria & Wie, 2e-6 on the full inertia and XTE (the RK4 steps' error: the stationarity in the
switch time is exact for the steps, see the docstring). Also the largest ``σ_i`` of the wrong sign
for its arc's control, relative alike, that :func:`bang_bang_certificate` takes for the co-state's
numerical error (0 on the three): above it Pontryagin's minimum condition fails."""
BANG_BANG_SIGN = 1e-3
"""``|σ_i|`` at most this times ``max|σ_i|`` counts as zero in the sign agreement
(:func:`~ocp.nlp.certificate.switching_agreement`'s relative tolerance, the ``switching`` fraction
recorded): samples beside a switch. A wrong sign below it is still refused
(:data:`BANG_BANG_ZERO`)."""
BANG_BANG_STRICT = 1e-2
"""Least strictness margin of a strictly bang-bang control: ``|σ_i(t)| / max|σ_i|`` divided by
``min(1, d(t) / T)`` (``d`` the distance to the nearest switch of control ``i``), over the
samples and the steps' cubics' extrema and, at the switches, ``σ̇_i T / max|σ_i|`` signed (negative
where ``σ_i`` crosses zero against the next arc's control). A simple zero and a clear sign elsewhere
give order 1 (0.3 to 3 on Bilimoria & Wie, the full inertia and XTE); a touch of zero between two
switches or a singular control (the eigenaxis slew's zero torques) gives 0."""
BANG_BANG_CONDITION = 1e8
"""Largest condition number of the shooting's Jacobian ``∂r/∂z`` (as many switch times and ``T``
as conditions or fewer) at which the feasible switch times are an isolated point: 1e1 to 1e3 on
Bilimoria & Wie, the full inertia and XTE."""
BANG_BANG_CURVATURE = 1e-6
"""Least eigenvalue, times ``T``, of the reduced Hessian of ``T + νᵀ r`` on the null space of
``∂r/∂z`` (more switch times than conditions) that counts as positive definite."""
BANG_BANG_SAMPLES = 4
"""Samples of the switching functions inside each RK4 step (cubic Hermite from the steps' ``σ``
and ``σ̇``), besides the steps' ends."""


def _final_miss(model: AttitudeModel, fixed_rate: bool) -> tuple[ca.SX, ca.SX, ca.SX]:
    """``(x, xf, r)``: the final conditions of :func:`_flight` as an expression of the final
    state (the vector part of ``conj(q_f) ⊗ q`` and, with ``fixed_rate``, ``ω − ω_f``)."""
    x, xf = ca.SX.sym("x", model.nx), ca.SX.sym("xf", model.nx)
    q, qf = x[:4], xf[:4]
    vector = qf[0] * q[1:4] - q[0] * qf[1:4] - ca.cross(qf[1:4], q[1:4])
    return x, xf, ca.vertcat(vector, x[4:7] - xf[4:7]) if fixed_rate else vector


def _costate_shooting(model: AttitudeModel, arcs: int, fixed_rate: bool, steps: int = SHOOTING_STEPS,
                      jacobians: bool = True) -> ca.Function:
    """``(x0, z, U, d, xf, E) -> (r, ∂r/∂z, ∂vec(∂r/∂z)/∂z, X, G)``: the shooting of :func:`_shooting`
    (the same RK4 steps, ``steps`` per arc) with its states ``X (nx, N + 1)`` at the steps' ends
    (``N`` = ``arcs steps``) and ``G = ∂r/∂[x_0, …, x_N] (m, nx (N + 1))``, the sensitivity of
    the final miss to a jump ``E`` (zero) of the state after each step: ``νᵀ G`` is the discrete
    co-state (the adjoint of the RK4 steps) of the multipliers ``ν``. Without ``jacobians``,
    ``(x0, z, U, d, xf, E) -> (X, G)`` (``r`` and ``∂r/∂z`` from :func:`_shooting`: the same
    numbers, the zero jumps adding nothing)."""
    nx = model.nx
    xt, u, h, d, e = (ca.SX.sym("xt", nx + 1), ca.SX.sym("u", model.nu), ca.SX.sym("h"), ca.SX.sym("d", 3),
                      ca.SX.sym("e", nx))
    x, t = xt[:-1], xt[-1]
    after = rk4_step(lambda state, time: model.rhs(state, u, time, d), x, t, h)
    step = ca.Function("rk4", [xt, u, h, d, e], [ca.vertcat(after + e, t + h)])
    arc = step.mapaccum(steps)
    S = steps
    x0, z, U = ca.MX.sym("x0", nx), ca.MX.sym("z", arcs), ca.MX.sym("U", model.nu, arcs)
    disturbance, xf, E = ca.MX.sym("d", 3), ca.MX.sym("xf", nx), ca.MX.sym("E", nx, arcs * S)
    state, start, columns = ca.vertcat(x0, 0), ca.MX(0), []
    for k in range(arcs):
        ends = arc(state, ca.repmat(U[:, k], 1, S), ca.repmat((z[k] - start) / S, 1, S), ca.repmat(disturbance, 1, S),
                   E[:, k * S:(k + 1) * S])
        columns.append(ends)
        state, start = ends[:, -1], z[k]
    xs, xfs, miss = _final_miss(model, fixed_rate)
    r = ca.Function("miss", [xs, xfs], [miss])(state[:nx], xf)
    X = ca.horzcat(x0, *[c[:nx, :] for c in columns])
    G = ca.jacobian(r, ca.vertcat(x0, ca.vec(E)))
    outputs = [X, G]
    if jacobians:
        J = ca.jacobian(r, z)
        outputs = [r, J, ca.jacobian(ca.vec(J), z) if arcs > r.numel() else ca.MX(0, 1), X, G]
    # dense (the structural zeros explicit): read through buffers (ocp.fast_call.matrices)
    return ca.Function("costate_shooting", [x0, z, U, disturbance, xf, E], [ca.densify(m) for m in outputs])


def _node_conditions(model: AttitudeModel) -> ca.Function:
    """``(x, p, u, d) -> (H − 1, σ, σ̇)`` at one point: ``pᵀ f``, ``σ = (∂f/∂u)ᵀ p`` and its time
    derivative along ``ẋ = f``, ``ṗ = −(∂f/∂x)ᵀ p``."""
    x, p, u, d = ca.SX.sym("x", model.nx), ca.SX.sym("p", model.nx), ca.SX.sym("u", model.nu), ca.SX.sym("d", 3)
    f = model.rhs(x, u, 0, d)
    sigma = ca.mtimes(ca.jacobian(f, u).T, p)
    pdot = -ca.mtimes(ca.jacobian(f, x).T, p)
    sigma_dot = ca.jtimes(sigma, ca.vertcat(x, p), ca.vertcat(f, pdot))
    return ca.Function("node_conditions", [x, p, u, d], [ca.densify(m) for m in (ca.dot(p, f), sigma, sigma_dot)])


def _sign_test(times: Array, sigma: Array, sigma_dot: Array, U: Array, low: Array, high: Array) -> dict[str, Any]:
    """Pontryagin's sign test of :func:`bang_bang_certificate`: ``σ_i`` against the control on
    each arc, between and at its switches.

    ``σ`` is the cubic Hermite interpolant of its values and rates at the RK4 steps' ends (the
    step's own accuracy): sampled at the ends and :data:`BANG_BANG_SAMPLES` points inside each
    step, and read at each step's cubic's extrema, so that no wrong sign between the samples
    escapes.

    Parameters
    ----------
    times : (arcs, S + 1) ndarray
        The steps' ends per arc [s] (an arc's last is the next one's first: the switch).
    sigma, sigma_dot : (arcs, S + 1, nu) ndarray
        ``σ`` and ``σ̇`` there, each arc's with its own control.
    U : (nu, arcs) ndarray
        The control on each arc.
    low, high : (nu,) ndarray
        The controls' bounds.

    Returns
    -------
    dict
        ``agreement`` (:func:`~ocp.nlp.certificate.switching_agreement` of the samples, ``|σ_i|``
        relative to ``max|σ_i|`` below :data:`BANG_BANG_SIGN` counted as zero), ``wrong_sign``
        (the largest ``σ_i`` of the wrong sign for the arc's control, relative to ``max|σ_i|``,
        over the samples and extrema but at the switches of control ``i``), ``zero`` (the largest
        ``|σ_i| / max|σ_i|`` at them) and ``strictness`` (:data:`BANG_BANG_STRICT`: the least of
        the margins over the samples and extrema and, at the switches, ``σ̇_i T / max|σ_i|``
        signed: negative where ``σ_i`` crosses zero the wrong way).
    """
    arcs, ends, nu = sigma.shape
    S = ends - 1
    T = float(times[-1, -1])
    h = ((times[:, -1] - times[:, 0]) / S)[:, None, None]  # (arcs, 1, 1)
    # inside each step: samples at s in [0, 1) and the cubic's extrema p'(s) = 0 in (0, 1)
    a, b, da, db = sigma[:, :-1], sigma[:, 1:], h * sigma_dot[:, :-1], h * sigma_dot[:, 1:]  # (arcs, S, nu)
    A, B, C = 6 * a + 3 * da - 6 * b + 3 * db, -6 * a - 4 * da + 6 * b - 2 * db, da  # p'(s) = A s² + B s + C
    with np.errstate(divide="ignore", invalid="ignore"):
        root = np.sqrt(B ** 2 - 4 * A * C)
        linear = np.abs(A) <= 1e-12 * (np.abs(B) + np.abs(C))
        extrema = np.stack([np.where(linear, -C / B, (-B - root) / (2 * A)),
                            np.where(linear, np.nan, (-B + root) / (2 * A))], axis=2)  # (arcs, S, 2, nu)
    inside = np.isfinite(extrema) & (extrema > 0) & (extrema < 1)
    extrema = np.where(inside, extrema, 0.0)  # else the step's start, a sample already
    # the cubic at the samples and the extrema at once: (arcs, S, samples + 2, nu)
    fractions = np.arange(BANG_BANG_SAMPLES + 1) / (BANG_BANG_SAMPLES + 1)
    s = np.concatenate([np.broadcast_to(fractions[None, None, :, None], (arcs, S, fractions.size, nu)), extrema],
                       axis=2)
    s2, s3 = s ** 2, s ** 3
    a, b, da, db = a[:, :, None], b[:, :, None], da[:, :, None], db[:, :, None]
    cubic = ((2 * s3 - 3 * s2 + 1) * a + (s3 - 2 * s2 + s) * da + (-2 * s3 + 3 * s2) * b + (s3 - s2) * db)
    samples, extreme_values = cubic[:, :, :fractions.size], cubic[:, :, fractions.size:]
    sample_times = times[:, :-1, None] + h * fractions[None, None, :]  # (arcs, S, samples)
    extreme_times = times[:, :-1, None, None] + h[..., None] * extrema
    # per control: every sample and extremum, its time, the arc's control; the arcs' last ends
    values = np.concatenate([samples.reshape(arcs, -1, nu), extreme_values.reshape(arcs, -1, nu), sigma[:, -1:]],
                            axis=1)
    every_time = np.concatenate([np.repeat(sample_times.reshape(arcs, -1, 1), nu, axis=2),
                                 extreme_times.reshape(arcs, -1, nu), np.repeat(times[:, -1:, None], nu, axis=2)],
                                axis=1)
    regular = samples.shape[1] * samples.shape[2]
    plain = np.concatenate([samples.reshape(arcs, -1, nu), sigma[:, -1:]], axis=1).reshape(-1, nu)
    plain_u = np.repeat(U.T[:, None, :], regular + 1, axis=1).reshape(-1, nu)
    # per control, σ relative to its largest value (a control whose σ is far below the others':
    # relative to a thousandth of the largest)
    largest = np.max(np.abs(values.reshape(-1, nu)), axis=0)
    scale = np.maximum(largest, BANG_BANG_SIGN * float(np.max(largest, initial=0.0)))
    scale = np.where(scale > 0, scale, 1.0)
    agreement = switching_agreement(plain_u, low, high, plain / scale, relative_tolerance=BANG_BANG_SIGN)
    # the sign σ_i has on an arc: positive at the lower bound (the control minimises σ u)
    expected = np.where(np.abs(U - low[:, None]) <= 1e-9 * (1 + np.abs(low[:, None])), 1.0, -1.0)  # (nu, arcs)
    signed = expected.T[:, None, :] * values / scale  # (arcs, points, nu)
    # the switches: which controls each flips, σ_i and σ̇_i there (the two arcs' ends' mean)
    k, i = np.nonzero((U[:, 1:] != U[:, :-1]).T)  # (arc before, control) per flip, in time order
    value = 0.5 * (sigma[k, -1, i] + sigma[k + 1, 0, i])
    rate = 0.5 * (sigma_dot[k, -1, i] + sigma_dot[k + 1, 0, i])
    # (Python's max and min over the flips in order, as a loop would take them: the first of equal values)
    zero = max([0.0, *(np.abs(value) / scale[i])])
    slope = min([np.inf, *(expected[i, k + 1] * rate * T / scale[i])])  # rising into the next arc's sign
    # per sample and control, the distance to the nearest switch of that control
    switch_times = np.where(i[:, None] == np.arange(nu)[None, :], times[k, -1][:, None], np.inf)  # (flips, nu)
    distance = np.min(np.abs(every_time[..., None, :] - switch_times), axis=2, initial=np.inf)  # (arcs, points, nu)
    away = distance > 1e-9 * T
    wrong = float(max([0.0, *np.max(np.where(away, -signed, 0.0), axis=(0, 1), initial=0.0)]))  # per control first
    with np.errstate(divide="ignore", invalid="ignore"):
        relative = np.abs(values) / largest / np.minimum(1.0, distance / T)  # to its own largest
    margins = np.min(np.where(away, relative, np.inf), axis=(0, 1))
    margins = np.where(largest == 0.0, 0.0, margins)
    return {"agreement": agreement, "wrong_sign": wrong, "zero": zero,
            "strictness": float(min(slope, float(np.min(margins, initial=np.inf))))}


def bang_bang_certificate(model: AttitudeModel, x0: Array, xf: Array, disturbance: Array, switch_times: Array,
                          controls: Array, T: float, low: Array, high: Array, fixed_rate: bool, *,
                          seeds: int | None = None, seeds_agreed: int | None = None) -> dict[str, Any]:
    """The certificate of a bang-bang minimum-time trajectory found by switch-time shooting:
    Pontryagin's minimum principle along its co-state and the second order of the problem in its
    switch times (see the module docstring).

    Parameters
    ----------
    model : AttitudeModel
        A rigid body (quaternion scalar first, body rate [rad/s]), with torquers or reaction wheels
        (their momenta [N m s] the states after the rate, ``nx`` 7 + wheels).
    x0 : (nx,) ndarray
        The initial state.
    xf : (nx,) ndarray
        The final attitude and rate ``[q_f, ω_f]`` first (the rate only with ``fixed_rate``); the
        wheel momenta are free at the end (their entries are not read).
    disturbance : (3,) ndarray
        Constant disturbance torque [N m], body frame.
    switch_times : (arcs − 1,) ndarray
        The switch times [s], in order.
    controls : (arcs, nu) ndarray
        The control on each arc.
    T : float
        The final time [s].
    low, high : (nu,) ndarray
        The controls' bounds.
    fixed_rate : bool
        The final rate is fixed (6 final conditions) or free (3).
    seeds, seeds_agreed : int or None
        Starts tried and agreeing (shown in the summary).

    Returns
    -------
    dict
        The keys of :func:`ocp.nlp.certificate.certificate` (``kkt_scaled`` and ``kkt_unscaled``
        the largest first-order residual: final miss, stationarity in ``z``, ``|H|``), ``method``
        ``"switch-time shooting"`` and ``pontryagin``, the checks: ``miss`` (of the switches flown
        exactly: the RK4 steps' error taken off), ``stationarity``, ``steps_per_arc`` (RK4, as
        :data:`SHOOTING_RICHARDSON` chooses them), ``rk4_error`` (the steps' error of the final
        miss, by step doubling), ``rk4_time_error_s`` (the error it makes in ``T`` at the steps'
        optimum [s]), ``hamiltonian`` (max ``|H|``), ``switching`` (agreement), ``wrong`` (fraction
        of samples on the wrong side by more than :data:`BANG_BANG_SIGN`), ``zero_at_switches``
        (max ``|σ_i| / max|σ_i|`` at them), ``wrong_sign`` (the largest ``σ_i`` of the wrong sign,
        relative alike, over the samples and the steps' cubics' extrema), ``strictness`` (least
        margin), ``bang_bang`` (all controls at a bound), ``simple_switches`` (one control
        per switch), ``switches``, ``condition`` (of ``∂r/∂z``, as many unknowns as conditions or
        fewer) or ``curvature`` (least reduced-Hessian eigenvalue times ``T``, more), ``first_order``,
        ``strict``, ``second_order`` (bools).
    """
    x0, xf = np.asarray(x0, dtype=float).ravel(), np.asarray(xf, dtype=float).ravel()
    disturbance = np.asarray(disturbance, dtype=float).ravel()
    U = np.atleast_2d(np.asarray(controls, dtype=float)).T  # (nu, arcs)
    low, high = np.asarray(low, dtype=float).ravel(), np.asarray(high, dtype=float).ravel()
    nx, nu, arcs = model.nx, model.nu, U.shape[1]
    z = np.append(np.asarray(switch_times, dtype=float).ravel(), float(T))
    conditions = 6 if fixed_rate else 3
    gradient = np.zeros(arcs)
    gradient[-1] = 1.0
    S, finer = SHOOTING_STEPS, False
    while True:  # the RK4 steps per arc as time_error chooses them (SHOOTING_RICHARDSON), or more for H
        if arcs <= conditions:  # r and ∂r/∂z by the shooting's sensitivities (time_error's, kept), X and G alone here
            shooting = _mapped(model, f"switch shooting dense {arcs} {fixed_rate} {S}", 1,
                               lambda: _shooting(model, arcs, fixed_rate, S))
            r, J = _evaluate(shooting, x0, z, U, disturbance, xf)
            function = model.solver_cache.get(("bang-bang co-state", arcs, fixed_rate, S),
                                              lambda: _costate_shooting(model, arcs, fixed_rate, S, jacobians=False))
            X, G = _evaluate(function, x0, z, U, disturbance, xf, np.zeros((nx, arcs * S)))
            curvature = np.zeros((0, 1))
        else:
            function = model.solver_cache.get(("bang-bang certificate dense", arcs, fixed_rate, S),
                                              lambda: _costate_shooting(model, arcs, fixed_rate, S))
            r, J, curvature, X, G = _evaluate(function, x0, z, U, disturbance, xf, np.zeros((nx, arcs * S)))
        r = r.ravel()
        # the multipliers: e_T + Jᵀ ν = 0 (solved, or in the least-squares sense)
        nu_ = np.linalg.lstsq(J.T, -gradient, rcond=None)[0]
        hessian = np.einsum("i,ijk->jk", nu_, curvature.reshape(arcs, conditions, arcs).transpose(1, 0, 2)) \
            if arcs > conditions else np.zeros((arcs, arcs))
        hessian = 0.5 * (hessian + hessian.T)
        # the RK4 steps' error of the miss, and of T: the Newton step it makes at the steps' optimum
        error = _rk4_error(model, x0, z, U, disturbance, xf, fixed_rate, S, r)
        matrix = J if arcs <= conditions else np.block([[hessian, J.T], [J, np.zeros((conditions, conditions))]])
        row = arcs if arcs > conditions else 0
        time_error_ = abs(float(_newton_step(matrix, np.zeros(len(matrix)), row, error)[-1]))
        if time_error_ > SHOOTING_RICHARDSON * float(T) and S < SHOOTING_MAX_STEPS:
            S *= 2
            continue
        # the co-state at the steps' ends, and H, σ, σ̇ there per arc (an arc's two ends with its control)
        P = (nu_ @ G).reshape(-1, nx).T  # (nx, N + 1)
        ends = np.arange(arcs)[:, None] * S + np.arange(S + 1)[None, :]  # (arcs, S + 1) step ends per arc
        points = ends.size
        node = _mapped(model, "bang-bang node conditions dense", points, lambda: _node_conditions(model))
        pf, sigma, sigma_dot = _evaluate(node, X[:, ends.ravel()], P[:, ends.ravel()], np.repeat(U, S + 1, axis=1),
                                        np.tile(disturbance, (points, 1)).T)
        hamiltonian = float(np.max(np.abs(1.0 + pf)))
        if hamiltonian <= BANG_BANG_HAMILTONIAN or S >= SHOOTING_MAX_STEPS or finer:
            break
        S, finer = 2 * S, True  # H above its tolerance: once more with twice the steps (their error / 16)
    stationarity = float(np.max(np.abs(gradient + J.T @ nu_)))
    singular_values = np.linalg.svd(J, compute_uv=False)
    # the miss of the switches flown exactly (the RK4 steps' error taken off)
    checks: dict[str, Any] = {"miss": float(np.max(np.abs(r - error))), "stationarity": stationarity,
                              "steps_per_arc": S, "rk4_error": float(np.max(np.abs(error))),
                              "rk4_time_error_s": time_error_}
    if arcs <= conditions:
        condition = float(singular_values[0] / singular_values[-1]) if singular_values[-1] > 0 else np.inf
        checks["condition"] = condition
        second = bool(condition <= BANG_BANG_CONDITION)
    else:  # the reduced Hessian of T + νᵀ r on the null space of J
        _, _, vt = np.linalg.svd(J)
        Z = vt[conditions:].T
        least = float(np.min(np.linalg.eigvalsh(Z.T @ hessian @ Z))) * float(T)
        checks["curvature"] = least
        second = bool(least > BANG_BANG_CURVATURE)
    starts = np.concatenate([[0.0], z[:-1]])
    times = starts[:, None] + (z - starts)[:, None] * np.arange(S + 1)[None, :] / S  # (arcs, S + 1)
    sigma, sigma_dot = sigma.T.reshape(arcs, S + 1, nu), sigma_dot.T.reshape(arcs, S + 1, nu)
    sign = _sign_test(times, sigma, sigma_dot, U, low, high)
    agreement, zero, wrong_sign, strictness = sign["agreement"], sign["zero"], sign["wrong_sign"], sign["strictness"]
    flips = U[:, 1:] != U[:, :-1]  # (nu, arcs − 1)
    bound = np.all((np.abs(U - low[:, None]) <= 1e-9 * (1 + np.abs(low[:, None])))
                   | (np.abs(U - high[:, None]) <= 1e-9 * (1 + np.abs(high[:, None]))))
    simple = bool(np.all(flips.sum(axis=0) == 1) and np.all(np.diff(z) > 1e-9 * float(T)) and z[0] > 0)
    first = bool(checks["miss"] <= BANG_BANG_MISS and stationarity <= BANG_BANG_STATIONARITY
                 and hamiltonian <= BANG_BANG_HAMILTONIAN and zero <= BANG_BANG_ZERO and agreement.wrong == 0.0
                 and wrong_sign <= BANG_BANG_ZERO and agreement.interior_large == 0.0)
    strict = bool(bound and simple and strictness >= BANG_BANG_STRICT)
    checks.update({"hamiltonian": hamiltonian, "switching": agreement.agreement, "wrong": agreement.wrong,
                   "zero_at_switches": zero, "wrong_sign": wrong_sign, "strictness": strictness,
                   "bang_bang": bool(bound),
                   "simple_switches": simple, "switches": arcs - 1, "first_order": first, "strict": strict,
                   "second_order": second})
    verdict = ("certified" if first and strict and second else "first-order" if first else "not certified")
    residual = max(checks["miss"], stationarity, hamiltonian)
    if first and strict and second:
        text = "strict strong local minimum: strictly bang-bang, the induced problem's SOSC"
    elif not second:
        text = "not certified: the induced problem's second order fails"
    elif not strict:
        text = "not certified: not strictly bang-bang"
    else:
        text = "not checked: Pontryagin's necessary conditions fail"
    record = {"kkt_scaled": residual, "kkt_unscaled": residual, "second_order": text,
              "switching": agreement.agreement, "costate_gap": None, "seeds": seeds, "seeds_agreed": seeds_agreed,
              "verdict": verdict, "method": "switch-time shooting", "summary": "", "kkt": None,
              "switching_detail": asdict(agreement), "pontryagin": checks}
    record["summary"] = summary_line(record)
    return record
