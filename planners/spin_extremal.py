"""Closed-form spin-stabilized extremals (Biggs & Horri, Theorem 1) with parameter optimisation.

Extremals of ``½∫(Ω2² + Ω3²) dt`` with the roll rate held at ``v``:
``ω*(t) = [v, r sin θ, r cos θ]``, ``θ = (v + c) t + β``. The attitude from ``q*(0) = 1`` is

    q*(t) = E1(−β) ⊗ exp(t [−c, 0, r] / 2) ⊗ E1(θ(t)),   E1(φ) = [cos φ/2, sin φ/2, 0, 0],

because in the frame turning with θ about the roll axis the rate is the constant ``[−c, 0, r]``
(norm ``K = √(r² + c²)``). Expanded, ``q0, q1`` carry the coefficients ``(K − c)`` with
``cos((c + K + v) t/2)`` and ``(K + c)`` with ``cos((c − K + v) t/2)``: eq. 11 prints them swapped
(invisible for the paper's c ≈ 0); ``q2, q3`` are eq. 11 with the + sign. Any initial attitude is
reached by ``q(t) = q0 ⊗ q*(t)``. The feed-forward torque is eq. 31 (checked against inverse dynamics).

The parameters ``(r, c, β)`` minimise ``J = J1 + k J2`` (eq. 34) by IPOPT's iterations (taken in NumPy
where they are plain Newton steps, IPOPT itself elsewhere: :class:`NewtonFirst`):
``J1 = min(‖q(T) − q_f‖², ‖q(T) + q_f‖²)`` (eq. 30 made invariant to ``q_f ~ −q_f``) and ``J2 = ∫‖u‖² dt`` in closed form (eq. 33 corrected:
its ``u2`` factor must be ``(α − v δ2)`` as in eq. 31, and its first term's brackets are misplaced).
A vectorised multi-start over branches of ``K T``, over ``β`` and over ``c`` seeds them.
"""
from __future__ import annotations

import copy
from collections.abc import Iterable
from dataclasses import dataclass, replace
from typing import Annotated, Any, cast

import casadi as ca
import numpy as np

from ocp import quat
from ocp.dynamics.spin_closed_form import extremal_quaternion
from ocp.errors import InvalidOption
from ocp.fast_call import buffered
from ocp.nlp.solve import solve_multistart, solver_options
from ocp.options import Range
from planners.base import Planner
from planners.conformance import ATTITUDE_TOLERANCE
from planners.problem import Array, ManeuverProblem
from planners.reference import FailedReference, Reference, ReferenceSample


def torque_amplitudes(v: float, r: float, c: float, moments: Array) -> Array:
    """Per-axis amplitudes of eq. 31's torque.

    Parameters
    ----------
    v : float
        Spin rate about the first body axis [rad/s].
    r, c : float
        Transverse rate amplitude and spin offset [rad/s].
    moments : (3,) ndarray
        Principal moments of inertia [kg m^2].

    Returns
    -------
    (3,) ndarray
        ``[½ I1 |δ1| r², I2 r |α − v δ2|, I3 r |α + v δ3|]`` [N m], body axes.
    """
    I1, I2, I3 = moments
    alpha = v + c
    return np.array([0.5 * abs(I2 - I3) * r**2, I2 * r * abs(alpha - v * (I3 - I1) / I2),
                     I3 * r * abs(alpha + v * (I1 - I2) / I3)])


def attitude_cost(q_end: Array, target: Array) -> Array:
    """Eq. 30 invariant to the double cover.

    Parameters
    ----------
    q_end : (..., 4) ndarray
        Final quaternions (scalar first).
    target : (4,) ndarray
        Target quaternion.

    Returns
    -------
    ndarray
        ``min(‖q − q_f‖², ‖q + q_f‖²)`` over the last axis (dimensionless).
    """
    return np.minimum(np.sum((q_end - target) ** 2, axis=-1), np.sum((q_end + target) ** 2, axis=-1))


