"""Planner contract: :class:`ManeuverProblem` in, :class:`Reference` out.

A planner turns a manoeuvre problem into a reference motion. The base class :class:`Planner`
states the contract; one module per method implements it; ``planners.PLANNERS`` maps registry
names to classes.
"""
from __future__ import annotations

import time
from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, ClassVar, Iterable, Mapping, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp import AttitudeModel, Environment, SolverCache, Spacecraft, quat
from ocp.options import Configurable

Array = NDArray[np.float64]
STATUSES = ("ok", "failed", "infeasible")


@dataclass(frozen=True)
class ManeuverProblem:
    """A slew to plan.

    Parameters
    ----------
    spacecraft, environment : the model.
    q0, omega0 : initial attitude (scalar first, body to inertial) and body rate (rad/s).
    qf, omegaf : target attitude and rate; ``None`` leaves the final attitude or rate free (a
        free attitude only suits planners that say so in :meth:`Planner.problem_error`).
    duration : s, manoeuvre time T (an initial guess or bound for minimum-time planners).
    wheel_momentum0 : (n_w,) N m s, initial wheel momenta (default zero).
    max_rate : rad/s, optional bound on the body rate norm for planners that honour it.
    """

    spacecraft: Spacecraft
    q0: Array
    omega0: Array
    qf: Array | None
    duration: float
    omegaf: Array | None = None
    environment: Environment = field(default_factory=Environment)
    wheel_momentum0: Array | None = None
    max_rate: float | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.spacecraft, Spacecraft):
            raise TypeError(f"spacecraft must be an ocp.Spacecraft, got {type(self.spacecraft).__name__}")
        if not isinstance(self.environment, Environment):
            raise TypeError(f"environment must be an ocp.Environment, got {type(self.environment).__name__}")
        object.__setattr__(self, "q0", _quaternion("q0", self.q0))
        if self.qf is not None:
            object.__setattr__(self, "qf", _quaternion("qf", self.qf))
        object.__setattr__(self, "omega0", _vector("omega0", self.omega0, 3))
        if self.omegaf is not None:
            object.__setattr__(self, "omegaf", _vector("omegaf", self.omegaf, 3))
        momentum = np.zeros(self.spacecraft.n_wheels) if self.wheel_momentum0 is None else self.wheel_momentum0
        object.__setattr__(self, "wheel_momentum0", _vector("wheel_momentum0", momentum, self.spacecraft.n_wheels))
        if not isinstance(self.duration, (int, float, np.floating)) or not np.isfinite(self.duration) or not self.duration > 0:
            raise ValueError(f"duration must be a finite positive number of seconds, got {self.duration!r}")
        if self.max_rate is not None and (not isinstance(self.max_rate, (int, float, np.floating))
                                          or not np.isfinite(self.max_rate) or not self.max_rate > 0):
            raise ValueError(f"max_rate must be a finite positive rate (rad/s) or None, got {self.max_rate!r}")

    @property
    def torque_limit(self) -> Array:
        """Per-body-axis torque bound (N m) of the actuators; see ``Spacecraft.body_torque_limit``."""
        return self.spacecraft.body_torque_limit()

    @cached_property
    def model(self) -> AttitudeModel:
        """The symbolic model of this spacecraft in this environment."""
        return AttitudeModel(self.spacecraft, self.environment)

    @property
    def initial_state(self) -> Array:
        """``[q0, ω0, h_w0]``."""
        return np.concatenate([self.q0, self.omega0, self.wheel_momentum0])


def _vector(name: str, value: ArrayLike, size: int) -> Array:
    """``value`` as a finite float vector of ``size`` entries, or a ``ValueError`` naming ``name``."""
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be {size} numbers, got {value!r}") from None
    if array.shape != (size,) or not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be {size} finite numbers, got shape {array.shape}: {array.tolist()}")
    return array


def _quaternion(name: str, value: ArrayLike) -> Array:
    """A unit quaternion from ``value`` (normalised), or a ``ValueError`` for a zero one."""
    q = _vector(name, value, 4)
    if not np.linalg.norm(q) > 1e-6:
        raise ValueError(f"{name} must be a non-zero quaternion [q0, q1, q2, q3] (scalar first), got {q.tolist()}")
    return q / np.linalg.norm(q)


