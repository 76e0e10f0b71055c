"""Indirect optimal control: the states and co-states of Pontryagin's principle as a two-point
boundary-value problem (Vepa, sections 3 and 6), solved with ``scipy.integrate.solve_bvp``.

Implemented form, ``objective: min_energy``: minimise ``½∫‖u‖² dt`` with
``I ω̇ = −ω × I ω + u + τ_gg(q, t)`` and ``q̇ = ½ Ω(ω) q``. Then ``u = −I⁻¹ λ_ω`` and, with
``Ξ(q)`` from ``q̇ = ½ Ξ(q) ω``,

    λ̇_q = −½ Ω(ω)ᵀ λ_q − (∂τ_gg/∂q)ᵀ I⁻¹ λ_ω
    λ̇_ω = −½ Ξ(q)ᵀ λ_q + ([ω×] I − [(I ω)×])ᵀ I⁻¹ λ_ω

(written out here; the gravity-gradient Jacobian comes from CasADi; a test checks the whole right
side against ``−∂H/∂x`` by automatic differentiation). Boundary conditions: ``x(0)`` fixed;
``vec(q_f* ⊗ q(T)) = 0`` and ``λ_q(T)·q(T) = 0`` (the scaling symmetry of the quaternion makes a
fourth attitude condition redundant; this fixes the gauge instead); ``ω(T) = ω_f``, or
``λ_ω(T) = 0`` when the final rate is free. Torque bounds are not imposed (unconstrained form).
A cold start uses the eigenaxis slew, and continuation walks the target from ``q0`` to ``q_f``
along the slerp, each solve seeding the next.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import casadi as ca
import numpy as np
from scipy.integrate import solve_bvp

from ocp import quat
from planners.base import (Array, FailedReference, ManeuverProblem, Planner, Reference, ReferenceSample)


def omega_matrix(omega):
    """``Ω(ω)`` with ``q̇ = ½ Ω(ω) q`` (scalar first, ω in body axes)."""
    w1, w2, w3 = omega[0], omega[1], omega[2]
    return ca.vertcat(ca.horzcat(0, -w1, -w2, -w3), ca.horzcat(w1, 0, w3, -w2),
                      ca.horzcat(w2, -w3, 0, w1), ca.horzcat(w3, w2, -w1, 0))


def xi_matrix(q):
    """``Ξ(q)`` with ``q̇ = ½ Ξ(q) ω``."""
    q0, q1, q2, q3 = q[0], q[1], q[2], q[3]
    return ca.vertcat(ca.horzcat(-q1, -q2, -q3), ca.horzcat(q0, -q3, q2),
                      ca.horzcat(q3, q0, -q1), ca.horzcat(-q2, q1, q0))


def skew(v):
    return ca.vertcat(ca.horzcat(0, -v[2], v[1]), ca.horzcat(v[2], 0, -v[0]), ca.horzcat(-v[1], v[0], 0))


class MinimumEnergySystem:
    """The Hamiltonian system of the minimum-energy problem for one spacecraft and environment."""

    def __init__(self, problem: ManeuverProblem):
        model = problem.model
        inertia = ca.DM(problem.spacecraft.inertia)
        inverse = ca.DM(np.linalg.inv(problem.spacecraft.inertia))
        t, x, lam = ca.SX.sym("t"), ca.SX.sym("x", 7), ca.SX.sym("lam", 7)
        q, omega, lam_q, lam_w = x[0:4], x[4:7], lam[0:4], lam[4:7]
        state = ca.vertcat(x, ca.SX.zeros(model.n_wheels))
        gravity = model.external_torque(state, t, ca.DM(model.default_parameters))
        u = -ca.mtimes(inverse, lam_w)
        q_dot = 0.5 * ca.mtimes(omega_matrix(omega), q)
        momentum = ca.mtimes(inertia, omega)
        omega_dot = ca.mtimes(inverse, -ca.cross(omega, momentum) + u + gravity)
        gyro_jacobian = ca.mtimes(skew(omega), inertia) - skew(momentum)  # ∂(ω × I ω)/∂ω
        lam_q_dot = -0.5 * ca.mtimes(omega_matrix(omega).T, lam_q) \
            - ca.mtimes(ca.jacobian(gravity, q).T, ca.mtimes(inverse, lam_w))
        lam_w_dot = -0.5 * ca.mtimes(xi_matrix(q).T, lam_q) + ca.mtimes(gyro_jacobian.T, ca.mtimes(inverse, lam_w))
        y = ca.vertcat(x, lam)
        rhs = ca.vertcat(q_dot, omega_dot, lam_q_dot, lam_w_dot)
        hamiltonian = 0.5 * ca.sumsqr(u) + ca.dot(lam_q, q_dot) + ca.dot(lam_w, omega_dot)
        self.rhs = ca.Function("hamiltonian_rhs", [t, y], [rhs])
        self.rhs_jacobian = ca.Function("hamiltonian_jac", [t, y], [ca.jacobian(rhs, y)])
        self.hamiltonian = ca.Function("hamiltonian", [t, y], [hamiltonian])
        self.control = ca.Function("control", [y], [u])
        self.gravity = ca.Function("gravity", [t, y], [gravity])
        self._mapped: dict[int, tuple[ca.Function, ca.Function]] = {}

    def vectorised(self, t: Array, y: Array) -> tuple[Array, Array]:
        """Right side (14, m) and its Jacobian (14, 14, m) at the columns of ``y``."""
        m = t.size
        if m not in self._mapped:
            self._mapped[m] = (self.rhs.map(m), self.rhs_jacobian.map(m))
        rhs, jac = self._mapped[m]
        jacobian = jac(t, y).full().reshape(14, m, 14).transpose(0, 2, 1)
        return rhs(t, y).full(), jacobian


class CostateReference(Reference):
    """States from ``solve_bvp``'s C¹ cubic interpolant; torque ``u + τ_gg`` from the co-states."""

    def __init__(self, system: MinimumEnergySystem, solution, duration: float, inertia: Array, message: str,
                 stats: dict):
        super().__init__("costate_tpbvp", duration, inertia, message=message, stats=stats)
        self.system, self.solution = system, solution

    def _evaluate(self, t: Array) -> ReferenceSample:
        y = self.solution.sol(t)
        rhs, _ = self.system.vectorised(t, y)
        control = self.system.control.map(t.size)(y).full()
        gravity = self.system.gravity.map(t.size)(t, y).full()
        return ReferenceSample(quat.normalize(y[0:4].T), y[4:7].T, rhs[4:7].T, (control + gravity).T)


