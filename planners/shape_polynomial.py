"""Shape-based quaternion polynomials (Vepa, section 7, after Caubet & Biggs), eq. 52-54.

With τ = t/t_f each component is a cubic Hermite polynomial matching ``q(0), q(1)`` and the boundary
rates, plus ``N`` free shapes ``e_ij [(j−4) τ² − (j−3) τ³ + τ^(j−1)]``, ``j = 5 … N+4``, which vanish
with zero slope at both ends (eq. 52), so every choice of coefficients meets the boundary
conditions exactly. The polynomial ``p(τ)`` is normalised, ``q = p/‖p‖``, which keeps the reference
unit and leaves the boundary values unchanged. The coefficients minimise (``cost``):

* ``path``: ``∫₀¹ ‖dq/dτ‖² dτ`` (our reading of eq. 53, whose integrand is garbled in the text; the
  smooth form of the path length, minimised by constant-speed geodesics), or
* ``torque``: ``∫ ‖I ω̇ + ω × I ω‖² dt`` over the scenario's duration.

``ω = 2 vec(q* ⊗ q̇)`` (eq. 54 in our convention). With ``duration: rate_limit`` the time is the
shortest that keeps ``‖ω‖ <= max_rate`` (the paper's choice): ``t_f = max_τ ‖ω_τ‖ / max_rate``;
the planner tries ``N = 1 … max_terms`` and keeps the shortest ``t_f`` (or the lowest cost).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Any, Literal

import casadi as ca
import numpy as np

from ocp import quat
from ocp import quat_casadi as qc
from ocp.nlp.solve import solve_multistart, solver_options
from ocp.options import Range
from planners.base import Planner
from planners.problem import Array, ManeuverProblem
from planners.reference import (
    FailedReference,
    Reference,
    ReferenceSample,
    inverse_dynamics_torque,
)

QUADRATURE_POINTS = 41  # uniform grid of the torque cost
NO_RATE_BOUND = ("duration: rate_limit (the default, the paper's minimum time) needs a rate bound: the option max_rate, "
                 "maneuver.max_rate or ManeuverProblem(..., max_rate=...); or plan over the problem's own duration "
                 "with duration: scenario (options {'duration': 'scenario'})")
"""Why the default ``duration: rate_limit`` refuses a problem without a rate bound."""
GAUSS_POINTS = 16       # Gauss-Legendre points of the path cost (exact for degree 31)


def shape_basis(tau: Any, terms: int, math: Any = np) -> tuple[list[Any], list[Any]]:
    """Hermite basis (4 functions) and the ``terms`` free shapes of eq. 52 at ``tau``, with τ-derivatives.

    Parameters
    ----------
    tau : float, ndarray or casadi.SX
        Scaled time ``τ = t / t_f`` in [0, 1] (dimensionless).
    terms : int
        N, the number of free shapes (``j = 5 … N+4``).
    math : module, optional
        ``numpy`` (default) or ``casadi``: unused by the arithmetic here, kept so that both
        backends call it alike.

    Returns
    -------
    basis : list
        ``4 + terms`` values like ``tau``: the cubic Hermite functions for ``q(0)``, ``dq/dτ(0)``,
        ``q(1)``, ``dq/dτ(1)``, then the free shapes.
    derivatives : list
        Their τ-derivatives, in the same order.
    """
    h = [2 * tau**3 - 3 * tau**2 + 1, tau**3 - 2 * tau**2 + tau, -2 * tau**3 + 3 * tau**2, tau**3 - tau**2]
    dh = [6 * tau**2 - 6 * tau, 3 * tau**2 - 4 * tau + 1, -6 * tau**2 + 6 * tau, 3 * tau**2 - 2 * tau]
    free = [(j - 4) * tau**2 - (j - 3) * tau**3 + tau ** (j - 1) for j in range(5, terms + 5)]
    dfree = [2 * (j - 4) * tau - 3 * (j - 3) * tau**2 + (j - 1) * tau ** (j - 2) for j in range(5, terms + 5)]
    return h + free, dh + dfree


def polynomial(tau: Any, q0: Any, q1: Any, slope0: Any, slope1: Any, coefficients: Any, terms: int,
               math: Any = np) -> tuple[Any, Any]:
    """The normalised quaternion polynomial of eq. 52 and its τ-derivative.

    Parameters
    ----------
    tau : (1, m) ndarray or casadi.SX
        Scaled times ``τ = t / t_f`` in [0, 1]: a row for NumPy, one scalar for CasADi.
    q0, q1 : (4, 1) ndarray or casadi.SX
        Boundary attitudes (scalar first, body to inertial), columns.
    slope0, slope1 : (4, 1) ndarray or casadi.SX
        Boundary slopes ``dq/dτ = t_f ½ q ⊗ [0, ω]`` [dimensionless], columns.
    coefficients : (4, terms) ndarray or casadi.SX
        ``e_ij`` of the free shapes.
    terms : int
        N, the number of free shapes.
    math : module, optional
        ``numpy`` (default; columns are times) or ``casadi`` (one scalar τ).

    Returns
    -------
    q : (4, m) ndarray or casadi.SX
        ``p/‖p‖``, unit quaternions.
    dq : (4, m) ndarray or casadi.SX
        ``dq/dτ`` (derivative of the normalised polynomial).
    """
    basis, dbasis = shape_basis(tau, terms, math)
    p = basis[0] * q0 + basis[1] * slope0 + basis[2] * q1 + basis[3] * slope1
    dp = dbasis[0] * q0 + dbasis[1] * slope0 + dbasis[2] * q1 + dbasis[3] * slope1
    for k in range(terms):
        p = p + basis[4 + k] * coefficients[:, k:k + 1]
        dp = dp + dbasis[4 + k] * coefficients[:, k:k + 1]
    if math is np:  # columns are times
        norm = np.linalg.norm(p, axis=0)
        q = p / norm
        return q, (dp - q * np.sum(q * dp, axis=0)) / norm
    norm = ca.norm_2(p)
    q = p / norm
    return q, (dp - q * ca.dot(q, dp)) / norm


def build_solver(terms: int, cost: str) -> ca.Function:
    """The IPOPT solver of the shape coefficients for one number of terms and one cost.

    Parameters
    ----------
    terms : int
        N, the number of free shapes.
    cost : {"path", "torque"}
        ``path``: ``∫₀¹ ‖dq/dτ‖² dτ`` (Gauss-Legendre); ``torque``: ``∫ ‖I ω̇ + ω × I ω‖² dt`` [N² m² s]
        on a uniform grid.

    Returns
    -------
    casadi.Function
        ``nlpsol`` with decision ``vec(e)`` (4 x terms, column-major), parameters
        ``[q0 (4), q1 (4), slope0 (4), slope1 (4), I (9, column-major, kg m^2), T (s)]`` and
        constraints ``‖p(τ_k)‖²`` at the quadrature points (bounded to keep the raw polynomial near
        the unit sphere).
    """
    e = ca.SX.sym("e", 4, terms)
    p = ca.SX.sym("p", 26)
    q0, q1, s0, s1 = p[0:4], p[4:8], p[8:12], p[12:16]
    inertia, duration = ca.reshape(p[16:25], 3, 3), p[25]
    if cost == "path":  # Gauss-Legendre: the integrand is smooth, so few points are exact enough
        nodes, gauss_weights = np.polynomial.legendre.leggauss(GAUSS_POINTS)
        taus, weights = 0.5 * (nodes + 1), 0.5 * gauss_weights
    else:  # a uniform grid, on which the torque's rate derivative is differenced
        taus = np.linspace(0, 1, QUADRATURE_POINTS)
        weights = np.full(QUADRATURE_POINTS, 1.0 / (QUADRATURE_POINTS - 1))
        weights[[0, -1]] /= 2
    total = 0
    rates, norms = [], []
    for tau, w in zip(taus, weights):
        q, dq = polynomial(tau, q0, q1, s0, s1, e, terms, math=ca)
        basis, _ = shape_basis(tau, terms, ca)
        raw = basis[0] * q0 + basis[1] * s0 + basis[2] * q1 + basis[3] * s1 + sum(basis[4 + k] * e[:, k] for k in range(terms))
        norms.append(ca.sumsqr(raw))
        if cost == "path":
            total += w * ca.sumsqr(dq)
        rates.append(2 * qc.product(qc.conjugate(q), dq)[1:4] / duration)
    if cost == "torque":
        h = 1.0 / (QUADRATURE_POINTS - 1)
        for k, (tau, w) in enumerate(zip(taus, weights)):
            rate_dot = (rates[min(k + 1, len(rates) - 1)] - rates[max(k - 1, 0)]) / ((2 if 0 < k < len(rates) - 1 else 1) * h * duration)
            torque = ca.mtimes(inertia, rate_dot) + ca.cross(rates[k], ca.mtimes(inertia, rates[k]))
            total += w * duration * ca.sumsqr(torque)
    # The cost only shapes the path (the boundary conditions hold exactly for any coefficients),
    # so a loose tolerance is enough.
    options = solver_options("ipopt", 1e-7, 100)
    # Keep the raw polynomial near the unit sphere: through the normalisation, a polynomial whose
    # norm blows up could turn between quadrature points where the cost does not see it.
    return ca.nlpsol(f"shape_{terms}_{cost}", "ipopt",
                     {"x": ca.vec(e), "p": p, "f": total, "g": ca.vertcat(*norms)}, options)


class ShapeReference(Reference):
    """Normalised polynomial attitude; rate by eq. 54, its derivative by central differences (step
    1e-5 in τ, one-sided at the ends), torque by inverse dynamics.

    Parameters
    ----------
    q0, q1 : (4,) ndarray
        Boundary attitudes, scalar first, body to inertial (``q1`` on the side of ``q0``).
    slope0, slope1 : (4,) ndarray
        Boundary slopes ``dq/dτ = T ½ q ⊗ [0, ω]`` with the problem's T (dimensionless).
    coefficients : (4, terms) ndarray
        ``e_ij`` of the free shapes.
    terms : int
        N, the number of free shapes.
    duration : float
        t_f [s], over which τ runs from 0 to 1.
    inertia : (3, 3) ndarray
        Body inertia [kg m^2].
    message : str
        Outcome description.
    stats : dict
        Solver statistics.
    """

    def __init__(self, q0: Array, q1: Array, slope0: Array, slope1: Array, coefficients: Array, terms: int,
                 duration: float, inertia: Array, message: str, stats: dict[str, Any]) -> None:
        super().__init__("shape_polynomial", duration, inertia, message=message, stats=stats)
        self.args = (q0, q1, slope0, slope1, coefficients, terms)

    def _rate(self, tau: Array) -> tuple[Array, Array]:
        q0, q1, slope0, slope1, coefficients, terms = self.args
        q, dq = polynomial(tau[None, :], np.asarray(q0)[:, None], np.asarray(q1)[:, None],
                           np.asarray(slope0)[:, None], np.asarray(slope1)[:, None], coefficients, terms)
        return q.T, 2 * quat.product(quat.conjugate(q.T), dq.T)[:, 1:] / self.duration

    def _evaluate(self, t: Array) -> ReferenceSample:
        tau = t / self.duration
        q, omega = self._rate(tau)
        step = 1e-5
        omega_dot = (self._rate(np.minimum(tau + step, 1))[1] - self._rate(np.maximum(tau - step, 0))[1]) / (
            (np.minimum(tau + step, 1) - np.maximum(tau - step, 0))[:, None] * self.duration)
        return ReferenceSample(q, omega, omega_dot, inverse_dynamics_torque(self.inertia, omega, omega_dot))


class ShapePolynomialPlanner(Planner):
    """Shape-based quaternion polynomial planner (see the module docstring)."""

    name = "shape_polynomial"
    example_options = ({"terms": 2}, {"terms": 2, "duration": "scenario", "cost": "torque"})

    @classmethod
    def minimises_time(cls, options: Any) -> bool:
        """Whether the duration is minimised (:func:`planners.capabilities.minimises_time`).

        Parameters
        ----------
        options : Options or any
            The planner's options.

        Returns
        -------
        bool
            True with ``duration: rate_limit`` (the shortest ``t_f`` within the rate bound, over the
            shapes tried); the paper's minimum-time choice within its polynomial family.
        """
        return getattr(options, "duration", None) == "rate_limit"

    @dataclass(frozen=True)
    class Options:
        """Options of ``shape_polynomial`` (YAML ``planner.options``).

        Attributes
        ----------
        terms : int or None
            N, the number of free shapes of eq. 52, 1 to 12; ``None`` (default): try
            ``1 … max_terms`` and keep the best (shortest t_f with ``duration: rate_limit``, else
            the lowest cost).
        max_terms : int
            Largest N tried when ``terms`` is ``None``, 1 to 12 (default 6).
        cost : {"path", "torque"}
            What the coefficients minimise: ``path`` (default) ``∫₀¹ ‖dq/dτ‖² dτ``, or ``torque``
            ``∫ ‖I ω̇ + ω × I ω‖² dt`` over the scenario's duration.
        duration : {"rate_limit", "scenario"}
            ``rate_limit`` (default; rest-to-rest only): the shortest t_f with ``‖ω‖ <= max_rate``,
            the paper's choice; ``scenario``: the scenario's T.
        max_rate : float or None
            Rate bound [rad/s] for ``duration: rate_limit``; it tightens the problem's bound
            (``maneuver.max_rate``, or ``requirements.rate.max``), never loosens it; ``None``
            (default): the problem's.
        rate_margin : float
            The rate requirement (``requirements.rate.max``, ``ManeuverProblem.rate_requirement``)
            is planned this fraction lower with ``duration: rate_limit``, in [0, 1) (default 0.01):
            a zero-order-hold closed loop tracking a reference at the bound overshoots it, a smooth
            peak as this polynomial's too (by 8e-6 of it at 0.1 s samples with unsaturated wheels,
            by 1-2 % where its torques saturate them);
            ``maneuver.max_rate`` and the option ``max_rate`` are imposed as given (the paper's
            minimum time, :meth:`~planners.problem.ManeuverProblem.rate_bound`).
        """

        terms: Annotated[int | None, Range(ge=1, le=12)] = None                                    # N; None tries 1..max_terms
        max_terms: Annotated[int, Range(ge=1, le=12)] = 6
        cost: Literal["path", "torque"] = "path"
        duration: Literal["rate_limit", "scenario"] = "rate_limit"
        max_rate: Annotated[float | None, Range(gt=0.0)] = None                               # rad/s; default: the problem's max_rate
        rate_margin: Annotated[float, Range(ge=0.0, lt=1.0)] = 0.01                           # the rate requirement is planned this fraction lower

    @classmethod
    def honoured(cls, options: Any) -> frozenset[str]:
        """The rate bound with ``duration: rate_limit`` (t_f is chosen so that ``‖ω‖`` peaks at it,
        2001 points in τ); nothing over the scenario's T.

        Parameters
        ----------
        options : Options
            The planner's options.

        Returns
        -------
        frozenset of str
        """
        return frozenset({"rate"}) if getattr(options, "duration", None) == "rate_limit" else frozenset()

    def problem_error(self, problem: ManeuverProblem) -> str | None:
        """Why the shape polynomials cannot take ``problem``.

        Parameters
        ----------
        problem : ManeuverProblem
            The problem to plan.

        Returns
        -------
        str or None
            The reason (no target attitude; ``duration: rate_limit`` without a rate bound or for a
            slew that does not start and end at rest), or ``None``.
        """
        o = self.options
        if o.duration == "rate_limit":
            if problem.rate_bound(o.max_rate, o.rate_margin) is None:
                return NO_RATE_BOUND
            if np.any(problem.omega0) or (problem.omegaf is not None and np.any(problem.omegaf)):
                return "duration: rate_limit is for rest-to-rest slews; use duration: scenario"
        return super().problem_error(problem)

    def _plan(self, problem: ManeuverProblem) -> Reference:
        o = self.options
        max_rate = problem.rate_bound(o.max_rate, o.rate_margin)
        if o.duration == "rate_limit" and max_rate is None:
            return FailedReference(self.name, NO_RATE_BOUND)
        omegaf = np.zeros(3) if problem.omegaf is None else problem.omegaf
        rest_to_rest = not np.any(problem.omega0) and not np.any(omegaf)
        if o.duration == "rate_limit" and not rest_to_rest:
            return FailedReference(self.name, "duration: rate_limit is for rest-to-rest slews; use duration: scenario")
        assert problem.qf is not None  # problem_error refuses a free attitude
        q0 = problem.q0
        q1 = problem.qf if problem.qf @ q0 >= 0 else -problem.qf  # the shorter way round
        T = problem.duration
        slope0, slope1 = T * quat.kinematics(q0, problem.omega0), T * quat.kinematics(q1, omegaf)
        params = np.concatenate([q0, q1, slope0, slope1, problem.spacecraft.inertia.ravel(order="F"), [T]])
        best, previous = None, np.zeros((4, 0))
        candidates = [o.terms] if o.terms is not None else range(1, o.max_terms + 1)
        for terms in candidates:
            solver = self.solver_cache(problem).get(("shape_polynomial", terms, o.cost),
                                                    lambda: build_solver(terms, o.cost))
            seed = np.zeros((4, terms))
            seed[:, :min(terms, previous.shape[1])] = previous[:, :terms]  # N − 1 terms seed N
            result = solve_multistart(solver, [seed.T.ravel()], p=params, lbg=0.5, ubg=2.0)
            if not result.success or result.x is None:
                continue
            coefficients = result.x.reshape(terms, 4).T
            previous = coefficients
            probe = ShapeReference(q0, q1, slope0, slope1, coefficients, terms, 1.0, problem.spacecraft.inertia, "", {})
            peak = float(np.max(np.linalg.norm(probe._rate(np.linspace(0, 1, 2001))[1], axis=1)))  # per unit τ
            duration = peak / max_rate if o.duration == "rate_limit" and max_rate is not None else T
            score = duration if o.duration == "rate_limit" else result.f
            if best is None or score < best[0]:
                best = (score, terms, coefficients, duration, result)
        if best is None:
            return FailedReference(self.name, "IPOPT did not converge for any number of shape terms")
        _, terms, coefficients, duration, result = best
        cost = result.f
        stats = result.stats()
        stats.update(terms=terms, cost=cost, duration=duration)
        message = f"N = {terms}, t_f = {duration:.4g} s, {o.cost} cost {cost:.4g}"
        return ShapeReference(q0, q1, slope0, slope1, coefficients, terms, duration, problem.spacecraft.inertia,
                              message, stats)
