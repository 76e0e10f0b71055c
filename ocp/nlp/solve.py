"""One solve path for every optimising planner: solver options, the status policy, multistart
with early stopping, and a result object in the style of ``scipy.optimize.OptimizeResult``.

Status policy
-------------
A start has **converged** when the solver reports success (IPOPT ``Solve_Succeeded`` or
``Solved_To_Acceptable_Level``, FATROP ``success``; FATROP's integer flags are named by
:data:`FATROP_STATUS`), or when IPOPT stopped with
``Search_Direction_Becomes_Too_Small`` at a point whose constraint violation (``g`` outside
``[lbg, ubg]``) is at most ``feasibility_tolerance``: the step has fallen below machine precision
at a feasible point (e.g. a zero-cost optimum), so no further progress is possible. Every other
outcome (maximum iterations, restoration failure, infeasibility, evaluation errors) is not
converged, whatever its violation. Among converged starts the lowest objective wins. An
unconverged result is ``"failed"``, also when every start ended ``Infeasible_Problem_Detected`` /
``Restoration_Failed`` (its message then says so): IPOPT's infeasibility is local, found from a
start, not a proof (collocation's minimum energy over XTE at 1.001 T* ended so from both its
starts, where four starts reach a feasible optimum), and ``"infeasible"`` is a planner's status for
a problem it shows cannot be met.

IPOPT's ``Solved_To_Acceptable_Level`` means that its *acceptable* tolerances (overall error 1e-6,
constraint violation and complementarity 1e-2, dual infeasibility 1e10, by default) held for 15
iterations in a row, not that the requested tolerance was met: a start that stalls on a slope can
stop there, far from any local minimum (the two-wheel minimum time: a start stopped at T = 150.01 s,
from which the same solver goes on to the optimum, 139.33 s). Such a start is therefore continued
once from the point where it stopped (same solver, its multipliers passed along); the continuation
is the start's outcome (its iterations and time added) when it converges, else the acceptable
point stands.

Early stopping
--------------
Starts are tried in order; the search stops once ``agree`` converged starts have objectives within
``rtol`` (relative, with ``atol``) of the best so far: the best optimum has been found again from
a different start, which is the evidence that more starts would not improve it.

Fallbacks
---------
``fallback`` guesses are tried only while no start has converged (e.g. the unperturbed warm start
after a perturbed copy of it that hit the iteration limit), and not where every start ended
``Infeasible_Problem_Detected``: the constraints were found locally infeasible from each, no
stall for a fallback to escape (a minimum time under a bound below it: Bilimoria & Wie's
unperturbed eigenaxis start under 3 s ran to the iteration limit, 500 of the verdict's 727
iterations).

Warm starts with multipliers
----------------------------
``lam_x0`` / ``lam_g0`` pass bound and constraint multipliers with the guesses (a solve of a nearby
problem, e.g. a regularised one); :func:`warm_start_options` are the matching IPOPT options, under
which the interior point starts at the guess and its multipliers instead of pushing it inside.

Restarts
--------
With ``restart > 0``, after the given guesses (once one has converged) come copies of the best point
so far perturbed by ``restart`` (relative), at most ``max_restarts`` of them. From a local minimum
such a restart comes back in a few iterations (and confirms it, which stops the search); from a
saddle or other stationary point (the eigenaxis slew for minimum time) it leaves for a better
point, which then becomes the best and is checked in turn. With ``second_order``, the best point is
first checked by the second-order sufficient conditions (:mod:`ocp.nlp.second_order`): a point that
satisfies them is a strict local minimum, which is what a restart would confirm, so the certificate
counts as one more start agreeing on it (with ``agree=2``, the first converged start then ends the
search); a point that does not (a saddle, or a degenerate minimum the check cannot certify) gets the
restarts as before. ``agree=0`` (try everything) still runs every restart.

Ties
----
With ``tie_break``, among the converged starts whose objectives agree (``rtol``/``atol``) with the
least objective found so far, the one with the least ``tie_break(x)`` is kept (then the least
objective, then the first): among optima equal in the objective, the secondary criterion decides
(e.g. the spin extremals, whose branches all reach the target exactly, J1 = 0, and differ in their
energy J2), not rounding at the level of ``atol``. A ``nan`` criterion ranks last. Early stopping
counts agreement with the kept start's objective.
"""
from __future__ import annotations

import time
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ocp.fast_call import buffered
from ocp.nlp.second_order import SecondOrderCheck, second_order_check

