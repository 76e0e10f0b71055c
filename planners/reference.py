"""What a planner returns: :class:`Reference`, evaluated as :class:`ReferenceSample` rows, part of
the planner contract of :mod:`planners.base`.

Conventions: scalar-first Hamilton quaternions ``q`` rotating body vectors to inertial, body rate
``ω`` relative to inertial in body axes, SI units (s, rad/s, rad/s^2, N m, kg m^2).
"""
from __future__ import annotations

import html
import textwrap
from abc import ABC, abstractmethod
from collections.abc import Iterable, Mapping
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planners.torque_free import TorqueFreeMotion

Array = NDArray[np.float64]
STATUSES = ("ok", "failed", "infeasible")
"""Values of :attr:`Reference.status`."""
_MESSAGE_CHARS = 100
"""Characters of a reference's message shown by its repr."""


class ReferenceSample(NamedTuple):
    """A reference evaluated at ``N`` times: what :meth:`Reference._evaluate` returns.

    ``_evaluate`` returns ``(N, 4)`` and ``(N, 3)`` arrays, one row per time of its 1-D input;
    :meth:`Reference.sample` returns ``(4,)`` and ``(3,)`` arrays for a scalar time.

    Attributes
    ----------
    q : (N, 4) ndarray
        Attitude quaternion, scalar first, rotating body vectors to inertial.
    omega : (N, 3) ndarray
        Body rate relative to inertial [rad/s], body axes.
    omega_dot : (N, 3) ndarray
        Time derivative of ``omega`` [rad/s^2], body axes.
    torque : (N, 3) ndarray
        Feed-forward torque [N m], body axes: the rigid-body ``u`` of ``I ω̇ = −ω × I ω + u``,
        i.e. ``I ω̇ + ω × I ω`` (:func:`inverse_dynamics_torque`). Wheel momentum, torquers,
        magnetorquers and the environment torques the planner models are all inside ``u``; the
        controllers map it to the actuators.
    """

    q: Array
    omega: Array
    omega_dot: Array
    torque: Array


BOUNDARY_CONDITIONS = ("q0", "omega0", "qf", "omegaf")
"""Names of the boundary conditions a reference may leave free (:attr:`Reference.free_boundary`)."""

JUMP_TOLERANCE = 1e-6
"""A change of a reference's body rate [rad/s] over an instant up to this is rounding, not a jump
(an impulse): the conformance check of the ends and the requirement scoring both use it."""

BREAKPOINT_INSTANT = 1e-9
"""Either side of a breakpoint ``b`` a reference is sampled at ``b ± δ``, ``δ`` this times
``max(T, 1 s)`` (:meth:`Reference.breakpoint_sides`): far enough for rounding to tell the sides
apart, near enough that what changes smoothly changes by ``δ`` times its rate only."""

_FIELD_WIDTHS = (("q", 4), ("omega", 3), ("omega_dot", 3), ("torque", 3))