def extremal_torque(t: Array, v: float, r: float, c: float, beta: float, moments: Array) -> Array:
    """Eq. 31: the body torque that makes a principal-axis body follow ``ω*``.

    Parameters
    ----------
    t : (n,) ndarray
        Times [s].
    v : float
        Spin rate [rad/s].
    r, c : float
        Transverse rate amplitude and spin offset [rad/s].
    beta : float
        Phase of the transverse rate [rad].
    moments : (3,) ndarray
        Principal moments of inertia [kg m^2].

    Returns
    -------
    (n, 3) ndarray
        Torque [N m], body axes, one row per time.
    """
    I1, I2, I3 = moments
    d1, d2, d3 = (I2 - I3) / I1, (I3 - I1) / I2, (I1 - I2) / I3
    alpha = v + c
    theta = alpha * t + beta
    return np.stack([-0.5 * I1 * r**2 * np.sin(2 * theta) * d1,
                     I2 * r * np.cos(theta) * (alpha - v * d2),
                     -I3 * r * np.sin(theta) * (alpha + v * d3)], axis=-1)


def _sin_ratio(x, duration, math):
    """``sin(x T)/x`` with its limit ``T`` at ``x = 0`` (series below 1e-4 relative)."""
    small = (x * duration) ** 2 < 1e-8
    if math is np:
        return np.where(small, duration, np.sin(x * duration) / np.where(small, 1.0, x))
    return ca.if_else(small, duration * (1 - (x * duration) ** 2 / 6), ca.sin(x * duration) / x)


def energy_cost(v: Any, r: Any, c: Any, beta: Any, duration: Any, moments: Any, math: Any = np) -> Any:
    """``J2 = ∫₀ᵀ ‖u‖² dt`` in closed form for the torque of eq. 31.

    Parameters
    ----------
    v : float or CasADi scalar
        Spin rate [rad/s].
    r, c : float, ndarray or CasADi scalar
        Transverse rate amplitude and spin offset [rad/s].
    beta : float, ndarray or CasADi scalar
        Phase of the transverse rate [rad].
    duration : float or CasADi scalar
        T [s].
    moments : (3,) sequence
        Principal moments of inertia [kg m^2].
    math : module
        ``numpy`` (default) or ``casadi``.

    Returns
    -------
    float, ndarray or CasADi scalar
        J2 [N² m² s].
    """
    I1, I2, I3 = moments
    d1, d2, d3 = (I2 - I3) / I1, (I3 - I1) / I2, (I1 - I2) / I3
    alpha = v + c
    cos2 = math.cos(alpha * duration + 2 * beta) * _sin_ratio(alpha, duration, math)        # ∫ cos 2θ
    cos4 = math.cos(2 * alpha * duration + 4 * beta) * _sin_ratio(2 * alpha, duration, math)  # ∫ cos 4θ
    return (0.125 * (I1 * d1) ** 2 * r**4 * (duration - cos4)
            + 0.5 * I2**2 * r**2 * (alpha - v * d2) ** 2 * (duration + cos2)
            + 0.5 * I3**2 * r**2 * (alpha + v * d3) ** 2 * (duration - cos2))


TOLERANCE = 1e-12
"""IPOPT's ``tol`` on the parameters' optimisation (its scaled gradient at the optimum)."""
MAX_ITERATIONS = 200
"""IPOPT's iteration limit there."""
NEWTON_ITERATIONS = 50
"""Newton steps at most before the start is handed to IPOPT (:class:`NewtonFirst`)."""
DEFINITE = 1e-8
"""A Hessian whose least eigenvalue is above this times its largest is positive definite for
IPOPT's factorisation too (:class:`NewtonFirst`)."""
SINGULAR = 1e-12
"""One whose least eigenvalue is at most this times its largest is not (it is singular, or
indefinite, to rounding: Bilimoria & Wie's, 0 at every iterate, which IPOPT perturbs); between the
two the start is left to IPOPT."""
DEGENERATE_ITERATIONS = 3
"""IPOPT's ``degen_iters_max``: perturbed iterations from the start after which it perturbs every
later one without trying ``δ = 0``."""
_EYE = np.eye(3)
_TINY_STEP = 10.0 * np.finfo(float).eps
"""IPOPT's ``Search_Direction_Becomes_Too_Small``: every step component below this times ``1 + |x_i|``."""


def _objective(x: ca.SX, p: ca.SX) -> ca.SX:
    """``J = J1 + k J2`` of (r, c, β) = ``x`` with parameters ``p`` = [v, T, I1, I2, I3, q_target (4), k]."""
    r, c, beta = x[0], x[1], x[2]
    v, duration, moments, target, weight = p[0], p[1], (p[2], p[3], p[4]), p[5:9], p[9]
    q_end = ca.vertcat(*extremal_quaternion(duration, v, r, c, beta, math=ca))
    j1 = ca.fmin(ca.sumsqr(q_end - target), ca.sumsqr(q_end + target))
    j2 = energy_cost(v, r, c, beta, duration, moments, math=ca)
    return j1 + weight * j2