class ReferenceSample(NamedTuple):
    """A reference evaluated at ``N`` times.

    Attributes
    ----------
    q : (N, 4) attitude quaternion, scalar first, body to inertial.
    omega : (N, 3) body rate w.r.t. inertial, body axes, rad/s.
    omega_dot : (N, 3) its time derivative, body axes, rad/s².
    torque : (N, 3) feed-forward body torque, N m: the rigid-body ``u`` of
        ``I ω̇ = −ω × I ω + u``, i.e. ``I ω̇ + ω × I ω`` (see :func:`inverse_dynamics_torque`);
        wheels, magnetorquers and environment torques the planner models are all inside ``u``.
    """

    q: Array
    omega: Array
    omega_dot: Array
    torque: Array


BOUNDARY_CONDITIONS = ("q0", "omega0", "qf", "omegaf")
"""Names of the boundary conditions a reference may leave free (:attr:`Reference.free_boundary`)."""

_FIELD_WIDTHS = (("q", 4), ("omega", 3), ("omega_dot", 3), ("torque", 3))


class Reference(ABC):
    """A reference motion on ``[0, duration]``, evaluable at any time and vectorised over times.

    Subclasses implement :meth:`_evaluate` on times within ``[0, duration]``; it returns a
    :class:`ReferenceSample` of ``(N, 4)``, ``(N, 3)``, ``(N, 3)``, ``(N, 3)`` arrays for ``N``
    times. After ``duration`` the reference continues as the torque-free motion of its final
    state (``I ω̇ = −ω × I ω``, ``q̇ = ½ q ⊗ [0, ω]``, torque zero), integrated numerically; a final
    state at rest holds the attitude. Before 0 it holds the initial values.

    Parameters
    ----------
    planner : registry name of the planner that made it.
    duration : s, manoeuvre time T.
    inertia : (3, 3) or (3,) kg m², the body inertia used for the feed-forward torque and the
        torque-free continuation after T (principal moments are turned into a diagonal matrix).
    status : ``"ok"``, ``"failed"`` or ``"infeasible"``.
    message : human-readable outcome (solver message, reason of failure).
    stats : solver statistics (iterations, objective, ...).
    free_boundary : names from :data:`BOUNDARY_CONDITIONS` that this reference does not meet by
        construction (e.g. ``{"omega0"}`` when the method chooses its own initial rate); the
        conformance test skips them and the metrics report the mismatch.
    breakpoints : s, times inside ``(0, T)`` where ``ω`` or ``ω̇`` may jump (switches of a
        bang-coast-bang profile, mesh nodes); finite-difference checks stay away from them.
    enforced_times : s, for a method that imposes the dynamics at discrete points only (direct
        collocation): those times. Between them the reference interpolates, and ``q̇ = ½ q ⊗ [0, ω]``
        and the inverse dynamics hold only to the transcription's accuracy; the conformance checks
        then test at these times. ``None`` (default): the reference is consistent everywhere.

    Attributes
    ----------
    plan_time_s : wall time of ``Planner.plan`` (s).
    """

    def __init__(self, planner: str, duration: float, inertia: ArrayLike, status: str = "ok",
                 message: str = "", stats: Mapping[str, Any] | None = None,
                 free_boundary: Iterable[str] = (), breakpoints: ArrayLike = (),
                 enforced_times: ArrayLike | None = None) -> None:
        if status not in STATUSES:
            raise ValueError(f"status must be one of {STATUSES}, got {status!r}")
        inertia = np.asarray(inertia, dtype=float)
        if inertia.shape == (3,):
            inertia = np.diag(inertia)
        if inertia.shape != (3, 3):
            raise ValueError(f"inertia must be the (3, 3) body inertia in kg m^2 (e.g. problem.spacecraft.inertia), "
                             f"got shape {inertia.shape}")
        free = frozenset(free_boundary)
        unknown = free - set(BOUNDARY_CONDITIONS)
        if unknown:
            raise ValueError(f"free_boundary entries must be among {BOUNDARY_CONDITIONS}, got {sorted(unknown)}")
        self.planner = planner
        self.duration = float(duration)
        self.inertia = inertia
        self.status = status
        self.message = message
        self.plan_time_s = 0.0
        self.stats: dict[str, Any] = dict(stats or {})
        self.free_boundary: frozenset[str] = free
        self.breakpoints: Array = np.sort(np.asarray(breakpoints, dtype=float).ravel())
        self.enforced_times: Array | None = (None if enforced_times is None
                                             else np.sort(np.asarray(enforced_times, dtype=float).ravel()))
        self._coast: TorqueFreeMotion | None = None

    @property
    def ok(self) -> bool:
        """Whether the planner succeeded (``status == "ok"``)."""
        return self.status == "ok"

    @abstractmethod
    def _evaluate(self, t: Array) -> ReferenceSample:
        """The reference at times ``t``.

        Parameters
        ----------
        t : (N,) s, times within ``[0, duration]``.

        Returns
        -------
        ReferenceSample
            ``q`` (N, 4), ``omega`` (N, 3) rad/s, ``omega_dot`` (N, 3) rad/s², ``torque`` (N, 3) N m.
        """

    def _checked(self, times: Array) -> ReferenceSample:
        """:meth:`_evaluate` with its output checked against the contract (shapes, type)."""
        sample = self._evaluate(times)
        name = type(self).__name__
        if not isinstance(sample, tuple) or len(sample) != 4:
            raise TypeError(f"{name}._evaluate must return planners.ReferenceSample(q, omega, omega_dot, torque), "
                            f"got {type(sample).__name__}")
        arrays = [np.asarray(a, dtype=float) for a in sample]
        n = times.size
        for array, (field_name, width) in zip(arrays, _FIELD_WIDTHS):
            if array.shape != (n, width):
                raise ValueError(
                    f"{name}._evaluate(t) with {n} times returned {field_name} of shape {array.shape}; expected "
                    f"({n}, {width}): one row per time of the 1-D array t (evaluate vectorised, e.g. "
                    f"np.stack([...], axis=-1) or np.broadcast_to(vector, (t.size, {width})))")
        return ReferenceSample(*arrays)

    def final_state(self) -> tuple[Array, Array]:
        """``(q(T), ω(T))``: attitude (4,) and body rate (3,) rad/s at the end of the manoeuvre."""
        end = self._checked(np.array([self.duration]))
        return end.q[0], end.omega[0]

    def sample(self, t: ArrayLike) -> ReferenceSample:
        """All four quantities at ``t``.

        Parameters
        ----------
        t : s, a scalar or an array of times (any order; after ``duration`` the torque-free
            continuation, before 0 the initial values).

        Returns
        -------
        ReferenceSample
            Shapes ``(4,)``/``(3,)`` for a scalar ``t``, ``(N, 4)``/``(N, 3)`` for ``N`` times.
        """
        times = np.atleast_1d(np.asarray(t, dtype=float))
        if times.ndim != 1:
            times = times.ravel()
        inside = self._checked(np.clip(times, 0.0, self.duration))
        after = times > self.duration
        if np.any(after):
            if self._coast is None:
                self._coast = TorqueFreeMotion(*self.final_state(), self.inertia, self.duration)
            q, omega, omega_dot, torque = (np.array(a) for a in inside)
            q[after], omega[after], omega_dot[after] = self._coast(times[after])
            torque[after] = 0.0
            inside = ReferenceSample(q, omega, omega_dot, torque)
        if np.ndim(t) == 0:
            return ReferenceSample(*(a[0] for a in inside))
        return inside

    def q(self, t: ArrayLike) -> Array:
        """Attitude quaternion(s) at ``t`` (s): (4,) or (N, 4), scalar first, body to inertial."""
        return self.sample(t).q

    def omega(self, t: ArrayLike) -> Array:
        """Body rate(s) at ``t`` (s): (3,) or (N, 3) rad/s, body axes."""
        return self.sample(t).omega

    def omega_dot(self, t: ArrayLike) -> Array:
        """Body acceleration(s) at ``t`` (s): (3,) or (N, 3) rad/s², body axes."""
        return self.sample(t).omega_dot

    def torque(self, t: ArrayLike) -> Array:
        """Feed-forward rigid-body torque(s) at ``t`` (s): (3,) or (N, 3) N m, body axes."""
        return self.sample(t).torque

    def symbolic_evaluator(self) -> Any:
        """The reference as a ``casadi.Function`` ``reference(t) -> row`` with ``row`` =
        ``[q, ω, ω̇, τ]`` (13 numbers, the layout of ``ocp.layout.REFERENCE_FIELDS``) for
        ``t`` in ``[0, duration]`` (clamped outside), or ``None`` when the reference has no closed
        form. Closed-form references (their planner sets ``Planner.closed_form``) implement it;
        ``slewbench codegen`` exports it as C."""
        return None


