"""Optimal-control problems on the attitude model, and the stage-wise NLP every transcription shares.

The problem (:class:`OptimalControlProblem`) says what is wanted; a :class:`Transcription` says how
one mesh interval becomes NLP variables and constraints. It owns its layout: the interval as a
CasADi function (mapped over the mesh, never called node by node from Python), the variables'
bounds, the seeding from another reference and the interpolation of the solution.

Every transcription is assembled the same way (:meth:`Transcription.build`), stage-wise as
structure-exploiting solvers need it (FATROP's ``structure_detection: auto``):

* variables ``w = [s_0, c_0, s_1, c_1, …, s_{N−1}, c_{N−1}, s_N]``: the stage state ``s_k`` (the
  model state at the mesh point, plus what the transcription carries across intervals, plus
  ``T`` when the final time is free: ``T_{k+1} = T_k`` is then an explicit continuity condition)
  and the interval's own variables ``c_k``;
* constraints ``[gap_0, path_0, x_0 − x0, gap_1, path_1, …, terminal]`` with
  ``gap_k = s_{k+1} − F(s_k, c_k)`` (explicit continuity) and the interval's path constraints.

Parameters ``p = [x0 (nx), qf (4), ωf (3), T, disturbance (3)]``: boundary values and T are not
baked into the graph, so a built solver is reused across plans.

Conventions: the terminal attitude condition is ``vec(q_f* ⊗ q(T)) = 0``, which accepts ``−q_f``;
the quaternion norm is preserved by the kinematics to the discretisation's accuracy (reported, not
constrained). Objective integrands use the actuators' body torque ``τ`` (N m): energy ``‖τ‖²``,
L1 ``Σ|τ_i|`` (with slacks), plus ``time_weight · T``.
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ocp import quat_casadi as qc
from ocp.model import AttitudeModel

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Cone:
    """Pointing constraint: the body ``boresight`` stays at least (keep-out) or at most (keep-in)
    ``angle`` from the inertial unit ``direction``.

    Parameters
    ----------
    boresight : (3,) tuple of float
        Unit vector, body axes.
    direction : (3,) tuple of float
        Unit vector, inertial frame.
    angle : float
        Cone half-angle [rad].
    keep_out : bool
        ``True``: the boresight stays outside the cone; ``False``: inside.
    """

    boresight: tuple[float, float, float]
    direction: tuple[float, float, float]
    angle: float
    keep_out: bool = True

    def expression(self, q: Any) -> Any:
        """The constraint as ``g <= 0`` (satisfied when non-positive).

        Parameters
        ----------
        q : (4,) CasADi expression
            Attitude quaternion (scalar first, body to inertial).

        Returns
        -------
        CasADi scalar expression
            Cosine of the boresight-direction angle minus ``cos(angle)`` (keep-out), or the
            negative (keep-in).
        """
        pointing = ca.mtimes(qc.rotation_matrix(q), ca.DM(self.boresight))
        cosine = ca.dot(pointing, ca.DM(self.direction))
        return cosine - np.cos(self.angle) if self.keep_out else np.cos(self.angle) - cosine


@dataclass(frozen=True)
class OptimalControlProblem:
    """What to optimise. Structural fields shape the NLP; values are passed at solve time.

    Parameters
    ----------
    model : AttitudeModel
        The spacecraft model (state ``x = [q, ω, h_w]``, control ``u`` of its actuators).
    energy_weight : float
        Weight of ∫‖τ‖² dt, τ the actuators' body torque [N m] (objective in N² m² s).
    l1_weight : float
        Weight of ∫Σ|τ_i| dt [N m s] (slack variables).
    time_weight : float
        Weight of the final time T [s].
    free_time : bool
        T is a decision variable (bounded by the problem's duration) instead of a parameter.
    fixed_final_rate : bool
        The final body rate is constrained to ``ω_f``.
    cones : tuple of Cone
        Pointing constraints along the path.
    """

    model: AttitudeModel
    energy_weight: float = 1.0
    l1_weight: float = 0.0
    time_weight: float = 0.0
    free_time: bool = False
    fixed_final_rate: bool = True
    cones: tuple[Cone, ...] = ()

    @property
    def uses_slack(self) -> bool:
        """Whether the cost needs L1 slack variables (``l1_weight > 0``)."""
        return self.l1_weight > 0

    def stage_cost(self, x: Any, u: Any, t: Any, slack: Any = None) -> Any:
        """The running cost's integrand.

        Parameters
        ----------
        x : (nx,) CasADi expression
            Model state.
        u : (nu,) CasADi expression
            Actuator controls.
        t : CasADi scalar
            Time [s].
        slack : (3,) CasADi expression or None
            L1 slacks bounding ``|τ_i|`` [N m] (``None`` without an L1 cost).

        Returns
        -------
        CasADi scalar expression
            ``energy_weight ‖τ‖² + l1_weight Σ slack``.
        """
        torque = self.model.actuator_torque(x, u, t)
        cost = self.energy_weight * ca.sumsqr(torque)
        if slack is not None:
            cost += self.l1_weight * ca.sum1(slack)
        return cost

    def path_constraints(self, x: Any) -> list[Any]:
        """The cones' constraints at one state.

        Parameters
        ----------
        x : (nx,) CasADi expression
            Model state (its first four entries are the quaternion).

        Returns
        -------
        list of CasADi scalar expressions
            One ``g <= 0`` per cone.
        """
        return [cone.expression(x[0:4]) for cone in self.cones]


@dataclass
class NLP:
    """A transcribed problem: a built solver and how to read its solution.

    Parameters
    ----------
    solver : casadi.Function
        The ``nlpsol`` function (inputs ``x0, p, lbx, ubx, lbg, ubg, lam_x0, lam_g0``).
    n_w : int
        Number of decision variables.
    unpack : casadi.Function
        ``unpack(w, p) -> (T [s], states, controls)`` in the transcription's own point layout.
    lbg, ubg : ndarray
        Constraint bounds.
    free_time : bool
        T is a decision variable (the last entry of every stage state).
    n_stage_state : int
        Size of a stage state ``s_k`` (T included when free).
    n_interval : int
        Size of an interval's own variables ``c_k``.
    layout : dict
        Transcription-specific notes on the layout (may be empty).
    """

    solver: ca.Function
    n_w: int
    unpack: ca.Function
    lbg: Array
    ubg: Array
    free_time: bool
    n_stage_state: int
    n_interval: int
    layout: dict[str, Any] = field(default_factory=dict)


@dataclass
class Interval:
    """One mesh interval, built by a transcription.

    Parameters
    ----------
    function : casadi.Function
        ``function(s, c, t0, h, d) -> (next, path, cost)`` with ``s`` the stage state without T,
        ``c`` the interval's variables, ``t0`` its start time [s], ``h`` its length [s], ``d`` the
        disturbance parameter (body torque [N m]); ``next`` is the stage state the interval reaches.
    n_state : int
        Size of ``s`` (without T).
    n_interval : int
        Size of ``c``.
    path_lower, path_upper : ndarray
        Bounds of ``path`` (``path_lower <= path <= path_upper``).
    """

    function: ca.Function
    n_state: int
    n_interval: int
    path_lower: Array
    path_upper: Array


class Transcription(ABC):
    """How an :class:`OptimalControlProblem` becomes an NLP on ``intervals`` mesh intervals.

    Subclasses implement :meth:`interval` (one interval as a CasADi function), the layout methods
    :meth:`stage_bounds`, :meth:`stage_guess`, :meth:`split` and :meth:`interpolate`, and
    :meth:`problem_error` for formulations they cannot take.

    Parameters
    ----------
    intervals : int
        Number of mesh intervals (equal lengths T / intervals).
    """

    name: str

    def __init__(self, intervals: int) -> None:
        self.intervals = intervals

    @classmethod
    @abstractmethod
    def from_options(cls, options: Any) -> Transcription:
        """The transcription configured from a planner's options.

        Parameters
        ----------
        options : object
            A planner's ``Options`` (``intervals``, ``degree``, ``substeps``, ...).

        Returns
        -------
        Transcription
        """

    @classmethod
    def problem_error(cls, l1: bool, cones: bool) -> str | None:
        """Why this transcription cannot take a formulation.

        Parameters
        ----------
        l1 : bool
            The cost has an L1 term.
        cones : bool
            The problem has pointing cones.

        Returns
        -------
        str or None
            The reason, or ``None`` when it can.
        """
        return None

    @abstractmethod
    def interval(self, problem: OptimalControlProblem) -> Interval:
        """One interval as a CasADi function.

        Parameters
        ----------
        problem : OptimalControlProblem
            What to optimise.

        Returns
        -------
        Interval
        """

    @abstractmethod
    def state_of(self, s: Any) -> Any:
        """The model state inside a stage state.

        Parameters
        ----------
        s : CasADi expression
            A stage state ``s_k`` (without T).

        Returns
        -------
        (nx,) CasADi expression
        """

    @abstractmethod
    def stage_bounds(self, problem: OptimalControlProblem, x_low: Array, x_high: Array, u_low: Array,
                     u_high: Array) -> tuple[Array, Array, Array, Array]:
        """Bounds of ``s_k`` (without T) and of ``c_k``.

        Parameters
        ----------
        problem : OptimalControlProblem
            What to optimise.
        x_low, x_high : (nx,) ndarray
            Bounds of the model state at every point (quaternion, rad/s, N m s).
        u_low, u_high : (nu,) ndarray
            Bounds of the actuator controls.

        Returns
        -------
        tuple of ndarray
            ``(s_low, s_high, c_low, c_high)``.
        """

    @abstractmethod
    def stage_guess(self, problem: OptimalControlProblem, sample: Callable[[Array], tuple[Array, Array, Array]],
                    duration: float) -> tuple[Array, Array]:
        """Initial guess of the stage states and interval variables.

        Parameters
        ----------
        problem : OptimalControlProblem
            What to optimise.
        sample : callable
            ``sample(times) -> (x (n, nx), u (n, nu), |torque| (n, 3))`` along the seeding reference.
        duration : float
            Duration of the guess [s].

        Returns
        -------
        tuple of ndarray
            ``(S (ns, N + 1), C (nc, N))``.
        """

    @abstractmethod
    def split(self, S: Any, C: Any) -> tuple[Any, Any]:
        """States and controls at the transcription's points from the stage matrices.

        Parameters
        ----------
        S : CasADi matrix (ns, N + 1)
            Stage states (without T).
        C : CasADi matrix (nc, N)
            Interval variables.

        Returns
        -------
        tuple
            ``(states, controls)`` as CasADi matrices, one column per point.
        """

    @abstractmethod
    def interpolate(self, model: AttitudeModel, states: Array, controls: Array, duration: float,
                    t: Array) -> tuple[Array, Array]:
        """The solution between its points.

        Parameters
        ----------
        model : AttitudeModel
            The spacecraft model.
        states, controls : ndarray
            ``unpack``'s states and controls (one column per point).
        duration : float
            T [s].
        t : (n,) ndarray
            Times in ``[0, duration]`` [s].

        Returns
        -------
        tuple of ndarray
            States ``(n, nx)`` and controls ``(n, nu)``.
        """

    @abstractmethod
    def smoothness(self, duration: float) -> tuple[Array, Array]:
        """Where an interpolated solution over ``[0, duration]`` may kink and where it is exact.

        Parameters
        ----------
        duration : float
            T [s].

        Returns
        -------
        tuple of ndarray
            ``(breakpoints, enforced_times)`` [s]: the times where its slopes may jump, and the
            times where the dynamics are imposed.
        """

    # -- the shared stage-wise assembly -------------------------------------------------------
    @staticmethod
    def terminal(problem: OptimalControlProblem, x_end: Any, qf: Any, omegaf: Any) -> list[Any]:
        """The terminal equality constraints.

        Parameters
        ----------
        problem : OptimalControlProblem
            What to optimise (``fixed_final_rate``).
        x_end : CasADi expression
            The model state at T.
        qf : (4,) CasADi expression
            Target quaternion.
        omegaf : (3,) CasADi expression
            Target body rate [rad/s].

        Returns
        -------
        list of CasADi expressions
            ``vec(q_f* ⊗ q(T)) = 0`` and, with a fixed final rate, ``ω(T) − ω_f = 0``.
        """
        g = [qc.product(qc.conjugate(qf), x_end[0:4])[1:4]]
        if problem.fixed_final_rate:
            g.append(x_end[4:7] - omegaf)
        return g

    def build(self, problem: OptimalControlProblem, solver: str, options: dict[str, Any]) -> NLP:
        """The NLP in the stage-wise layout of the module docstring, solved by ``solver``.

        Parameters
        ----------
        problem : OptimalControlProblem
            What to optimise.
        solver : str
            ``"ipopt"`` or ``"fatrop"`` (a ``casadi.nlpsol`` plugin).
        options : dict
            ``nlpsol`` options (see :func:`ocp.nlp.solver_options`); ``expand`` defaults to true.

        Returns
        -------
        NLP
            The built solver, its constraint bounds and the ``unpack`` function.
        """
        model, N = problem.model, self.intervals
        nx = model.nx
        interval = self.interval(problem)
        ns0, nc = interval.n_state, interval.n_interval
        ns = ns0 + (1 if problem.free_time else 0)
        p = ca.MX.sym("p", nx + 4 + 3 + 1 + 3)
        x0, qf, omegaf, T_param, disturbance = p[0:nx], p[nx:nx + 4], p[nx + 4:nx + 7], p[nx + 7], p[nx + 8:nx + 11]
        w = ca.MX.sym("w", (ns + nc) * N + ns)
        Z = ca.reshape(w[:(ns + nc) * N], ns + nc, N)
        S = ca.horzcat(Z[:ns, :], w[(ns + nc) * N:])
        C = Z[ns:, :]
        if problem.free_time:
            T_row, T = S[ns0, :N], S[ns0, 0]
        else:
            T_row, T = ca.repmat(T_param, 1, N), T_param
        h_row = T_row / N
        t0_row = h_row * ca.DM(np.arange(N)).T
        following, path, cost = interval.function.map(N)(S[:ns0, :N], C, t0_row, h_row, disturbance)
        gap = S[:ns0, 1:] - following
        if problem.free_time:
            gap = ca.vertcat(gap, S[ns0, 1:] - S[ns0, :N])  # explicit continuity of T
        blocks = ca.vertcat(gap, path)
        initial = self.state_of(S[:ns0, 0]) - x0
        terminal = self.terminal(problem, self.state_of(S[:ns0, N]), qf, omegaf)
        g = ca.vertcat(blocks[:, 0], initial, ca.vec(blocks[:, 1:]), *terminal)
        zero_gap = np.zeros(ns)
        stage_low = np.concatenate([zero_gap, interval.path_lower])
        stage_high = np.concatenate([zero_gap, interval.path_upper])
        n_terminal = sum(c.numel() for c in terminal)
        lbg = np.concatenate([stage_low, np.zeros(nx), np.tile(stage_low, N - 1), np.zeros(n_terminal)])
        ubg = np.concatenate([stage_high, np.zeros(nx), np.tile(stage_high, N - 1), np.zeros(n_terminal)])
        objective = ca.sum2(cost) + problem.time_weight * T
        states, controls = self.split(S[:ns0, :], C)
        unpack = ca.Function("unpack", [w, p], [T, states, controls])
        opts = dict(options)
        opts.setdefault("expand", True)
        if solver == "fatrop":
            opts["equality"] = [bool(v) for v in (lbg == ubg)]
        nlp_solver = ca.nlpsol(f"{self.name}_{solver}", solver, {"x": w, "p": p, "f": objective, "g": g}, opts)
        return NLP(nlp_solver, w.numel(), unpack, lbg, ubg, problem.free_time, ns, nc)

    def bounds(self, problem: OptimalControlProblem, nlp: NLP, x_low: Array, x_high: Array, u_low: Array,
               u_high: Array, duration: float) -> tuple[Array, Array]:
        """Bounds of the decision vector.

        Parameters
        ----------
        problem : OptimalControlProblem
            What to optimise.
        nlp : NLP
            The built NLP (its ``free_time``).
        x_low, x_high : (nx,) ndarray
            Bounds of the model state at every point.
        u_low, u_high : (nu,) ndarray
            Bounds of the actuator controls.
        duration : float
            The problem's duration [s]: a free ``T`` lies in ``[1e-3, 1] × duration``.

        Returns
        -------
        tuple of ndarray
            ``(lbx, ubx)`` in the decision-vector layout.
        """
        s_low, s_high, c_low, c_high = self.stage_bounds(problem, x_low, x_high, u_low, u_high)
        if nlp.free_time:
            s_low, s_high = np.append(s_low, 1e-3 * duration), np.append(s_high, duration)
        N = self.intervals
        low = np.concatenate([np.tile(np.concatenate([s_low, c_low]), N), s_low])
        high = np.concatenate([np.tile(np.concatenate([s_high, c_high]), N), s_high])
        return low, high

    def seed(self, problem: OptimalControlProblem, nlp: NLP, sample: Callable[[Array], tuple[Array, Array, Array]],
             duration: float) -> Array:
        """An initial decision vector.

        Parameters
        ----------
        problem : OptimalControlProblem
            What to optimise.
        nlp : NLP
            The built NLP (its ``free_time``).
        sample : callable
            The seeding reference, as in :meth:`stage_guess`.
        duration : float
            Duration of the guess [s] (also the guess of a free T).

        Returns
        -------
        ndarray
            The decision vector.
        """
        S, C = self.stage_guess(problem, sample, duration)
        if nlp.free_time:
            S = np.vstack([S, np.full((1, S.shape[1]), duration)])
        N = self.intervals
        return np.concatenate([np.vstack([S[:, :N], C]).T.ravel(), S[:, N]])