Array = NDArray[np.float64]


@dataclass
class StartResult:
    """One start of :func:`solve_multistart`.

    Parameters
    ----------
    status : str
        The solver's return status (e.g. IPOPT ``Solve_Succeeded``).
    f : float
        Objective at the point where the start stopped (the problem's units).
    iterations : int
        Solver iterations of this start.
    time_s : float
        Wall time of this start [s].
    violation : float
        Largest constraint violation at that point (constraint units).
    converged : bool
        Whether the module's status policy accepts the start.
    solver : str
        The solver that reached that point: the ``nlpsol`` plugin (``"ipopt"``, ``"fatrop"``), or
        what a stand-in's ``stats()`` names (``"interior_point"``: :mod:`ocp.nlp.interior_point`; it
        names ``"ipopt"`` where it handed the start over).
    """

    status: str
    f: float
    iterations: int
    time_s: float
    violation: float
    converged: bool
    solver: str = ""


@dataclass
class NLPResult:
    """The outcome of :func:`solve_multistart` (attributes as in ``scipy.optimize.OptimizeResult``).

    Parameters
    ----------
    x : ndarray or None
        The best converged decision vector, or ``None``.
    f : float
        Its objective (``inf`` without one).
    g : ndarray or None
        Its constraint values, or ``None``.
    success : bool
        A start converged (see the module's status policy).
    status : str
        ``"ok"`` or ``"failed"`` (the planners' statuses; never ``"infeasible"``: the module's
        status policy).
    message : str
        A human-readable summary.
    iterations : int
        Solver iterations over all starts.
    time_s : float
        Wall time of all starts [s].
    best_start : int or None
        Index of the winning start, or ``None``.
    starts : list of StartResult
        Per-start outcomes, in the order tried.
    lam_x, lam_g : ndarray or None
        Bound and constraint multipliers at ``x`` (``None`` without a converged start).
    second_order : SecondOrderCheck or None
        The second-order check of the best point (``None``: not made).
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
    lam_x: Array | None = None
    lam_g: Array | None = None
    second_order: SecondOrderCheck | None = None

    @property
    def statuses(self) -> list[str]:
        """The solver status of every start, in order."""
        return [s.status for s in self.starts]

    def stats(self) -> dict[str, Any]:
        """A planner's ``stats`` entries.

        Returns
        -------
        dict
            ``objective``, ``iterations``, ``solver_status`` (list), ``solve_time_s`` [s],
            ``best_start``, ``starts`` (one dict per start, fields of :class:`StartResult`) and,
            when made, ``second_order`` (fields of :class:`~ocp.nlp.second_order.SecondOrderCheck`).
        """
        stats = {"objective": self.f, "iterations": self.iterations, "solver_status": self.statuses,
                 "solve_time_s": self.time_s, "best_start": self.best_start,
                 "starts": [vars(s) for s in self.starts]}
        if self.second_order is not None:
            stats["second_order"] = vars(self.second_order)
        return stats


SUCCESS = ("Solve_Succeeded", "Solved_To_Acceptable_Level")
ACCEPTABLE = ("Solved_To_Acceptable_Level",)
"""Successes at IPOPT's acceptable tolerances only: continued once (module docstring)."""
STALLED_AT_FEASIBLE = ("Search_Direction_Becomes_Too_Small",)
INFEASIBLE = ("Infeasible_Problem_Detected", "Restoration_Failed")
SOLVERS = ("ipopt", "fatrop")
FATROP_STATUS = {0: "Fatrop_Converged", 1: "Fatrop_Stopped"}
"""FATROP's integer return flags, named: 0 converged (to the tolerance, to the acceptable tolerance
after its count of acceptable iterations, or at a vanishing search direction at the least barrier
parameter), 1 stopped without converging (the iteration limit, or a failed restoration phase: FATROP
returns the same flag for both). Another flag is named ``Fatrop_Flag_<n>``."""


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


