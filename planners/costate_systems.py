"""Hamiltonian systems of Vepa's indirect method (sections 3 and 6): states, co-states, the
optimal control and the boundary conditions of each problem form, for ``planners.costate_tpbvp``.

Every system solves in scaled time ``s = t / t_f ∈ [0, 1]``. ``y = [x, λ]`` stacks the state and the
co-state. The right-hand sides are written out by hand (a test checks them against ``−∂H/∂x``
from CasADi's automatic differentiation of :attr:`HamiltonianSystem.hamiltonian`). The
gravity-gradient Jacobian alone is taken from CasADi, and so is the environment model itself.

``q̇ = ½ Ω(ω) q = ½ Ξ(q) ω`` (scalar first); ``Ξ`` is Vepa's ``Γ`` (eq. 11-12) in our order.
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Any

import casadi as ca
import numpy as np

from ocp import quat
from ocp.fast_call import BufferedFunction
from planners.base import Array, ManeuverProblem, ReferenceSample, inverse_dynamics_torque


def omega_matrix(omega):
    """``Ω(ω)`` with ``q̇ = ½ Ω(ω) q`` (scalar first, ω in body axes)."""
    w1, w2, w3 = omega[0], omega[1], omega[2]
    return ca.vertcat(ca.horzcat(0, -w1, -w2, -w3), ca.horzcat(w1, 0, w3, -w2),
                      ca.horzcat(w2, -w3, 0, w1), ca.horzcat(w3, w2, -w1, 0))


def xi_matrix(q):
    """``Ξ(q)`` with ``q̇ = ½ Ξ(q) ω``; its columns are orthonormal and orthogonal to a unit ``q``."""
    q0, q1, q2, q3 = q[0], q[1], q[2], q[3]
    return ca.vertcat(ca.horzcat(-q1, -q2, -q3), ca.horzcat(q0, -q3, q2),
                      ca.horzcat(q3, q0, -q1), ca.horzcat(-q2, q1, q0))


def skew(v):
    """``[v×]``."""
    return ca.vertcat(ca.horzcat(0, -v[2], v[1]), ca.horzcat(v[2], 0, -v[0]), ca.horzcat(-v[1], v[0], 0))


class HamiltonianSystem(ABC):
    """One problem form: the Hamiltonian system and its boundary conditions.

    Contract
    --------
    * ``n_state`` states and as many co-states; ``y = [x, λ]``.
    * ``free_final_time``: ``t_f`` is an unknown parameter of the TPBVP (minimum time, closed by
      ``H(t_f) = 0`` for ``J = t_f``); otherwise ``t_f`` is the scenario's duration.
    * :meth:`boundary` gives the residuals of the boundary conditions for a continuation
      ``fraction`` (1: the problem itself); :meth:`guess` gives ``t_f``, mesh and ``y`` to start.
    * :meth:`sample` turns ``y`` at times ``t`` into a :class:`ReferenceSample`.
    * Forms whose control is a torque (``torque_control``) also give :meth:`feedback_torque`, the
      optimal control as a function of an estimated co-state (Vepa eq. 42).
    """

    n_state: int
    free_final_time: bool
    torque_control = False
    continued = True
    """Solved by continuation in the target (a fixed-time steering form is not: it is singular for
    the nearby targets it can reach early, and its guess is already in the right basin)."""

    def free_boundary(self) -> frozenset[str]:
        """Boundary conditions of the problem this form leaves free or only penalises (a terminal
        cost), as names of ``planners.base.BOUNDARY_CONDITIONS``; none by default."""
        return frozenset()

    def __init__(self, problem: ManeuverProblem, t_f: float):
        self.problem, self.t_f_fixed = problem, t_f
        self.inertia = problem.spacecraft.inertia
        t, y, u = ca.SX.sym("t"), ca.SX.sym("y", 2 * self.n_state), ca.SX.sym("u", 3)
        rhs, hamiltonian, control = self.equations(t, y, u)
        self.rhs = ca.Function("hamiltonian_rhs", [t, y], [rhs])
        self.hamiltonian = ca.Function("hamiltonian", [t, y, u], [hamiltonian])
        self.control = ca.Function("control", [y], [control])
        self.derivatives = ca.Function("rhs_derivatives", [t, y],
                                       [rhs, ca.densify(ca.jacobian(rhs, y)), ca.densify(ca.jacobian(rhs, t))])
        self._mapped: dict[tuple[int, bool], BufferedFunction] = {}

    @abstractmethod
    def equations(self, t, y, u) -> tuple[Any, Any, Any]:
        """``(ẏ, H(t, y, u), u*(y))`` as expressions; ``ẏ`` uses ``u*``, ``H`` the free ``u``."""

    @abstractmethod
    def boundary(self, fraction: float):
        """``bc(ya, yb, t_f) -> residuals`` of the problem scaled by the continuation ``fraction``."""

    @abstractmethod
    def guess(self, nodes: int, fraction: float) -> tuple[float, Array, Array]:
        """``(t_f, s, y)`` for the problem at continuation ``fraction``: a starting final time,
        scaled mesh on [0, 1] and ``y`` (2n, nodes)."""

    @abstractmethod
    def sample(self, t: Array, y: Array, t_f: float) -> ReferenceSample:
        """Reference quantities at times ``t`` (s, within ``[0, t_f]``) from ``y`` (2n, m)."""

    def evaluate(self, t: Array, y: Array, derivatives: bool = True) -> tuple[Array, Array | None, Array | None]:
        """``f``, ``∂f/∂y`` (2n, 2n, m) and ``∂f/∂t`` (2n, m) at the columns of ``y``, in real time
        (the derivatives ``None`` unless asked for)."""
        m, n = t.size, 2 * self.n_state
        width = 1 << max(m - 1, 1).bit_length()  # one mapped Function per power of two, padded
        key = (width, derivatives)
        if key not in self._mapped:
            self._mapped[key] = BufferedFunction((self.derivatives if derivatives else self.rhs).map(width))
        pad = width - m
        times, states = np.pad(t, (0, pad), mode="edge"), np.pad(y, ((0, 0), (0, pad)), mode="edge")
        if not derivatives:
            return self._mapped[key](times, states.ravel(order="F")).reshape(width, n)[:m].T.copy(), None, None
        f, jac, f_t = self._mapped[key].all_outputs(times, states.ravel(order="F"))
        f = f.reshape(width, n)[:m].T.copy()
        jac = jac.reshape(width, n, n)[:m].transpose(2, 1, 0).copy()  # blocks (n x n) column-major, per time
        return f, jac, f_t.reshape(width, n)[:m].T.copy()

    def hamiltonian_at(self, t: float, y: Array) -> float:
        """``H`` at the optimal control."""
        return float(self.hamiltonian(t, y, self.control(y)))

    def final_time(self, p) -> float:
        """``t_f``: the unknown parameter ``p[0]`` of a free-time form, else the fixed time."""
        return float(p[0]) if self.free_final_time else self.t_f_fixed


class _RigidBodySystem(HamiltonianSystem):
    """States ``x = [q, ω]``; ``I ω̇ = −ω × I ω + M_c + M_gg(q, t)``. Subclasses give ``M_c(λ_ω)``
    and the running cost."""

    n_state = 7
    torque_control = True

    @abstractmethod
    def torque(self, u):
        """Control torque ``M_c`` (N m) of the control variable ``u``."""

    @abstractmethod
    def optimal_control(self, lam_omega):
        """``u*`` minimising ``H`` for the co-state ``λ_ω``."""

    def running_cost(self, u):
        return 0

    def equations(self, t, y, u):
        model = self.problem.model
        inertia, inverse = ca.DM(self.inertia), ca.DM(np.linalg.inv(self.inertia))
        q, omega, lam_q, lam_w = y[0:4], y[4:7], y[7:11], y[11:14]
        state = ca.vertcat(y[0:7], ca.SX.zeros(model.n_wheels))
        gravity = model.external_torque(state, t, ca.DM(model.default_parameters))
        momentum = ca.mtimes(inertia, omega)

        def state_rhs(control):
            return ca.vertcat(0.5 * ca.mtimes(omega_matrix(omega), q),
                              ca.mtimes(inverse, -ca.cross(omega, momentum) + self.torque(control) + gravity))

        optimal = self.optimal_control(lam_w)
        gyro_jacobian = ca.mtimes(skew(omega), inertia) - skew(momentum)  # ∂(ω × I ω)/∂ω
        lam_q_dot = -0.5 * ca.mtimes(omega_matrix(omega).T, lam_q) \
            - ca.mtimes(ca.jacobian(gravity, q).T, ca.mtimes(inverse, lam_w))
        lam_w_dot = -0.5 * ca.mtimes(xi_matrix(q).T, lam_q) + ca.mtimes(gyro_jacobian.T, ca.mtimes(inverse, lam_w))
        rhs = ca.vertcat(state_rhs(optimal), lam_q_dot, lam_w_dot)
        hamiltonian = self.running_cost(u) + ca.dot(y[7:14], state_rhs(u))
        return rhs, hamiltonian, optimal

    def sample(self, t: Array, y: Array, t_f: float) -> ReferenceSample:
        f, _, _ = self.evaluate(t, y, derivatives=False)
        omega = y[4:7].T
        return ReferenceSample(quat.normalize(y[0:4].T), omega, f[4:7].T,
                               inverse_dynamics_torque(self.inertia, omega, f[4:7].T))

    def environment_torque(self, t: Array, x: Array) -> Array:
        """Gravity gradient plus the constant disturbance (N m) at times ``t`` for states ``x`` (7, m)."""
        model = self.problem.model
        states = np.vstack([x, np.zeros((model.n_wheels, t.size))])
        return model.environment_torque.map(t.size)(states, t, model.default_parameters).full()

    def feedback_torque(self, lam_omega: Array, lam_omega_reference: Array) -> Array:
        """Control torque (N m) for an estimated co-state ``λ_ω`` (Vepa eq. 42)."""
        return np.asarray(self.torque(self.optimal_control(lam_omega)), dtype=float).ravel()


class MinimumEnergySystem(_RigidBodySystem):
    """``min ½∫‖M_c‖² dt``, ``u = M_c = −I⁻¹ λ_ω``; ``x(0)``, ``q(t_f) = q_f`` and ``ω(t_f) = ω_f``
    fixed (``λ_ω(t_f) = 0`` when the final rate is free). Only three attitude conditions are
    independent (``q`` stays unit), so the gauge ``λ_q(t_f)·q(t_f) = 0`` closes the set.
    Continuation moves the target along the slerp from ``q0``."""

    free_final_time = False

    def torque(self, u):
        return u

    def optimal_control(self, lam_omega):
        return -ca.mtimes(ca.DM(np.linalg.inv(self.inertia)), lam_omega)

    def running_cost(self, u):
        return 0.5 * ca.sumsqr(u)

    def boundary(self, fraction: float):
        p = self.problem
        x0, target = p.initial_state[:7], quat.slerp(p.q0, p.qf, fraction)

        def bc(ya, yb, t_f=None):
            final_rate = yb[4:7] - p.omegaf if p.omegaf is not None else yb[11:14]
            miss = quat.product(quat.conjugate(target), yb[0:4])[1:]
            return np.concatenate([ya[0:7] - x0, miss, [yb[7:11] @ yb[0:4]], final_rate])
        return bc

    def guess(self, nodes: int, fraction: float) -> tuple[float, Array, Array]:
        from planners.eigenaxis import EigenaxisPlanner

        T = self.t_f_fixed
        s = np.linspace(0.0, 1.0, nodes)
        sample = EigenaxisPlanner().plan(self.problem).sample(s * T)
        x = np.vstack([sample.q.T, sample.omega.T])
        gravity = self.environment_torque(s * T, x)
        return T, s, np.vstack([x, np.zeros((4, nodes)), -self.inertia @ (sample.torque.T - gravity)])




class RateAcquisitionSystem(_RigidBodySystem):
    """Rate acquisition with a steering direction (Vepa section 3): ``M_c = diag(τ) W u``, ``‖u‖ = 1``.

    ``ω̇ = I⁻¹(M_gg − ω × I ω) + G u`` with ``G = I⁻¹ diag(τ) W``, and ``u = −Gᵀλ_ω / ‖Gᵀλ_ω‖``
    (eq. 34, which reads ``−Wλ_ω/‖Wλ_ω‖`` for the paper's ``G = T W``). The paper writes
    ``M_c = I T W u`` with one scalar ``T``, which cannot honour per-axis limits such as its
    ``[0.62, 1, 1]`` N m; we scale ``W`` by the per-axis torque ``τ`` instead, so ``|M_c,i| <= τ_i``.

    * ``minimum_time``: ``ω(t_f) = ω_d`` exactly and ``t_f`` free, closed by ``H(t_f) = 0`` for
      ``J = t_f`` (the limit of eq. 37 as ``Q_f → ∞``, with the transfer time the paper also seeks).
    * otherwise ``t_f = T`` and the terminal cost ``½(ω − ω_d)ᵀQ_f(ω − ω_d)`` of eq. 23, with the
      transversality conditions ``λ_ω(t_f) = Q_f (ω(t_f) − ω_d)`` (eq. 37).

    Either way ``λ_q(t_f) = 0`` (eq. 36: the attitude is free) and ``λ_c = 0`` (eq. 38).
    Continuation moves ``ω_d`` from ``ω0``.
    """

    def __init__(self, problem: ManeuverProblem, t_f: float, steering_torque: Array, weighting: Array,
                 terminal_weight: float, minimum_time: bool):
        self.torque_map = np.diag(steering_torque) @ weighting
        self.steering = np.linalg.solve(problem.spacecraft.inertia, self.torque_map)  # G
        self.terminal_weight, self.free_final_time = terminal_weight, minimum_time
        self.continued = minimum_time
        super().__init__(problem, t_f)

    def free_boundary(self) -> frozenset[str]:
        """The attitude is free (eq. 36); with a fixed time the final rate is a terminal cost."""
        return frozenset({"qf"} if self.free_final_time else {"qf", "omegaf"})

    def torque(self, u):
        return ca.mtimes(ca.DM(self.torque_map), u)

    def optimal_control(self, lam_omega):
        direction = ca.mtimes(ca.DM(self.steering).T, lam_omega)
        return -direction / ca.norm_2(direction)

    def feedback_torque(self, lam_omega: Array, lam_omega_reference: Array) -> Array:
        """Eq. 42: ``u = −r⁻¹ Gᵀ λ̂_ω`` with ``r = ‖Gᵀ λ_ω,ref‖`` taken on the reference, so the
        correction changes the torque's size as well as its direction."""
        r = np.linalg.norm(self.steering.T @ lam_omega_reference)
        return self.torque_map @ (-(self.steering.T @ lam_omega) / r)

    def _target(self, fraction: float) -> Array:
        p = self.problem
        return p.omega0 + fraction * (p.omegaf - p.omega0)

    def boundary(self, fraction: float):
        x0, target, weight = self.problem.initial_state[:7], self._target(fraction), self.terminal_weight

        def bc(ya, yb, t_f=None):
            if self.free_final_time:
                final = np.concatenate([yb[4:7] - target, [1.0 + self.hamiltonian_at(float(t_f[0]), yb)]])
            else:
                final = yb[11:14] - weight * (yb[4:7] - target)
            return np.concatenate([ya[0:7] - x0, yb[7:11], final])
        return bc

    def minimum_time_estimate(self, fraction: float = 1.0) -> float:
        """``‖G⁻¹ Δω‖``: exact for a spherical body without gravity gradient (s)."""
        change = self._target(fraction) - self.problem.omega0
        return float(np.linalg.norm(np.linalg.solve(self.steering, change)))

    def guess(self, nodes: int, fraction: float) -> tuple[float, Array, Array]:
        p = self.problem
        t_min = self.minimum_time_estimate(fraction)
        t_f = t_min if self.free_final_time else self.t_f_fixed
        s = np.linspace(0.0, 1.0, nodes)
        reach = min(1.0, t_f / t_min)
        change = reach * (self._target(fraction) - p.omega0)
        omega = p.omega0[:, None] + s * change[:, None]
        angle = t_f * (np.outer(p.omega0, s) + 0.5 * np.outer(change, s**2))  # exact for a fixed axis
        q = quat.product(p.q0, quat.from_rotation_vector(angle.T)).T
        direction = np.linalg.solve(self.steering, p.omegaf - p.omega0)
        if self.free_final_time:
            lam_omega = -np.linalg.solve(self.steering.T, direction / np.linalg.norm(direction))
        else:
            lam_omega = self.terminal_weight * (omega[:, -1] - self._target(fraction))
        y = np.vstack([q, omega, np.zeros((4, nodes)), np.repeat(lam_omega[:, None], nodes, axis=1)])
        return t_f, s, y


class AttitudeAcquisitionSystem(HamiltonianSystem):
    """Attitude acquisition with the rate as the control (Vepa section 6): ``ω = ω_max u``, ``‖u‖ = 1``.

    ``q̇ = ½ Ξ(q) ω``, ``H = ½ ω_max λ_qᵀ Ξ(q) u``, ``u = −Ξᵀλ_q / ‖Ξᵀλ_q‖`` (eq. 50) and
    ``λ̇_q = −½ Ω(ω)ᵀ λ_q`` (eq. 49). With ``minimum_time`` the target is met exactly and ``t_f`` is
    free (``H(t_f) = −1``, gauge ``λ_q·q = 0``, which the flow conserves); otherwise ``t_f = T`` with
    ``λ_q(t_f) = Q_f (q(t_f) − q_d)`` (eq. 51). The optimum is the constant-rate eigenaxis rotation
    (a geodesic of the unit sphere); the rate steps from 0 to ``ω_max`` at the start and back at the
    end, where the reference is at rest (the impulsive torque of those steps is not in the reference).
    """

    n_state = 4

    def __init__(self, problem: ManeuverProblem, t_f: float, max_rate: float, terminal_weight: float,
                 minimum_time: bool):
        self.max_rate, self.terminal_weight, self.free_final_time = max_rate, terminal_weight, minimum_time
        self.continued = minimum_time
        self.target = problem.qf if problem.qf @ problem.q0 >= 0 else -problem.qf
        super().__init__(problem, t_f)
        t, y = ca.SX.sym("t"), ca.SX.sym("y", 8)
        rate = self.max_rate * self.control(y)
        self.rate = ca.Function("rate", [t, y], [rate, ca.mtimes(ca.jacobian(rate, y), self.rhs(t, y))])

    def free_boundary(self) -> frozenset[str]:
        """The rate starts and ends at rest (non-zero boundary rates are not met); with a fixed
        time the final attitude is a terminal cost."""
        p = self.problem
        free = {name for name, rate in (("omega0", p.omega0), ("omegaf", p.omegaf))
                if rate is not None and np.any(rate != 0)}
        return frozenset(free | (set() if self.free_final_time else {"qf"}))

    def equations(self, t, y, u):
        q, lam_q = y[0:4], y[4:8]
        direction = ca.mtimes(xi_matrix(q).T, lam_q)
        optimal = -direction / ca.norm_2(direction)
        omega = self.max_rate * optimal
        rhs = ca.vertcat(0.5 * ca.mtimes(omega_matrix(omega), q), -0.5 * ca.mtimes(omega_matrix(omega).T, lam_q))
        hamiltonian = 0.5 * self.max_rate * ca.dot(lam_q, ca.mtimes(xi_matrix(q), u))
        return rhs, hamiltonian, optimal

    def _target(self, fraction: float) -> Array:
        return quat.slerp(self.problem.q0, self.target, fraction)

    def boundary(self, fraction: float):
        q0, target, weight = self.problem.q0, self._target(fraction), self.terminal_weight

        def bc(ya, yb, t_f=None):
            if self.free_final_time:
                miss = quat.product(quat.conjugate(target), yb[0:4])[1:]
                final = np.concatenate([miss, [yb[4:8] @ yb[0:4], 1.0 + self.hamiltonian_at(float(t_f[0]), yb)]])
            else:
                final = yb[4:8] - weight * (yb[0:4] - target)
            return np.concatenate([ya[0:4] - q0, final])
        return bc

    def guess(self, nodes: int, fraction: float) -> tuple[float, Array, Array]:
        rotation = quat.to_rotation_vector(quat.product(quat.conjugate(self.problem.q0), self._target(fraction)))
        angle = float(np.linalg.norm(rotation))
        axis = rotation / angle if angle > 0 else np.array([1.0, 0.0, 0.0])
        t_f = angle / self.max_rate if self.free_final_time else self.t_f_fixed
        s = np.linspace(0.0, 1.0, nodes)
        swept = min(angle, self.max_rate * t_f) * s
        q = quat.product(self.problem.q0, quat.from_rotation_vector(np.outer(swept, axis)))
        lam_q = -(2.0 / self.max_rate) * quat.product(q, np.r_[0.0, axis]).T  # −(2/ω_max) Ξ(q) e
        return t_f, s, np.vstack([q.T, lam_q])

    def sample(self, t: Array, y: Array, t_f: float) -> ReferenceSample:
        rate, rate_dot = (a.full() for a in self.rate.map(t.size)(t, y))
        at_rest = (t <= 0.0) | (t >= t_f)
        rate[:, at_rest], rate_dot[:, at_rest] = 0.0, 0.0
        omega, omega_dot = rate.T, rate_dot.T
        return ReferenceSample(quat.normalize(y[0:4].T), omega, omega_dot,
                               inverse_dynamics_torque(self.inertia, omega, omega_dot))