class CostateTPBVPPlanner(Planner):
    """Indirect (co-state) planner; see the module docstring."""

    name = "costate_tpbvp"

    @dataclass(frozen=True)
    class Options:
        objective: Literal["min_energy"] = "min_energy"
        continuation_steps: int = 3          # targets along the slerp from q0 to qf, the last one qf
        nodes: int = 60                      # initial mesh
        tolerance: float = 1e-8              # solve_bvp residual tolerance
        max_nodes: int = 20000

        def __post_init__(self) -> None:
            if self.continuation_steps < 1 or self.nodes < 5:
                raise ValueError("continuation_steps must be >= 1 and nodes >= 5")

    def _plan(self, problem: ManeuverProblem) -> Reference:
        system = MinimumEnergySystem(problem)
        T = problem.duration
        t = np.linspace(0.0, T, self.options.nodes)
        from planners.eigenaxis import EigenaxisPlanner

        guess_reference = EigenaxisPlanner().plan(problem)
        sample = guess_reference.sample(t)
        gravity = system.gravity.map(t.size)(t, np.vstack([sample.q.T, sample.omega.T, np.zeros((7, t.size))])).full()
        control = sample.torque.T - gravity
        y = np.vstack([sample.q.T, sample.omega.T, np.zeros((4, t.size)),
                       -problem.spacecraft.inertia @ control])
        x0 = problem.initial_state[:7]
        omegaf = problem.omegaf

        def residual_for(target):
            def bc(ya, yb):
                final_rate = yb[4:7] - omegaf if omegaf is not None else yb[11:14]
                miss = quat.product(quat.conjugate(target), yb[0:4])[1:]
                return np.concatenate([ya[0:7] - x0, miss, [yb[7:11] @ yb[0:4]], final_rate])
            return bc

        def fun(s, ys):
            return system.vectorised(s, ys)[0]

        def fun_jac(s, ys):
            return system.vectorised(s, ys)[1]

        steps, solution = self.options.continuation_steps, None
        for fraction in np.linspace(1.0 / steps, 1.0, steps):
            target = quat.slerp(problem.q0, problem.qf, fraction)
            solution = solve_bvp(fun, residual_for(target), t, y, fun_jac=fun_jac, tol=self.options.tolerance,
                                 max_nodes=self.options.max_nodes)
            if solution.status != 0:
                return FailedReference(self.name, f"solve_bvp failed at continuation fraction {fraction:.2f}: "
                                       f"{solution.message}", stats={"nodes": solution.x.size})
            t, y = solution.x, solution.y
        fine = np.linspace(0, T, 4001)
        energy = float(np.trapezoid(np.sum(system.control.map(fine.size)(solution.sol(fine)).full() ** 2, axis=0), fine))
        stats = {"int_u2": energy, "nodes": int(t.size), "rms_residual": float(np.max(solution.rms_residuals)),
                 "continuation_steps": steps}
        message = f"min-energy TPBVP: ∫‖u‖² = {energy:.6g} N² m² s on {t.size} nodes (solve_bvp)"
        return CostateReference(system, solution, T, problem.spacecraft.inertia, message, stats)
