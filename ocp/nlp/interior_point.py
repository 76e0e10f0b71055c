"""IPOPT's interior point on a compiled sparse LDLᵀ, for small NLPs with equality constraints and bounds.

What it solves: ``min f(x, p)`` subject to ``g(x, p) = b`` (every row an equality, ``lbg = ubg``)
and ``lbx ≤ x ≤ ubx``: the NLP of a ``casadi.nlpsol`` function (its ``oracle``). What for: the cold
coarse-mesh starts of collocation's minimum time, where IPOPT spends most of its time around its
linear algebra rather than in it: 0.6 ms an iteration on the 312-variable coarse NLP of Bilimoria &
Wie (MUMPS's calls and IPOPT's own vectors), where one factorisation of its KKT matrix takes 35 µs
in compiled code (:mod:`ocp.nlp.sparse_ldl`) and CasADi's derivatives about 20 µs. The derivatives
are the ``nlpsol``'s own (``nlp_hess_l``, ``nlp_jac_g``, ``nlp_grad_f``), composed in MX: nothing is
differentiated again, and building an instance takes milliseconds (differentiating the oracle anew
took 50-90 ms, more than a first plan gained). The loops over the bounded entries are C too
(``interior_point.c``, compiled as the factorisation is).

The method is IPOPT's (A. Wächter and L. T. Biegler, *Math. Program.* 106, 25-57, 2006; the
constants are IPOPT 3.14's defaults, :data:`IPOPT_DEFAULTS`), so that it takes IPOPT's iterates:

- IPOPT's gradient-based scaling of the objective and of each constraint row (at most 100 in a
  gradient at the start), the starting point pushed inside its bounds (``bound_push``,
  ``bound_frac``), bound multipliers 1 and least-squares constraint multipliers (dropped above
  ``constr_mult_init_max``);
- the primal-dual Newton step of the barrier problem from the augmented system
  ``[[W + Σ + δ_w I, Jᵀ], [J, −δ_c I]] [dx; dy] = −[∇φ_μ + Jᵀ y; c]`` (``Σ = Z_L (X − L)⁻¹ + Z_U
  (U − X)⁻¹``), the bound multipliers' steps from ``dx``;
- IPOPT's inertia correction: the inertia of the factorised matrix must be ``(n, m, 0)``, else
  ``δ_w`` is tried at ``first_hessian_perturbation`` (or a third of its last value), then grown
  (``perturb_inc_fact_first`` after an unperturbed iteration, ``perturb_inc_fact`` after a
  perturbed one), and after ``DEGENERATE_ITERATIONS`` perturbed iterations from the start
  every iteration is perturbed without trying ``δ_w = 0`` first;
- the monotone barrier update (``μ ← max(tol / 10, min(κ_μ μ, μ^θ_μ))`` while the barrier
  problem's scaled error is below ``κ_ε μ``), the fraction to the boundary ``τ = max(τ_min, 1 − μ)``
  on the primal and the bound multipliers' steps, the bound multipliers kept within
  ``[μ / (κ_Σ s), κ_Σ μ / s]``;
- the filter line search on ``θ = ‖c‖₁`` and the barrier function ``φ_μ`` (the switching condition,
  the Armijo condition of f-type steps, the filter's margins, backtracking by halves down to the
  least step ``α_min``);
- IPOPT's scaled optimality error with ``s_max`` as the stopping test (``tol``), with the unscaled
  dual infeasibility, constraint violation and complementarity within IPOPT's defaults.

Where it differs, and why:

- **The factorisation.** An LDLᵀ without numerical pivoting in a fixed fill-reducing order
  (:class:`~ocp.nlp.sparse_ldl.SparseLDL`), where IPOPT's MUMPS pivots: the constraint block is
  always regularised, ``δ_c = 1e-8 μ^¼`` (IPOPT's value for a singular Jacobian, which IPOPT uses
  only when MUMPS finds one), so that the matrix is quasi-definite once the inertia is right; a
  pivot below :data:`PIVOT_TOLERANCE` is replaced by it with the sign its row expects (a static
  pivot); every solve is refined against the unperturbed matrix, and a solve whose residual stays
  above :data:`SOLVE_ACCEPTED` counts as a factorisation of wrong inertia (``δ_w`` grows). A
  factorisation stops at the first pivot that makes the inertia wrong.
- **Fixed variables** (``lbx = ubx``), which IPOPT takes out of the problem, and a **tiny step**
  (``max |dx_i| / (1 + |x_i|) < 10 ε``, after which IPOPT takes the full step and lowers ``μ``) are
  handed to IPOPT, as is a start with multipliers or with an inequality row. Bounds beyond ±1e19
  are no bounds, as in IPOPT.
- **No restoration phase, second-order corrections or watchdog; no acceptable level; no bound
  relaxation.** Where the line search would need a restoration phase (the step falls below
  ``α_min``), or after :data:`HAND_OVER_AFTER` iterations, the solve is handed to IPOPT from the same start
  (``nlpsol``, as given): the answer is then IPOPT's, and the statistics count both. IPOPT's bounds
  are relaxed by ``bound_relax_factor`` (1e-8 relative), these are not: on Bilimoria & Wie's coarse
  mesh T is 1.6e-8 s longer than IPOPT's, at its bang-bang controls exactly at ±1.

The result: on that coarse NLP the same iterates as IPOPT for its first 20 iterations (the
objective to 6 digits), the same optima (decision vectors within 2e-6), 23 + 24 iterations from the
two seeds against IPOPT's 22 + 24, each start in 0.28-0.39 of IPOPT's time on the suite's
minimum-time cases (``tests/benchmarks/test_bench_interior_point.py``).

Converged points are ordinary KKT points, certified downstream as IPOPT's are: ``lam_g`` the
constraint multipliers and ``lam_x = z_U − z_L`` the bound multipliers in CasADi's signs
(``∇f + Jᵀ lam_g + lam_x = 0``). The statuses are IPOPT's names for the same outcomes
(``Solve_Succeeded``; ``Search_Direction_Becomes_Too_Small``); the statistics say which solver
reached them (``solver``).

May import: CasADi, NumPy, the standard library, :mod:`ocp.fast_call`, :mod:`ocp.native`, :mod:`ocp.errors`
and :mod:`ocp.nlp.sparse_ldl`.
"""
from __future__ import annotations