def build_solver() -> ca.Function:
    """IPOPT on (r, c, β) with parameters [v, T, I1, I2, I3, q_target (4), k].

    At a zero-cost optimum (k = 0, target reached) IPOPT reports
    ``Search_Direction_Becomes_Too_Small``, which the status policy of :mod:`ocp.nlp.solve` counts as
    converged (the problem is unconstrained).

    Returns
    -------
    casadi.Function
        The ``nlpsol`` function.
    """
    x, p = ca.SX.sym("x", 3), ca.SX.sym("p", 10)
    # Unbounded: (−r, β + π) is the same extremal, so r >= 0 is restored afterwards instead of
    # being a bound whose barrier would cost IPOPT iterations. J1 is written as eq. 30's sum of
    # squares: the equal 2 − 2|q·q_f| cancels at the optimum and leaves IPOPT a noisy gradient.
    return ca.nlpsol("spin_extremal", "ipopt", {"x": x, "p": p, "f": _objective(x, p)},
                     solver_options("ipopt", TOLERANCE, MAX_ITERATIONS))


def build_derivatives() -> ca.Function:
    """``(x, p) -> (J, ∇J, ∇²J)`` of :func:`build_solver`'s objective (the Hessian dense, 3 x 3).

    Returns
    -------
    casadi.Function
        The objective, its gradient and its Hessian in (r, c, β).
    """
    x, p = ca.SX.sym("x", 3), ca.SX.sym("p", 10)
    f = _objective(x, p)
    hessian, gradient = ca.hessian(f, x)
    return ca.Function("spin_extremal_derivatives", [x, p], [f, gradient, ca.densify(hessian)])


