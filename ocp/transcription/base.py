"""Optimal-control problems on the attitude model, and the stage-wise NLP every transcription shares.

The problem (:class:`~ocp.transcription.problem.OptimalControlProblem`, with
:class:`~ocp.transcription.problem.Interval` and :class:`~ocp.transcription.problem.NLP`) says what is wanted; a :class:`Transcription` says how
one mesh interval becomes NLP variables and constraints. It owns its layout: the interval as a
CasADi function (mapped over the mesh, never called node by node from Python), the variables'
bounds, the seeding from another reference and the interpolation of the solution.

Every transcription is assembled the same way (:meth:`Transcription.build`), stage-wise as
structure-exploiting solvers need it (FATROP's ``structure_detection: auto``):

* variables ``w = [s_0, c_0, s_1, c_1, …, s_{N−1}, c_{N−1}, s_N]``: the stage state ``s_k`` (the
  model state at the mesh point, plus what the transcription carries across intervals, plus
  ``T`` when the final time is free: ``T_{k+1} = T_k`` is then an explicit continuity condition)
  and the interval's own variables ``c_k``;
* constraints ``[gap_0, path_0, x_0 − x0, initial, gap_1, path_1, …, terminal]`` with
  ``gap_k = s_{k+1} − F(s_k, c_k)`` (explicit continuity), the interval's path constraints and the
  transcription's affine equalities on ``s_0`` (:meth:`Transcription.initial_equalities`, none
  by default: multiple shooting's ``u_0`` under the controllers' allocation).

Parameters ``p = [x0 (nx), qf (4), ωf (3), T, disturbance (3)]``: boundary values and T are not
baked into the graph, so a built solver is reused across plans.

Conventions: the terminal attitude condition is ``vec(q_f* ⊗ q(T)) = 0``, which accepts ``−q_f``;
the quaternion norm is preserved by the kinematics to the discretisation's accuracy (reported, not
constrained). Objective integrands use the actuators' body torque ``τ`` (N m): energy ``‖τ‖²``,
L1 ``Σ|τ_i|`` (with slacks), plus ``time_weight · T``.
"""
from __future__ import annotations

import copy
from abc import ABC, abstractmethod
from collections.abc import Callable
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ocp import quat_casadi as qc
from ocp.dynamics.model import AttitudeModel
from ocp.transcription.problem import NLP, Interval, OptimalControlProblem
from ocp.transcription.stagewise import assemble

Array = NDArray[np.float64]
__all__ = ["Array", "Transcription"]