import ctypes
import functools
import math
import threading
import time
import weakref
from pathlib import Path
from typing import Any, NamedTuple

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ocp import native
from ocp.errors import CompilerUnavailable
from ocp.fast_call import BufferedFunction
from ocp.nlp.sparse_ldl import FLAGS, SparseLDL
from ocp.nlp.sparse_ldl import available as sparse_ldl_available

Array = NDArray[np.float64]

IPOPT_DEFAULTS: dict[str, float] = {
    "bound_push": 0.01, "bound_frac": 0.01, "mu_init": 0.1, "barrier_tol_factor": 10.0,
    "mu_linear_decrease_factor": 0.2, "mu_superlinear_decrease_power": 1.5, "tau_min": 0.99,
    "kappa_sigma": 1e10, "s_max": 100.0, "nlp_scaling_max_gradient": 100.0, "constr_mult_init_max": 1000.0,
    "gamma_theta": 1e-5, "gamma_phi": 1e-8, "delta": 1.0, "s_theta": 1.1, "s_phi": 2.3, "eta_phi": 1e-8,
    "alpha_min_frac": 0.05, "dual_inf_tol": 1.0, "constr_viol_tol": 1e-4, "compl_inf_tol": 1e-4,
    "first_hessian_perturbation": 1e-4, "min_hessian_perturbation": 1e-20, "perturb_inc_fact": 8.0,
    "perturb_inc_fact_first": 100.0, "perturb_dec_fact": 1.0 / 3.0, "max_hessian_perturbation": 1e20,
    "jacobian_regularization_value": 1e-8, "jacobian_regularization_exponent": 0.25,
}
"""IPOPT 3.14's options as this method uses them (IPOPT's names; its documented defaults)."""
OPTION_RANGES: dict[str, tuple[float, float]] = {
    "perturb_inc_fact": (1.0, np.inf), "perturb_inc_fact_first": (1.0, np.inf), "perturb_dec_fact": (0.0, 1.0),
    "mu_linear_decrease_factor": (0.0, 1.0), "mu_superlinear_decrease_power": (1.0, 2.0), "tau_min": (0.0, 1.0),
    "bound_frac": (0.0, 0.5 + 1e-15), "kappa_sigma": (1.0, np.inf), "gamma_theta": (0.0, 1.0),
    "gamma_phi": (0.0, 1.0), "eta_phi": (0.0, 0.5), "alpha_min_frac": (0.0, 1.0), "s_phi": (1.0, np.inf),
    "s_theta": (1.0, np.inf),
}
"""The open interval of each option of :data:`IPOPT_DEFAULTS` (IPOPT's documented ranges); an option
not listed is a positive finite number."""
INFINITE_BOUND = 1e19
"""IPOPT's ``nlp_lower_bound_inf`` / ``nlp_upper_bound_inf``: bounds beyond ±1e19 are no bounds."""
DEGENERATE_ITERATIONS = 3
"""IPOPT's ``degen_iters_max``: perturbed iterations from the start after which the Hessian is taken
as degenerate (every later iteration perturbed, without trying ``δ_w = 0`` first)."""
PIVOT_TOLERANCE = 1e-14
"""Pivots of smaller magnitude are replaced by it (a static pivot, with the sign the row expects)."""
SOLVE_TOLERANCE = 1e-10
"""Backward error of a solve that refinement aims at (IPOPT's ``residual_ratio_max``)."""
SOLVE_ACCEPTED = 1e-5
"""Backward error above which a refined solve is rejected, its factorisation counted as one of wrong
inertia (IPOPT's ``residual_ratio_singular``)."""
REFINEMENTS = 10
"""Refinement steps at most per solve."""
HAND_OVER_AFTER = 150
"""Iterations after which an unfinished solve is handed to IPOPT (the coarse starts of the suite take
9-70): IPOPT's restoration phase and watchdog, which this method lacks, may be what it needs."""
SOLVER_NAME = "interior_point"
"""``stats()["solver"]`` of a solve this module finished (``"ipopt"`` after a hand-over)."""


