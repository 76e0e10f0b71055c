"""Problem forms of Vepa's indirect method (sections 3 and 6) for ``planners.costate.tpbvp``: the
optimal control and boundary conditions of minimum energy, rate acquisition and attitude
acquisition, on the Hamiltonian systems of :mod:`planners.costate.hamiltonian`.
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

import casadi as ca
import numpy as np

from ocp import quat
from planners.costate.hamiltonian import (
    HamiltonianSystem,
    RigidBodySystem,
    omega_matrix,
    xi_matrix,
)
from planners.problem import Array, ManeuverProblem
from planners.reference import ReferenceSample, inverse_dynamics_torque
from planners.torque_free import TorqueFreeMotion

__all__ = ["SPIN_MESH_ANGLE", "AttitudeAcquisitionSystem", "ColdStartError", "MinimumEnergySystem", "RateAcquisitionSystem"]

SPIN_MESH_ANGLE = 0.1
"""rad: the coarsest mesh of a spinning cold start, one interval per this angle turned. On the spin
re-pointing problem (40 rad in 200 s) the stages at tolerance 1e-5 end on 700 to 1200 nodes; from
60 nodes (the default) solve_bvp cannot add them within a stage's limit."""

class MinimumEnergySystem(RigidBodySystem):
    """``min ½∫‖M_c‖² dt``, ``u = M_c = −I⁻¹ λ_ω``; ``x(0)``, ``q(t_f) = q_f`` and ``ω(t_f) = ω_f``
    fixed (``λ_ω(t_f) = 0`` when the final rate is free). Only three attitude conditions are
    independent (``q`` stays unit), so the gauge ``λ_q(t_f)·q(t_f) = 0`` closes the set.

    Two cold starts (``coast``), each with its continuation of the target:

    * the eigenaxis slew (default): the target moves along the slerp from ``q0``;
    * the torque-free coast from ``x(0)``, for a spinning start (``ω0 ≠ 0``), with zero co-states:
      the exact solution (without environment torques) for the target it ends at, ``(q_c(T),
      ω_c(T))``, from which the target attitude moves along the slerp (and a fixed final rate
      along the line). It is the :meth:`fallback` of the eigenaxis start from a spin, whose
      rest-to-rest guess can fail at the first stage (the spin re-pointing benchmark: ω0 = 0.2
      rad/s for 200 s); a continuation of ``ω0`` from zero meets turning points of the solution
      path there instead. The eigenaxis start stays first: where both solve they can reach
      different extremals (a 0.1 rad/s spin brought to rest in 120 s: 0.0201 from the eigenaxis
      start, as collocation, 0.0682 from the coast).

    Parameters
    ----------
    problem : ManeuverProblem
        The manoeuvre; it needs a target attitude.
    t_f : float
        The manoeuvre time T [s].
    coast : bool, optional
        Start from the torque-free coast (default ``False``: the eigenaxis slew); ``ValueError``
        from rest, where the coast is rest.
    """

    free_final_time = False

    def __init__(self, problem: ManeuverProblem, t_f: float, coast: bool = False) -> None:
        super().__init__(problem, t_f)
        spinning = bool(np.any(problem.omega0 != 0))
        if coast and not spinning:
            raise ValueError("the torque-free coast is a cold start from a spin; maneuver.initial.omega is zero")
        self.coast = TorqueFreeMotion(problem.q0, problem.omega0, self.inertia, 0.0) if coast else None
        """The torque-free motion from ``x(0)`` of the coast start; ``None`` for the eigenaxis start."""
        self.cold_start = "torque-free coast" if coast else "eigenaxis slew"

    def fallback(self) -> MinimumEnergySystem | None:
        """The coast start, for the eigenaxis start from a spin.

        Returns
        -------
        MinimumEnergySystem or None
            The problem with the torque-free coast as its cold start when this one starts from the
            eigenaxis slew and ``ω0 ≠ 0``; otherwise ``None``.
        """
        if self.coast is not None or not np.any(self.problem.omega0 != 0):
            return None
        return MinimumEnergySystem(self.problem, self.t_f_fixed, coast=True)

    def torque(self, u: Any) -> Any:
        return u

    def optimal_control(self, lam_omega: Any) -> Any:
        return -ca.mtimes(ca.DM(np.linalg.inv(self.inertia)), lam_omega)

    def running_cost(self, u: Any) -> Any:
        return 0.5 * ca.sumsqr(u)

    def boundary(self, fraction: float) -> Callable[..., Array]:
        p = self.problem
        assert p.qf is not None  # the min_energy form is built for a target attitude only
        x0, final_rate = p.initial_state[:7], p.omegaf
        if self.coast is None:
            target = quat.slerp(p.q0, p.qf, fraction)
        else:
            q_coast, omega_coast, _ = self.coast(np.array([self.t_f_fixed]))
            target = quat.slerp(q_coast[0], p.qf, fraction)
            if final_rate is not None:
                final_rate = omega_coast[0] + fraction * (final_rate - omega_coast[0])

        def bc(ya, yb, t_f=None):
            rate = yb[4:7] - final_rate if final_rate is not None else yb[11:14]
            miss = quat.product(quat.conjugate(target), yb[0:4])[1:]
            return np.concatenate([ya[0:7] - x0, miss, [yb[7:11] @ yb[0:4]], rate])
        return bc

    def guess(self, nodes: int, fraction: float) -> tuple[float, Array, Array]:
        """The eigenaxis slew, or the torque-free coast (``coast``) with zero co-states on at least
        one node per :data:`SPIN_MESH_ANGLE` of the angle it turns (the 40 rad of the spin
        re-pointing problem need 400).

        Parameters
        ----------
        nodes : int
            The least number of mesh points.
        fraction : float
            Continuation fraction in (0, 1] (the coast does not depend on it).

        Returns
        -------
        t_f : float
            T [s].
        s : (m,) ndarray
            Scaled mesh on [0, 1], ``m >= nodes``.
        y : (14, m) ndarray
            States and co-states on the mesh.

        Raises
        ------
        ColdStartError
            When the eigenaxis slew fails (a numerical failure such as ``T = 1e300`` s).
        """
        T = self.t_f_fixed
        if self.coast is not None:
            s = np.linspace(0.0, 1.0, nodes)
            turned = float(np.trapezoid(np.linalg.norm(self.coast(s * T)[1], axis=1), s * T))
            s = np.linspace(0.0, 1.0, max(nodes, int(np.ceil(turned / SPIN_MESH_ANGLE)) + 1))
            q, omega, _ = self.coast(s * T)
            return T, s, np.vstack([q.T, omega.T, np.zeros((7, s.size))])
        from planners.eigenaxis import EigenaxisPlanner

        s = np.linspace(0.0, 1.0, nodes)
        start = EigenaxisPlanner().plan_start(self.problem)
        if not start.ok:
            raise ColdStartError(f"the eigenaxis cold start failed: {start.message}")
        sample = start.sample(s * T)
        x = np.vstack([sample.q.T, sample.omega.T])
        gravity = self.environment_torque(s * T, x)
        return T, s, np.vstack([x, np.zeros((4, nodes)), -self.inertia @ (sample.torque.T - gravity)])


