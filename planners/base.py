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
from typing import Any, Mapping, NamedTuple

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
    """A reference evaluated at times ``t``: attitude (N, 4), body rate (N, 3) rad/s, body
    acceleration (N, 3) rad/s², feed-forward body torque (N, 3) N m for ``I ω̇ = −ω × I ω + u``."""

    q: Array
    omega: Array
    omega_dot: Array
    torque: Array


class Reference(ABC):
    """A reference motion on ``[0, duration]``, evaluable at any time and vectorised over times.

    Subclasses implement :meth:`_evaluate` on times within ``[0, duration]``. After ``duration``
    the reference holds the final attitude with the final rate; the torque there keeps that rate,
    ``ω_T × I ω_T``, and ``ω̇ = 0``. Before 0 it holds the initial values.

    Attributes
    ----------
    planner : registry name of the planner that made it.
    status : ``"ok"``, ``"failed"`` or ``"infeasible"``.
    message : human-readable outcome (solver message, reason of failure).
    plan_time_s : wall time of ``Planner.plan`` (s).
    stats : solver statistics (iterations, objective, ...).
    """

    def __init__(self, planner: str, duration: float, inertia: ArrayLike, status: str = "ok",
                 message: str = "", stats: Mapping[str, Any] | None = None):
        if status not in STATUSES:
            raise ValueError(f"status must be one of {STATUSES}, got {status!r}")
        self.planner = planner
        self.duration = float(duration)
        self.inertia = np.asarray(inertia, dtype=float)
        self.status = status
        self.message = message
        self.plan_time_s = 0.0
        self.stats: dict[str, Any] = dict(stats or {})

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    @abstractmethod
    def _evaluate(self, t: Array) -> ReferenceSample:
        """The reference at times ``t`` (1-D, all within ``[0, duration]``)."""

    def sample(self, t: ArrayLike) -> ReferenceSample:
        """All four quantities at ``t`` (scalar or array); shapes ``(4,)``/``(3,)`` for a scalar."""
        times = np.atleast_1d(np.asarray(t, dtype=float))
        inside = self._evaluate(np.clip(times, 0.0, self.duration))
        after = times > self.duration
        if np.any(after):
            q, omega, omega_dot, torque = (np.array(a) for a in inside)
            end = self._evaluate(np.array([self.duration]))
            w_end = end.omega[0]
            q[after], omega[after], omega_dot[after] = end.q[0], w_end, 0.0
            torque[after] = np.cross(w_end, self.inertia @ w_end)
            inside = ReferenceSample(q, omega, omega_dot, torque)
        if np.ndim(t) == 0:
            return ReferenceSample(*(a[0] for a in inside))
        return inside

    def q(self, t: ArrayLike) -> Array:
        return self.sample(t).q

    def omega(self, t: ArrayLike) -> Array:
        return self.sample(t).omega

    def omega_dot(self, t: ArrayLike) -> Array:
        return self.sample(t).omega_dot

    def torque(self, t: ArrayLike) -> Array:
        return self.sample(t).torque

    def symbolic_evaluator(self) -> Any:
        """The reference as a ``casadi.Function`` ``reference(t) -> row`` with ``row`` =
        ``[q, ω, ω̇, τ]`` (13 numbers, the layout of ``ocp.layout.REFERENCE_FIELDS``) for
        ``t`` in ``[0, duration]`` (clamped outside), or ``None`` when the reference has no closed
        form. Closed-form references (their planner sets ``Planner.closed_form``) implement it;
        ``slewbench codegen`` exports it as C."""
        return None


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
    """Body torque ``I ω̇ + ω × I ω`` (N m) for rows of ``ω``, ``ω̇``."""
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
    * ``closed_form``: its references are closed-form expressions of time and implement
      :meth:`Reference.symbolic_evaluator` (``slewbench codegen`` exports them as C).
    """

    closed_form: bool = False

    def __init__(self, options: Mapping[str, Any] | Any | None = None, path: str = "options",
                 cache: SolverCache | None = None):
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
