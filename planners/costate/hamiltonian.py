"""Hamiltonian systems of Vepa's indirect method (sections 3 and 6): the common contract
:class:`HamiltonianSystem`, the rigid-body states and co-states :class:`RigidBodySystem`, and the
matrices of the quaternion kinematics. The problem forms are in :mod:`planners.costate.systems`.

Every system solves in scaled time ``s = t / t_f ∈ [0, 1]``. ``y = [x, λ]`` stacks the state and the
co-state. The right-hand sides are written out by hand (a test checks them against ``−∂H/∂x``
from CasADi's automatic differentiation of :attr:`HamiltonianSystem.hamiltonian`). The
gravity-gradient Jacobian alone is taken from CasADi, and so is the environment model itself.

``q̇ = ½ Ω(ω) q = ½ Ξ(q) ω`` (scalar first); ``Ξ`` is Vepa's ``Γ`` (eq. 11-12) in our order.
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable
from typing import Any

import casadi as ca
import numpy as np

from ocp import quat
from ocp.fast_call import BufferedFunction
from planners.problem import Array, ManeuverProblem
from planners.reference import ReferenceSample, inverse_dynamics_torque


def omega_matrix(omega: Any) -> Any:
    """``Ω(ω)`` with ``q̇ = ½ Ω(ω) q`` (scalar first, ω in body axes).

    Parameters
    ----------
    omega : (3,) casadi.SX or sequence
        Body rate [rad/s], body axes.

    Returns
    -------
    (4, 4) casadi.SX
        ``Ω(ω)`` [rad/s], skew-symmetric.
    """
    w1, w2, w3 = omega[0], omega[1], omega[2]
    return ca.vertcat(ca.horzcat(0, -w1, -w2, -w3), ca.horzcat(w1, 0, w3, -w2),
                      ca.horzcat(w2, -w3, 0, w1), ca.horzcat(w3, w2, -w1, 0))


def xi_matrix(q: Any) -> Any:
    """``Ξ(q)`` with ``q̇ = ½ Ξ(q) ω`` (Vepa's ``Γ``, eq. 11-12, in scalar-first order).

    Parameters
    ----------
    q : (4,) casadi.SX or sequence
        Attitude quaternion, scalar first, body to inertial.

    Returns
    -------
    (4, 3) casadi.SX
        ``Ξ(q)``; its columns are orthonormal and orthogonal to a unit ``q``.
    """
    q0, q1, q2, q3 = q[0], q[1], q[2], q[3]
    return ca.vertcat(ca.horzcat(-q1, -q2, -q3), ca.horzcat(q0, -q3, q2),
                      ca.horzcat(q3, q0, -q1), ca.horzcat(-q2, q1, q0))


def skew(v: Any) -> Any:
    """The cross-product matrix ``[v×]``, ``[v×] w = v × w``.

    Parameters
    ----------
    v : (3,) casadi.SX or sequence
        A vector (any units).

    Returns
    -------
    (3, 3) casadi.SX
        ``[v×]``, skew-symmetric, in the units of ``v``.
    """
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
    * :meth:`fallback` may give the same problem with another cold start, solved when this one's
      continuation fails.

    Parameters
    ----------
    problem : ManeuverProblem
        The manoeuvre (spacecraft, environment, boundary conditions).
    t_f : float
        The final time [s] of a fixed-time form (the scenario's duration); a free-time form
        solves for its own.
    """

    n_state: int
    free_final_time: bool
    torque_control = False
    continued = True
    """Solved by continuation in the target (a fixed-time steering form is not: it is singular for
    the nearby targets it can reach early, and its guess is already in the right basin)."""
    cold_start = "own"
    """What the cold start of :meth:`guess` is, for the reference's message and statistics."""

    def fallback(self) -> HamiltonianSystem | None:
        """The same problem with another cold start and continuation, tried when this one fails.

        Returns
        -------
        HamiltonianSystem or None
            A system whose :meth:`boundary` at fraction 1 is this one's; ``None`` (default): none.
        """
        return None

    def free_boundary(self) -> frozenset[str]:
        """Boundary conditions of the problem this form leaves free or only penalises.

        Returns
        -------
        frozenset of str
            Names of ``planners.base.BOUNDARY_CONDITIONS`` the reference declares free (a free
            attitude, a terminal cost instead of a condition); none by default.
        """
        return frozenset()

    def breakpoints(self, t_f: float) -> Array:
        """Times where the reference's rate may jump (``planners.Reference.breakpoints``).

        Parameters
        ----------
        t_f : float
            The solved final time [s].

        Returns
        -------
        (K,) ndarray
            Times [s] in ``[0, t_f]``; none by default (the torque forms integrate a bounded ``ω̇``).
        """
        return np.zeros(0)

    def __init__(self, problem: ManeuverProblem, t_f: float) -> None:
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

    def __getstate__(self) -> dict[str, Any]:
        """The state to pickle: without the mapped functions' call buffers (capsules), which are
        rebuilt on first use."""
        state = self.__dict__.copy()
        state["_mapped"] = {}
        return state

    @abstractmethod
    def equations(self, t: Any, y: Any, u: Any) -> tuple[Any, Any, Any]:
        """The Hamiltonian system as CasADi expressions, in real time.

        Parameters
        ----------
        t : casadi.SX
            Time [s] (the environment torque depends on it through the orbit).
        y : (2n,) casadi.SX
            ``[x, λ]``, state and co-state.
        u : (3,) casadi.SX
            A free control, for the Hamiltonian.

        Returns
        -------
        rhs : (2n,) casadi.SX
            ``ẏ`` with the optimal control ``u*(y)``.
        hamiltonian : casadi.SX
            ``H(t, y, u)`` with the free ``u``.
        control : (3,) casadi.SX
            ``u*(y)``, the control minimising ``H``.
        """

    @abstractmethod
    def boundary(self, fraction: float) -> Callable[..., Array]:
        """The boundary conditions for ``solve_bvp``.

        Parameters
        ----------
        fraction : float
            Continuation fraction in (0, 1]; 1 is the problem itself, smaller values move the
            target towards the initial state.

        Returns
        -------
        callable
            ``bc(ya, yb, t_f=None) -> residuals``: ``ya``, ``yb`` the ``y`` (2n,) at ``s = 0`` and
            ``s = 1``, ``t_f`` the unknown parameters of a free-time form (``[t_f]``, s); ``2n``
            residuals, plus one for a free final time.
        """

    @abstractmethod
    def guess(self, nodes: int, fraction: float) -> tuple[float, Array, Array]:
        """A cold start for the problem at a continuation fraction.

        Parameters
        ----------
        nodes : int
            Number of mesh points.
        fraction : float
            Continuation fraction in (0, 1].

        Returns
        -------
        t_f : float
            Starting final time [s].
        s : (nodes,) ndarray
            Scaled mesh on [0, 1].
        y : (2n, nodes) ndarray
            States and co-states on the mesh.
        """

    @abstractmethod
    def sample(self, t: Array, y: Array, t_f: float) -> ReferenceSample:
        """Reference quantities from the solution.

        Parameters
        ----------
        t : (m,) ndarray
            Times [s] within ``[0, t_f]``.
        y : (2n, m) ndarray
            ``[x, λ]`` at those times.
        t_f : float
            Final time [s].

        Returns
        -------
        ReferenceSample
            ``q`` (m, 4), ``omega``, ``omega_dot``, ``torque`` (m, 3) (body axes, rad/s, rad/s^2,
            N m; the torque is the rigid-body ``u``, environment torque included).
        """

    def evaluate(self, t: Array, y: Array, derivatives: bool = True) -> tuple[Array, Array | None, Array | None]:
        """The right-hand side and its derivatives at many points, in real time.

        Parameters
        ----------
        t : (m,) ndarray
            Times [s].
        y : (2n, m) ndarray
            ``[x, λ]`` at those times, one column per time.
        derivatives : bool, optional
            Whether to return the Jacobians (default ``True``).

        Returns
        -------
        f : (2n, m) ndarray
            ``ẏ`` in real time (units of ``y`` per second).
        jacobian : (2n, 2n, m) ndarray or None
            ``∂f/∂y``; ``None`` unless ``derivatives``.
        f_t : (2n, m) ndarray or None
            ``∂f/∂t``; ``None`` unless ``derivatives``.
        """
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
        """The Hamiltonian at the optimal control.

        Parameters
        ----------
        t : float
            Time [s].
        y : (2n,) ndarray
            ``[x, λ]``.

        Returns
        -------
        float
            ``H(t, y, u*(y))``.
        """
        return float(self.hamiltonian(t, y, self.control(y)))

    def final_time(self, p: Any) -> float:
        """The final time of a ``solve_bvp`` iterate.

        Parameters
        ----------
        p : sequence of float or None
            ``solve_bvp``'s unknown parameters (``[t_f]`` for a free-time form).

        Returns
        -------
        float
            ``t_f`` [s]: ``p[0]`` for a free-time form, else the fixed time.
        """
        return float(p[0]) if self.free_final_time else self.t_f_fixed


class RigidBodySystem(HamiltonianSystem):
    """States ``x = [q, ω]``; ``I ω̇ = −ω × I ω + M_c + M_gg(q, t)``. Subclasses give ``M_c(λ_ω)``
    and the running cost."""

    n_state = 7
    torque_control = True

    @abstractmethod
    def torque(self, u: Any) -> Any:
        """Control torque of the control variable.

        Parameters
        ----------
        u : (3,) casadi.SX
            The control.

        Returns
        -------
        (3,) casadi.SX
            ``M_c`` [N m], body axes.
        """

    @abstractmethod
    def optimal_control(self, lam_omega: Any) -> Any:
        """The control minimising ``H``.

        Parameters
        ----------
        lam_omega : (3,) casadi.SX or ndarray
            The rate co-state ``λ_ω``.

        Returns
        -------
        (3,) casadi.SX
            ``u*(λ_ω)``.
        """

    def running_cost(self, u: Any) -> Any:
        """The integrand of the cost.

        Parameters
        ----------
        u : (3,) casadi.SX
            The control.

        Returns
        -------
        casadi.SX or float
            ``L(u)``; zero by default (minimum-time and terminal-cost forms).
        """
        return 0

    def equations(self, t: Any, y: Any, u: Any) -> tuple[Any, Any, Any]:
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
        """Environment torque along a trajectory.

        Parameters
        ----------
        t : (m,) ndarray
            Times [s].
        x : (7, m) ndarray
            States ``[q, ω]``, one column per time.

        Returns
        -------
        (3, m) ndarray
            Gravity gradient plus the constant disturbance [N m], body axes.
        """
        model = self.problem.model
        states = np.vstack([x, np.zeros((model.n_wheels, t.size))])
        return model.environment_torque.map(t.size)(states, t, model.default_parameters).full()

    def feedback_torque(self, lam_omega: Array, lam_omega_reference: Array) -> Array:
        """The optimal control torque at an estimated co-state (Vepa eq. 42).

        Parameters
        ----------
        lam_omega : (3,) ndarray
            The estimated rate co-state ``λ̂_ω``.
        lam_omega_reference : (3,) ndarray
            The reference's ``λ_ω`` at the same time (unused by the minimum-energy form).

        Returns
        -------
        (3,) ndarray
            Control torque ``M_c`` [N m], body axes (without the environment torque).
        """
        return np.asarray(self.torque(self.optimal_control(lam_omega)), dtype=float).ravel()