def warm_start_options(solver: str = "ipopt", mu_init: float = 1e-6, bound_push: float = 1e-9,
                       mult_bound_push: float = 1e-9) -> dict[str, Any]:
    """Extra ``nlpsol`` options to start from a guess together with its multipliers.

    Parameters
    ----------
    solver : str
        ``"ipopt"`` (FATROP takes no multiplier warm start here: an empty dict).
    mu_init : float
        Initial barrier parameter: small, since the guess is already (nearly) optimal.
    bound_push : float
        How far (absolute and relative to the bounds' distance) the guess and its slacks are pushed
        inside their bounds: tiny for the optimum of the same problem, larger for a guess from
        another mesh whose active set may differ.
    mult_bound_push : float
        The least value of a bound multiplier at the start.

    Returns
    -------
    dict
        Options to merge into :func:`solver_options`' ``extra``.
    """
    if solver != "ipopt":
        return {}
    return {"ipopt.warm_start_init_point": "yes", "ipopt.mu_init": mu_init,
            "ipopt.warm_start_bound_push": bound_push, "ipopt.warm_start_bound_frac": bound_push,
            "ipopt.warm_start_mult_bound_push": mult_bound_push, "ipopt.warm_start_slack_bound_push": bound_push,
            "ipopt.warm_start_slack_bound_frac": bound_push}


def status_name(stats: Mapping[str, Any]) -> str:
    """The solver's return status as a name.

    Parameters
    ----------
    stats : mapping
        ``solver.stats()`` after a solve.

    Returns
    -------
    str
        IPOPT's status string as it is (e.g. ``Solve_Succeeded``); FATROP's integer flag named by
        :data:`FATROP_STATUS`; ``"unknown"`` when the solver reported none.
    """
    raw = stats.get("return_status", "unknown")
    if isinstance(raw, (int, np.integer)) and not isinstance(raw, bool):
        return FATROP_STATUS.get(int(raw), f"Fatrop_Flag_{int(raw)}")
    return str(raw)


def violation(g: Array, lbg: Any, ubg: Any) -> float:
    """Largest violation of ``lbg <= g <= ubg``.

    Parameters
    ----------
    g : array_like
        Constraint values.
    lbg, ubg : float or array_like
        Their bounds (broadcast to ``g``).

    Returns
    -------
    float
        The largest excess over a bound (0 when every bound holds).
    """
    g = np.ravel(g)
    if g.size == 0:
        return 0.0
    low, high = np.broadcast_to(lbg, g.shape), np.broadcast_to(ubg, g.shape)
    return float(np.max(np.maximum(np.maximum(low - g, g - high), 0.0)))


def converged(status: str, success: bool, violation_: float, feasibility_tolerance: float) -> bool:
    """The status policy of the module docstring.

    Parameters
    ----------
    status : str
        The solver's return status.
    success : bool
        The solver's own ``success`` flag.
    violation_ : float
        Largest constraint violation at the returned point.
    feasibility_tolerance : float
        Violation accepted with ``Search_Direction_Becomes_Too_Small``.

    Returns
    -------
    bool
        Whether the start counts as converged.
    """
    return success or status in SUCCESS or (status in STALLED_AT_FEASIBLE and violation_ <= feasibility_tolerance)


