"""Multiple shooting as a :class:`~ocp.transcription.base.Transcription`.

Controls are piecewise linear and continuous. To keep the stage-wise structure (FATROP) the stage
state carries the control at the mesh point, ``s_k = [x_k, u_k]``, and the interval's variable is
the next control, ``c_k = u_{k+1}``; the gap conditions are ``x_{k+1} = Φ(x_k, u_k, u_{k+1})``
(``substeps`` RK4 steps, the running cost integrated as an extra state by the same RK4) and
``u_{k+1} = c_k``. The controls are ``u_0`` (the first stage state's) and the interval variables
``c_0 … c_{N−1}`` (:meth:`MultipleShooting.initial_controls`, :meth:`MultipleShooting.control_points`):
a linear condition on each of them holds on every interval's linear control. Path constraints
(cones, the rate norm) hold at the end of every RK4 step, at its time (the initial state is
given). The interval is expanded to SX (one compact function mapped over the mesh). States between
nodes: cubic Hermite with the model's derivatives.
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ocp.dynamics.integration import rk4_step
from ocp.dynamics.model import AttitudeModel
from ocp.transcription.base import Array, Transcription
from ocp.transcription.problem import Interval, OptimalControlProblem


class MultipleShooting(Transcription):
    """Multiple shooting with piecewise-linear controls (see the module docstring).

    Parameters
    ----------
    intervals : int
        Number of mesh intervals.
    substeps : int
        RK4 steps per interval.
    """

    name = "multiple_shooting"

    def __init__(self, intervals: int, substeps: int = 4) -> None:
        super().__init__(intervals)
        self.substeps = substeps

    @classmethod
    def from_options(cls, options: Any) -> MultipleShooting:
        return cls(options.intervals, getattr(options, "substeps", 4))

    @classmethod
    def problem_error(cls, l1: bool, cones: bool) -> str | None:
        if l1:
            return "multiple_shooting supports energy and time objectives; use transcription: collocation for L1 costs"
        return None

    def state_of(self, s: Any) -> Any:
        return s[:self._nx]

    def control_points(self, problem: OptimalControlProblem, s: Any, c: Any) -> list[tuple[Any, float]]:
        # c_k = u_{k+1}, the control at the interval's end: u_1 … u_N over the mesh (the stage
        # states' copies equal them through the gaps); u_0 is the first stage state's
        return [(c, 1.0)]

    def initial_controls(self, problem: OptimalControlProblem, s: Any) -> list[Any]:
        # u_0, in s_0 = [x_0, u_0]: no interval's own variable
        return [s[problem.model.nx:]]

    def interval(self, problem: OptimalControlProblem) -> Interval:
        model, M = problem.model, self.substeps
        nx, nu = model.nx, model.nu
        self._nx = nx
        s, u1 = ca.SX.sym("s", nx + nu), ca.SX.sym("u1", nu)
        x, u0 = s[:nx], s[nx:]
        t0, h_interval, dist = ca.SX.sym("t0"), ca.SX.sym("h"), ca.SX.sym("d", 3)
        h = h_interval / M

        def augmented(state, t):
            fraction = (t - t0) / h_interval
            control = (1 - fraction) * u0 + fraction * u1
            return ca.vertcat(model.dynamics(state[:nx], control, t, dist), problem.stage_cost(state[:nx], control, t))

        state = ca.vertcat(x, 0)
        path = []
        for m in range(M):
            state = rk4_step(augmented, state, t0 + h * m, h)
            # path constraints at the end of every RK4 step, at its time (positions())
            path += problem.path_constraints(state[:nx], t0 + h * (m + 1))
        function = ca.Function("shooting_interval", [s, u1, t0, h_interval, dist],
                               [ca.vertcat(state[:nx], u1), ca.vertcat(*path) if path else ca.DM.zeros(0, 1),
                                state[nx]])
        return Interval(function, nx + nu, nu, np.full(len(path), -np.inf), np.zeros(len(path)))

    def positions(self, problem: OptimalControlProblem, interval: Interval) -> tuple[Array, Array]:
        # c_k is the control at the interval's end; path constraints at the ends of the RK4 steps
        steps = np.arange(1, self.substeps + 1) / self.substeps
        return np.ones(interval.n_interval), np.repeat(steps, problem.n_path)

    def step_scaled_gaps(self, problem: OptimalControlProblem, interval: Interval) -> NDArray[np.bool_]:
        # x_{k+1} = Φ(...): a costate; u_{k+1} = c_k: O(h) (the control's stationarity)
        nx = problem.model.nx
        return np.arange(interval.n_state) >= nx

    def stage_bounds(self, problem: OptimalControlProblem, x_low: Array, x_high: Array, u_low: Array,
                     u_high: Array) -> tuple[Array, Array, Array, Array]:
        return np.concatenate([x_low, u_low]), np.concatenate([x_high, u_high]), u_low, u_high

    def stage_guess(self, problem: OptimalControlProblem, sample: Callable[[Array], tuple[Array, Array, Array]],
                    duration: float) -> tuple[Array, Array]:
        N = self.intervals
        x, u, _ = sample(np.linspace(0.0, duration, N + 1))
        return np.hstack([x, u]).T, u[1:].T

    def split(self, S: Any, C: Any) -> tuple[Any, Any]:
        nx = self._nx
        return S[:nx, :], S[nx:, :]

    def smoothness(self, duration: float) -> tuple[Array, Array]:
        # Cubic Hermite states with the model's derivatives at the nodes: C¹, exact at the nodes.
        return np.zeros(0), np.arange(1, self.intervals) * duration / self.intervals

    def interpolate(self, model: AttitudeModel, states: Array, controls: Array, duration: float,
                    t: Array, left: bool = False) -> tuple[Array, Array]:
        # states (cubic Hermite) and controls (linear) are continuous at the nodes: ``left`` is moot
        N = self.intervals
        h = duration / N
        k = np.minimum((t / h).astype(int), N - 1)
        tau = t / h - k
        u = (1 - tau)[:, None] * controls[:, k].T + tau[:, None] * controls[:, k + 1].T
        x0, x1 = states[:, k].T, states[:, k + 1].T
        disturbance = model.default_parameters
        n = t.size

        def rhs(x, u_, times):
            return model.rhs.map(n)(x.T, u_.T, times, np.tile(disturbance[:, None], n)).full().T

        f0, f1 = rhs(x0, controls[:, k].T, k * h), rhs(x1, controls[:, k + 1].T, (k + 1) * h)
        h00, h10 = 2 * tau**3 - 3 * tau**2 + 1, tau**3 - 2 * tau**2 + tau
        h01, h11 = -2 * tau**3 + 3 * tau**2, tau**3 - tau**2
        x = h00[:, None] * x0 + h10[:, None] * h * f0 + h01[:, None] * x1 + h11[:, None] * h * f1
        return x, u
