"""The FATROP peer: a hand-written CasADi Opti multiple shooting (RK4, piecewise-constant torques,
N = 50, for minimum time T a per-stage state with explicit continuity, stage-wise declaration)
solved by FATROP with ``structure_detection: auto`` (FATROP ships with CasADi). One solve from
``collocation``'s first start (:func:`~scenarios.bench.peers._shooting.first_start_guess`) after a
first solve that pays the build.
"""
from __future__ import annotations

import time
from typing import Any

import casadi as ca
import numpy as np

from planners.problem import ManeuverProblem
from scenarios.bench.peers._shooting import (
    N,
    first_start_guess,
    rigid_body,
    rk4_step,
    terminal_error,
)
from scenarios.bench.peers.base import (
    PeerResult,
    box_torque_problem_error,
    torque_bounds,
)

__all__ = ["PEER", "FatropPeer", "build_opti"]


def build_opti(problem: ManeuverProblem, states: np.ndarray, T0: float, objective: str = "min_time",
               intervals: int = N) -> tuple[ca.Opti, Any]:
    """The Opti multiple shooting of the module docstring, initialised at ``states`` and ``T0``.

    Parameters
    ----------
    problem : ManeuverProblem
        A box-torque problem (:func:`~scenarios.bench.peers.base.box_torque_problem_error`).
    states : (7, intervals + 1) ndarray
        Initial guess of the node states ``[q, ω]``.
    T0 : float
        Initial guess of the final time [s] (``min_time``); the duration for ``min_energy``.
    objective : str, optional
        ``"min_time"`` (default) or ``"min_energy"`` (∫‖u‖² dt, rectangle rule on the held torques).
    intervals : int, optional
        Shooting intervals (default 50).

    Returns
    -------
    tuple
        The ``casadi.Opti`` and the objective expression.
    """
    f = rigid_body(problem.spacecraft.inertia)
    step = rk4_step(f)
    u_max = torque_bounds(problem)
    opti = ca.Opti()
    X: list[Any] = []
    U: list[Any] = []
    T: list[Any] = []
    free_time = objective == "min_time"
    for k in range(intervals + 1):
        X.append(opti.variable(7))
        T.append(opti.variable() if free_time else None)
        if k < intervals:
            U.append(opti.variable(3))
    h_fixed = problem.duration / intervals
    for k in range(intervals):
        h = T[k] / intervals if free_time else h_fixed
        opti.subject_to(X[k + 1] == step(X[k], U[k], h))
        if free_time:
            opti.subject_to(T[k + 1] == T[k])
        if k == 0:
            opti.subject_to(X[0] == ca.DM(problem.initial_state))
        opti.subject_to(opti.bounded(-ca.DM(u_max), U[k], ca.DM(u_max)))
        if free_time:
            opti.subject_to(T[k] >= 0)
    opti.subject_to(terminal_error(problem.qf, X[intervals][:4]) == 0)
    if problem.omegaf is not None:
        opti.subject_to(X[intervals][4:] == ca.DM(problem.omegaf))
    cost = T[0] if free_time else sum(h_fixed * ca.sumsqr(u) for u in U)
    opti.minimize(cost)
    for k in range(intervals + 1):
        opti.set_initial(X[k], states[:, k])
        if free_time:
            opti.set_initial(T[k], T0)
    opti.solver("fatrop", {"expand": True, "structure_detection": "auto", "fatrop.print_level": 0,
                           "print_time": False})
    return opti, cost


class FatropPeer:
    """The FATROP multiple-shooting peer (module docstring)."""

    name = "fatrop"

    def unavailable(self) -> str | None:
        """Why the peer cannot run here (``None``: it can).

        Returns
        -------
        str or None
            ``None`` when CasADi has its FATROP plugin.
        """
        return None if ca.has_nlpsol("fatrop") else "this CasADi has no FATROP plugin"

    def version(self) -> str:
        """FATROP's: the plugin of the CasADi it ships with.

        Returns
        -------
        str
            ``"FATROP plugin of CasADi <version>"``.
        """
        return f"FATROP plugin of CasADi {ca.CasadiMeta.version()}"

    def problem_error(self, problem: ManeuverProblem, objective: str) -> str | None:
        """Why the peer cannot express the problem (``None``: it can).

        Parameters
        ----------
        problem : ManeuverProblem
            The problem.
        objective : str
            ``"min_time"`` or ``"min_energy"``.

        Returns
        -------
        str or None
            The reason, or ``None``.
        """
        return box_torque_problem_error(problem, objective)

    def solve(self, problem: ManeuverProblem, objective: str) -> PeerResult:
        """Build, solve once (the build), then solve again and time that solve, both from
        :func:`~scenarios.bench.peers._shooting.first_start_guess` (computed before the build's
        clock starts: the guess is ours, not the peer's).

        Parameters
        ----------
        problem : ManeuverProblem
            A problem :meth:`problem_error` accepts.
        objective : str
            ``"min_time"`` or ``"min_energy"``.

        Returns
        -------
        PeerResult
            The objective reached, the second solve's time, the status and iterations; the message
            names the start, ``extra["start"]`` too.
        """
        guess = first_start_guess(problem, objective)
        start = time.perf_counter()
        opti, cost = build_opti(problem, guess.states, guess.duration, objective)
        try:
            opti.solve()
        except RuntimeError:
            pass  # the build is paid; the timed solve below reports the outcome
        build = time.perf_counter() - start
        start, cpu = time.perf_counter(), time.process_time()
        try:
            solution = opti.solve()
        except RuntimeError as error:
            stats = opti.stats()
            return PeerResult(None, time.perf_counter() - start, "failed", stats.get("iter_count"),
                              f"{guess.start}; FATROP: {stats.get('return_status', error)}", build,
                              {"start": guess.start}, time.process_time() - cpu)
        elapsed, cpu = time.perf_counter() - start, time.process_time() - cpu
        stats = solution.stats()
        return PeerResult(float(solution.value(cost)), elapsed, "ok", stats.get("iter_count"),
                          f"{guess.start}; FATROP: return status {stats.get('return_status', '?')}", build,
                          {"start": guess.start}, cpu)


PEER = FatropPeer()
"""The peer ``slewbench bench`` runs."""