class NewtonFirst:
    """IPOPT's iterations on (r, c, β) taken as the Newton steps they are, IPOPT itself otherwise.

    On this unconstrained problem IPOPT's step solves ``(s ∇²J + δ I) d = −s ∇J`` (``s`` its
    gradient-based scaling of the objective, below) with IPOPT's inertia correction ``δ`` (0 when the Hessian is positive definite; else, as IPOPT's
    ``PDPerturbationHandler``, 1e-4 the first time, then a third of the last ``δ``, raised 100-fold
    then 8-fold until the matrix is positive definite; after :data:`DEGENERATE_ITERATIONS`
    perturbed iterations from the start, every later one is perturbed so without trying 0, and once
    ``δ = 0`` has worked it is always tried first). The step is taken in full when it meets the
    Armijo condition (``η_φ = 1e-8``; no barrier and no filter entries without constraints). IPOPT
    stops when the gradient, scaled by its gradient-based factor ``min(1, 100 / ‖∇J(x0)‖∞)``, is
    within :data:`TOLERANCE`, or when a step is below ``10 ε`` of every ``1 + |x_i|``
    (``Search_Direction_Becomes_Too_Small``). Here those steps are taken in NumPy, without IPOPT's
    fixed cost of about 1-2 ms a solve. A start where this would guess what IPOPT's factorisation
    decides (a least eigenvalue of the perturbed Hessian between :data:`SINGULAR` and
    :data:`DEFINITE` times the largest), where the Armijo condition refuses the full step (IPOPT
    backtracks) or that takes :data:`NEWTON_ITERATIONS` steps is solved by IPOPT from its
    beginning. Called and read as the ``nlpsol`` function it stands for (``solver(x0=..., p=...)``,
    :meth:`stats`), for :func:`~ocp.nlp.solve.solve_multistart`.

    Parameters
    ----------
    derivatives : casadi.Function
        :func:`build_derivatives`.
    ipopt : casadi.Function
        :func:`build_solver`.
    """

    def __init__(self, derivatives: ca.Function, ipopt: ca.Function) -> None:
        self.derivatives = buffered(derivatives)  # its buffers made once per function and thread
        self.ipopt = ipopt
        self._stats: dict[str, Any] = {}

    def stats(self) -> dict[str, Any]:
        """The last call's statistics, as ``nlpsol``'s ``stats()``.

        Returns
        -------
        dict
            ``return_status``, ``success`` and ``iter_count`` after the Newton steps; IPOPT's own
            after a call it solved.
        """
        return self._stats

    def _evaluate(self, x: Array) -> tuple[float, Array, Array, bool]:
        """J, ∇J, ∇²J at ``x`` (arrays of their own) and whether all of them are finite."""
        values = np.concatenate(self.derivatives.all_outputs(x))  # one copy of J, ∇J and ∇²J
        return float(values[0]), values[1:4], values[4:].reshape(3, 3), bool(np.isfinite(values).all())

    @staticmethod
    def _definite(eigenvalues: list[float], shift: float) -> bool | None:
        """Whether ``∇²J + shift I`` is positive definite as IPOPT's factorisation finds it;
        ``None`` where its rounding would decide."""
        least = eigenvalues[0] + shift
        largest = max(abs(eigenvalues[2] + shift), abs(least))
        if least > DEFINITE * largest:
            return True
        if least <= SINGULAR * largest:
            return False
        return None

    def _newton(self, x: Array) -> tuple[Array, float, int, str] | None:
        """The point, J, the steps and IPOPT's status there; ``None`` where IPOPT would not step so."""
        # Plain floats where NumPy's per-call cost would dominate (3-vectors); the same IEEE
        # operations, so the same numbers: max |·| is exact, as are the comparisons.
        f, gradient, hessian, finite = self._evaluate(x)
        largest = max(map(abs, gradient.tolist()))
        scale = 100.0 / largest if largest > 100.0 else 1.0  # IPOPT's nlp_scaling_max_gradient
        last = 0.0  # IPOPT's delta_x_last
        degenerate: bool | None = None  # IPOPT's hess_degenerate (None: not yet determined)
        perturbed = 0
        for k in range(NEWTON_ITERATIONS + 1):
            if not finite:
                return None
            if scale * max(map(abs, gradient.tolist())) <= TOLERANCE:
                return x, f, k, "Solve_Succeeded"
            if k == NEWTON_ITERATIONS:
                return None
            scaled = scale * hessian
            eigenvalues = np.linalg.eigvalsh(scaled).tolist()  # IPOPT perturbs the scaled problem's Hessian
            shift = 0.0
            if not degenerate:
                definite = self._definite(eigenvalues, 0.0)
                if definite is None:
                    return None
                if definite and degenerate is None:
                    degenerate = False
            if degenerate or not definite:
                shift = 1e-4 if last == 0.0 else max(1e-20, last / 3.0)
                while True:
                    definite = self._definite(eigenvalues, shift)
                    if definite is None or shift > 1e20:
                        return None
                    if definite:
                        break
                    shift *= 100.0 if last == 0.0 or 1e5 * last < shift else 8.0
                last = shift
                if degenerate is None:
                    perturbed += 1
                    degenerate = True if perturbed >= DEGENERATE_ITERATIONS else None
            step = -np.linalg.solve(scaled + shift * _EYE, scale * gradient)
            if not np.isfinite(step).all():
                return None
            if max(abs(s) / (1.0 + abs(y)) for s, y in zip(step.tolist(), x.tolist())) < _TINY_STEP:
                return x, f, k, "Search_Direction_Becomes_Too_Small"
            trial = x + step
            f_trial, gradient_trial, hessian_trial, finite = self._evaluate(trial)
            if not f_trial <= f + 1e-8 * float(gradient @ step):  # Armijo refuses the full step (or NaN)
                return None
            x, f, gradient, hessian = trial, f_trial, gradient_trial, hessian_trial
        return None

    def __call__(self, *, x0: Any, p: Any, **arguments: Any) -> dict[str, Any]:
        self.derivatives.inputs[1][:] = np.asarray(p, dtype=float).ravel()
        found = self._newton(np.asarray(x0, dtype=float).ravel().copy())
        if found is None:
            solution = self.ipopt(x0=x0, p=p, **arguments)
            self._stats = self.ipopt.stats()
            return solution
        x, f, steps, status = found
        self._stats = {"return_status": status, "success": status == "Solve_Succeeded", "iter_count": steps}
        empty = ca.DM(0, 1)
        return {"x": ca.DM(x), "f": ca.DM(f), "g": empty, "lam_x": ca.DM.zeros(3), "lam_g": empty,
                "lam_p": ca.DM.zeros(10)}


