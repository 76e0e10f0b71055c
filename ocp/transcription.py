"""Optimal-control problems on the attitude model and their transcriptions into NLPs.

The problem (:class:`OptimalControlProblem`) says what is wanted; a transcription
(:class:`RadauCollocation` or :class:`MultipleShooting`, one interface) says how it becomes an NLP.
Both build CasADi SX graphs once per problem structure; boundary values and T enter as parameters
so a built solver is reused across plans. IPOPT solves with exact sparse derivatives.

Conventions: the terminal attitude condition is ``vec(q_f* ⊗ q(T)) = 0``, which accepts ``−q_f``
(the double cover); the quaternion norm is preserved by the kinematics to the discretisation's
accuracy (reported, not constrained). Objective integrands use the actuators' body torque
``τ`` (N m): energy ``‖τ‖²``, L1 ``Σ|τ_i|`` (with slacks), plus ``time_weight · T``.
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ocp import quat_casadi as qc
from ocp.integration import rk4_step
from ocp.model import AttitudeModel

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Cone:
    """Pointing constraint: the body ``boresight`` stays at least (keep-out) or at most (keep-in)
    ``angle`` (rad) from the inertial unit ``direction``."""

    boresight: tuple[float, float, float]
    direction: tuple[float, float, float]
    angle: float
    keep_out: bool = True

    def expression(self, q):
        """``g <= 0`` when satisfied."""
        pointing = ca.mtimes(qc.rotation_matrix(q), ca.DM(self.boresight))
        cosine = ca.dot(pointing, ca.DM(self.direction))
        return cosine - np.cos(self.angle) if self.keep_out else np.cos(self.angle) - cosine


@dataclass(frozen=True)
class OptimalControlProblem:
    """What to optimise. Structural fields shape the NLP; values are passed at solve time."""

    model: AttitudeModel
    energy_weight: float = 1.0
    l1_weight: float = 0.0
    time_weight: float = 0.0
    free_time: bool = False
    fixed_final_rate: bool = True
    cones: tuple[Cone, ...] = ()

    def stage_cost(self, x, u, t, slack=None):
        torque = self.model.actuator_torque(x, u, t)
        cost = self.energy_weight * ca.sumsqr(torque)
        if slack is not None:
            cost += self.l1_weight * ca.sum1(slack)
        return cost

    def path_constraints(self, x):
        return [cone.expression(x[0:4]) for cone in self.cones]


@dataclass
class NLP:
    """A transcribed problem: a built IPOPT solver and how to read its solution."""

    solver: ca.Function
    n_w: int
    unpack: ca.Function            # w -> (T, nodes, states (nx, n_points), controls (nu, n_points))
    lbg: Array
    ubg: Array
    layout: dict = field(default_factory=dict)


class Transcription(ABC):
    """How an :class:`OptimalControlProblem` becomes an NLP on ``intervals`` mesh intervals."""

    name: str

    def __init__(self, intervals: int):
        self.intervals = intervals

    @abstractmethod
    def build(self, problem: OptimalControlProblem, options: dict) -> NLP:
        """Decision vector layout, constraints and objective, with parameters
        ``p = [x0 (nx), qf (4), ωf (3), T, disturbance (3)]``."""

    @staticmethod
    def parameters(model: AttitudeModel):
        p = ca.SX.sym("p", model.nx + 4 + 3 + 1 + 3)
        nx = model.nx
        return p, p[0:nx], p[nx:nx + 4], p[nx + 4:nx + 7], p[nx + 7], p[nx + 8:nx + 11]

    @staticmethod
    def terminal(problem: OptimalControlProblem, x_end, qf, omegaf):
        g = [qc.product(qc.conjugate(qf), x_end[0:4])[1:4]]
        if problem.fixed_final_rate:
            g.append(x_end[4:7] - omegaf)
        return g


class RadauCollocation(Transcription):
    """Legendre-Gauss-Radau collocation of degree ``degree``: states at the interval start and at the
    ``degree`` Radau points, controls at the Radau points (so a control polynomial of degree
    ``degree − 1`` per interval), path constraints also imposed midway between state points."""

    name = "collocation"

    def __init__(self, intervals: int, degree: int = 3):
        super().__init__(intervals)
        self.degree = degree
        tau = np.append(0.0, ca.collocation_points(degree, "radau"))
        self.tau = tau
        self.derivative = np.zeros((degree + 1, degree + 1))  # derivative[r, j] = ℓ_r'(τ_j)
        self.quadrature = np.zeros(degree + 1)
        for r in range(degree + 1):
            basis = np.poly1d([1.0])
            for s in range(degree + 1):
                if s != r:
                    basis *= np.poly1d([1.0, -tau[s]]) / (tau[r] - tau[s])
            self.derivative[r] = np.polyder(basis)(tau)
            self.quadrature[r] = np.polyint(basis)(1.0)
        midpoints = 0.5 * (tau[:-1] + tau[1:])
        self.midpoint_weights = np.array([[np.prod([(m - tau[s]) / (tau[r] - tau[s]) for s in range(degree + 1) if s != r])
                                           for r in range(degree + 1)] for m in midpoints])

    def build(self, problem: OptimalControlProblem, options: dict) -> NLP:
        model, d, N = problem.model, self.degree, self.intervals
        nx, nu = model.nx, model.nu
        p, x0, qf, omegaf, T_param, disturbance = self.parameters(model)
        T = ca.SX.sym("T") if problem.free_time else T_param
        use_slack = problem.l1_weight > 0
        X = [ca.SX.sym(f"X_{k}", nx, d + 1) for k in range(N)]
        U = [ca.SX.sym(f"U_{k}", nu, d) for k in range(N)]
        S = [ca.SX.sym(f"S_{k}", 3, d) for k in range(N)] if use_slack else []
        x_end = ca.SX.sym("X_end", nx)
        g, lbg, ubg, cost = [X[0][:, 0] - x0], [np.zeros(nx)], [np.zeros(nx)], 0
        h = T / N
        for k in range(N):
            for j in range(1, d + 1):
                t_kj = h * (k + self.tau[j])
                slope = ca.mtimes(X[k], ca.DM(self.derivative[:, j]))
                x_kj, u_kj = X[k][:, j], U[k][:, j - 1]
                g.append(slope - h * model.dynamics(x_kj, u_kj, t_kj, disturbance))
                lbg.append(np.zeros(nx)), ubg.append(np.zeros(nx))
                slack = None
                if use_slack:
                    slack = S[k][:, j - 1]
                    torque = model.actuator_torque(x_kj, u_kj, t_kj)
                    g += [slack - torque, slack + torque]
                    lbg += [np.zeros(3)] * 2
                    ubg += [np.full(3, np.inf)] * 2
                cost += h * self.quadrature[j] * problem.stage_cost(x_kj, u_kj, t_kj, slack)
            following = X[k + 1][:, 0] if k + 1 < N else x_end
            g.append(following - X[k][:, d])
            lbg.append(np.zeros(nx)), ubg.append(np.zeros(nx))
            states = [X[k][:, j] for j in range(d + 1)] + [ca.mtimes(X[k], ca.DM(w)) for w in self.midpoint_weights]
            for state in states:
                for constraint in problem.path_constraints(state):
                    g.append(constraint), lbg.append([-np.inf]), ubg.append([0.0])
        for constraint in self.terminal(problem, x_end, qf, omegaf):
            g.append(constraint), lbg.append(np.zeros(constraint.numel())), ubg.append(np.zeros(constraint.numel()))
        cost += problem.time_weight * T
        blocks = [ca.vec(v) for v in X] + [ca.vec(v) for v in U] + [ca.vec(v) for v in S] + [x_end]
        if problem.free_time:
            blocks.append(T)
        w = ca.vertcat(*blocks)
        nodes = ca.vertcat(*[h * (k + ca.DM(self.tau)) for k in range(N)])
        unpack = ca.Function("unpack", [w, p], [T, nodes, ca.horzcat(*X), ca.horzcat(*U)])
        solver = ca.nlpsol("collocation", "ipopt", {"x": w, "p": p, "f": cost, "g": ca.vertcat(*g)}, options)
        layout = {"X": (N, nx, d + 1), "U": (N, nu, d), "S": len(S) * 3 * d, "free_time": problem.free_time}
        return NLP(solver, w.numel(), unpack, np.concatenate([np.ravel(v) for v in lbg]),
                   np.concatenate([np.ravel(v) for v in ubg]), layout)


class MultipleShooting(Transcription):
    """Multiple shooting with piecewise-linear continuous controls and ``substeps`` RK4 steps per
    interval; the running cost is integrated by the same RK4 as an extra state."""

    name = "multiple_shooting"

    def __init__(self, intervals: int, substeps: int = 4):
        super().__init__(intervals)
        self.substeps = substeps

    def build(self, problem: OptimalControlProblem, options: dict) -> NLP:
        if problem.l1_weight > 0 or problem.cones:
            raise ValueError("multiple shooting supports energy and time objectives without cones; use collocation")
        model, N, M = problem.model, self.intervals, self.substeps
        nx, nu = model.nx, model.nu
        # One interval as a compact SX function, mapped over the intervals in an MX graph: the NLP's
        # derivatives then come from AD of this function instead of one deep inlined expression.
        x, u0, u1 = ca.SX.sym("x", nx), ca.SX.sym("u0", nu), ca.SX.sym("u1", nu)
        t_start, h_interval, dist = ca.SX.sym("t0"), ca.SX.sym("h"), ca.SX.sym("d", 3)
        h = h_interval / M

        def augmented(state, t):
            fraction = (t - t_start) / h_interval  # piecewise-linear control across the interval
            control = (1 - fraction) * u0 + fraction * u1
            return ca.vertcat(model.dynamics(state[:nx], control, t, dist),
                              problem.stage_cost(state[:nx], control, t))

        state = ca.vertcat(x, 0)
        for m in range(M):
            state = rk4_step(augmented, state, t_start + h * m, h)
        interval = ca.Function("interval", [x, u0, u1, t_start, h_interval, dist], [state[:nx], state[nx]])
        shots = interval.map(N)

        p = ca.MX.sym("p", nx + 4 + 3 + 1 + 3)
        x0, qf, omegaf, T_param, disturbance = p[0:nx], p[nx:nx + 4], p[nx + 4:nx + 7], p[nx + 7], p[nx + 8:nx + 11]
        T = ca.MX.sym("T") if problem.free_time else T_param
        X, U = ca.MX.sym("X", nx, N + 1), ca.MX.sym("U", nu, N + 1)
        starts = ca.DM(np.arange(N)).T * (T / N)
        ends, costs = shots(X[:, :N], U[:, :N], U[:, 1:], starts, T / N, disturbance)
        g = [X[:, 0] - x0, ca.vec(X[:, 1:] - ends)]
        lbg = [np.zeros(nx), np.zeros(nx * N)]
        for constraint in self.terminal(problem, X[:, N], qf, omegaf):
            g.append(constraint), lbg.append(np.zeros(constraint.numel()))
        cost = ca.sum2(costs) + problem.time_weight * T
        w = ca.vertcat(ca.vec(X), ca.vec(U), *([T] if problem.free_time else []))
        unpack = ca.Function("unpack", [w, p], [T, ca.DM(np.linspace(0, 1, N + 1)) * T, X, U])
        solver = ca.nlpsol("multiple_shooting", "ipopt", {"x": w, "p": p, "f": cost, "g": ca.vertcat(*g)}, options)
        layout = {"X": (1, nx, N + 1), "U": (1, nu, N + 1), "S": 0, "free_time": problem.free_time}
        bounds = np.concatenate([np.ravel(v) for v in lbg])
        return NLP(solver, w.numel(), unpack, bounds, bounds.copy(), layout)


TRANSCRIPTIONS: dict[str, type[Transcription]] = {cls.name: cls for cls in (RadauCollocation, MultipleShooting)}