class InteriorPoint:
    """The interior point of the module docstring for the NLP of ``nlpsol``, called as ``nlpsol`` is.

    Parameters
    ----------
    nlpsol : casadi.Function
        An IPOPT ``casadi.nlpsol`` function: its ``oracle()`` ``(x, p) -> (f, g)`` is the NLP, and it
        solves what this method hands over (``nlpsol`` attribute; its derivatives are those a
        certificate of the point reads).
    tolerance : float
        IPOPT's ``tol`` (the scaled optimality error at which a solve stops).
    max_iterations : int
        IPOPT's ``max_iter``: a solve that reaches it stops there, ``Maximum_Iterations_Exceeded`` at
        its last point, as IPOPT's does (no hand-over).
    hand_over_after : int
        Iterations after which a solve still running (below ``max_iterations``) is handed to
        ``nlpsol`` from its start.
    options : dict
        Overrides of :data:`IPOPT_DEFAULTS` by IPOPT's names (``bound_push``, ``perturb_inc_fact``, ...).

    Raises
    ------
    RuntimeError
        Where the compiled factorisation is not available (:func:`ocp.nlp.sparse_ldl.available`).

    Notes
    -----
    ``solver(x0=..., p=..., lbx=..., ubx=..., lbg=..., ubg=...)`` returns ``x, f, g, lam_x, lam_g`` as
    flat arrays; :meth:`stats` the last call's ``return_status``, ``success``, ``iter_count``,
    ``solver`` and ``t_wall_total`` [s] (after a hand-over, IPOPT's status and ``iter_count`` both
    solvers' iterations, ``interior_point`` this method's own status and iterations). A call with
    multipliers (``lam_x0``/``lam_g0``) or with a row whose ``lbg ≠ ubg`` is IPOPT's from the start.
    """

    def __init__(self, nlpsol: ca.Function, tolerance: float = 1e-8, max_iterations: int = 3000,
                 options: dict[str, float] | None = None, hand_over_after: int = HAND_OVER_AFTER) -> None:
        unknown = set(options or {}) - set(IPOPT_DEFAULTS)
        if unknown:
            raise ValueError(f"unknown options {sorted(unknown)}; known: {sorted(IPOPT_DEFAULTS)}")
        self.options = {**IPOPT_DEFAULTS, **(options or {})}
        for name, value in self.options.items():
            low, high = OPTION_RANGES.get(name, (0.0, np.inf))
            if not (isinstance(value, (int, float)) and not isinstance(value, bool) and low < value < high):
                raise ValueError(f"option {name}: {value!r} is not a number in ({low:g}, {high:g})")
        self.nlpsol = nlpsol
        self.tolerance, self.max_iterations = float(tolerance), int(max_iterations)
        self.hand_over_after = int(hand_over_after)
        # The NLP's derivatives as nlpsol built them (nothing differentiated again: building this
        # costs milliseconds, not the tens a symbolic Hessian would), composed in MX.
        oracle = nlpsol.oracle()
        self._hessian = nlpsol.get_function("nlp_hess_l")  # (x, p, λ_f, λ_g) -> ∇²(λ_f f + λ_gᵀ g), a triangle
        self._jacobian = nlpsol.get_function("nlp_jac_g")  # (x, p) -> (g, ∂g/∂x)
        self._gradient = nlpsol.get_function("nlp_grad_f")  # (x, p) -> (f, ∇f)
        n, m = oracle.nnz_in(0), oracle.nnz_out(1)
        self.n, self.m = n, m
        x, p = ca.MX.sym("x", n), ca.MX.sym("p", oracle.nnz_in(1))
        sf, sg, y = ca.MX.sym("sf"), ca.MX.sym("sg", m), ca.MX.sym("y", m)
        self._symbols = (x, p, y, sf, sg)
        f, gradient = self._gradient(x, p)
        g, jacobian = self._jacobian(x, p)
        # the KKT matrix's lower triangle, its whole diagonal in the pattern
        self._pattern = self._kkt(self._lower(self._hessian(x, p, sf, y)), jacobian).sparsity() \
            + ca.Sparsity.diag(n + m)
        rows, columns = (np.asarray(v, dtype=np.int64) for v in self._pattern.get_triplet())
        diagonal = np.flatnonzero(rows == columns)
        diagonal = diagonal[np.argsort(rows[diagonal])]  # the position of K[i, i] among the nonzeros
        self._diagonal_x, self._diagonal_y = diagonal[:n], diagonal[n:]
        # The least-squares multipliers' matrix [[I, Jᵀ], [J, 0]] (in K's pattern) and ∇f at the start
        scaled_jacobian = ca.mtimes(ca.diag(sg), jacobian)
        self._least_squares = BufferedFunction(ca.Function(
            "ip_least_squares", [x, p, sf, sg], [self._kkt(ca.MX.eye(n), scaled_jacobian), sf * gradient]))
        self._unscaled = BufferedFunction(oracle)
        self._start = BufferedFunction(ca.Function("ip_start", [x, p], [gradient, jacobian]))
        jacobian_rows = np.asarray(jacobian.sparsity().get_triplet()[0], dtype=np.int64)
        self._jacobian_by_row = np.argsort(jacobian_rows, kind="stable")  # its nonzeros grouped by row
        counts = np.bincount(jacobian_rows, minlength=m)
        self._row_starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
        self._row_nonempty = counts > 0
        self._ldl = SparseLDL(rows, columns, n + m, np.concatenate([np.ones(n), -np.ones(m)]))
        self._compiled: dict[bool, _Compiled] = {}
        vectors = _vector_library()
        if vectors is None:
            raise RuntimeError(available()[1])
        self._vectors = vectors
        self._stats: dict[str, Any] = {}
        self.trace: Any = None  # a callable given each iteration's record (debugging, tests)

    @staticmethod
    def _lower(hessian: ca.MX) -> ca.MX:
        """The lower triangle of ``nlp_hess_l``'s output (IPOPT's nlpsol gives the upper one)."""
        return hessian.T if hessian.sparsity().is_triu() and not hessian.sparsity().is_tril() else ca.tril(hessian)

    def _kkt(self, lower_hessian: ca.MX, jacobian: ca.MX) -> ca.MX:
        """``[[W, 0], [J, 0]]`` (the KKT matrix's lower triangle) in :attr:`_pattern` where it is set."""
        n, m = self.n, self.m
        matrix = ca.blockcat([[lower_hessian, ca.MX(n, m)], [jacobian, ca.MX(m, m)]])
        return ca.project(matrix, self._pattern) if hasattr(self, "_pattern") else matrix

    def _functions(self, scaled: bool) -> _Compiled:
        """The iteration's compiled functions of the scaled NLP (``scaled``: the objective and rows
        scaled by the inputs ``sf``, ``sg``; else not, where IPOPT's scaling is 1 throughout, ``sf``
        and ``sg`` then unused), built once each, :class:`_Compiled`:

        - ``iterate(x, p, y, sf, sg, c)``: the KKT matrix's nonzeros (its lower triangle: ``W`` and
          ``J``; ``Σ`` and the regularisations are added to its diagonal in place), ``∇f``,
          ``∇f + Jᵀ y`` and ``[f, ‖c‖∞, ‖c‖₁, ‖y‖₁]``, ``c`` the constraints' residual given;
        - ``merit(x, p, sf, sg, b)``: ``[f, ‖c‖₁]`` and ``c = g − b`` at a trial point.
        """
        found = self._compiled.get(scaled)
        if found is not None:
            return found
        x, p, y, sf, sg = self._symbols
        m = self.m
        f, gradient = self._gradient(x, p)
        g, jacobian = self._jacobian(x, p)
        if scaled:
            hessian = self._hessian(x, p, sf, sg * y)
            f, gradient, g, jacobian = sf * f, sf * gradient, sg * g, ca.mtimes(ca.diag(sg), jacobian)
        else:
            hessian = self._hessian(x, p, 1.0, y)
        kkt = self._kkt(self._lower(hessian), jacobian)
        c, b = ca.MX.sym("c", m), ca.MX.sym("b", m)
        zero = ca.MX(0)
        iterate = BufferedFunction(ca.Function(
            "ip_iterate", [x, p, y, sf, sg, c],
            [kkt, ca.densify(gradient), ca.densify(gradient + ca.mtimes(jacobian.T, y)),
             ca.vertcat(f, ca.norm_inf(c) if m else zero, ca.norm_1(c) if m else zero,
                        ca.norm_1(y) if m else zero)]))
        values, constraints = self._unscaled_symbols(x, p)
        if scaled:
            values, constraints = sf * values, sg * constraints
        residual = constraints - b
        merit = BufferedFunction(ca.Function(
            "ip_merit", [x, p, sf, sg, b], [ca.vertcat(values, ca.norm_1(residual) if m else zero),
                                            ca.densify(residual)]))
        found = self._compiled[scaled] = _Compiled(iterate, merit)
        return found

    def _unscaled_symbols(self, x: ca.MX, p: ca.MX) -> tuple[ca.MX, ca.MX]:
        """``(f, g)`` of the NLP at the symbols (its oracle, called)."""
        f, g = self._unscaled.function(x, p)
        return f, g

    def stats(self) -> dict[str, Any]:
        """The last call's statistics, as ``nlpsol``'s ``stats()`` (see the class notes).

        Returns
        -------
        dict
        """
        return self._stats

    def __call__(self, *, x0: Any, p: Any = None, lbx: Any = None, ubx: Any = None, lbg: Any = None,
                 ubg: Any = None, lam_x0: Any = None, lam_g0: Any = None) -> dict[str, Any]:
        tic = time.perf_counter()
        n, m = self.n, self.m
        arguments = {"x0": x0, "p": p, "lbx": lbx, "ubx": ubx, "lbg": lbg, "ubg": ubg}
        low_g = np.broadcast_to(0.0 if lbg is None else np.asarray(lbg, dtype=float).ravel(), (m,))
        high_g = np.broadcast_to(0.0 if ubg is None else np.asarray(ubg, dtype=float).ravel(), (m,))
        if lam_x0 is not None or lam_g0 is not None or np.any(low_g != high_g):
            return self._handed_over(arguments, {"lam_x0": lam_x0, "lam_g0": lam_g0}, None, 0, tic)
        start = np.array(np.broadcast_to(np.asarray(x0, dtype=float).ravel(), (n,)))
        params = np.zeros(self._unscaled.inputs[1].size) if p is None else np.asarray(p, dtype=float).ravel()
        low = np.broadcast_to(-np.inf if lbx is None else np.asarray(lbx, dtype=float).ravel(), (n,))
        high = np.broadcast_to(np.inf if ubx is None else np.asarray(ubx, dtype=float).ravel(), (n,))
        status, iterations, solution = self._solve(start, params, low, high, np.array(low_g, dtype=float))
        if solution is None:
            return self._handed_over(arguments, {}, status, iterations, tic)
        self._stats = {"return_status": status, "success": status == "Solve_Succeeded", "iter_count": iterations,
                       "solver": SOLVER_NAME, "t_wall_total": time.perf_counter() - tic}
        return solution

    def _handed_over(self, arguments: dict[str, Any], multipliers: dict[str, Any], status: str | None,
                     iterations: int, tic: float) -> dict[str, Any]:
        """IPOPT's solve of the same call (``status``: this method's, ``None`` where it did not try)."""
        given = {key: value for key, value in {**arguments, **multipliers}.items() if value is not None}
        solution = self.nlpsol(**given)
        stats = dict(self.nlpsol.stats())
        self._stats = {"return_status": stats.get("return_status", "unknown"), "success": bool(stats.get("success")),
                       "iter_count": iterations + int(stats.get("iter_count", 0)), "solver": "ipopt",
                       "t_wall_total": time.perf_counter() - tic}
        if status is not None:
            self._stats["interior_point"] = {"status": status, "iterations": iterations}
        return {key: np.asarray(value.full() if isinstance(value, ca.DM) else value, dtype=float).ravel()
                for key, value in solution.items()}

    def _solve(self, start: Array, p: Array, low: Array, high: Array,
               b: Array) -> tuple[str, int, dict[str, Array] | None]:
        """IPOPT's iterations from ``start``: ``(status, iterations, solution)``, the solution ``None``
        where the solve is to be handed over."""
        o = self.options
        n, m = self.n, self.m
        if np.any(low > high):
            return "Invalid_Option", 0, None  # IPOPT says what is wrong
        if np.any(low == high):
            return "Fixed_Variables", 0, None  # IPOPT takes them out of the problem: its turn
        # The bounded entries as one vector: s = side (x[index] − bound) > 0, z their multipliers.
        lower, upper = np.flatnonzero(low > -INFINITE_BOUND), np.flatnonzero(high < INFINITE_BOUND)
        index = np.ascontiguousarray(np.concatenate([lower, upper]), dtype=np.int32)
        side = np.concatenate([np.ones(lower.size), -np.ones(upper.size)])
        bound = np.concatenate([low[lower], high[upper]])
        nb = index.size
        # IPOPT's gradient-based scaling at the caller's start
        gradient0, jacobian0 = (array.copy() for array in self._start.all_outputs(start, p))
        # IPOPT's starting point: pushed inside the bounds by bound_push and bound_frac
        x = start.copy()
        gap = np.where((low > -INFINITE_BOUND) & (high < INFINITE_BOUND), high - low, np.inf)
        push_l = np.minimum(o["bound_push"] * np.maximum(1.0, np.abs(low[lower])), o["bound_frac"] * gap[lower])
        push_u = np.minimum(o["bound_push"] * np.maximum(1.0, np.abs(high[upper])), o["bound_frac"] * gap[upper])
        x[lower] = np.maximum(x[lower], low[lower] + push_l)
        x[upper] = np.minimum(x[upper], high[upper] - push_u)
        if not (np.all(np.isfinite(gradient0)) and np.all(np.isfinite(jacobian0)) and np.all(np.isfinite(x))):
            return "Invalid_Number_Detected", 0, None
        largest = o["nlp_scaling_max_gradient"]
        sf = min(1.0, largest / max(float(np.max(np.abs(gradient0), initial=0.0)), 1e-300))
        row_max = np.zeros(m)
        if jacobian0.size:  # the largest |∂g_i/∂x_j| of each row
            grouped = np.abs(jacobian0[self._jacobian_by_row])
            row_max[self._row_nonempty] = np.maximum.reduceat(grouped, self._row_starts[self._row_nonempty])
        sg = np.minimum(1.0, largest / np.maximum(row_max, 1e-300))
        b = sg * b
        iterate, merit = self._functions(sf != 1.0 or bool(np.any(sg != 1.0)))
        ldl, diagonal_x, diagonal_y, lib = self._ldl, self._diagonal_x, self._diagonal_y, self._vectors
        for function, (at_p, at_sf, at_sg) in ((iterate, (1, 3, 4)), (merit, (1, 2, 3))):  # the inputs that stay
            function.inputs[at_p][:] = p
            function.inputs[at_sf][:] = sf
            function.inputs[at_sg][:] = sg
        merit.inputs[4][:] = b
        # the C loops' arrays, and their addresses
        z = np.ones(nb)
        s, s_trial, dz = np.zeros(nb), np.zeros(nb), np.zeros(nb)
        sigma, barrier, work = np.zeros(n), np.zeros(n), np.zeros(n)
        out = np.zeros(3)
        log_sum = ctypes.c_double(0.0)
        log_address = ctypes.addressof(log_sum)
        bounded = (nb, index.ctypes.data, side.ctypes.data, bound.ctypes.data)
        x_trial = merit.inputs[0]
        # least-squares constraint multipliers: [[I, Jᵀ], [J, −δ I]] [w; y] = −[∇f − z_L + z_U; 0]
        values, gradient = self._least_squares.all_outputs(x, p, sf, sg)
        values[diagonal_y] = -o["jacobian_regularization_value"]
        y = np.zeros(m)
        negative, _ = ldl.factor(values, PIVOT_TOLERANCE)
        if negative == m and m:
            rhs = np.zeros(n + m)
            rhs[:n] = np.bincount(index, side * z, minlength=n) - gradient
            estimate, error = ldl.solve(rhs, SOLVE_TOLERANCE, REFINEMENTS)
            if error <= SOLVE_ACCEPTED and np.max(np.abs(estimate[n:]), initial=0.0) <= o["constr_mult_init_max"]:
                y = estimate[n:]
        mu = o["mu_init"]
        tol = self.tolerance
        s_max = o["s_max"]
        mu_least = tol / 10.0
        barrier_tol, kappa_mu, theta_mu = (o["barrier_tol_factor"], o["mu_linear_decrease_factor"],
                                           o["mu_superlinear_decrease_power"])
        filter_: list[tuple[float, float]] = []
        last_dw = 0.0
        degenerate: bool | None = None
        perturbed_iterations = 0
        alpha_min_frac, gamma_theta, gamma_phi = o["alpha_min_frac"], o["gamma_theta"], o["gamma_phi"]
        s_theta, s_phi, delta, eta_phi = o["s_theta"], o["s_phi"], o["delta"], o["eta_phi"]
        kappa_sigma, tau_min = o["kappa_sigma"], o["tau_min"]
        unscaled_c = 1.0 / float(np.min(sg, initial=1.0))
        tiny = 10.0 * np.finfo(float).eps
        x_in, y_in, c_in = iterate.inputs[0], iterate.inputs[2], iterate.inputs[5]
        rhs, step = np.zeros(n + m), np.zeros(n + m)
        dx, dy = step[:n], step[n:]
        # the addresses the C loops take (s and s_trial swap at each accepted step, their addresses too)
        p_index, p_side, p_z, p_dz, p_x, p_step = (index.ctypes.data, side.ctypes.data, z.ctypes.data, dz.ctypes.data,
                                                   x.ctypes.data, step.ctypes.data)
        p_s, p_trial = s.ctypes.data, s_trial.ctypes.data
        p_barrier_args = (sigma.ctypes.data, barrier.ctypes.data, work.ctypes.data, out.ctypes.data)
        p_out, p_x_trial = out.ctypes.data, x_trial.ctypes.data
        p_gradient_lag = iterate.outputs[2].ctypes.data  # the function's output buffer: fixed
        # the start's residual and slacks
        x_trial[:] = x
        merit.evaluate()
        c = merit.outputs[1].copy()
        if not lib.sb_ip_slacks(*bounded, p_x_trial, p_s, log_address) > 0.0:
            return "Invalid_Number_Detected", 0, None  # (a start inside its bounds has every s > 0)
        log_s = log_sum.value
        limit = min(self.max_iterations, self.hand_over_after)
        for iteration in range(limit + 1):
            x_in[:] = x
            y_in[:] = y
            c_in[:] = c
            iterate.evaluate()
            values, gradient, gradient_lag, scalars = iterate.outputs
            f_s, primal_inf, theta, y_norm = scalars.tolist()
            lib.sb_ip_barrier(n, nb, p_index, p_side, p_s, p_z, p_gradient_lag, *p_barrier_args)
            dual_inf, comp, z_norm = out.tolist()
            if not math.isfinite(f_s + dual_inf + float(values.sum())):  # (or an overflow)
                return "Invalid_Number_Detected", iteration, None
            if iteration == 0:
                theta_max, theta_min = 1e4 * max(1.0, theta), 1e-4 * max(1.0, theta)
            # IPOPT's optimality error, scaled, and the unscaled tolerances
            s_d = max(s_max, (y_norm + z_norm) / max(1, m + nb)) / s_max
            s_c = max(s_max, z_norm / max(1, nb)) / s_max
            if (max(dual_inf / s_d, primal_inf, comp / s_c) <= tol and dual_inf / sf <= o["dual_inf_tol"]
                    and primal_inf * unscaled_c <= o["constr_viol_tol"] and comp / sf <= o["compl_inf_tol"]):
                return "Solve_Succeeded", iteration, self._solution(x, p, y * sg / sf, index, side, z / sf)
            if iteration == limit:  # at the caller's cap: stopped here, as IPOPT stops; else IPOPT's turn
                solution = (self._solution(x, p, y * sg / sf, index, side, z / sf)
                            if limit == self.max_iterations else None)
                return "Maximum_Iterations_Exceeded", iteration, solution
            # the monotone barrier update (several decreases at once, IPOPT's fast monotone decrease)
            while mu > mu_least and max(dual_inf / s_d, primal_inf) <= barrier_tol * mu \
                    and lib.sb_ip_complementarity(nb, p_s, p_z, mu) / s_c <= barrier_tol * mu:
                mu = max(mu_least, min(kappa_mu * mu, mu ** theta_mu))
                filter_ = []
            # the Newton system of the barrier problem: rhs = −[∇φ_μ + Jᵀ y; c]
            np.multiply(barrier, mu, out=rhs[:n])
            rhs[:n] -= gradient_lag
            np.negative(c, out=rhs[n:])
            delta_c = o["jacobian_regularization_value"] * mu ** o["jacobian_regularization_exponent"]
            dw = (max(o["min_hessian_perturbation"], o["perturb_dec_fact"] * last_dw) if last_dw > 0.0
                  else o["first_hessian_perturbation"]) if degenerate else 0.0
            values[diagonal_y] -= delta_c
            base = values[diagonal_x] + sigma
            while True:
                np.add(base, dw, out=work)
                values[diagonal_x] = work
                negative, _ = ldl.factor(values, PIVOT_TOLERANCE, m)
                if negative == m:
                    _, error = ldl.solve(rhs, SOLVE_TOLERANCE, REFINEMENTS, out=step)
                    if error <= SOLVE_ACCEPTED:
                        break
                if dw == 0.0:
                    dw = (o["first_hessian_perturbation"] if last_dw == 0.0
                          else max(o["min_hessian_perturbation"], o["perturb_dec_fact"] * last_dw))
                else:
                    dw *= o["perturb_inc_fact_first"] if last_dw == 0.0 else o["perturb_inc_fact"]
                if dw > o["max_hessian_perturbation"]:
                    return "Error_In_Step_Computation", iteration, None
            if degenerate is None:
                if dw == 0.0:
                    degenerate = False
                else:
                    perturbed_iterations += 1
                    degenerate = True if perturbed_iterations >= DEGENERATE_ITERATIONS else None
            if dw > 0.0:
                last_dw = dw
            lib.sb_ip_step(n, nb, p_index, p_side, p_s, p_z, p_step, p_x, mu, max(tau_min, 1.0 - mu), p_dz, p_out)
            alpha_max, alpha_z, relative = out.tolist()
            if relative < tiny:
                # IPOPT's tiny step (max |dx_i| / (1 + |x_i|) < 10 ε): it then takes the full step,
                # lowers μ, and stops only where μ cannot fall; not repeated here: IPOPT's turn
                return "Search_Direction_Becomes_Too_Small", iteration, None
            # the filter line search on θ and φ_μ
            phi = f_s - mu * log_s
            slope = float(gradient @ dx) - mu * float(barrier @ dx)
            try:
                if slope < 0.0 and theta <= theta_min:
                    alpha_min = alpha_min_frac * min(gamma_theta, gamma_phi * theta / -slope,
                                                     delta * theta ** s_theta / (-slope) ** s_phi)
                elif slope < 0.0:
                    alpha_min = alpha_min_frac * min(gamma_theta, gamma_phi * theta / -slope)
                else:
                    alpha_min = alpha_min_frac * gamma_theta
                switch_scale = (-slope) ** s_phi if slope < 0.0 else 0.0
                switch_bound = delta * theta ** s_theta
            except OverflowError:  # magnitudes beyond 1e150: IPOPT's turn (it reports what it finds)
                return "Invalid_Number_Detected", iteration, None
            alpha_min = max(alpha_min, tiny)  # (θ = 0 gives 0: the halving must end)
            alpha = alpha_max
            accepted: bool | None = None
            while alpha >= alpha_min:
                np.multiply(dx, alpha, out=x_trial)
                x_trial += x
                if lib.sb_ip_slacks(*bounded, p_x_trial, p_trial, log_address) > 0.0:
                    merit.evaluate()
                    f_trial, theta_trial = merit.outputs[0].tolist()
                    phi_trial = f_trial - mu * log_sum.value
                    if (math.isfinite(phi_trial) and math.isfinite(theta_trial) and theta_trial <= theta_max
                            and not any(theta_trial >= t and phi_trial >= q for t, q in filter_)):
                        if slope < 0.0 and theta <= theta_min and alpha * switch_scale > switch_bound:  # f-type
                            if phi_trial <= phi + eta_phi * alpha * slope:
                                accepted = False
                                break
                        elif theta_trial <= (1.0 - gamma_theta) * theta or phi_trial <= phi - gamma_phi * theta:
                            accepted = True
                            break
                alpha *= 0.5
            if self.trace is not None:
                self.trace({"iteration": iteration, "f": f_s / sf, "theta": theta, "mu": mu, "delta_w": dw,
                            "alpha": alpha, "alpha_max": alpha_max, "alpha_z": alpha_z, "accepted": accepted,
                            "dual_inf": dual_inf / sf, "primal_inf": primal_inf})
            if accepted is None:
                return "Restoration_Needed", iteration, None  # IPOPT would restore feasibility: hand over
            if accepted:  # an h-type step augments the filter
                filter_.append(((1.0 - gamma_theta) * theta, phi - gamma_phi * theta))
            x[:] = x_trial
            c[:] = merit.outputs[1]
            s, s_trial, p_s, p_trial = s_trial, s, p_trial, p_s
            log_s = log_sum.value
            y += alpha * dy
            lib.sb_ip_update(nb, p_z, p_dz, alpha_z, mu, p_s, kappa_sigma)
        return "Maximum_Iterations_Exceeded", limit, None  # (not reached: the loop returns at its limit)

    def _solution(self, x: Array, p: Array, y: Array, index: NDArray[np.integer], side: Array,
                  z: Array) -> dict[str, Array]:
        """The outputs of ``nlpsol`` at ``x``: unscaled objective, constraints and multipliers."""
        f, g = (array.copy() for array in self._unscaled.all_outputs(x, p))
        lam_x = -np.bincount(index, side * z, minlength=self.n)  # z_U − z_L
        return {"x": x.copy(), "f": f, "g": g, "lam_x": lam_x, "lam_g": y.copy(), "lam_p": np.zeros(p.size)}