@dataclass(frozen=True)
class SpinParameters:
    """The extremal's free parameters.

    Parameters
    ----------
    r : float
        Transverse rate amplitude [rad/s].
    c : float
        Spin offset [rad/s].
    beta : float
        Phase of the transverse rate [rad].
    """

    r: float
    c: float
    beta: float


class SpinExtremalReference(Reference):
    """``q(t) = q0 ⊗ q*(t)``, ``ω = ω*(t)``, torque of eq. 31.

    The extremal's rates ``ω*(0) = [v, r sin β, r cos β]`` and ``ω*(T)`` are set by the parameters,
    not by the problem: the initial transverse rates are free parameters of the method (matching
    them would fix ``r`` and ``β`` and leave ``c`` alone to reach a three-dimensional target; with
    the body at rest transversally, ``r = 0`` and the extremal is the free spin ``E1(v t)``), so
    ``omega0`` and ``omegaf`` are declared free; ``qf`` too when ``J1`` is only a weighted cost
    (``weight > 0``) or the parameters are fixed. ``omegaf`` is free in the problem too: the planner
    refuses a problem that fixes a final rate (:meth:`SpinExtremalPlanner.problem_error`).

    Parameters
    ----------
    q0 : (4,) ndarray
        Initial attitude (scalar first).
    v : float
        Spin rate about the first body axis [rad/s].
    params : SpinParameters
        ``(r, c, β)``.
    duration : float
        T [s].
    moments : (3,) ndarray
        Principal moments of inertia [kg m^2].
    message : str
        Summary for the planner's row.
    stats : dict
        Planner statistics.
    free_boundary : iterable of str
        Boundary conditions the reference does not meet (see :class:`~planners.base.Reference`).
    """

    def __init__(self, q0: Array, v: float, params: SpinParameters, duration: float, moments: Array,
                 message: str, stats: dict, free_boundary: Iterable[str] = ("omega0", "omegaf")) -> None:
        super().__init__("spin_extremal", duration, np.diag(moments), message=message, stats=stats,
                         free_boundary=free_boundary)
        self.q0, self.v, self.params, self.moments = q0, v, params, moments

    def _evaluate(self, t: Array) -> ReferenceSample:
        r, c, beta = self.params.r, self.params.c, self.params.beta
        q_star = np.stack(extremal_quaternion(t, self.v, r, c, beta), axis=-1)
        theta = (self.v + c) * t + beta
        omega = np.stack([np.full_like(t, self.v), r * np.sin(theta), r * np.cos(theta)], axis=-1)
        rate = (self.v + c) * r
        omega_dot = np.stack([np.zeros_like(t), rate * np.cos(theta), -rate * np.sin(theta)], axis=-1)
        return ReferenceSample(quat.product(self.q0, q_star), omega, omega_dot,
                               extremal_torque(t, self.v, r, c, beta, self.moments))