def solve_multistart(solver: ca.Function, guesses: Iterable[Array], *, p: Any = None, lbx: Any = None,
                     ubx: Any = None, lbg: Any = None, ubg: Any = None, agree: int = 2, rtol: float = 1e-6,
                     atol: float = 1e-12, feasibility_tolerance: float = 1e-8,
                     max_starts: int | None = None, restart: float = 0.0, max_restarts: int = 4,
                     fallback: Sequence[Array] = (), lam_x0: Any = None, lam_g0: Any = None,
                     second_order: bool = False,
                     tie_break: Callable[[Array], float] | None = None) -> NLPResult:
    """Solve from each guess in turn, keep the best converged start, stop early on agreement.

    Parameters
    ----------
    solver : casadi.Function
        A ``casadi.nlpsol`` function, or a stand-in called as one whose ``nlpsol`` attribute is the
        function whose derivatives describe the NLP (:class:`ocp.nlp.interior_point.InteriorPoint`,
        :class:`planners.spin_extremal.NewtonFirst` takes none: no second-order check there).
    guesses : iterable of ndarray
        Initial decision vectors (clipped into ``[lbx, ubx]``); may be a lazy iterable.
    p, lbx, ubx, lbg, ubg : array_like or None
        The solver's arguments (``None``: the solver's defaults).
    agree : int
        Stop once this many converged starts lie within ``rtol``/``atol`` of the best
        objective (1: stop at the first converged start; 0: never stop early).
    rtol, atol : float
        Relative and absolute agreement of objectives.
    feasibility_tolerance : float
        Constraint violation accepted by the status policy.
    max_starts : int or None
        Try at most this many guesses (``None``: all).
    restart : float
        Relative perturbation of the restarts from the best point (0: no restarts).
    max_restarts : int
        Restarts at most.
    fallback : sequence of ndarray
        Guesses tried after ``guesses`` only while no start has converged.
    lam_x0, lam_g0 : array_like or None
        Initial bound and constraint multipliers passed with every guess (``None``: zeros).
    second_order : bool
        Before the restarts, check the best point by the second-order sufficient conditions; when
        it satisfies them, the certificate counts as one more start agreeing on it (with
        ``agree=2``, no restart; see the module docstring).
    tie_break : callable or None
        Secondary criterion of a decision vector: among converged starts whose objectives agree
        with the least one, the one with the least value is kept (see the module docstring);
        ``None``: the least objective.

    Returns
    -------
    NLPResult
        The best converged start and the record of all starts.
    """
    args: dict[str, Any] = {}
    for name, value in (("p", p), ("lbx", lbx), ("ubx", ubx), ("lbg", lbg), ("ubg", ubg),
                        ("lam_x0", lam_x0), ("lam_g0", lam_g0)):
        if value is not None:
            args[name] = value
    low = -np.inf if lbx is None else np.asarray(lbx, dtype=float)
    high = np.inf if ubx is None else np.asarray(ubx, dtype=float)
    g_low = -np.inf if lbg is None else lbg
    g_high = np.inf if ubg is None else ubg
    best: dict[str, Any] = {}
    best_f, best_index = np.inf, None
    ranked: list[tuple[float, float, int, dict[str, Any]]] = []  # with tie_break
    checks: dict[int, SecondOrderCheck] = {}
    starts: list[StartResult] = []
    objectives: list[float] = []
    begin = time.perf_counter()
    call = _caller(solver)
    # a stand-in for an nlpsol function (:class:`ocp.nlp.interior_point.InteriorPoint`) names the one
    # whose derivatives describe its NLP
    derivatives: ca.Function = getattr(solver, "nlpsol", solver)
    default_name = (derivatives.class_name().removesuffix("Interface").lower() if isinstance(derivatives, ca.Function)
                    else type(solver).__name__)

    def agreeing() -> int:
        return sum(abs(value - best_f) <= atol + rtol * abs(best_f) for value in objectives)

    def candidates() -> Iterator[Array]:
        for index, guess in enumerate(guesses):
            if max_starts is not None and index >= max_starts:
                break
            yield guess
        for guess in fallback:
            if best or (starts and all(start.status == INFEASIBLE[0] for start in starts)):
                break  # converged, or every start found the constraints locally infeasible: no stall to escape
            yield guess
        for k in range(max_restarts if restart > 0 and best else 0):
            if second_order and agree:
                assert best_index is not None  # set with best
                if best_index not in checks:
                    checks[best_index] = second_order_check(derivatives, best["x"], best["lam_x"], best["lam_g"],
                                                            p=p, lbx=low, ubx=high, lbg=g_low, ubg=g_high)
                # the certificate counts as one more start agreeing on the best point
                if checks[best_index].certified and agreeing() + 1 >= agree:
                    break
            yield perturbed(best["x"], 1, seed=k + 1, scales=(restart, restart))[0]

    for index, guess in enumerate(candidates()):
        tic = time.perf_counter()
        solution, stats = call(x0=np.clip(np.asarray(guess, dtype=float), low, high), **args)
        status = status_name(stats)
        g = solution["g"]
        excess = violation(g, g_low, g_high)
        f = float(solution["f"][0])
        ok = bool(np.isfinite(f)) and converged(status, bool(stats.get("success", False)), excess,
                                                 feasibility_tolerance)
        iterations = int(stats.get("iter_count", 0))
        name = str(stats.get("solver", default_name))
        if ok and status in ACCEPTABLE:  # stopped at the acceptable level: continued once
            again, stats = call(x0=solution["x"], **{**args, "lam_x0": solution["lam_x"], "lam_g0": solution["lam_g"]})
            iterations += int(stats.get("iter_count", 0))
            g_again = again["g"]
            excess_again, f_again = violation(g_again, g_low, g_high), float(again["f"][0])
            if np.isfinite(f_again) and converged(status_name(stats), bool(stats.get("success", False)),
                                                  excess_again, feasibility_tolerance):
                solution, status, g, excess, f = again, status_name(stats), g_again, excess_again, f_again
        elapsed = time.perf_counter() - tic
        starts.append(StartResult(status, f, iterations, elapsed, excess, ok, name))
        if not ok:
            continue
        objectives.append(f)
        if tie_break is None:
            if f < best_f:
                best = {key: solution[key] for key in ("x", "lam_x", "lam_g")}
                best["g"], best_f, best_index = g, f, index
        else:
            # Judged against the least objective, not the start kept so far: tolerance chains
            # (a ≈ b ≈ c, a ≉ c) would otherwise drift away from it, and the order would decide.
            point = {key: solution[key] for key in ("x", "lam_x", "lam_g")}
            tie = float(tie_break(point["x"]))
            ranked.append((np.inf if np.isnan(tie) else tie, f, index, {**point, "g": g}))
            least = min(entry[1] for entry in ranked)
            _, best_f, best_index, best = min((entry for entry in ranked
                                               if abs(entry[1] - least) <= atol + rtol * abs(least)),
                                              key=lambda entry: entry[:3])
        if agree and agreeing() >= agree:
            break
    total = time.perf_counter() - begin
    iterations = sum(s.iterations for s in starts)
    statuses = [s.status for s in starts]
    if best_index is None:
        message = f"no start converged: {sorted(set(statuses))}"
        if statuses and all(s in INFEASIBLE for s in statuses):
            message += " (every start locally infeasible: not a proof, another start may find a feasible point)"
        return NLPResult(None, np.inf, None, False, "failed", message, iterations, total, None, starts)
    message = f"objective {best_f:.8g} from start {best_index} of {len(starts)} tried ({statuses[best_index]})"
    if best_index in checks:
        message += f"; second order: {checks[best_index].message}"
    return NLPResult(best["x"], best_f, best["g"], True, "ok", message, iterations, total, best_index, starts,
                     best["lam_x"], best["lam_g"], checks.get(best_index))