class Transcription(ABC):
    """How an :class:`OptimalControlProblem` becomes an NLP on ``intervals`` mesh intervals.

    Subclasses implement :meth:`interval` (one interval as a CasADi function), the layout methods
    :meth:`stage_bounds`, :meth:`stage_guess`, :meth:`split` and :meth:`interpolate`, and
    :meth:`problem_error` for formulations they cannot take.

    Parameters
    ----------
    intervals : int
        Number of mesh intervals (equal lengths T / intervals unless ``mesh`` says otherwise).
    mesh : (intervals + 1,) array_like or None
        The mesh nodes as fractions of T, increasing from 0 to 1 (a non-uniform mesh: nodes at a
        bang-bang control's switching times, say); ``None`` (default): uniform.
    """

    name: str
    non_uniform: bool = False
    """Whether it takes a non-uniform ``mesh`` (:meth:`with_mesh`)."""
    fatrop_seed: bool = False
    """Whether FATROP, not IPOPT, solves its coarse seed of a fixed final time (measured:
    :data:`planners.collocation.strategy.SEED_FATROP`)."""

    def __init__(self, intervals: int, mesh: Array | None = None) -> None:
        self.intervals = intervals
        self.mesh: Array | None = None
        if mesh is not None:
            nodes = np.asarray(mesh, dtype=float)
            if (nodes.shape != (intervals + 1,) or not np.all(np.isfinite(nodes)) or nodes[0] != 0.0
                    or nodes[-1] != 1.0 or not np.all(np.diff(nodes) > 0.0)):
                raise ValueError(f"mesh: expected {intervals + 1} increasing fractions of T from 0 to 1, got {nodes}")
            nodes.setflags(write=False)
            self.mesh = nodes

    def with_mesh(self, mesh: Array) -> Transcription:
        """A copy of this transcription on the mesh ``mesh`` (its number of intervals).

        Parameters
        ----------
        mesh : (intervals + 1,) ndarray
            The nodes as fractions of T, increasing from 0 to 1.

        Returns
        -------
        Transcription

        Raises
        ------
        ValueError
            The transcription takes no non-uniform mesh (:attr:`non_uniform`), or ``mesh`` is not one.
        """
        if not self.non_uniform:
            raise ValueError(f"{self.name} takes no non-uniform mesh")
        copied = copy.copy(self)
        Transcription.__init__(copied, len(mesh) - 1, mesh)
        return copied

    @property
    def nodes(self) -> Array:
        """The mesh nodes as fractions of T.

        Returns
        -------
        (intervals + 1,) ndarray
            From 0 to 1: :attr:`mesh`, or uniform.
        """
        return np.arange(self.intervals + 1) / self.intervals if self.mesh is None else self.mesh

    def fractions(self, k: NDArray[np.int_] | Array, tau: Array) -> Array:
        """Times as fractions of T of positions ``tau`` in intervals ``k``.

        Parameters
        ----------
        k : ndarray of int
            Interval indices (broadcast with ``tau``).
        tau : ndarray
            Positions in the interval, fractions of its length in [0, 1].

        Returns
        -------
        ndarray
            ``t / T``: ``(k + τ) / N`` on a uniform mesh.
        """
        if self.mesh is None:
            return (k + tau) / self.intervals
        nodes = self.mesh
        return nodes[k] + tau * (nodes[np.asarray(k) + 1] - nodes[k])

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
            The problem has path constraints (pointing cones or a rate-norm bound,
            :meth:`OptimalControlProblem.path_constraints`).

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
                    t: Array, left: bool = False) -> tuple[Array, Array]:
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
        left : bool, optional
            At a mesh node ``t_k`` (``0 < k < N``), read the interval that ends there (``True``:
            the left limit) instead of the one that starts there (``False``, default). It matters
            only where the interpolant jumps at the nodes (Radau's controls).

        Returns
        -------
        tuple of ndarray
            States ``(n, nx)`` and controls ``(n, nu)``.
        """

    def interval_index(self, duration: float, t: Array, left: bool = False) -> NDArray[np.int_]:
        """The mesh interval that holds each time (:attr:`nodes`).

        Parameters
        ----------
        duration : float
            T [s].
        t : (n,) ndarray
            Times in ``[0, duration]`` [s].
        left : bool, optional
            As in :meth:`interpolate`: interval ``k`` holds ``[t_k, t_(k+1))`` (``False``, default)
            or ``(t_k, t_(k+1)]`` (``True``); a time within 1e-9 of an interval's length of a node
            counts as the node.

        Returns
        -------
        (n,) ndarray of int
            Interval indices in ``0 … N − 1``.
        """
        if self.mesh is not None:  # within 1e-9 of the shortest interval of a node counts as the node
            s = np.asarray(t, dtype=float) / duration
            tol = 1e-9 * float(np.min(np.diff(self.mesh)))
            nodes = self.mesh
            k = (np.searchsorted(nodes, s - tol, side="left") - 1 if left
                 else np.searchsorted(nodes, s + tol, side="right") - 1)
            return np.clip(k, 0, self.intervals - 1)
        s = np.asarray(t, dtype=float) * self.intervals / duration
        k = np.ceil(s - 1e-9).astype(int) - 1 if left else np.floor(s + 1e-9).astype(int)
        return np.clip(k, 0, self.intervals - 1)

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

    def control_points(self, problem: OptimalControlProblem, s: Any, c: Any) -> list[tuple[Any, float]] | None:
        """The controls one interval's variables hold, with their positions in the interval.

        Together with :meth:`initial_controls` they are every control the solution uses, each once
        over the mesh (what the transcription interpolates between is among them), so that a
        constraint imposed on each of them holds for every control of the solution.

        Parameters
        ----------
        problem : OptimalControlProblem
            What to optimise.
        s, c : CasADi expression
            A stage state ``s_k`` (without T) and the interval's own variables ``c_k``.

        Returns
        -------
        list of (CasADi expression (nu,), float) or None
            ``(u, position)`` pairs, positions as fractions of the interval in [0, 1]; ``None``
            (the default) when the transcription does not say.
        """
        return None

    def initial_controls(self, problem: OptimalControlProblem, s: Any) -> list[Any]:
        """The controls the first stage state holds that no interval's :meth:`control_points` hold.

        Parameters
        ----------
        problem : OptimalControlProblem
            What to optimise.
        s : CasADi expression
            The stage state ``s_0`` (without T).

        Returns
        -------
        list of CasADi expression (nu,)
            By default none (every control lies in the intervals' own variables).
        """
        return []

    def initial_equalities(self, problem: OptimalControlProblem, s: Any) -> Any:
        """Equalities on the first stage state besides ``x_0 = x0``, affine in ``s_0``.

        :meth:`build` places them after the initial condition (the rows between the first block and
        the second, which :mod:`ocp.transcription.mesh_transfer` carries as they are).

        Parameters
        ----------
        problem : OptimalControlProblem
            What to optimise.
        s : casadi.SX
            The stage state ``s_0`` (without T).

        Returns
        -------
        (k,) casadi.SX
            Expressions held at 0; by default none.
        """
        return ca.SX.zeros(0, 1)

    def positions(self, problem: OptimalControlProblem, interval: Interval) -> tuple[Array, Array]:
        """Where the entries of ``c_k`` and of the path constraints sit in their interval.

        Parameters
        ----------
        problem : OptimalControlProblem
            What to optimise.
        interval : Interval
            ``interval(problem)``.

        Returns
        -------
        tuple of ndarray
            ``(c_position (nc,), path_position (n_path,))``, fractions of the interval in [0, 1]
            (used to carry multipliers between meshes, :mod:`ocp.transcription.mesh_transfer`); by default the
            interval's midpoint.
        """
        return np.full(interval.n_interval, 0.5), np.full(interval.path_lower.size, 0.5)

    def step_scaled_gaps(self, problem: OptimalControlProblem, interval: Interval) -> NDArray[np.bool_]:
        """Which entries of the gap ``s_{k+1} − F(s_k, c_k)`` have multipliers that scale with the step.

        The gap of a state that the dynamics integrate over the interval has a multiplier that tends
        to the costate (independent of the step ``h``). The gap of a copy of an interval variable
        (a control carried in the stage state, ``u_{k+1} = c_k``) balances that variable's
        stationarity, whose terms (running cost, ``h f``, bound multipliers) are all ``O(h)``: its
        multiplier scales with ``h`` (:mod:`ocp.transcription.mesh_transfer`).

        Parameters
        ----------
        problem : OptimalControlProblem
            What to optimise.
        interval : Interval
            ``interval(problem)``.

        Returns
        -------
        (interval.n_state,) ndarray of bool
            ``True`` where the gap's multiplier scales with ``h``; by default none.
        """
        return np.zeros(interval.n_state, dtype=bool)

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
            ``nlpsol`` options (see :func:`ocp.nlp.solve.solver_options`); ``expand`` defaults to true.

        Returns
        -------
        NLP
            The built solver, its constraint bounds and the ``unpack`` function.
        """
        nx, N = problem.model.nx, self.intervals
        interval = self.interval(problem)
        ns0, nc = interval.n_state, interval.n_interval
        ns = ns0 + (1 if problem.free_time else 0)
        stages = assemble(self, problem, interval, expand=solver != "fatrop")  # FATROP takes no derivatives
        zero_gap = np.zeros(ns)
        stage_low = np.concatenate([zero_gap, interval.path_lower])
        stage_high = np.concatenate([zero_gap, interval.path_upper])
        n_terminal = stages.n_terminal
        lbg = np.concatenate([stage_low, np.zeros(nx), np.tile(stage_low, N - 1), np.zeros(n_terminal)])
        ubg = np.concatenate([stage_high, np.zeros(nx), np.tile(stage_high, N - 1), np.zeros(n_terminal)])
        g, jac_g, hess_lag = stages.g, stages.jac_g, stages.hess_lag
        initial = self._initial_rows(problem, ns0, stages.w.numel())
        if initial is not None:  # after the initial condition: [gap_0, path_0, x_0 − x0, these, gap_1, …]
            at = ns + interval.path_lower.size + nx
            g, jac_g, hess_lag = _insert_affine_rows(stages.w, stages.p, g, jac_g, hess_lag, at, *initial)
            lbg = np.concatenate([lbg[:at], np.zeros(initial[0].shape[0]), lbg[at:]])
            ubg = np.concatenate([ubg[:at], np.zeros(initial[0].shape[0]), ubg[at:]])
        states, controls = self.split(stages.S[:ns0, :], stages.C)
        unpack = ca.Function("unpack", [stages.w, stages.p], [stages.T, states, controls])
        opts = dict(options)
        opts.setdefault("expand", True)
        if solver == "fatrop":
            opts["equality"] = [bool(v) for v in (lbg == ubg)]
        else:
            # the block-assembled derivatives (ocp.transcription.stagewise), not CasADi's of the whole graph
            opts.update(jac_g=jac_g, hess_lag=hess_lag)
        nlp = {"x": stages.w, "p": stages.p, "f": stages.f, "g": g}
        nlp_solver = ca.nlpsol(f"{self.name}_{solver}", solver, nlp, opts)
        c_position, path_position = self.positions(problem, interval)
        if c_position.shape != (nc,) or path_position.shape != interval.path_lower.shape:
            raise AssertionError(f"{self.name}: positions() does not match the interval's layout")
        scaled = self.step_scaled_gaps(problem, interval)
        if scaled.shape != (ns0,):
            raise AssertionError(f"{self.name}: step_scaled_gaps() does not match the stage state")
        layout = {"n_path": interval.path_lower.size, "n_terminal": n_terminal, "c_position": c_position,
                  "path_equality": interval.path_lower == interval.path_upper, "path_position": path_position,
                  # T's continuity T_{k+1} = T_k (free T): a running sum of O(1/N) terms, not scaled
                  "gap_step_scaled": np.append(scaled, np.zeros(ns - ns0, dtype=bool))}
        return NLP(nlp_solver, stages.w.numel(), unpack, lbg, ubg, problem.free_time, ns, nc, layout)

    def _initial_rows(self, problem: OptimalControlProblem, ns0: int, nw: int) -> tuple[Array, Array] | None:
        """:meth:`initial_equalities` as ``(J, b)``, the rows ``J w + b`` on the decision vector
        (``s_0`` is its first entries), or ``None`` when there are none."""
        s = ca.SX.sym("s0", ns0)
        rows = ca.SX(self.initial_equalities(problem, s))
        if rows.numel() == 0:
            return None
        jacobian = ca.jacobian(rows, s)
        if ca.depends_on(jacobian, s):
            raise AssertionError(f"{self.name}: initial_equalities() must be affine in s_0")
        J = np.zeros((rows.numel(), nw))
        J[:, :ns0] = np.asarray(ca.evalf(jacobian), dtype=float)
        b = np.asarray(ca.evalf(ca.substitute(rows, s, ca.SX.zeros(ns0))), dtype=float).ravel()
        return J, b

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


def _insert_affine_rows(w: Any, p: Any, g: Any, jac_g: ca.Function, hess_lag: ca.Function, at: int, J: Array,
                        b: Array) -> tuple[Any, ca.Function, ca.Function]:
    """``g`` with the rows ``J w + b`` inserted before its entry ``at``, and the derivative functions
    of :mod:`ocp.transcription.stagewise` with them: their Jacobian rows are ``J``, and affine rows add
    nothing to the Lagrangian's Hessian (their multipliers are dropped before the stage-wise one)."""
    rows = ca.mtimes(ca.DM(ca.sparsify(ca.DM(J))), w) + ca.DM(b)
    g_new = ca.vertcat(g[:at], rows, g[at:])
    value, jacobian = jac_g(w, p)
    jacobian = ca.vertcat(jacobian[:at, :], ca.MX(ca.sparsify(ca.DM(J))), jacobian[at:, :])
    jac_new = ca.Function("nlp_jac_g", [w, p], [ca.vertcat(value[:at], rows, value[at:]), jacobian],
                          ["x", "p"], ["g", "jac_g_x"])
    lam_f, lam_g = ca.MX.sym("lam_f"), ca.MX.sym("lam_g", g_new.numel())
    k = J.shape[0]
    hess_new = ca.Function("nlp_hess_l", [w, p, lam_f, lam_g],
                           [hess_lag(w, p, lam_f, ca.vertcat(lam_g[:at], lam_g[at + k:]))],
                           ["x", "p", "lam_f", "lam_g"], ["hess_gamma_x_x"])
    # MX wrappers of the expanded stage-wise functions: expanding them again took 2.2 s per build
    return g_new, jac_new, hess_new
