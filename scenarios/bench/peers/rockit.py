"""The rockit peer: rockit (``rockit-meco``) multiple shooting (RK4, N = 50) solved by IPOPT,
from ``collocation``'s first start (:func:`~scenarios.bench.peers._shooting.first_start_guess`).
Optional: without rockit installed the peer is skipped with a note.
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
    terminal_error,
)
from scenarios.bench.peers.base import (
    PeerResult,
    box_torque_problem_error,
    torque_bounds,
)

try:
    import rockit
except ImportError:  # optional: the peer says so through unavailable()
    rockit = None

__all__ = ["PEER", "RockitPeer", "build_ocp"]


def build_ocp(problem: ManeuverProblem, states: np.ndarray, T0: float, objective: str = "min_time",
              intervals: int = N) -> Any:
    """The rockit OCP of the module docstring, initialised at ``states`` and ``T0``.

    Parameters
    ----------
    problem : ManeuverProblem
        A box-torque problem.
    states : (7, intervals + 1) ndarray
        Initial guess of the node states ``[q, ω]``.
    T0 : float
        Initial guess of the final time [s]; the duration for ``min_energy``.
    objective : str, optional
        ``"min_time"`` (default) or ``"min_energy"``.
    intervals : int, optional
        Shooting intervals (default 50).

    Returns
    -------
    rockit.Ocp
        The problem, its solver set.
    """
    free_time = objective == "min_time"
    ocp = rockit.Ocp(T=rockit.FreeTime(T0) if free_time else problem.duration)
    x = ocp.state(7)
    u = ocp.control(3)
    ocp.set_der(x, rigid_body(problem.spacecraft.inertia)(x, u))
    u_max = ca.DM(torque_bounds(problem))
    ocp.subject_to(-u_max <= (u <= u_max))
    ocp.subject_to(ocp.at_t0(x) == ca.DM(problem.initial_state))
    ocp.subject_to(terminal_error(problem.qf, ocp.at_tf(x)[:4]) == 0)
    if problem.omegaf is not None:
        ocp.subject_to(ocp.at_tf(x)[4:] == ca.DM(problem.omegaf))
    ocp.add_objective(ocp.T if free_time else ocp.integral(ca.sumsqr(u)))
    ocp.method(rockit.MultipleShooting(N=intervals, M=1, intg="rk"))
    ocp.set_initial(x, states)
    ocp.solver("ipopt", {"expand": True, "ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes"})
    return ocp


class RockitPeer:
    """The rockit peer (module docstring)."""

    name = "rockit"

    def unavailable(self) -> str | None:
        """Why the peer cannot run here (``None``: it can).

        Returns
        -------
        str or None
            The missing library, or ``None``.
        """
        return None if rockit is not None else "rockit (pip install rockit-meco) is not installed"

    def version(self) -> str:
        """The tools that solve: rockit's distribution and the CasADi whose IPOPT it calls.

        Returns
        -------
        str
            ``"rockit-meco <version>, IPOPT of CasADi <version>"``.
        """
        from importlib.metadata import PackageNotFoundError, version

        try:
            own = version("rockit-meco")
        except PackageNotFoundError:
            own = getattr(rockit, "__version__", "unknown")
        return f"rockit-meco {own}, IPOPT of CasADi {ca.CasadiMeta.version()}"

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
            The objective reached, the second solve's time, the status; the message names the
            start, ``extra["start"]`` too.
        """
        guess = first_start_guess(problem, objective)
        start = time.perf_counter()
        ocp = build_ocp(problem, guess.states, guess.duration, objective)
        try:
            ocp.solve()
        except RuntimeError:
            pass
        build = time.perf_counter() - start
        start, cpu = time.perf_counter(), time.process_time()
        try:
            solution = ocp.solve()
        except RuntimeError as error:
            return PeerResult(None, time.perf_counter() - start, "failed", None, f"{guess.start}; rockit/IPOPT: {error}",
                              build, {"start": guess.start}, time.process_time() - cpu)
        elapsed, cpu = time.perf_counter() - start, time.process_time() - cpu
        value = float(solution.value(ocp.T)) if objective == "min_time" else float(
            solution.value(ocp.objective))
        stats = solution.stats if isinstance(getattr(solution, "stats", None), dict) else {}
        return PeerResult(value, elapsed, "ok", stats.get("iter_count"), guess.start, build, {"start": guess.start}, cpu)


PEER = RockitPeer()
"""The peer ``slewbench bench`` runs."""