class Reference(ABC):
    """A reference motion on ``[0, duration]``, evaluable at any time and vectorised over times.

    Subclasses implement :meth:`_evaluate` on times within ``[0, duration]``: it receives a 1-D
    array of ``N`` times and returns a :class:`ReferenceSample` of ``(N, 4)``, ``(N, 3)``,
    ``(N, 3)``, ``(N, 3)`` arrays (``q``, ``ω`` [rad/s], ``ω̇`` [rad/s^2], torque [N m]; body axes),
    each row depending on its own time only. The torque is the rigid-body ``u`` of
    ``I ω̇ = −ω × I ω + u`` (:func:`inverse_dynamics_torque`). :meth:`sample` checks the shapes
    and handles times outside ``[0, duration]``: after ``duration`` the reference continues as the
    torque-free motion of its final state (``I ω̇ = −ω × I ω``, ``q̇ = ½ q ⊗ [0, ω]``, torque zero;
    :class:`~planners.torque_free.TorqueFreeMotion`), so a final state at rest holds the attitude;
    before 0 it holds the initial values.

    A reference meets the problem's boundary conditions ``q(0) = q0``, ``ω(0) = ω0``,
    ``q(T) = qf``, ``ω(T) = ωf`` (those not ``None``) unless it declares them in
    ``free_boundary``. A subclass calls ``super().__init__(name, T, problem.spacecraft.inertia,
    ...)`` and implements ``_evaluate``; the extension guide :doc:`/extending/planner` has a complete one,
    and :func:`planners.conformance.check_reference` checks it.

    Parameters
    ----------
    planner : str
        Registry name of the planner that made it (``Planner.name``).
    duration : float
        Manoeuvre time T [s]; may differ from the problem's for minimum-time planners.
    inertia : (3, 3) or (3,) array_like
        Body inertia [kg m^2], body axes (``problem.spacecraft.inertia``): stored as the (3, 3)
        ``inertia`` attribute for the subclass's :func:`inverse_dynamics_torque`, the torque-free
        continuation after T and the conformance checks of the torque. Principal moments (3,)
        become a diagonal matrix.
    status : str, optional
        One of :data:`STATUSES`: ``"ok"`` (default), ``"failed"`` (numerical failure) or
        ``"infeasible"`` (the problem cannot be met under the planner's bounds).
    message : str, optional
        Human-readable outcome (solver message, reason of failure).
    stats : mapping or None, optional
        Solver statistics (iterations, objective, ...), copied into a dict; ``None``: empty. Keys
        that others read: ``certificate`` (:mod:`ocp.nlp.certificate`'s record of an optimum) and
        ``functional``, ``{"name": ..., "value": ...}``, the functional the plan minimised and its
        value by the planner's own quadrature (``"int_actuator_torque_squared"``: ``∫‖τ‖² dt`` of
        the actuators' torque on a rigid body without actuator states); a run cross-checks a
        direct and an indirect (co-state) optimum of the same functional
        (:func:`scenarios.runner.run`).
    free_boundary : iterable of str, optional
        Names from :data:`BOUNDARY_CONDITIONS` (``"q0"``, ``"omega0"``, ``"qf"``, ``"omegaf"``)
        that this reference does not meet by construction (e.g. ``{"omega0"}`` when the method
        chooses its own initial rate); the conformance test skips them and the metrics report the
        mismatch (``initial_rate_error``, ``final_error_deg``, ``final_rate_error``). Default: none.
    breakpoints : array_like, optional
        Times [s] in ``[0, T]`` where ``ω`` or ``ω̇`` may jump (switches of a bang-coast-bang
        profile, the end of an arc); finite-difference checks stay away from them. A breakpoint at
        0 or T declares a rate step at that end (a method whose rate is the control): the sample at
        0 is then the right limit ``ω(0⁺)``, the step from the manoeuvre's ``ω0`` an impulse the
        scoring counts, and the sample at T the rate after the step, from which the reference
        coasts (it still meets ``ωf`` unless declared free; the actuator requirement sees that step
        where it samples after T). Default: none.
    enforced_times : array_like or None, optional
        For a method that imposes the dynamics at discrete points only (direct collocation): those
        times [s]. Between them the reference interpolates, and ``q̇ = ½ q ⊗ [0, ω]`` and the
        inverse dynamics hold only to the transcription's accuracy; the conformance checks then
        test at these times. ``None`` (default): the reference is consistent everywhere.

    Attributes
    ----------
    plan_time_s : float
        Wall time of :meth:`Planner.plan` [s] (set by ``plan``; 0 until then).
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
        self._sides: tuple[bytes, Array, ReferenceSample] | None = None

    @property
    def ok(self) -> bool:
        """Whether the planner succeeded (``status == "ok"``): on its own terms, not against the
        scenario's requirements (actuator limits, pointing, rate, final accuracy), which
        :func:`scenarios.runner.run` scores for every row."""
        return self.status == "ok"

    def _summary(self) -> dict[str, str]:
        """What the repr and the HTML table show: planner, status, duration, planning time, message."""
        return {"planner": self.planner, "status": self.status, "duration": f"{self.duration:.4g} s",
                "planned in": f"{self.plan_time_s:.3g} s",
                "message": textwrap.shorten(self.message, _MESSAGE_CHARS, placeholder=" ...")}

    def __repr__(self) -> str:
        facts = self._summary()
        message = facts.pop("message")
        return (f"<{type(self).__name__} of {facts.pop('planner')}: " + ", ".join(f"{k} {v}" for k, v in facts.items())
                + (f"; {message}" if message else "") + ">")

    def _repr_html_(self) -> str:
        facts = self._summary()
        header = "".join(f"<th>{html.escape(name)}</th>" for name in facts)
        cells = "".join(f"<td>{html.escape(value)}</td>" for value in facts.values())
        return f"<table><caption>{html.escape(type(self).__name__)}</caption><tr>{header}</tr><tr>{cells}</tr></table>"

    @abstractmethod
    def _evaluate(self, t: Array) -> ReferenceSample:
        """The reference at times ``t``: what a subclass implements.

        Parameters
        ----------
        t : (N,) ndarray
            Times [s] within ``[0, duration]``, any order; each row of the result depends on its
            own time only.

        Returns
        -------
        ReferenceSample
            ``q`` (N, 4) scalar first, body to inertial; ``omega`` (N, 3) [rad/s] and ``omega_dot``
            (N, 3) [rad/s^2], body axes; ``torque`` (N, 3) [N m], body axes, the rigid-body ``u``
            of ``I ω̇ = −ω × I ω + u`` (:func:`inverse_dynamics_torque`).
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
        """The state at the end of the manoeuvre.

        Returns
        -------
        q : (4,) ndarray
            Attitude ``q(T)``, scalar first, body to inertial.
        omega : (3,) ndarray
            Body rate ``ω(T)`` [rad/s], body axes.
        """
        end = self._checked(np.array([self.duration]))
        return end.q[0], end.omega[0]

    def sample(self, t: ArrayLike) -> ReferenceSample:
        """All four quantities at ``t``.

        Parameters
        ----------
        t : float or array_like
            Time [s] or array of times (any order; flattened if not 1-D). After ``duration``: the
            torque-free continuation of the final state; before 0: the values at 0.

        Returns
        -------
        ReferenceSample
            ``q`` (4,), ``omega``, ``omega_dot``, ``torque`` (3,) for a scalar ``t``; ``(N, 4)`` and
            ``(N, 3)`` for ``N`` times. Units and frames as in :class:`ReferenceSample`.

        Raises
        ------
        ValueError
            If a time is not finite (NaN or infinite).
        TypeError
            If ``t`` is not numbers (``None``, text).
        TypeError, ValueError
            If :meth:`_evaluate` breaks the contract (not a ``ReferenceSample``, wrong shapes).
        RuntimeError
            If the reference is a :class:`FailedReference`.
        """
        if t is None or np.asarray(t).dtype.kind in "USO":  # None reads as NaN, text "1.0" as a number
            raise TypeError(f"reference times must be numbers [s] (a float or an array of floats), got {t!r}")
        times = np.atleast_1d(np.asarray(t, dtype=float))
        if times.ndim != 1:
            times = times.ravel()
        if not np.isfinite(times).all():
            bad = times[~np.isfinite(times)]
            raise ValueError(f"reference times must be finite [s]; got {bad[:3].tolist()}"
                             f"{' and more' if bad.size > 3 else ''} among {times.size}")
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

    def breakpoint_sides(self) -> tuple[Array, ReferenceSample]:
        """The reference an instant before and an instant after each of its :attr:`breakpoints`.

        Where ``ω`` or ``ω̇`` may jump, a sample on either side stands for the one-sided limits: the
        requirement scoring reads them for the jumps of the rate
        (:func:`scenarios.requirements.scoring.rate_jumps`), for the attitude between its samples, for
        the actuator demand (which it integrates up to each side, never across a switch) and for the
        peak rate (a bang-bang's at its switch, between two samples). They
        are sampled once per reference and kept (computed again only if the breakpoints or the
        duration change).

        Returns
        -------
        times : (2K,) ndarray
            ``b − δ`` for each of the ``K`` breakpoints ``b`` in order, then ``b + δ`` for each
            [s], ``δ`` = :data:`BREAKPOINT_INSTANT` ``× max(T, 1 s)``; outside ``[0, T]`` the
            reference's continuation (:meth:`sample`).
        sample : ReferenceSample
            The reference at ``times``: ``(2K, 4)`` and ``(2K, 3)`` arrays (empty without
            breakpoints). Kept by the reference, so read-only (copy them to change them).
        """
        key = np.append(self.breakpoints, self.duration).tobytes()
        cached = getattr(self, "_sides", None)
        if cached is not None and cached[0] == key:
            return cached[1], cached[2]
        instant = BREAKPOINT_INSTANT * max(self.duration, 1.0)
        times = np.concatenate([self.breakpoints - instant, self.breakpoints + instant])
        sample = (self.sample(times) if times.size else
                  ReferenceSample(*(np.zeros((0, width)) for _, width in _FIELD_WIDTHS)))
        for array in (times, *sample):
            array.flags.writeable = False  # kept: read, never changed
        self._sides = (key, times, sample)
        return times, sample

    def q(self, t: ArrayLike) -> Array:
        """Attitude quaternion(s) at ``t`` (see :meth:`sample`).

        Parameters
        ----------
        t : float or array_like
            Time [s] or array of ``N`` times.

        Returns
        -------
        (4,) or (N, 4) ndarray
            Attitude quaternion(s) scalar first, body to inertial.
        """
        return self.sample(t).q

    def omega(self, t: ArrayLike) -> Array:
        """Body rate(s) at ``t`` (see :meth:`sample`).

        Parameters
        ----------
        t : float or array_like
            Time [s] or array of ``N`` times.

        Returns
        -------
        (3,) or (N, 3) ndarray
            Body rate(s) [rad/s], body axes.
        """
        return self.sample(t).omega

    def omega_dot(self, t: ArrayLike) -> Array:
        """Body acceleration(s) at ``t`` (see :meth:`sample`).

        Parameters
        ----------
        t : float or array_like
            Time [s] or array of ``N`` times.

        Returns
        -------
        (3,) or (N, 3) ndarray
            Body acceleration(s) [rad/s^2], body axes.
        """
        return self.sample(t).omega_dot

    def torque(self, t: ArrayLike) -> Array:
        """Feed-forward rigid-body torque(s) at ``t`` (see :meth:`sample`).

        Parameters
        ----------
        t : float or array_like
            Time [s] or array of ``N`` times.

        Returns
        -------
        (3,) or (N, 3) ndarray
            Feed-forward rigid-body torque(s) [N m], body axes: the ``u`` of
            ``I ω̇ = −ω × I ω + u``; zero after T.
        """
        return self.sample(t).torque

    def symbolic_evaluator(self) -> Any:
        """The reference as a CasADi function of time, for code generation.

        Closed-form references (their planner sets ``Planner.closed_form``) implement it;
        ``slewbench codegen`` exports it as C.

        Returns
        -------
        casadi.Function or None
            ``reference(t) -> row``, ``t`` [s] clamped to ``[0, duration]``, ``row`` the 13 numbers
            ``[q (4), ω (3) rad/s, ω̇ (3) rad/s^2, τ (3) N m]`` (body axes; the layout of
            ``ocp.dynamics.layout.REFERENCE_FIELDS``); ``None`` (default) when the reference has no closed form.
        """
        return None


