"""Second-order sufficient conditions at a converged NLP point: a strict local minimum or not.

A first-order point (the KKT conditions hold) can be a minimum, a saddle or a maximum: the eigenaxis
slew is such a saddle for minimum time under per-axis torque bounds (Bilimoria & Wie's 3.5449
against 3.2431). The second-order sufficient conditions (Nocedal & Wright, *Numerical
Optimization*, 2nd ed., Theorem 12.6) decide it: the Hessian of the Lagrangian ``∇²L`` is positive
definite on the critical cone of the active constraints. Here that cone is bounded from outside
by the subspace

    Z = { d : ∇g_i·d = 0 for equality and strongly active rows,  d_j = 0 for strongly active bounds },

a constraint or bound being *strongly active* when it is at its bound with a multiplier above
``multiplier_tolerance``. A weakly active one (at its bound, multiplier about zero) is left free,
which only enlarges ``Z``: positive definiteness on ``Z`` then implies it on the critical cone, so
the check is conservative. It can report "not certified" at a true minimum (degenerate or singular
arcs), never "certified" at a saddle: a caller falls back to its other evidence (restarts).

The subspace is the null space of the active rows restricted to the free variables, from a
column-pivoted QR factorisation of those rows (dense: meant for the small NLPs of a coarse mesh, a
few hundred variables; on :data:`BLAS_THREADS` BLAS threads).
``Z = {0}`` (a vertex: as many independent active constraints as variables, e.g. a bang-bang
optimum) is a strict local minimum by itself.

The theorem assumes a KKT point, so the first-order conditions are verified first (stationarity of
the Lagrangian ``L = f + lam_gᵀ g + lam_xᵀ x``, CasADi's signs; every multiplier of the sign of the
bound it belongs to and zero away from it; feasibility): a solve that stalled (the multistart
accepts IPOPT's ``Search_Direction_Becomes_Too_Small`` at a feasible point) or multipliers of another
convention are reported as not checked, never certified.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray
from threadpoolctl import threadpool_limits

from ocp.fast_call import BufferedFunction

Array = NDArray[np.float64]

BLAS_THREADS = 1
"""BLAS threads of the dense factorisations here (``threadpoolctl``). A few hundred rows are too
few to share among threads, and a threaded BLAS waits for cores another process holds: Bilimoria &
Wie's default minimum time (one check per plan, a 230 x 312 column-pivoted QR) took 500-540 ms per
plan with NumPy's OpenBLAS on its default 2 threads while another process kept both cores busy,
against 135-153 ms on one thread; on that QR alone 20.3 against 5.9 ms. Trade studies run several
planners side by side, which is that situation."""

MAX_VARIABLES = 400
"""Larger NLPs are not checked: the dense factorisation would cost more than the restarts it saves.
Bilimoria & Wie's minimum time (Radau degree 3), the check against one 5 % restart from the optimum:
8 intervals (312 variables) 5-15 ms against 23 ms; 12 intervals (464) 44 against 36 ms; 30
intervals (1148) 242 against 49 ms."""


@dataclass(frozen=True)
class SecondOrderCheck:
    """The outcome of :func:`second_order_check`.

    Parameters
    ----------
    certified : bool
        The second-order sufficient conditions hold: a strict local minimum.
    null_dimension : int
        Dimension of the subspace ``Z`` of the module docstring (-1: not checked).
    min_curvature : float
        Least eigenvalue of ``∇²L`` on ``Z`` (``inf`` when ``Z = {0}``, ``nan`` when not checked).
    message : str
        What was found, or why the point was not checked.
    """

    certified: bool
    null_dimension: int
    min_curvature: float
    message: str


def _not_checked(message: str) -> SecondOrderCheck:
    return SecondOrderCheck(False, -1, float("nan"), message)


def _output(function: ca.Function, names: tuple[str, ...]) -> int:
    """Index of the output of ``function`` named one of ``names`` (the plugins differ: IPOPT's
    ``nlp_hess_l`` returns ``triu_hess_gamma_x_x`` alone, FATROP's ``grad_gamma_x`` first, then the
    full ``hess_gamma_x_x``; ``nlp_grad_f`` returns ``f`` first or not at all)."""
    for index in range(function.n_out()):
        if function.name_out(index) in names:
            return index
    raise RuntimeError(f"{function.name()} has none of the outputs {names}")


def _dense(function: BufferedFunction, index: int) -> Array:
    """Output ``index`` of the last evaluation as a dense array."""
    sparsity = function.function.sparsity_out(index)
    out = np.zeros(sparsity.shape)
    out[np.asarray(sparsity.row(), dtype=int), np.asarray(sparsity.get_col(), dtype=int)] = function.outputs[index]
    return out


def _null_space(A: Array, n: int) -> Array:
    """An orthonormal basis of ``{d : A d = 0}`` (``n`` columns of ``A``), through ``A P = Q R``
    with column pivoting: ``R = [R11 R12]`` of rank ``r``, the basis ``P [-R11⁻¹ R12; I]``
    orthonormalised (no full ``Q`` is formed)."""
    if A.shape[0] == 0 or n == 0:
        return np.eye(n)
    import scipy.linalg  # here, not at the top: it takes 0.16 s to import, and every command imports this module

    R, P = scipy.linalg.qr(A, mode="r", pivoting=True)
    diagonal = np.abs(np.diag(R))
    rank = int(np.sum(diagonal > 1e-9 * diagonal[0])) if diagonal[0] > 0 else 0
    if rank == n:
        return np.zeros((n, 0))
    basis = np.zeros((n, n - rank))
    basis[P[:rank]] = -scipy.linalg.solve_triangular(R[:rank, :rank], R[:rank, rank:])
    basis[P[rank:]] = np.eye(n - rank)
    return np.linalg.qr(basis)[0]


def _broadcast(bound: Any, like: Array) -> Array:
    """A bound (scalar or array) as a float array shaped like ``like``."""
    return np.broadcast_to(np.asarray(bound, dtype=float), like.shape)


def _active(values: Array, low: Array, high: Array, multipliers: Array, multiplier_tolerance: float,
            bound_tolerance: float) -> NDArray[np.bool_]:
    """Rows at a (finite) bound with a multiplier above the tolerance, and rows with equal bounds."""
    with np.errstate(invalid="ignore"):  # inf - inf where a value is infinite: not near
        near_low = np.isfinite(low) & (values - low <= bound_tolerance * (1.0 + np.abs(low)))
        near_high = np.isfinite(high) & (high - values <= bound_tolerance * (1.0 + np.abs(high)))
    return (low == high) | ((near_low | near_high) & (np.abs(multipliers) > multiplier_tolerance))


def _complementarity(values: Array, low: Array, high: Array, multipliers: Array) -> float:
    """Largest violation of the sign and complementarity conditions, ``|λ| × min(1, distance to the
    bound λ belongs to)`` (CasADi's signs: a positive multiplier belongs to the upper bound, a
    negative one to the lower; an infinite bound is at distance 1)."""
    with np.errstate(invalid="ignore"):
        to_low = np.where(np.isfinite(low), values - low, 1.0)
        to_high = np.where(np.isfinite(high), high - values, 1.0)
    violation = (np.maximum(multipliers, 0.0) * np.clip(to_high, 0.0, 1.0)
                 + np.maximum(-multipliers, 0.0) * np.clip(to_low, 0.0, 1.0))
    return float(np.max(violation, initial=0.0))


def _infeasibility(values: Array, low: Array, high: Array) -> float:
    """Largest distance outside a bound, relative to ``1 + |bound|``."""
    with np.errstate(invalid="ignore"):
        below = np.where(np.isfinite(low), (low - values) / (1.0 + np.abs(low)), 0.0)
        above = np.where(np.isfinite(high), (values - high) / (1.0 + np.abs(high)), 0.0)
    return float(np.max(np.maximum(below, above), initial=0.0))


def second_order_check(solver: ca.Function, x: Array, lam_x: Array, lam_g: Array, *, p: Any = None,
                       lbx: Any = -np.inf, ubx: Any = np.inf, lbg: Any = -np.inf, ubg: Any = np.inf,
                       multiplier_tolerance: float = 1e-6, bound_tolerance: float = 1e-6,
                       curvature_tolerance: float = 1e-8, kkt_tolerance: float = 1e-6) -> SecondOrderCheck:
    """Whether a converged point of ``solver`` satisfies the second-order sufficient conditions.

    Parameters
    ----------
    solver : casadi.Function
        The ``casadi.nlpsol`` function that found the point (its ``nlp_hess_l``, ``nlp_jac_g``
        and ``nlp_grad_f``).
    x : (n,) ndarray
        The point.
    lam_x, lam_g : ndarray
        Its bound and constraint multipliers, CasADi's signs: ``∇f + J_gᵀ lam_g + lam_x = 0``, a
        positive multiplier for an upper bound, a negative one for a lower bound.
    p, lbx, ubx, lbg, ubg : array_like
        The solver's parameters and bounds at that solve.
    multiplier_tolerance : float
        A multiplier above this (absolute) makes its constraint strongly active.
    bound_tolerance : float
        Relative distance to a bound (``× (1 + |bound|)``) within which a value is at it; also the
        largest accepted violation of a bound.
    curvature_tolerance : float
        The least curvature on ``Z`` must exceed this, relative to the largest (at least 1).
    kkt_tolerance : float
        The first-order conditions the theorem assumes must hold to this: the stationarity residual
        ``‖∇f + J_gᵀ lam_g + lam_x‖∞`` relative to the largest of its terms (at least 1), and the
        sign and complementarity of every multiplier (``|λ| × min(1, distance to its bound)``)
        relative to the largest multiplier (at least 1). Otherwise the point is not checked.

    Returns
    -------
    SecondOrderCheck
        ``certified`` only when the conditions provably hold (see the module docstring).
    """
    x = np.asarray(x, dtype=float).ravel()
    n = x.size
    if n > MAX_VARIABLES:
        return _not_checked(f"{n} variables: more than {MAX_VARIABLES}, not checked")
    try:
        hessian = BufferedFunction(solver.get_function("nlp_hess_l"))
        jacobian = BufferedFunction(solver.get_function("nlp_jac_g"))
        gradient = BufferedFunction(solver.get_function("nlp_grad_f"))
        h_out = _output(hessian.function, ("triu_hess_gamma_x_x", "hess_gamma_x_x"))
        g_out, j_out = _output(jacobian.function, ("g",)), _output(jacobian.function, ("jac_g_x",))
        f_out = _output(gradient.function, ("grad_f_x",))
    except RuntimeError as error:  # a plugin without these functions
        return _not_checked(f"no derivatives from the solver: {str(error).splitlines()[0]}")
    p = np.zeros(solver.nnz_in("p")) if p is None else p
    lam_x = np.asarray(lam_x, dtype=float).ravel()
    lam_g = np.asarray(lam_g, dtype=float).ravel()
    hessian.all_outputs(x, p, 1.0, lam_g)
    upper = np.triu(_dense(hessian, h_out))  # IPOPT's is upper triangular, FATROP's full
    H = upper + np.triu(upper, 1).T
    jacobian.all_outputs(x, p)
    g, J = jacobian.outputs[g_out].copy(), _dense(jacobian, j_out)
    grad = gradient.all_outputs(x, p)[f_out].copy()
    g_low, g_high, x_low, x_high = _broadcast(lbg, g), _broadcast(ubg, g), _broadcast(lbx, x), _broadcast(ubx, x)
    # The theorem assumes a KKT point: a stalled solve or multipliers of other signs are not one.
    terms = [grad, J.T @ lam_g, lam_x]
    moving = x_low != x_high  # a fixed variable's multiplier takes any value
    stationarity = float(np.max(np.abs(sum(terms))[moving], initial=0.0)) \
        / max([1.0] + [float(np.max(np.abs(t), initial=0.0)) for t in terms])
    complementarity = max(_complementarity(g, g_low, g_high, lam_g), _complementarity(x, x_low, x_high, lam_x)) \
        / max(1.0, float(np.max(np.abs(lam_g), initial=0.0)), float(np.max(np.abs(lam_x), initial=0.0)))
    infeasibility = max(_infeasibility(g, g_low, g_high), _infeasibility(x, x_low, x_high))
    if stationarity > kkt_tolerance or complementarity > kkt_tolerance or infeasibility > bound_tolerance:
        return _not_checked(f"not a first-order point: stationarity {stationarity:.2g}, complementarity "
                            f"{complementarity:.2g}, infeasibility {infeasibility:.2g}")
    rows = _active(g, g_low, g_high, lam_g, multiplier_tolerance, bound_tolerance)
    fixed = _active(x, x_low, x_high, lam_x, multiplier_tolerance, bound_tolerance)
    free = ~fixed
    A = J[np.ix_(rows, free)]
    n_free = int(free.sum())
    with threadpool_limits(limits=BLAS_THREADS, user_api="blas"):
        Z = _null_space(A, n_free)
        if Z.shape[1] == 0:
            return SecondOrderCheck(True, 0, float("inf"), "a vertex: the active constraints fix the point")
        curvature = np.linalg.eigvalsh(Z.T @ H[np.ix_(free, free)] @ Z)
    least = float(curvature[0])
    certified = least > curvature_tolerance * max(1.0, float(np.max(np.abs(curvature))))
    verdict = "positive definite" if certified else "not positive definite"
    return SecondOrderCheck(certified, Z.shape[1], least,
                            f"reduced Hessian on {Z.shape[1]} free directions {verdict} (least eigenvalue {least:.3g})")
