"""One solve path for every optimising planner: solver options, the status policy, multistart
with early stopping, and a result object in the style of ``scipy.optimize.OptimizeResult``.

Status policy
-------------
A start has **converged** when the solver reports success (IPOPT ``Solve_Succeeded`` or
``Solved_To_Acceptable_Level``, FATROP ``success``), or when IPOPT stopped with
``Search_Direction_Becomes_Too_Small`` at a point whose constraint violation (``g`` outside
``[lbg, ubg]``) is at most ``feasibility_tolerance``: the step has fallen below machine precision
at a feasible point (e.g. a zero-cost optimum), so no further progress is possible. Every other
outcome (maximum iterations, restoration failure, infeasibility, evaluation errors) is not
converged, whatever its violation. Among converged starts the lowest objective wins. A result
whose starts all ended ``Infeasible_Problem_Detected`` / ``Restoration_Failed`` is
``"infeasible"``, otherwise an unconverged result is ``"failed"``.

Early stopping
--------------
Starts are tried in order; the search stops once ``agree`` converged starts have objectives within
``rtol`` (relative, with ``atol``) of the best so far: the best optimum has been found again from
a different start, which is the evidence that more starts would not improve it.

Restarts
--------
With ``restart > 0``, after the given guesses (once one has converged) come copies of the best point
so far perturbed by ``restart`` (relative), at most ``max_restarts`` of them. From a local minimum
such a restart comes back in a few iterations (and confirms it, which stops the search); from a
saddle or other stationary point (the eigenaxis slew for minimum time) it leaves for a better
point, which then becomes the best and is checked in turn.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any, Iterable, Mapping, Sequence

import casadi as ca
import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]

SUCCESS = ("Solve_Succeeded", "Solved_To_Acceptable_Level")
STALLED_AT_FEASIBLE = ("Search_Direction_Becomes_Too_Small",)
INFEASIBLE = ("Infeasible_Problem_Detected", "Restoration_Failed")
SOLVERS = ("ipopt", "fatrop")


def solver_options(solver: str = "ipopt", tolerance: float = 1e-8, max_iterations: int = 500,
                   extra: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """``nlpsol`` options for ``solver``: quiet, exact derivatives, the given tolerance.

    Parameters
    ----------
    solver : ``"ipopt"`` or ``"fatrop"``.
    tolerance : the solver's convergence tolerance (scaled KKT error).
    max_iterations : iteration limit.
    extra : further ``nlpsol`` options, overriding these (e.g. ``{"ipopt.constr_viol_tol": 1e-13}``).

    Returns
    -------
    dict
        The options for ``casadi.nlpsol``.
    """
    common: dict[str, Any] = {"print_time": False, "show_eval_warnings": False}
    if solver == "ipopt":
        common.update({"ipopt.print_level": 0, "ipopt.sb": "yes", "ipopt.tol": tolerance,
                       "ipopt.max_iter": max_iterations})
    elif solver == "fatrop":
        common.update({"structure_detection": "auto", "expand": True, "fatrop.print_level": 0,
                       "fatrop.tol": tolerance, "fatrop.max_iter": max_iterations})
    else:
        raise ValueError(f"solver must be one of {SOLVERS}, got {solver!r}")
    common.update(extra or {})
    return common


@dataclass
class StartResult:
    """One start: solver status, objective, iterations, wall time (s), constraint violation."""

    status: str
    f: float
    iterations: int
    time_s: float
    violation: float
    converged: bool


@dataclass
class NLPResult:
    """The outcome of :func:`solve_multistart` (attributes as in ``scipy.optimize.OptimizeResult``).

    Attributes
    ----------
    x : the best converged decision vector, or ``None``.
    f : its objective (``inf`` without one).
    g : its constraint values, or ``None``.
    success : a start converged (see the module's status policy).
    status : ``"ok"``, ``"failed"`` or ``"infeasible"`` (the planners' statuses).
    message : a human-readable summary.
    iterations : solver iterations over all starts.
    time_s : wall time of all starts (s).
    best_start : index of the winning start, or ``None``.
    starts : per-start :class:`StartResult`.
    """

    x: Array | None
    f: float
    g: Array | None
    success: bool
    status: str
    message: str
    iterations: int
    time_s: float
    best_start: int | None
    starts: list[StartResult] = field(default_factory=list)

    @property
    def statuses(self) -> list[str]:
        return [s.status for s in self.starts]

    def stats(self) -> dict[str, Any]:
        """A planner's ``stats`` entries: objective, iterations, statuses, timings, per start."""
        return {"objective": self.f, "iterations": self.iterations, "solver_status": self.statuses,
                "solve_time_s": self.time_s, "best_start": self.best_start,
                "starts": [vars(s) for s in self.starts]}


def violation(g: Array, lbg: Any, ubg: Any) -> float:
    """Largest violation of ``lbg <= g <= ubg`` (0 when satisfied)."""
    g = np.ravel(g)
    if g.size == 0:
        return 0.0
    low, high = np.broadcast_to(lbg, g.shape), np.broadcast_to(ubg, g.shape)
    return float(np.max(np.maximum(np.maximum(low - g, g - high), 0.0)))


def converged(status: str, success: bool, violation_: float, feasibility_tolerance: float) -> bool:
    """The status policy of the module docstring."""
    return success or status in SUCCESS or (status in STALLED_AT_FEASIBLE and violation_ <= feasibility_tolerance)


def solve_multistart(solver: ca.Function, guesses: Iterable[Array], *, p: Any = None, lbx: Any = None,
                     ubx: Any = None, lbg: Any = None, ubg: Any = None, agree: int = 2, rtol: float = 1e-6,
                     atol: float = 1e-12, feasibility_tolerance: float = 1e-8,
                     max_starts: int | None = None, restart: float = 0.0, max_restarts: int = 4) -> NLPResult:
    """Solve from each guess in turn, keep the best converged start, stop early on agreement.

    Parameters
    ----------
    solver : a ``casadi.nlpsol`` function.
    guesses : initial decision vectors (clipped into ``[lbx, ubx]``); may be a lazy iterable.
    p, lbx, ubx, lbg, ubg : the solver's arguments (``None``: the solver's defaults).
    agree : stop once this many converged starts lie within ``rtol``/``atol`` of the best
        objective (1: stop at the first converged start; 0: never stop early).
    feasibility_tolerance : constraint violation accepted by the status policy.
    max_starts : try at most this many guesses.
    restart : relative perturbation of the restarts from the best point (0: no restarts).
    max_restarts : restarts at most.

    Returns
    -------
    NLPResult
    """
    args: dict[str, Any] = {}
    for name, value in (("p", p), ("lbx", lbx), ("ubx", ubx), ("lbg", lbg), ("ubg", ubg)):
        if value is not None:
            args[name] = value
    low = -np.inf if lbx is None else np.asarray(lbx, dtype=float)
    high = np.inf if ubx is None else np.asarray(ubx, dtype=float)
    g_low = -np.inf if lbg is None else lbg
    g_high = np.inf if ubg is None else ubg
    best_x, best_g, best_f, best_index = None, None, np.inf, None
    starts: list[StartResult] = []
    objectives: list[float] = []
    begin = time.perf_counter()

    def candidates():
        for index, guess in enumerate(guesses):
            if max_starts is not None and index >= max_starts:
                break
            yield guess
        for k in range(max_restarts if restart > 0 and best_x is not None else 0):
            yield perturbed(best_x, 1, seed=k + 1, scales=(restart, restart))[0]

    for index, guess in enumerate(candidates()):
        tic = time.perf_counter()
        solution = solver(x0=np.clip(np.asarray(guess, dtype=float), low, high), **args)
        elapsed = time.perf_counter() - tic
        stats = solver.stats()
        status = str(stats.get("return_status", "unknown"))
        g = solution["g"].full().ravel()
        excess = violation(g, g_low, g_high)
        f = float(solution["f"])
        ok = bool(np.isfinite(f)) and converged(status, bool(stats.get("success", False)), excess,
                                                 feasibility_tolerance)
        starts.append(StartResult(status, f, int(stats.get("iter_count", 0)), elapsed, excess, ok))
        if not ok:
            continue
        objectives.append(f)
        if f < best_f:
            best_x, best_g, best_f, best_index = solution["x"].full().ravel(), g, f, index
        close = sum(abs(value - best_f) <= atol + rtol * abs(best_f) for value in objectives)
        if agree and close >= agree:
            break
    total = time.perf_counter() - begin
    iterations = sum(s.iterations for s in starts)
    statuses = [s.status for s in starts]
    if best_x is None:
        status = "infeasible" if statuses and all(s in INFEASIBLE for s in statuses) else "failed"
        message = f"no start converged: {sorted(set(statuses))}"
        return NLPResult(None, np.inf, None, False, status, message, iterations, total, None, starts)
    message = f"objective {best_f:.8g} from start {best_index} of {len(starts)} tried ({statuses[best_index]})"
    return NLPResult(best_x, best_f, best_g, True, "ok", message, iterations, total, best_index, starts)


def perturbed(center: Array, count: int, seed: int = 0, scales: Sequence[float] = (0.01, 0.05)) -> list[Array]:
    """``count`` copies of ``center`` with relative normal noise: the first at ``scales[0]``, the
    rest at ``scales[1]`` (noise proportional to ``|center| + 1e-3``, reproducible by ``seed``)."""
    rng = np.random.default_rng(seed)
    size = np.abs(center) + 1e-3
    return [center + rng.normal(0.0, 1.0, center.size) * size * (scales[0] if k == 0 else scales[1])
            for k in range(count)]