class ColdStartError(RuntimeError):
    """A cold start (:meth:`MinimumEnergySystem.guess`) could not be built; the planner returns a
    failed reference with this message."""


class RateAcquisitionSystem(RigidBodySystem):
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

    Parameters
    ----------
    problem : ManeuverProblem
        The manoeuvre; its ``omegaf`` is the target rate ``ω_d`` (required).
    t_f : float
        The final time T [s] of the fixed-time form (the starting guess is the estimate of
        :meth:`minimum_time_estimate` when ``minimum_time``).
    steering_torque : (3,) ndarray
        ``τ``, torque per body axis [N m], positive.
    weighting : (3, 3) ndarray
        ``W`` (eq. 34; diagonal in the planner).
    terminal_weight : float
        ``Q_f = terminal_weight · I`` of the fixed-time terminal cost ``½ (ω − ω_d)ᵀ Q_f (ω − ω_d)``
        (eq. 23).
    minimum_time : bool
        Solve for the minimum time (``ω(t_f) = ω_d`` exactly) rather than the fixed-time terminal cost.
    """

    def __init__(self, problem: ManeuverProblem, t_f: float, steering_torque: Array, weighting: Array,
                 terminal_weight: float, minimum_time: bool) -> None:
        self.torque_map = np.diag(steering_torque) @ weighting
        self.steering = np.linalg.solve(problem.spacecraft.inertia, self.torque_map)  # G
        self.terminal_weight, self.free_final_time = terminal_weight, minimum_time
        self.continued = minimum_time
        super().__init__(problem, t_f)

    def free_boundary(self) -> frozenset[str]:
        """The attitude is free (eq. 36); with a fixed time the final rate is a terminal cost.

        Returns
        -------
        frozenset of str
            ``{"qf"}``, plus ``"omegaf"`` for the fixed-time form.
        """
        return frozenset({"qf"} if self.free_final_time else {"qf", "omegaf"})

    def torque(self, u: Any) -> Any:
        return ca.mtimes(ca.DM(self.torque_map), u)

    def optimal_control(self, lam_omega: Any) -> Any:
        direction = ca.mtimes(ca.DM(self.steering).T, lam_omega)
        return -direction / ca.norm_2(direction)

    def feedback_torque(self, lam_omega: Array, lam_omega_reference: Array) -> Array:
        """Eq. 42: ``u = −r⁻¹ Gᵀ λ̂_ω`` with ``r = ‖Gᵀ λ_ω,ref‖`` taken on the reference, so the
        correction changes the torque's size as well as its direction.

        Parameters
        ----------
        lam_omega : (3,) ndarray
            The estimated rate co-state ``λ̂_ω``.
        lam_omega_reference : (3,) ndarray
            The reference's ``λ_ω`` at the same time.

        Returns
        -------
        (3,) ndarray
            Control torque ``diag(τ) W u`` [N m], body axes.
        """
        r = np.linalg.norm(self.steering.T @ lam_omega_reference)
        return self.torque_map @ (-(self.steering.T @ lam_omega) / r)

    def _target(self, fraction: float) -> Array:
        p = self.problem
        assert p.omegaf is not None  # the rate_acquisition form is built for a target rate only
        return p.omega0 + fraction * (p.omegaf - p.omega0)

    def boundary(self, fraction: float) -> Callable[..., Array]:
        x0, target, weight = self.problem.initial_state[:7], self._target(fraction), self.terminal_weight

        def bc(ya, yb, t_f=None):
            if self.free_final_time:
                final = np.concatenate([yb[4:7] - target, [1.0 + self.hamiltonian_at(float(t_f[0]), yb)]])
            else:
                final = yb[11:14] - weight * (yb[4:7] - target)
            return np.concatenate([ya[0:7] - x0, yb[7:11], final])
        return bc

    def minimum_time_estimate(self, fraction: float = 1.0) -> float:
        """The minimum time of the rate change, ignoring gyroscopic and environment torques.

        Parameters
        ----------
        fraction : float, optional
            Continuation fraction of the rate change (default 1, the whole change).

        Returns
        -------
        float
            ``‖G⁻¹ Δω‖`` [s]: exact for a spherical body without gravity gradient.
        """
        change = self._target(fraction) - self.problem.omega0
        return float(np.linalg.norm(np.linalg.solve(self.steering, change)))

    def guess(self, nodes: int, fraction: float) -> tuple[float, Array, Array]:
        p = self.problem
        t_min = self.minimum_time_estimate(fraction)
        t_f = t_min if self.free_final_time else self.t_f_fixed
        s = np.linspace(0.0, 1.0, nodes)
        reach = 1.0 if t_f >= t_min else t_f / t_min  # t_min = 0: no rate change (fixed T), nothing to scale
        change = reach * (self._target(fraction) - p.omega0)
        omega = p.omega0[:, None] + s * change[:, None]
        angle = t_f * (np.outer(p.omega0, s) + 0.5 * np.outer(change, s**2))  # exact for a fixed axis
        q = quat.product(p.q0, quat.from_rotation_vector(angle.T)).T
        assert p.omegaf is not None  # the rate_acquisition form is built for a target rate only
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
    (a geodesic of the unit sphere).

    The form is kinematic: the rate is the control and ``‖ω‖ = ω_max`` on all of ``(0, t_f)``, so
    the paper's solution cannot meet the manoeuvre's rates ``ω0`` and ``ω_f`` (leaving their
    tracking to the controller, section 6). The reference steps at both ends, and says so: its
    breakpoints are ``0`` and ``t_f`` (:meth:`breakpoints`); its sample at 0 is the right limit
    ``ω(0⁺) = ω_max u(0)``, so the jump from the manoeuvre's ``ω0`` is an impulse ``I Δω`` the
    scoring sees, and its sample at ``t_f`` is ``ω_f`` (rest when the final rate is free), after the
    stop, from which the reference coasts torque-free.

    Parameters
    ----------
    problem : ManeuverProblem
        The manoeuvre; it needs a target attitude.
    t_f : float
        The final time T [s] of the fixed-time form.
    max_rate : float
        ``ω_max``, the rate norm of the control [rad/s].
    terminal_weight : float
        ``Q_f = terminal_weight · I`` of the fixed-time terminal cost on the attitude (eq. 51).
    minimum_time : bool
        Solve for the minimum time (target met exactly) rather than the fixed-time terminal cost.
    """

    n_state = 4

    def __init__(self, problem: ManeuverProblem, t_f: float, max_rate: float, terminal_weight: float,
                 minimum_time: bool) -> None:
        self.max_rate, self.terminal_weight, self.free_final_time = max_rate, terminal_weight, minimum_time
        self.continued = minimum_time
        assert problem.qf is not None  # the attitude_acquisition form is built for a target attitude only
        self.target = problem.qf if problem.qf @ problem.q0 >= 0 else -problem.qf
        super().__init__(problem, t_f)
        t, y = ca.SX.sym("t"), ca.SX.sym("y", 8)
        rate = self.max_rate * self.control(y)
        self.rate = ca.Function("rate", [t, y], [rate, ca.mtimes(ca.jacobian(rate, y), self.rhs(t, y))])

    def free_boundary(self) -> frozenset[str]:
        """With a fixed time the final attitude is a terminal cost. The rates are not free: the
        reference meets them across the jumps at its :meth:`breakpoints`, impulses the scoring
        counts (a free ``ω0`` would exempt the start from the actuator requirement).

        Returns
        -------
        frozenset of str
            ``{"qf"}`` for the fixed-time form, empty for the minimum-time one.
        """
        return frozenset() if self.free_final_time else frozenset({"qf"})

    def breakpoints(self, t_f: float) -> Array:
        """Both ends: the rate steps from ``ω0`` to ``ω_max u(0)`` at 0 and from ``ω_max u(t_f)`` to
        ``ω_f`` at ``t_f`` (the control ``‖ω‖ = ω_max`` holds on the open interval only).

        Parameters
        ----------
        t_f : float
            The solved final time [s].

        Returns
        -------
        (2,) ndarray
            ``[0, t_f]`` [s].
        """
        return np.array([0.0, t_f])

    def equations(self, t: Any, y: Any, u: Any) -> tuple[Any, Any, Any]:
        q, lam_q = y[0:4], y[4:8]
        direction = ca.mtimes(xi_matrix(q).T, lam_q)
        optimal = -direction / ca.norm_2(direction)
        omega = self.max_rate * optimal
        rhs = ca.vertcat(0.5 * ca.mtimes(omega_matrix(omega), q), -0.5 * ca.mtimes(omega_matrix(omega).T, lam_q))
        hamiltonian = 0.5 * self.max_rate * ca.dot(lam_q, ca.mtimes(xi_matrix(q), u))
        return rhs, hamiltonian, optimal

    def _target(self, fraction: float) -> Array:
        return quat.slerp(self.problem.q0, self.target, fraction)

    def boundary(self, fraction: float) -> Callable[..., Array]:
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
        """The control rate ``ω_max u`` on ``[0, t_f)`` (the right limit at 0), and at ``t_f`` the
        final rate ``ω_f`` (zero when free) with its torque-free ``ω̇``, where the coast after
        ``t_f`` starts (see the class docstring).

        Parameters
        ----------
        t : (N,) ndarray
            Times [s] in ``[0, t_f]``.
        y : (8, N) ndarray
            ``[q, λ_q]`` at ``t``.
        t_f : float
            The final time [s].

        Returns
        -------
        ReferenceSample
            ``q``, ``ω``, ``ω̇`` and the inverse-dynamics torque at ``t``.
        """
        rate, rate_dot = (a.full() for a in self.rate.map(t.size)(t, y))
        end = t >= t_f
        if np.any(end):
            final = np.zeros(3) if self.problem.omegaf is None else np.asarray(self.problem.omegaf, dtype=float)
            rate[:, end] = final[:, None]
            rate_dot[:, end] = -np.linalg.solve(self.inertia, np.cross(final, self.inertia @ final))[:, None]
        omega, omega_dot = rate.T, rate_dot.T
        return ReferenceSample(quat.normalize(y[0:4].T), omega, omega_dot,
                               inverse_dynamics_torque(self.inertia, omega, omega_dot))