REST_RATE = 1e-15
"""rad/s: a final rate at or below this is rounding residue; the torque-free coast is then rest."""


class TorqueFreeMotion:
    """Torque-free motion of a rigid body from ``(q_T, ω_T)`` at time ``start``, integrated with
    DOP853 (rtol 1e-12) in chunks of fixed length, so that a value does not depend on which
    times were asked for before.

    Parameters
    ----------
    q_start : (4,) attitude at ``start``, scalar first, body to inertial.
    omega_start : (3,) rad/s, body rate at ``start``, body axes.
    inertia : (3, 3) kg m², body inertia.
    start : s, the time of the initial state.
    """

    def __init__(self, q_start: Array, omega_start: Array, inertia: Array, start: float) -> None:
        self.q_start = quat.normalize(np.asarray(q_start, dtype=float))
        self.omega_start = np.asarray(omega_start, dtype=float)
        self.inertia = np.asarray(inertia, dtype=float)
        self.inverse = np.linalg.inv(self.inertia)
        self.start = float(start)
        rate = float(np.linalg.norm(self.omega_start))
        # A rest-to-rest profile ends at rest up to rounding (~1e-17 rad/s: a degree in 10⁸
        # years); below REST_RATE the coast is rest, and scipy.integrate (0.5 s) is not imported.
        self.at_rest = rate <= REST_RATE
        # About a quarter turn per chunk at the initial rate (the rate norm is bounded by energy).
        self.chunk = 1.0 if self.at_rest else float(np.clip(1.5 / rate, 1.0, 1e4))
        self._chunks: list[Any] = []
        self._ends = [np.concatenate([self.q_start, self.omega_start])]

    def _rhs(self, _t: float, y: Array) -> Array:
        q, w = y[:4], y[4:]
        return np.concatenate([quat.kinematics(q, w), -self.inverse @ np.cross(w, self.inertia @ w)])

    def _solution(self, index: int) -> Any:
        while len(self._chunks) <= index:
            k = len(self._chunks)
            from scipy.integrate import solve_ivp  # lazily: 0.5 s to import, needed only after T

            solution = solve_ivp(self._rhs, (0.0, self.chunk), self._ends[k], method="DOP853", rtol=1e-12,
                                 atol=1e-14, dense_output=True)
            self._chunks.append(solution.sol)
            end = solution.y[:, -1].copy()
            end[:4] /= np.linalg.norm(end[:4])
            self._ends.append(end)
        return self._chunks[index]

    def __call__(self, t: Array) -> tuple[Array, Array, Array]:
        """Attitude (N, 4), rate (N, 3) rad/s and acceleration (N, 3) rad/s² at times ``t`` >= start."""
        t = np.asarray(t, dtype=float)
        if self.at_rest:
            return np.tile(self.q_start, (t.size, 1)), np.zeros((t.size, 3)), np.zeros((t.size, 3))
        elapsed = np.maximum(t - self.start, 0.0)
        index = np.minimum((elapsed / self.chunk).astype(int), 10**6)
        y = np.empty((t.size, 7))
        for k in np.unique(index):
            mask = index == k
            y[mask] = self._solution(int(k))(elapsed[mask] - k * self.chunk).T
        q = quat.normalize(y[:, :4])
        omega = y[:, 4:]
        omega_dot = -np.cross(omega, omega @ self.inertia.T) @ self.inverse.T
        return q, omega, omega_dot