def _caller(solver: Any) -> Callable[..., tuple[dict[str, Array], Mapping[str, Any]]]:
    """How :func:`solve_multistart` calls ``solver``: ``call(**arguments) -> (outputs, stats)``, the
    outputs as flat arrays of their own and the stats of that call.

    An ``nlpsol`` function is evaluated through its buffers (:func:`ocp.fast_call.buffered`: the same
    evaluation, without converting its vectors to CasADi matrices and back, milliseconds a call on a
    50-interval collocation NLP), an argument not given taking the input's default as a plain call
    does; anything else called as it stands (a stand-in such as
    :class:`planners.spin_extremal.NewtonFirst`), read through its ``stats()``.
    """
    if not isinstance(solver, ca.Function):
        def plain(**arguments: Any) -> tuple[dict[str, Array], Mapping[str, Any]]:
            solution = solver(**arguments)
            outputs = {name: np.asarray(value.full() if isinstance(value, ca.DM) else value, dtype=float).ravel()
                       for name, value in solution.items()}
            return outputs, solver.stats()

        return plain
    function = buffered(solver)
    names_in = [solver.name_in(i) for i in range(solver.n_in())]
    defaults = [solver.default_in(i) for i in range(solver.n_in())]
    names_out = [solver.name_out(i) for i in range(solver.n_out())]

    def call(**arguments: Any) -> tuple[dict[str, Array], Mapping[str, Any]]:
        for target, name, default in zip(function.inputs, names_in, defaults):
            value = arguments.get(name)
            target[:] = default if value is None else np.asarray(value, dtype=float).ravel()
        function.evaluate()  # raises where a plain call raises (``error_on_fail``)
        return {name: output.copy() for name, output in zip(names_out, function.outputs)}, function.stats()

    return call


def perturbed(center: Array, count: int, seed: int = 0, scales: Sequence[float] = (0.01, 0.05),
              floor: Array | float = 1e-3) -> list[Array]:
    """Copies of a point with relative normal noise.

    Parameters
    ----------
    center : ndarray
        The point (a decision vector).
    count : int
        How many copies.
    seed : int
        Seed of the random generator (the copies are reproducible).
    scales : (2,) sequence of float
        Relative noise of the first copy and of the others; the noise of a component is
        proportional to ``|center| + floor``.
    floor : float or ndarray
        Added to ``|center|`` (per component when an array): the size of the noise where the
        point is zero, e.g. half a control's range, so that a symmetric point (zero torques and
        rates about two axes) is left in every direction.

    Returns
    -------
    list of ndarray
        ``count`` perturbed copies of ``center``.
    """
    rng = np.random.default_rng(seed)
    size = np.abs(center) + floor
    return [center + rng.normal(0.0, 1.0, center.size) * size * (scales[0] if k == 0 else scales[1])
            for k in range(count)]