class _Compiled(NamedTuple):
    """The compiled functions of the scaled or the unscaled NLP (:meth:`InteriorPoint._functions`)."""

    iterate: BufferedFunction
    merit: BufferedFunction


VECTORS = Path(__file__).with_name("interior_point.c")
"""The C loops of the iteration over the bounded entries (slacks, Σ, the step's fractions, the
multipliers' safeguard), shipped with the package."""


@functools.lru_cache(maxsize=1)
def _vector_library() -> ctypes.CDLL | None:
    """The loaded loops of :data:`VECTORS` (built once per machine, loaded once per process), or
    ``None`` where no compiler works (:func:`available` says why)."""
    try:
        library = native.load_library(VECTORS, FLAGS)
    except CompilerUnavailable:
        return None
    pointer, integer, real = ctypes.c_void_p, ctypes.c_int, ctypes.c_double
    library.sb_ip_slacks.argtypes = [integer] + [pointer] * 6
    library.sb_ip_slacks.restype = real
    library.sb_ip_barrier.argtypes = [integer, integer] + [pointer] * 9
    library.sb_ip_barrier.restype = None
    library.sb_ip_complementarity.argtypes = [integer, pointer, pointer, real]
    library.sb_ip_complementarity.restype = real
    library.sb_ip_step.argtypes = [integer, integer] + [pointer] * 6 + [real, real, pointer, pointer]
    library.sb_ip_step.restype = None
    library.sb_ip_update.argtypes = [integer, pointer, pointer, real, real, pointer, real]
    library.sb_ip_update.restype = None
    return library


