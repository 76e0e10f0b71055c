"""A certificate of a converged NLP point: how well it satisfies the optimality conditions, in one record.

Three pieces of evidence, each computed here from the point alone (never from the solver's claim):

* **KKT residuals** (:func:`kkt_residuals`), CasADi's signs (``L = f + lam_gᵀ g + lam_xᵀ x``, a
  positive multiplier belongs to an upper bound, a negative one to a lower): stationarity
  ``‖∇f + J_gᵀ lam_g + lam_x‖∞`` (fixed variables, ``lbx = ubx``, left out: their multiplier takes
  any value), primal feasibility (largest excess of ``g`` or ``x`` over a bound) and complementarity
  with the multipliers' signs (``|λ| × min(1, distance to the bound λ belongs to)``, the measure of
  :mod:`ocp.nlp.second_order`). Each is given **unscaled** (absolute) and **in IPOPT's scaling**.
  IPOPT's gradient-based scaling (``nlp_scaling_method = gradient-based``, its default) multiplies
  the objective by ``s_f = min(1, nlp_scaling_max_gradient / ‖∇f(x₀)‖∞)`` and constraint ``i`` by
  ``s_i = min(1, nlp_scaling_max_gradient / ‖∇g_i(x₀)‖∞)`` (``nlp_scaling_max_gradient = 100``,
  floors ``nlp_scaling_min_value = 1e-8``), at its starting point ``x₀``; the variables are not
  scaled. In the scaled problem the multipliers become ``s_f λ / s_i`` and ``s_f z``, so its
  stationarity and complementarity are ``s_f`` times the unscaled ones and its constraint violation
  is ``s_i`` times row ``i``'s. IPOPT's overall error, which its ``tol`` bounds, divides the
  stationarity by ``s_d = max(100, (‖ỹ‖₁ + ‖z̃‖₁ + ‖ṽ‖₁)/(m + n_b + n_v)) / 100`` and the
  complementarity by ``s_c = max(100, (‖z̃‖₁ + ‖ṽ‖₁)/(n_b + n_v)) / 100`` (Wächter & Biegler
  2006, eq. 5, as IPOPT computes it; ``ỹ, z̃`` the scaled constraint and bound multipliers, ``n_b``
  the finite bounds of the variables that are not fixed, lower and upper counted apart). IPOPT
  writes an inequality row as ``g(x) − s = 0`` with its bounds on the slack ``s``: their
  multipliers ``ṽ`` (``n_v`` the finite bounds of the inequality rows, ``lbg < ubg``, lower and
  upper counted apart) count in both sums. At a KKT point the slack's stationarity makes them the
  row's multiplier split by sign (``ṽ_U − ṽ_L = ỹ``, one of them zero where the row is at a bound),
  which is how they are read here from ``lam_g``. The solver's statistics keep only the
  iterations' ``inf_du`` (the scaled stationarity) and ``inf_pr`` (unscaled), of the last start
  solved, which need not be the point certified; so the factors are computed here the way IPOPT
  does, at ``scaling_point`` (IPOPT's own starting point when the caller has it, else the point
  itself: at an optimum of the collocation problems the gradients are far below 100 and every
  factor is 1 either way). The scaled stationarity equals IPOPT's reported ``inf_du`` at the same
  iterate (tested). Other solvers (FATROP) are taken unscaled: factors 1, ``s_d`` and ``s_c`` kept.
* **Second order**: :func:`ocp.nlp.second_order.second_order_check` (a strict local minimum;
  degenerate, no curvature below ``−δ`` but some near zero; not certified, negative curvature; or
  not checked and why).
* **Pontryagin switching** (:func:`switching_agreement`): for bang-bang minimum time, the fraction
  of control samples at a bound whose sign is opposite to the switching function's
  ``σ = ∂H/∂u`` (the Hamiltonian ``H = L + pᵀ f`` is minimised) with ``|σ|`` above a tolerance.
  The co-states ``p`` come from the caller (a transcription's multipliers, see
  :mod:`planners.collocation.certificate`).

:func:`certificate` combines them into the JSON record of ``Reference.stats["certificate"]`` with a
verdict: ``"certified"`` when the KKT residual (scaled) is at most
:data:`KKT_TOLERANCE` and the second-order sufficient conditions hold (a strict local minimum of the
discretised problem). ``"first-order, bang-bang"`` when the KKT residual is as small and, for
bang-bang minimum time where the second-order check could not be made (a factorisation that failed
its accuracy guard, a solver without the derivatives) or found the point degenerate (curvature near
zero in some direction, none below ``−δ``: no saddle direction), the switching agreement is at
least :data:`SWITCHING_THRESHOLD` with no sample on the wrong side (the controls at a bound, on the
side Pontryagin's minimum principle asks, with a switching function clear of zero; a check that
found negative curvature is not overruled). That is not ``"certified"``: Pontryagin's sign
condition is a necessary condition, and a degenerate check has found a few directions of near-zero
curvature (on fine meshes, the controls of the intervals that hold a switch, free between their
bounds) where neither sign is proven; the summary says what was found (``SOSC degenerate,
switching 98%``). ``"first-order"`` when only the KKT residual is small; ``"not certified"``
otherwise.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict, dataclass
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ocp.nlp.second_order import (
    SecondOrderCheck,
    _broadcast,
    _complementarity,
    _derivative,
    _evaluated,
    _output,
    _triplets,
    second_order_check,
)

Array = NDArray[np.float64]

KKT_TOLERANCE = 1e-6
"""Largest scaled KKT residual (IPOPT's overall error) of a certified or first-order point: the
acceptable level of IPOPT's own tolerances (``acceptable_tol``), far above the 1e-8 to 1e-10 the
planners ask (:func:`ocp.nlp.solve.solver_options`)."""

SWITCHING_THRESHOLD = 0.9
"""Least switching agreement of a bang-bang certificate: the samples left over lie where a control
switches inside a mesh interval (a control polynomial between its bounds, ``σ`` near zero there).
Bilimoria & Wie's minimum time (50 intervals, degree 3) agrees on 0.95-0.99 of its samples; the
eigenaxis saddle, whose two other torques are singular (zero), on a third."""

MAX_GRADIENT = 100.0
"""IPOPT's ``nlp_scaling_max_gradient`` default."""
MIN_SCALING = 1e-8
"""IPOPT's ``nlp_scaling_min_value`` default."""
S_MAX = 100.0
"""IPOPT's ``s_max`` of the overall error's ``s_d`` and ``s_c``."""


@dataclass(frozen=True)
class KKTResiduals:
    """The residuals of :func:`kkt_residuals` (see the module docstring).

    Parameters
    ----------
    stationarity, feasibility, complementarity : float
        Unscaled (absolute) residuals.
    stationarity_scaled, feasibility_scaled, complementarity_scaled : float
        In the solver's scaling (stationarity before the division by ``s_d``: IPOPT's ``inf_du``).
    unscaled : float
        The largest unscaled residual.
    scaled : float
        IPOPT's overall error: ``max(stationarity_scaled / s_d, feasibility_scaled,
        complementarity_scaled / s_c)``.
    objective_scaling : float
        ``s_f``.
    """

    stationarity: float
    feasibility: float
    complementarity: float
    stationarity_scaled: float
    feasibility_scaled: float
    complementarity_scaled: float
    unscaled: float
    scaled: float
    objective_scaling: float


def _scaling(gradient: Array, jacobian: tuple[NDArray[np.integer], Array, int],
             solver_name: str) -> tuple[float, Array]:
    """IPOPT's gradient-based factors ``(s_f, s_i)`` from the gradient and the Jacobian (its entries'
    rows, their values and its number of rows) at its scaling point."""
    entry_rows, values, size = jacobian
    if solver_name != "ipopt":
        return 1.0, np.ones(size)
    s_f = float(np.clip(MAX_GRADIENT / max(float(np.max(np.abs(gradient), initial=0.0)), 1e-300), MIN_SCALING, 1.0))
    rows = np.zeros(size)  # per row, the largest |entry| (a row without entries: 0)
    np.maximum.at(rows, entry_rows, np.abs(values))
    s_g = np.clip(MAX_GRADIENT / np.maximum(rows, 1e-300), MIN_SCALING, 1.0)
    return s_f, s_g


def _excess(values: Array, low: Array, high: Array) -> Array:
    """Per row, the excess over a (finite) bound, absolute (0 inside)."""
    with np.errstate(invalid="ignore"):
        below = np.where(np.isfinite(low), low - values, 0.0)
        above = np.where(np.isfinite(high), values - high, 0.0)
    return np.maximum(np.maximum(below, above), 0.0)


def kkt_residuals(solver: ca.Function, x: Array, lam_x: Array, lam_g: Array, *, p: Any = None,
                  lbx: Any = -np.inf, ubx: Any = np.inf, lbg: Any = -np.inf, ubg: Any = np.inf,
                  scaling_point: Array | None = None, solver_name: str = "ipopt") -> KKTResiduals:
    """The first-order residuals of a point of ``solver``, unscaled and in the solver's scaling.

    Parameters
    ----------
    solver : casadi.Function
        The ``casadi.nlpsol`` function (its ``nlp_jac_g`` and ``nlp_grad_f``).
    x : (n,) ndarray
        The point.
    lam_x, lam_g : ndarray
        Its bound and constraint multipliers, CasADi's signs (``∇f + J_gᵀ lam_g + lam_x = 0``).
    p, lbx, ubx, lbg, ubg : array_like
        The solver's parameters and bounds at that solve.
    scaling_point : (n,) ndarray or None
        Where IPOPT computed its scaling factors (its starting point); ``None``: ``x``.
    solver_name : str
        ``"ipopt"`` (gradient-based scaling) or another plugin (no problem scaling).

    Returns
    -------
    KKTResiduals
        The residuals (see the module docstring).
    """
    x = np.asarray(x, dtype=float).ravel()
    lam_x = np.asarray(lam_x, dtype=float).ravel()
    lam_g = np.asarray(lam_g, dtype=float).ravel()
    p = np.zeros(solver.nnz_in("p")) if p is None else p
    jacobian = _derivative(solver, "nlp_jac_g")
    gradient = _derivative(solver, "nlp_grad_f")
    g_out, j_out = _output(jacobian.function, ("g",)), _output(jacobian.function, ("jac_g_x",))
    f_out = _output(gradient.function, ("grad_f_x",))
    if scaling_point is not None:
        point = np.asarray(scaling_point, dtype=float).ravel()
        _evaluated(jacobian, point, p)
        j_rows, _, j_values = _triplets(jacobian, j_out)
        grad0 = _evaluated(gradient, point, p)[f_out].copy()
        s_f, s_g = _scaling(grad0, (j_rows, j_values, jacobian.function.size1_out(j_out)), solver_name)
    g = _evaluated(jacobian, x, p)[g_out].copy()
    j_rows, j_columns, j_values = _triplets(jacobian, j_out)
    grad = _evaluated(gradient, x, p)[f_out].copy()
    if scaling_point is None:
        s_f, s_g = _scaling(grad, (j_rows, j_values, g.size), solver_name)
    g_low, g_high, x_low, x_high = _broadcast(lbg, g), _broadcast(ubg, g), _broadcast(lbx, x), _broadcast(ubx, x)
    moving = x_low != x_high
    # Jᵀ lam_g column by column in storage order, as SciPy's product adds it
    jt_lam = np.bincount(j_columns, j_values * lam_g[j_rows], minlength=x.size)
    stationarity = float(np.max(np.abs(grad + jt_lam + lam_x)[moving], initial=0.0))
    g_excess, x_excess = _excess(g, g_low, g_high), _excess(x, x_low, x_high)
    feasibility = float(max(np.max(g_excess, initial=0.0), np.max(x_excess, initial=0.0)))
    feasibility_scaled = float(max(np.max(s_g * g_excess, initial=0.0), np.max(x_excess, initial=0.0)))
    complementarity = max(_complementarity(g, g_low, g_high, lam_g), _complementarity(x, x_low, x_high, lam_x))
    # the scaled multipliers ỹ = s_f λ / s_i, z̃ = s_f z, and IPOPT's s_d, s_c
    bounded = int(np.sum(np.isfinite(x_low) & moving) + np.sum(np.isfinite(x_high) & moving))
    y_scaled = s_f * lam_g / s_g
    y_norm = float(np.sum(np.abs(y_scaled)))
    z_norm = float(np.sum(np.abs(s_f * lam_x[moving])))
    # the slack bounds of the inequality rows and their multipliers, the row's split by sign (docstring)
    inequality = g_low != g_high
    slack_low, slack_high = inequality & np.isfinite(g_low), inequality & np.isfinite(g_high)
    v_norm = float(np.sum(np.maximum(-y_scaled, 0.0)[slack_low]) + np.sum(np.maximum(y_scaled, 0.0)[slack_high]))
    slack_bounds = int(np.sum(slack_low) + np.sum(slack_high))
    s_d = max(S_MAX, (y_norm + z_norm + v_norm) / max(g.size + bounded + slack_bounds, 1)) / S_MAX
    s_c = max(S_MAX, (z_norm + v_norm) / max(bounded + slack_bounds, 1)) / S_MAX
    stationarity_scaled = s_f * stationarity
    complementarity_scaled = s_f * complementarity
    return KKTResiduals(stationarity, feasibility, complementarity, stationarity_scaled, feasibility_scaled,
                        complementarity_scaled, max(stationarity, feasibility, complementarity),
                        max(stationarity_scaled / s_d, feasibility_scaled, complementarity_scaled / s_c), s_f)


@dataclass(frozen=True)
class Switching:
    """The outcome of :func:`switching_agreement`.

    Parameters
    ----------
    agreement : float
        Fraction of all samples (points × controls) at a bound on the side Pontryagin asks
        (``sign(u) = −sign(σ)``) with ``|σ|`` above the tolerance.
    wrong : float
        Fraction at a bound on the other side with ``|σ|`` above the tolerance (a violation).
    interior_large : float
        Fraction between the bounds with ``|σ|`` above the tolerance (a violation: ``H`` is not
        minimised there).
    singular : float
        Fraction with ``|σ|`` at most the tolerance (a switch or a singular arc).
    tolerance : float
        The tolerance on ``|σ|`` used (absolute).
    """

    agreement: float
    wrong: float
    interior_large: float
    singular: float
    tolerance: float


def switching_agreement(u: Array, u_low: Array, u_high: Array, sigma: Array, *, relative_tolerance: float = 1e-3,
                        bound_tolerance: float = 1e-6) -> Switching:
    """How well bang-bang controls agree with their switching functions (Pontryagin's minimum principle).

    Parameters
    ----------
    u : (n, m) ndarray
        Controls at ``n`` samples (any units).
    u_low, u_high : (m,) or (n, m) ndarray
        Their bounds.
    sigma : (n, m) ndarray
        The switching functions ``σ = ∂H/∂u`` at the samples, ``H = L + pᵀ f`` minimised by ``u``.
    relative_tolerance : float
        ``|σ|`` at most this times the largest ``|σ|`` counts as zero.
    bound_tolerance : float
        A control within this times ``(1 + |bound|)`` of a bound is at it.

    Returns
    -------
    Switching
        The fractions (see :class:`Switching`).
    """
    u, sigma = np.atleast_2d(np.asarray(u, dtype=float)), np.atleast_2d(np.asarray(sigma, dtype=float))
    low, high = np.broadcast_to(u_low, u.shape), np.broadcast_to(u_high, u.shape)
    tolerance = relative_tolerance * float(np.max(np.abs(sigma), initial=0.0))
    large = np.abs(sigma) > tolerance
    at_low = u - low <= bound_tolerance * (1.0 + np.abs(low))
    at_high = high - u <= bound_tolerance * (1.0 + np.abs(high))
    right = large & ((at_high & (sigma < 0)) | (at_low & (sigma > 0)))
    wrong = large & ((at_high & (sigma > 0)) | (at_low & (sigma < 0)))
    interior = large & ~at_low & ~at_high
    n = max(u.size, 1)
    return Switching(float(right.sum() / n), float(wrong.sum() / n), float(interior.sum() / n),
                     float((~large).sum() / n), tolerance)


def seed_counts(stats: Mapping[str, Any], rtol: float = 1e-6) -> tuple[int | None, int | None]:
    """How many starts were tried and how many agreed on the optimum, from a planner's stats.

    Parameters
    ----------
    stats : mapping
        ``Reference.stats``: its ``seeds`` entry (``{"tried", "agreed", ...}``) when present, else
        the ``starts`` of its coarse multistart (``stats["coarse"]``) or its own.
    rtol : float
        Relative agreement of the converged starts' objectives with the least one.

    Returns
    -------
    tuple
        ``(tried, agreed)``; ``(None, None)`` when the stats hold neither.
    """
    seeds = stats.get("seeds")
    if isinstance(seeds, Mapping) and "tried" in seeds:
        return int(seeds["tried"]), (None if seeds.get("agreed") is None else int(seeds["agreed"]))
    coarse = stats.get("coarse")
    starts = coarse.get("starts") if isinstance(coarse, Mapping) else None
    starts = starts if starts else stats.get("starts")
    if not starts:
        return None, None
    values = [float(s["f"]) for s in starts if s.get("converged")]
    if not values:
        return len(starts), 0
    best = min(values)
    return len(starts), sum(abs(v - best) <= 1e-12 + rtol * abs(best) for v in values)


def _second_order_text(check: SecondOrderCheck | str | None) -> str:
    """The ``second_order`` string of the record."""
    if check is None:
        return "not checked: no multipliers"
    if isinstance(check, str):
        return check
    if check.certified:
        return "strict local minimum"
    if check.negative_curvatures < 0:
        return "not checked: " + check.message
    if check.degenerate:
        return "degenerate: " + check.message
    return "not certified: " + check.message


def _second_order_detail(check: SecondOrderCheck | str | None) -> dict[str, Any] | None:
    """The ``second_order_detail`` of the record: the check's numbers (``None`` for a text)."""
    if not isinstance(check, SecondOrderCheck):
        return None
    threshold = float(check.curvature_threshold)
    return {"certified": bool(check.certified),
            "negative_curvatures": None if check.negative_curvatures < 0 else int(check.negative_curvatures),
            "curvature_threshold": threshold if np.isfinite(threshold) else None, "message": check.message}


def certificate(kkt: KKTResiduals | None, second_order: SecondOrderCheck | str | None,
                switching: Switching | None = None, *, costate_gap: float | None = None,
                seeds: int | None = None, seeds_agreed: int | None = None,
                kkt_tolerance: float = KKT_TOLERANCE,
                switching_threshold: float = SWITCHING_THRESHOLD) -> dict[str, Any]:
    """The JSON record ``Reference.stats["certificate"]`` from the pieces of evidence.

    Parameters
    ----------
    kkt : KKTResiduals or None
        The residuals (``None``: not computed, the point is not certified).
    second_order : SecondOrderCheck, str or None
        The second-order check, or a ready ``"not checked: <why>"`` text.
    switching : Switching or None
        The switching agreement (bang-bang minimum time only).
    costate_gap : float or None
        Relative difference to a co-state (indirect) solution, when one exists.
    seeds, seeds_agreed : int or None
        Starts tried and starts agreeing on the optimum (:func:`seed_counts`).
    kkt_tolerance : float
        Largest scaled KKT residual of a first-order point.
    switching_threshold : float
        Least switching agreement of a bang-bang certificate.

    Returns
    -------
    dict
        ``kkt_scaled``, ``kkt_unscaled``, ``second_order``, ``switching``, ``costate_gap``,
        ``seeds``, ``seeds_agreed``, ``verdict`` (``"certified"`` with the second-order sufficient
        conditions only, ``"first-order, bang-bang"`` with the switching evidence in their place,
        ``"first-order"`` or ``"not certified"``), ``summary`` (one line), ``kkt`` (the residuals
        by kind), ``switching_detail`` (:class:`Switching`'s fractions) and ``second_order_detail``
        (the check's numbers when ``second_order`` is a :class:`~ocp.nlp.second_order.SecondOrderCheck`:
        ``certified``, ``negative_curvatures`` (an upper bound on the directions curving below
        ``−δ``; ``None`` when not checked), ``curvature_threshold`` (the ``δ`` certified at, or
        checked against; ``None`` when not checked) and ``message`` (the free variables and active
        rows it was checked on); ``None`` for a text).
    """
    text = _second_order_text(second_order)
    first_order = kkt is not None and kkt.scaled <= kkt_tolerance
    sosc = text == "strict local minimum"
    # The switching evidence stands in for a second-order check that was not made or found the point
    # degenerate (no curvature below -δ), never for one that found negative curvature (a saddle), and
    # only with no sample on the side Pontryagin forbids.
    bang_bang = (switching is not None and switching.agreement >= switching_threshold and switching.wrong == 0.0
                 and text.startswith(("not checked", "degenerate")))
    # Only the second-order sufficient conditions certify; the switching evidence, a necessary
    # condition, reads as its own verdict, never as "certified".
    verdict = ("certified" if first_order and sosc else "first-order, bang-bang" if first_order and bang_bang
               else "first-order" if first_order else "not certified")
    record = {"kkt_scaled": None if kkt is None else kkt.scaled, "kkt_unscaled": None if kkt is None else kkt.unscaled,
              "second_order": text, "switching": None if switching is None else switching.agreement,
              "costate_gap": costate_gap, "seeds": seeds, "seeds_agreed": seeds_agreed, "verdict": verdict,
              "method": None, "summary": "",
              "kkt": None if kkt is None else asdict(kkt),
              "switching_detail": None if switching is None else asdict(switching),
              "second_order_detail": _second_order_detail(second_order)}
    record["summary"] = summary_line(record)
    return record


def summary_line(record: dict[str, Any]) -> str:
    """The one-line ``summary`` of a certificate record, from its other entries.

    Parameters
    ----------
    record : dict
        A record of :func:`certificate` or :func:`necessary_conditions_certificate`.

    Returns
    -------
    str
        ``"<verdict>: KKT ..., SOSC ..., switching ..%, co-state gap .., 2/2 seeds agreed"`` for a
        direct solution (the parts it has evidence for; ``1 seed`` when one start was made:
        ``_seeds_text``); ``"<verdict>: <method> residual ... (Pontryagin's
        necessary conditions)[, gap to the direct solution ..]"`` for an indirect one.
    """
    verdict, gap = record["verdict"], record.get("costate_gap")
    if record.get("pontryagin") is not None:  # an exact bang-bang trajectory (switch-time shooting)
        return f"{verdict}: {record['method']}, " + ", ".join(_bang_bang_parts(record))
    if record.get("method") is not None:  # an indirect solution
        return (f"{verdict}: {record['method']} residual {record['kkt_scaled']:.1g} (Pontryagin's necessary "
                f"conditions)" + ("" if gap is None else f", gap to the direct solution {gap:.1g}"))
    text = record["second_order"]
    kkt = record.get("kkt_scaled")
    parts = [f"KKT {kkt:.1g}" if kkt is not None else "KKT not computed"]
    parts.append("SOSC" if text == "strict local minimum" else "SOSC " + text.split(":")[0])
    if record.get("switching") is not None:
        parts.append(f"switching {100.0 * record['switching']:.0f}%")
    if gap is not None:
        parts.append(f"co-state gap {gap:.1g}")
    if record.get("seeds") is not None:
        parts.append(_seeds_text(record["seeds"], record.get("seeds_agreed")))
    return f"{verdict}: " + ", ".join(parts)


def _seeds_text(tried: int, agreed: int | None) -> str:
    """What the summary says of the starts: one start is no agreement, several are.

    Parameters
    ----------
    tried : int
        Starts tried (``seeds``).
    agreed : int or None
        Starts that reached the optimum (``seeds_agreed``; ``None``: not known).

    Returns
    -------
    str
        ``1 seed`` (one start, which reached the point: nothing to agree with), ``1 seed, not
        converged``, ``2/2 seeds agreed``, ``1/2 seeds agreed`` (one of two reached the optimum, the
        other stopped elsewhere), ``3 seeds`` (agreement not known).
    """
    if tried == 1:
        return "1 seed" if agreed != 0 else "1 seed, not converged"
    if agreed is None:
        return f"{tried} seeds"
    return f"{agreed}/{tried} seeds agreed"


def _bang_bang_parts(record: dict[str, Any]) -> list[str]:
    """The summary's parts of a bang-bang trajectory's record (its ``pontryagin`` checks, see
    :func:`planners.collocation.certificate.bang_bang_certificate`)."""
    checks = record["pontryagin"]
    parts = [f"Pontryagin H {checks['hamiltonian']:.1g}", f"switching {100.0 * checks['switching']:.0f}%"]
    if checks["wrong"] > 0:
        parts.append(f"{100.0 * checks['wrong']:.0f}% on the wrong side")
    parts += [f"{name} {checks[name]:.1g}" for name in ("miss", "stationarity") if checks[name] > 1e-8]
    switches = checks["switches"]
    why = ("a control inside its bounds" if not checks["bang_bang"] else "coinciding switches"
           if not checks["simple_switches"] else f"strictness margin {checks['strictness']:.1g}")
    parts.append(f"{switches} simple switches" if checks["strict"] else
                 f"{switches} switches, not strictly bang-bang ({why})")
    if "condition" in checks:
        parts.append(f"induced SOSC (cond {checks['condition']:.0e})" if checks["second_order"] else
                     f"induced problem singular (cond {checks['condition']:.0e})")
    else:
        parts.append(f"induced {'SOSC' if checks['second_order'] else 'SOSC fails'} "
                     f"(least eigenvalue {checks['curvature']:.1g})")
    if record.get("seeds") is not None:
        parts.append(_seeds_text(record["seeds"], record.get("seeds_agreed")))
    return parts


def with_costate_gap(record: dict[str, Any], gap: float) -> dict[str, Any]:
    """A certificate record with its ``costate_gap`` set and its ``summary`` redone.

    Parameters
    ----------
    record : dict
        A record of :func:`certificate` or :func:`necessary_conditions_certificate`.
    gap : float
        The relative difference between the direct and the indirect (co-state) solution's values of
        the functional both minimise, ``|J_direct − J_costate| / |J_costate|``.

    Returns
    -------
    dict
        A new record (the verdict is unchanged: the gap is evidence shown beside it).
    """
    updated = {**record, "costate_gap": float(gap)}
    updated["summary"] = summary_line(updated)
    return updated


def certify(solver: ca.Function, x: Array, lam_x: Array, lam_g: Array, *, p: Any = None, lbx: Any = -np.inf,
            ubx: Any = np.inf, lbg: Any = -np.inf, ubg: Any = np.inf, solver_name: str = "ipopt",
            second_order: SecondOrderCheck | str | None = None, switching: Switching | None = None,
            costate_gap: float | None = None, seeds: int | None = None,
            seeds_agreed: int | None = None) -> dict[str, Any]:
    """The certificate of a converged point of ``solver``: its KKT residuals, its second-order check
    (run here when not given, :func:`~ocp.nlp.second_order.second_order_check`) and the given
    evidence, as :func:`certificate`'s record.

    Parameters
    ----------
    solver : casadi.Function
        The ``casadi.nlpsol`` function that found the point.
    x, lam_x, lam_g : ndarray
        The point and its multipliers (CasADi's signs).
    p, lbx, ubx, lbg, ubg : array_like
        The solver's parameters and bounds.
    solver_name : str
        The ``nlpsol`` plugin (``"ipopt"``: its gradient-based scaling).
    second_order : SecondOrderCheck, str or None
        A check already made at this point (the multistart's), or ``None`` to run it here.
    switching : Switching or None
        The switching agreement, for bang-bang minimum time.
    costate_gap : float or None
        Relative difference to a co-state solution.
    seeds, seeds_agreed : int or None
        Starts tried and agreeing.

    Returns
    -------
    dict
        :func:`certificate`'s record.
    """
    bounds = {"p": p, "lbx": lbx, "ubx": ubx, "lbg": lbg, "ubg": ubg}
    kkt = kkt_residuals(solver, x, lam_x, lam_g, solver_name=solver_name, **bounds)
    if second_order is None:
        second_order = second_order_check(solver, x, lam_x, lam_g, **bounds)
    return certificate(kkt, second_order, switching, costate_gap=costate_gap, seeds=seeds, seeds_agreed=seeds_agreed)


def necessary_conditions_certificate(residual: float, method: str, *, tolerance: float = KKT_TOLERANCE,
                                     costate_gap: float | None = None) -> dict[str, Any]:
    """The record of :func:`certificate` for an indirect solution: Pontryagin's necessary conditions
    solved as a boundary-value problem, whose residual stands for both KKT entries; nothing is known
    of second order, so the verdict is at best ``"first-order"``.

    Parameters
    ----------
    residual : float
        The largest residual of the boundary-value solution (differential equations and boundary
        conditions).
    method : str
        What solved it, for the ``second_order`` text and the summary (e.g. ``"solve_bvp"``).
    tolerance : float
        Largest residual of a first-order point.
    costate_gap : float or None
        Relative difference to another solution, when known.

    Returns
    -------
    dict
        The keys of :func:`certificate`; ``verdict`` ``"first-order"`` or ``"not certified"``.
    """
    verdict = "first-order" if residual <= tolerance else "not certified"
    record = {"kkt_scaled": float(residual), "kkt_unscaled": float(residual),
              "second_order": f"not checked: an indirect solution ({method}), Pontryagin's necessary conditions only",
              "switching": None, "costate_gap": costate_gap, "seeds": None, "seeds_agreed": None, "verdict": verdict,
              "method": method, "summary": "", "kkt": None, "switching_detail": None, "second_order_detail": None}
    record["summary"] = summary_line(record)
    return record