class FailedReference(Reference):
    """What a planner returns when it cannot produce a motion; evaluating it is an error.

    Parameters
    ----------
    planner : str
        Registry name of the planner.
    message : str
        Why it failed (shown in the results table and by the loader).
    status : str, optional
        ``"failed"`` (default: a numerical failure) or ``"infeasible"`` (the problem cannot be met
        under the planner's bounds); ``"ok"`` is refused with a ``ValueError``.
    duration : float, optional
        Manoeuvre time [s] to report, 0 by default.
    stats : mapping or None, optional
        Solver statistics gathered before the failure.
    """

    def __init__(self, planner: str, message: str, status: str = "failed", duration: float = 0.0,
                 stats: Mapping[str, Any] | None = None) -> None:
        if status == "ok":
            raise ValueError("a FailedReference cannot have status 'ok'")
        super().__init__(planner, duration, np.eye(3), status, message, stats)

    def _evaluate(self, t: Array) -> ReferenceSample:
        raise RuntimeError(f"the {self.planner} reference {self.status}: {self.message}")


def inverse_dynamics_torque(inertia: Array, omega: Array, omega_dot: Array) -> Array:
    """The rigid-body feed-forward torque ``u = I ω̇ + ω × I ω`` of a reference.

    Parameters
    ----------
    inertia : (3, 3) ndarray
        Body inertia [kg m^2], body axes.
    omega : (N, 3) or (3,) ndarray
        Body rates [rad/s], body axes, one row per time.
    omega_dot : (N, 3) or (3,) ndarray
        Body accelerations [rad/s^2], body axes, one row per time.

    Returns
    -------
    (N, 3) or (3,) ndarray
        Torque [N m], body axes: the ``u`` of ``I ω̇ = −ω × I ω + u``.
    """
    return omega_dot @ inertia.T + np.cross(omega, omega @ inertia.T)
