"""Legendre-Gauss-Radau collocation as a :class:`~ocp.transcription.base.Transcription`.

Per interval: the state at its start (the stage state ``s_k``) and at the ``degree`` Radau points
``τ_1 … τ_d`` (``τ_d = 1``), controls at the Radau points (a control polynomial of degree
``d − 1``), L1 slacks there when the cost needs them. The gap condition is
``s_{k+1} = X_k(τ_d)``. The running cost is the Radau quadrature ``h Σ_j w_j L(x_j, u_j)`` with the
weights of the ``d``-point Radau rule (exact for polynomials of degree ``2d − 2``): ``w_j = ∫₀¹ ℓ_j``
for the Lagrange basis through the Radau points alone (degree 1: the single weight 1). Path
constraints (cones) hold at every state point and midway between them.
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

import casadi as ca
import numpy as np

from ocp.dynamics.model import AttitudeModel
from ocp.transcription.base import Array, Transcription
from ocp.transcription.problem import Interval, OptimalControlProblem


def lagrange(points: Array, tau: Array) -> Array:
    """Values of the Lagrange basis through ``points``.

    Parameters
    ----------
    points : (n,) ndarray
        Distinct interpolation points (dimensionless).
    tau : (m,) ndarray
        Where to evaluate the basis.

    Returns
    -------
    (m, n) ndarray
        ``[i, r] = ℓ_r(tau[i])``.
    """
    basis = np.ones((tau.size, points.size))
    for r, p_r in enumerate(points):
        for s, p_s in enumerate(points):
            if s != r:
                basis[:, r] *= (tau - p_s) / (p_r - p_s)
    return basis


def differentiation_matrix(points: Array) -> Array:
    """Derivatives of the Lagrange basis through ``points`` at those points (barycentric form).

    Parameters
    ----------
    points : (n,) ndarray
        Distinct interpolation points (dimensionless, e.g. on [0, 1]).

    Returns
    -------
    (n, n) ndarray
        ``D[r, j] = ℓ_r'(points[j])``.
    """
    difference = points[:, None] - points[None, :]
    np.fill_diagonal(difference, 1.0)
    barycentric = 1.0 / np.prod(difference, axis=1)
    derivative = (barycentric[None, :] / barycentric[:, None]) / difference  # [j, r], r != j
    np.fill_diagonal(derivative, 0.0)
    np.fill_diagonal(derivative, -derivative.sum(axis=1))
    return derivative.T


def radau_weights(degree: int) -> Array:
    """Weights on [0, 1] of the ``degree``-point Radau rule (right end point included).

    Parameters
    ----------
    degree : int
        Number of Radau points.

    Returns
    -------
    (degree,) ndarray
        ``w_j = ∫₀¹ ℓ_j`` for the Lagrange basis through the Radau points.
    """
    points = np.asarray(ca.collocation_points(degree, "radau"))
    # Exact for the monomials 1 … τ^(d−1): Σ_j w_j τ_j^k = 1/(k + 1), the same weights as ∫ ℓ_j.
    return np.linalg.solve(np.vander(points, degree, increasing=True).T, 1.0 / np.arange(1, degree + 1))


class RadauCollocation(Transcription):
    """Legendre-Gauss-Radau collocation of degree ``degree`` (see the module docstring).

    Parameters
    ----------
    intervals : int
        Number of mesh intervals.
    degree : int
        Radau points per interval (state polynomials of this degree).
    mesh : (intervals + 1,) array_like or None
        The mesh nodes as fractions of T (:class:`~ocp.transcription.base.Transcription`);
        ``None`` (default): uniform.
    """

    name = "collocation"
    non_uniform = True
    fatrop_seed = True  # see planners.collocation.strategy.SEED_FATROP

    def __init__(self, intervals: int, degree: int = 3, mesh: Array | None = None) -> None:
        super().__init__(intervals, mesh)
        self.degree = degree
        tau = np.append(0.0, ca.collocation_points(degree, "radau"))
        self.tau = tau
        self.derivative = differentiation_matrix(tau)  # [r, j] = ℓ_r'(τ_j)
        self.quadrature = radau_weights(degree)
        midpoints = 0.5 * (tau[:-1] + tau[1:])
        self.midpoint_weights = lagrange(tau, midpoints)
        for table in (self.tau, self.derivative, self.quadrature, self.midpoint_weights):
            table.setflags(write=False)  # shared by every plan of a cached transcription: read-only

    @classmethod
    def from_options(cls, options: Any) -> RadauCollocation:
        return cls(options.intervals, options.degree)

    def _sizes(self, problem: OptimalControlProblem) -> tuple[int, int, int]:
        model, d = problem.model, self.degree
        return model.nx * d, model.nu * d, (3 * d if problem.uses_slack else 0)

    def state_of(self, s: Any) -> Any:
        return s

    def interval(self, problem: OptimalControlProblem) -> Interval:
        model, d = problem.model, self.degree
        nx, nu = model.nx, model.nu
        n_states, n_controls, n_slack = self._sizes(problem)
        s, c = ca.SX.sym("s", nx), ca.SX.sym("c", n_states + n_controls + n_slack)
        t0, h, dist = ca.SX.sym("t0"), ca.SX.sym("h"), ca.SX.sym("d", 3)
        X = ca.horzcat(s, ca.reshape(c[:n_states], nx, d))
        U = ca.reshape(c[n_states:n_states + n_controls], nu, d)
        slack = ca.reshape(c[n_states + n_controls:], 3, d) if n_slack else None
        equalities, inequalities, cost = [], [], 0
        for j in range(1, d + 1):
            t_j = t0 + h * self.tau[j]
            x_j, u_j = X[:, j], U[:, j - 1]
            equalities.append(ca.mtimes(X, ca.DM(self.derivative[:, j])) - h * model.dynamics(x_j, u_j, t_j, dist))
            s_j = None
            if slack is not None:
                s_j = slack[:, j - 1]
                torque = model.actuator_torque(x_j, u_j, t_j)
                inequalities += [s_j - torque, s_j + torque]
            cost += h * self.quadrature[j - 1] * problem.stage_cost(x_j, u_j, t_j, s_j)
        cones = []
        if problem.n_path:
            # the node, the Radau points and the midpoints between them (positions()), each at its time
            states = [X[:, j] for j in range(d + 1)] + [ca.mtimes(X, ca.DM(w)) for w in self.midpoint_weights]
            for state, tau in zip(states, self._path_points()):
                cones += problem.path_constraints(state, t0 + h * tau)
        path = ca.vertcat(*equalities, *inequalities, *cones)
        n_eq, n_ineq = nx * d, 6 * d if n_slack else 0
        lower = np.concatenate([np.zeros(n_eq), np.zeros(n_ineq), np.full(len(cones), -np.inf)])
        upper = np.concatenate([np.zeros(n_eq), np.full(n_ineq, np.inf), np.zeros(len(cones))])
        function = ca.Function("radau_interval", [s, c, t0, h, dist], [X[:, d], path, cost])
        return Interval(function, nx, c.numel(), lower, upper)

    def positions(self, problem: OptimalControlProblem, interval: Interval) -> tuple[Array, Array]:
        model, tau = problem.model, self.tau
        slack = 3 if problem.uses_slack else 0  # per Radau point (_sizes)
        c = np.concatenate([np.repeat(tau[1:], model.nx), np.repeat(tau[1:], model.nu), np.repeat(tau[1:], slack)])
        # collocation equations and slack inequalities at the Radau points; cones (and the rate
        # norm) at the node, the Radau points and the midpoints between them (the order of interval())
        path = np.concatenate([np.repeat(tau[1:], model.nx), np.repeat(tau[1:], 2 * slack),
                               np.repeat(self._path_points(), problem.n_path)])
        return c, path

    def _path_points(self) -> Array:
        """Where the path constraints are imposed, as fractions of the interval: the node, the
        Radau points and the midpoints between consecutive points."""
        tau = self.tau
        return np.concatenate([tau, 0.5 * (tau[:-1] + tau[1:])])

    def stage_bounds(self, problem: OptimalControlProblem, x_low: Array, x_high: Array, u_low: Array,
                     u_high: Array) -> tuple[Array, Array, Array, Array]:
        d = self.degree
        _, _, n_slack = self._sizes(problem)
        c_low = np.concatenate([np.tile(x_low, d), np.tile(u_low, d), np.zeros(n_slack)])
        c_high = np.concatenate([np.tile(x_high, d), np.tile(u_high, d), np.full(n_slack, np.inf)])
        return x_low, x_high, c_low, c_high

    def stage_guess(self, problem: OptimalControlProblem, sample: Callable[[Array], tuple[Array, Array, Array]],
                    duration: float) -> tuple[Array, Array]:
        N = self.intervals
        if self.mesh is None:
            h = duration / N
            nodes = np.arange(N + 1, dtype=float) * h
            times = ((np.arange(N)[:, None] + self.tau[None, 1:]) * h).ravel()
        else:
            nodes = self.mesh * duration
            times = (self.fractions(np.arange(N)[:, None], self.tau[None, 1:]) * duration).ravel()
        # one call for the nodes and the points (a sample's rows depend on their own times only)
        x_all, u_all, torque_all = sample(np.concatenate([nodes, times]))
        x_nodes, x, u, torque = x_all[:N + 1], x_all[N + 1:], u_all[N + 1:], torque_all[N + 1:]
        blocks = [x.reshape(N, -1), u.reshape(N, -1)]
        if problem.uses_slack:
            blocks.append(torque.reshape(N, -1))
        return x_nodes.T, np.hstack(blocks).T

    def split(self, S: Any, C: Any) -> tuple[Any, Any]:
        nx, d, N = S.shape[0], self.degree, self.intervals
        # column k of [S; interior] is [x_k0, x_k1 … x_kd]: reshaped, the states point by point
        states = ca.reshape(ca.vertcat(S[:, :N], C[:nx * d, :]), nx, N * (d + 1))
        return states, C[nx * d:, :]

    def smoothness(self, duration: float) -> tuple[Array, Array]:
        # The state polynomials join continuously at the mesh nodes, their slopes and the controls
        # do not; the dynamics hold at the Radau points inside each interval.
        radau = self.tau[1:-1] if self.tau[-1] == 1.0 else self.tau[1:]
        if self.mesh is not None:
            inner = (self.fractions(np.arange(self.intervals)[:, None], radau[None, :]) * duration).ravel()
            return self.mesh[1:-1] * duration, inner
        nodes = np.arange(1, self.intervals) * duration / self.intervals
        inner = ((np.arange(self.intervals)[:, None] + radau[None, :]) * duration / self.intervals).ravel()
        return nodes, inner

    def interpolate(self, model: AttitudeModel, states: Array, controls: Array, duration: float,
                    t: Array, left: bool = False) -> tuple[Array, Array]:
        N, d = self.intervals, self.degree
        # The control polynomial passes through τ_1 … τ_d = 1 only: its value at τ = 0 is an
        # extrapolation, while the left limit at a node is the decision variable of the ending
        # interval's point τ_d = 1 (``interval_index``'s ``left``).
        k = self.interval_index(duration, t, left)
        if self.mesh is None:
            tau = np.asarray(t, dtype=float) * N / duration - k
        else:
            tau = (np.asarray(t, dtype=float) / duration - self.mesh[k]) / (self.mesh[k + 1] - self.mesh[k])
        X = states.reshape(model.nx, N, d + 1)
        U = controls[:model.nu * d, :].reshape(d, model.nu, N).transpose(1, 2, 0)
        x = np.einsum("tik,tk->ti", X[:, k, :].transpose(1, 0, 2), lagrange(self.tau, tau))
        u = np.einsum("tik,tk->ti", U[:, k, :].transpose(1, 0, 2), lagrange(self.tau[1:], tau))
        return x, u