class SpinExtremalPlanner(Planner):
    """Spin-stabilized extremal planner (Biggs & Horri); needs a principal-axis inertia."""

    name = "spin_extremal"
    example_options = ({}, {"weight": 0.1})
    cheap = True
    _start = False
    """Set on the copy :meth:`plan_start` plans with: a start that misses the target is returned."""

    @dataclass(frozen=True)
    class Options:
        """Options of ``spin_extremal`` (YAML keys).

        Attributes
        ----------
        weight : float
            k of J = J1 + k J2 [1/(N² m² s)]; 0 (default): reach the target, J2 only breaks ties.
        spin_rate : float or None
            v [rad/s]; ``None`` (default): the initial roll rate ω0[0].
        parameters : list of 3 floats or None
            Fixed [r, c, β] (rad/s, rad/s, rad), each in (-1000, 1000), r and c not both 0 (K =
            √(r² + c²) > 0): no optimisation; ``None`` (default): optimised.
        starts : int
            Multi-start candidates polished by IPOPT.
        """

        weight: Annotated[float, Range(ge=0.0)] = 0.0                        # k of J = J1 + k J2 (1/(N² m² s))
        spin_rate: Annotated[float | None, Range(gt=-1e3, lt=1e3)] = None             # v (rad/s); default: the initial roll rate ω0[0]
        parameters: Annotated[list[float] | None, Range(gt=-1e3, lt=1e3, size=3)] = None  # fixed [r, c, β] (rad/s, rad/s, rad): no optimisation
        starts: Annotated[int, Range(ge=1, le=50)] = 3                            # multi-start candidates polished by IPOPT

        def __post_init__(self) -> None:
            if self.parameters is not None and self.parameters[0] == 0 and self.parameters[1] == 0:
                raise InvalidOption("parameters", f"r = c = 0 leaves K = sqrt(r^2 + c^2) = 0, which divides the "
                                                  f"closed form; expected r or c non-zero, got {self.parameters}")

    def problem_error(self, problem: ManeuverProblem) -> str | None:
        """Why the spin extremals cannot take ``problem``.

        Parameters
        ----------
        problem : ManeuverProblem
            The manoeuvre.

        Returns
        -------
        str or None
            The reason (no target, non-principal inertia, a fixed final rate), or ``None``.

        Notes
        -----
        A fixed final rate is refused: the extremal ends at ``ω*(T) = [v, r sin θ(T), r cos θ(T)]``,
        set by the parameters that reach the attitude. Meeting ``ωf`` needs ``r = |ωf⊥|``; with
        ``ωf⊥ = 0`` (a body brought to rest, or left spinning about roll) that is ``r = 0``, the free
        spin ``E1(v t)``, which re-points nothing; otherwise ``r`` and ``θ(T)`` fixed leave one
        parameter for a three-dimensional attitude. The reference would end turning at ``r`` and
        coast on after ``T`` (:meth:`~planners.reference.Reference.sample`), the closed loop with it
        (a rest-to-rest 100 deg slew of a wheeled pyramid ended 75 deg off its target 100 s after T).
        The method is for a spinning body whose final rate is free (``maneuver.final.omega: null``).
        """
        if not problem.spacecraft.is_principal:
            return ("the spin extremals need a principal-axis (diagonal) inertia; "
                    "rotate the problem into principal axes first")
        if problem.omegaf is not None:
            return ("the spin extremals cannot meet a fixed final rate (maneuver.final.omega = "
                    f"{np.array2string(np.asarray(problem.omegaf), precision=4)} rad/s): they end at "
                    "omega*(T) = [v, r sin theta(T), r cos theta(T)] set by the parameters that reach the attitude, "
                    "still turning at r > 0 whenever they re-point the body, and coast on after T; set "
                    "maneuver.final.omega: null (a spinning body's free final rate, the method's problem) or "
                    "use another planner")
        return super().problem_error(problem)

    def start_error(self, problem: ManeuverProblem) -> str | None:
        """:meth:`problem_error` on ``problem`` with its final rate freed: a fixed ``omegaf``, which
        refuses the extremal as a row, does not refuse it as a start (:meth:`plan_start` frees it too).

        Parameters
        ----------
        problem : ManeuverProblem
            As :meth:`Planner.start_error <planners.base.Planner.start_error>`.

        Returns
        -------
        str or None
            As :meth:`Planner.start_error <planners.base.Planner.start_error>`.
        """
        return self.problem_error(problem if problem.omegaf is None else replace(problem, omegaf=None))

    def plan_start(self, problem: ManeuverProblem) -> Reference:
        """The extremal as a start for another method: on ``problem`` with its final rate freed.

        A start need not meet the final rate (the method it starts imposes it), so a problem that
        fixes one, which :meth:`problem_error` refuses as a row, still gets the extremal (the same
        one: the optimisation never reads ``omegaf``), e.g. as ``collocation``'s ``warm_start``.

        Parameters
        ----------
        problem : ManeuverProblem
            The slew to plan.

        Returns
        -------
        Reference
            As :meth:`~planners.base.Planner.plan_start` on ``problem`` with ``omegaf = None``.
        """
        # a start that misses the target (a local minimum of J1) still starts the other method
        # well: it is returned, not refused as a row's would be (_plan)
        planner = copy.copy(self)  # with_cache may return self: the flag is the copy's alone
        if problem.omegaf is not None:
            # the freed problem is a new ManeuverProblem with a model of its own: build into this
            # problem's cache, or every start would build the extremal's NLP again (25 ms a plan)
            planner.cache = self.solver_cache(problem)
            problem = replace(problem, omegaf=None)
        planner._start = True
        return Planner.plan_start(planner, problem)

    def _plan(self, problem: ManeuverProblem) -> Reference:
        moments = np.diag(problem.spacecraft.inertia).copy()
        v = float(problem.omega0[0]) if self.options.spin_rate is None else self.options.spin_rate
        T = problem.duration
        assert problem.qf is not None  # problem_error refuses a free final attitude
        target = quat.product(quat.conjugate(problem.q0), problem.qf)
        if self.options.parameters is not None:
            params = SpinParameters(*self.options.parameters)
            stats: dict[str, Any] = {"fixed_parameters": True}
        else:
            cache = self.solver_cache(problem)
            solver = NewtonFirst(cache.get(("spin_extremal", "derivatives"), build_derivatives),
                                 cache.get(("spin_extremal",), build_solver))
            params, stats = self._optimise(solver, v, T, moments, target)
            if params is None:
                return FailedReference(self.name, stats["message"], stats=stats)
        with np.errstate(all="ignore"):  # a non-finite closed form is refused just below
            q_end = np.array(extremal_quaternion(T, v, params.r, params.c, params.beta))
        if not np.all(np.isfinite(q_end)):  # r² + c² under- or overflowed (fixed parameters)
            return FailedReference(self.name, f"the closed form is not finite at T for r={params.r:.6g}, "
                                              f"c={params.c:.6g}, beta={params.beta:.6g}: {q_end}")
        stats.update(r=params.r, c=params.c, beta=params.beta, spin_rate=v, weight=self.options.weight,
                     J1=float(attitude_cost(q_end, target)),
                     J2=float(energy_cost(v, params.r, params.c, params.beta, T, moments)))
        amplitudes = torque_amplitudes(v, params.r, params.c, moments)
        stats["torque_amplitudes"] = amplitudes.tolist()
        message = (f"r={params.r:.6g} c={params.c:.4g} beta={params.beta:.6g}; J1={stats['J1']:.3g} "
                   f"J2={stats['J2']:.4g}; torque amplitudes {np.array2string(amplitudes, precision=4)} N m")
        soft_target = self.options.weight > 0 or self.options.parameters is not None
        miss = float(quat.error_angle(q_end, target))
        if not soft_target and miss > ATTITUDE_TOLERANCE and not self._start:  # a condition, not a cost: a local minimum
            return FailedReference(self.name, f"the best of {self.options.starts} starts ends {np.rad2deg(miss):.3g} deg "
                                   f"from the target (J1 = {stats['J1']:.3g}, a local minimum of the attitude cost); "
                                   f"raise planners[].options.starts (up to 50)", stats=stats)
        free = ("omega0", "omegaf") + (("qf",) if soft_target else ())
        return SpinExtremalReference(problem.q0, v, params, T, moments, message, stats, free)

    def _seeds(self, v: float, T: float, moments: Array, target: Array) -> Array:
        """Best distinct starts of a grid over K T branches, c and β (vectorised evaluation)."""
        base = np.pi / T
        grid = np.meshgrid(base * np.array([0.5, 1.0, 2.0, 3.0, 5.0]),
                           base * np.array([0.0, -1.0, 1.0, -2.0, 2.0, -4.0, 4.0]),
                           np.linspace(-np.pi, np.pi, 12, endpoint=False), indexing="ij")
        r, c, beta = (axis.ravel() for axis in grid)
        q_end = np.stack(extremal_quaternion(T, v, r, c, beta), axis=-1)
        cost = attitude_cost(q_end, target) + self.options.weight * energy_cost(v, r, c, beta, T, moments)
        return np.column_stack([r, c, beta])[np.argsort(cost)[: self.options.starts]]

    def _optimise(self, solver: NewtonFirst | ca.Function, v: float, T: float, moments: Array, target: Array):
        parameters = np.r_[v, T, moments, target, self.options.weight]
        # Every start is a different branch of K T by design: all are tried (agree = 0). Branches that
        # all reach the target (J1 = 0 to rounding) differ in energy: J2 breaks the tie, not rounding.
        # NewtonFirst is called and read as the nlpsol function it stands for
        result = solve_multistart(cast(ca.Function, solver), self._seeds(v, T, moments, target), p=parameters, agree=0,
                                  tie_break=lambda x: float(energy_cost(v, x[0], x[1], x[2], T, moments)))
        stats = result.stats()
        if result.x is None:
            stats["message"] = f"IPOPT did not converge from any start: {sorted(set(result.statuses))}"
            return None, stats
        r, c, beta = (float(v) for v in result.x)
        if r < 0:
            r, beta = -r, beta + np.pi
        return SpinParameters(r, c, float(np.mod(beta + np.pi, 2 * np.pi) - np.pi)), stats