def available() -> tuple[bool, str]:
    """Whether the compiled kernels (the factorisation and :data:`VECTORS`) can be used here, and a
    note saying from where or why not.

    Returns
    -------
    tuple
        ``(bool, note)``.
    """
    ok, note = sparse_ldl_available()
    if ok and _vector_library() is None:
        try:
            native.load_library(VECTORS, FLAGS)
        except CompilerUnavailable as error:
            return False, f"the interior point's loops are not available: {error}"
    return ok, note


_PER_THREAD = threading.local()
"""Per thread: ``.built``, a weak table of each ``nlpsol``'s :class:`InteriorPoint` instances
(:func:`for_nlpsol`): an instance evaluates into buffers of its own, one solve at a time."""


def for_nlpsol(nlpsol: ca.Function, tolerance: float, options: dict[str, float] | None = None,
                   max_iterations: int = 3000) -> InteriorPoint | None:
    """The :class:`InteriorPoint` of ``nlpsol`` with these settings, built once per thread while
    ``nlpsol`` lives (its buffers serve one solve at a time, as :func:`ocp.fast_call.buffered`'s do);
    ``None`` where the compiled factorisation is not available (the caller keeps ``nlpsol``).

    Parameters
    ----------
    nlpsol : casadi.Function
        An IPOPT ``nlpsol`` function.
    tolerance : float
        IPOPT's ``tol``.
    options : dict or None
        Overrides of :data:`IPOPT_DEFAULTS`.
    max_iterations : int
        IPOPT's ``max_iter`` (:class:`InteriorPoint`).

    Returns
    -------
    InteriorPoint or None
    """
    if not available()[0]:
        return None
    key = (float(tolerance), tuple(sorted((options or {}).items())), int(max_iterations))
    built: weakref.WeakKeyDictionary | None = getattr(_PER_THREAD, "built", None)
    if built is None:
        built = _PER_THREAD.built = weakref.WeakKeyDictionary()
    table = built.setdefault(nlpsol, {})
    found = table.get(key)
    if found is None:
        # over a handle of its own to the same function: the entry must not keep its key alive
        found = table[key] = InteriorPoint(ca.Function(nlpsol), tolerance, max_iterations, options)
    return found