class FailedReference(Reference):
    """What a planner returns when it cannot produce a motion; evaluating it is an error."""

    def __init__(self, planner: str, message: str, status: str = "failed", duration: float = 0.0,
                 stats: Mapping[str, Any] | None = None):
        if status == "ok":
            raise ValueError("a FailedReference cannot have status 'ok'")
        super().__init__(planner, duration, np.eye(3), status, message, stats)

    def _evaluate(self, t: Array) -> ReferenceSample:
        raise RuntimeError(f"the {self.planner} reference {self.status}: {self.message}")


def inverse_dynamics_torque(inertia: Array, omega: Array, omega_dot: Array) -> Array:
    """The rigid-body feed-forward torque ``u = I ω̇ + ω × I ω`` of a reference.

    Parameters
    ----------
    inertia : (3, 3) kg m², body inertia.
    omega : (N, 3) rad/s, body rates (body axes), one row per time.
    omega_dot : (N, 3) rad/s², body accelerations, one row per time.

    Returns
    -------
    (N, 3) N m, body torque for ``I ω̇ = −ω × I ω + u``.
    """
    return omega_dot @ inertia.T + np.cross(omega, omega @ inertia.T)


class Planner(Configurable, ABC):
    """Base class of every planner.

    Contract
    --------
    * ``name`` is the registry key; ``Options`` is a dataclass of the planner's options with
      defaults (the YAML ``options:`` mapping is checked against it).
    * ``plan(problem)`` returns a :class:`Reference` and sets its ``plan_time_s``. A numerical
      failure (no convergence, infeasible bounds) is returned as a reference with
      ``status="failed"`` or ``"infeasible"`` and a message; ``plan`` does not raise for it.
    * ``problem_error(problem)`` says, cheaply, why the planner cannot take a problem (``None``
      if it can); the scenario loader reports it against the planner's YAML entry and ``plan``
      returns it as a failed reference. By default a planner needs a target attitude.
    * Planners never read YAML and never simulate.
    * ``cache`` (constructor) is an explicit :class:`~ocp.cache.SolverCache` for what the planner
      builds (NLPs); without one, the planner keeps its builds in the model's own cache
      (``problem.model.solver_cache``).
    * The reference meets the problem's boundary conditions ``q(0) = q0``, ``ω(0) = ω0``,
      ``q(T) = qf`` and ``ω(T) = ωf`` (when not ``None``), except those it declares in
      ``Reference.free_boundary``; it satisfies ``q̇ = ½ q ⊗ [0, ω]``, its ``omega_dot`` is the
      derivative of its ``omega`` and its torque the inverse dynamics ``I ω̇ + ω × I ω``.
    * ``example_options`` lists option sets for the conformance test.
    * ``closed_form``: its references are closed-form expressions of time and implement
      :meth:`Reference.symbolic_evaluator` (``slewbench codegen`` exports them as C).
    """

    example_options: ClassVar[tuple[Mapping[str, Any], ...]] = ({},)
    """Option sets that exercise the planner's distinct kinds of reference (profiles, objectives);
    the conformance test (tests/test_planner_conformance.py) plans the standard problems with each."""

    closed_form: bool = False

    def __init__(self, options: Mapping[str, Any] | Any | None = None, path: str = "options",
                 cache: SolverCache | None = None) -> None:
        super().__init__(options, path)
        self.cache = cache

    def solver_cache(self, problem: ManeuverProblem) -> SolverCache:
        """The cache to build into: the one given to the constructor, else the model's."""
        return self.cache if self.cache is not None else problem.model.solver_cache

    def problem_error(self, problem: ManeuverProblem) -> str | None:
        """Why this planner cannot plan ``problem``, or ``None``."""
        if problem.qf is None:
            return f"planner {self.name} needs a target attitude (maneuver.final.q)"
        return None

    def plan(self, problem: ManeuverProblem) -> Reference:
        """Plan the manoeuvre; the wall time goes into ``reference.plan_time_s``."""
        start = time.perf_counter()
        error = self.problem_error(problem)
        reference = FailedReference(self.name, error) if error else self._plan(problem)
        reference.plan_time_s = time.perf_counter() - start
        return reference

    @abstractmethod
    def _plan(self, problem: ManeuverProblem) -> Reference:
        """The method itself."""
