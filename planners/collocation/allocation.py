"""The controllers' allocation imposed on ``collocation``'s controls, so that the plan is what the
closed loop realises.

Every controller maps a body torque onto the actuators the same way (``controllers.allocation``):
the working wheels take ``g = −A⁺ τ`` (``A⁺`` the pseudo-inverse of the working wheels' axes), and
what they cannot give, ``(1 − A A⁺) τ``, goes to
:attr:`~ocp.dynamics.spacecraft.Spacecraft.residual_actuator` (the kind of lowest
:attr:`~ocp.dynamics.actuator_kinds.Actuator.residual_rank`: the torquers, else the magnetorquers);
the scenario's actuator requirement scores a reference's torque through that map. The NLP's
controls are the actuators' own commands, so without more it may plan wheel torques that the
allocation never gives: on a skewed array (a four-wheel pyramid) a wheel torque pattern with a
component in the null space of ``A`` reaches torques whose min-norm allocation exceeds the limits
(the fresh-eyes user's pyramid slew: planned within 0.0100000094 N m, scored 1.31 times the limit
at t = 0, the closed loop saturating 24 % of the time).

:func:`allocation_constraints` gives the linear equalities ``E u = 0`` that make the controls the
allocation of their own body torque:

* the working wheels' torques lie in the row space of their axes (``g = A⁺ A g``: no component
  in the null space of ``A``; failed wheels are held at 0 by their bounds). With these the wheel
  torques are the min-norm allocation of their body torque, so their bounds bound ``A⁺ τ``, and
  the wheel momenta, ``ḣ = g``, follow from those torques as in the closed loop;
* the actuator that takes the residual gives no torque in the wheels' span (the wheels would take
  it): none at all when the working wheels span three axes; a kind whose torque depends on the
  state (magnetorquers, ``m × B``) is held at zero when the wheels span three axes. Beside wheels
  that span one or two axes such a kind is refused (:func:`allocation_error`): the allocation
  sends it ``r = (1 − A A⁺) τ`` and it gives ``r − (r·B̂) B̂`` only, so the closed loop realises
  ``τ − (r·B̂) B̂``; a plan is that only where its ``m × B`` has no part in the wheels' span (then
  ``r = m × B``, across the field), a condition on the attitude through the field that linear rows
  on the controls cannot state;
* another kind with a ``residual_rank`` (magnetorquers beside torquers) is never commanded by the
  allocation: held at zero.

With wheels along the three body axes alone (or any array whose working axes are three
independent ones, with nothing beside them) ``E`` is empty and the NLP is the one without it.

:func:`with_allocation` adds ``E u = 0`` at every control a transcription uses: at the controls
one interval's variables hold (:meth:`~ocp.transcription.base.Transcription.control_points`; for
Radau collocation, whose module does not yet provide them, :data:`CONTROL_POINTS`: its collocation
points) as equality path constraints, and at the controls the first stage state alone holds
(:meth:`~ocp.transcription.base.Transcription.initial_controls`: multiple shooting's ``u_0``) as
equalities after the initial condition
(:meth:`~ocp.transcription.base.Transcription.initial_equalities`). Multiple shooting's controls
are linear between ``u_k`` and ``u_{k+1}``, so ``E u = 0`` at the nodes holds on the whole of each
interval (at every RK4 stage). A transcription that says neither is refused where ``E`` is not
empty (:func:`allocation_error`).
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

import casadi as ca
import numpy as np

from ocp import Spacecraft
from ocp.dynamics.layout import actuator_blocks
from ocp.transcription import (
    TRANSCRIPTIONS,
    OptimalControlProblem,
    RadauCollocation,
    Transcription,
)
from ocp.transcription.problem import Interval
from planners.problem import Array

__all__ = ["CONTROL_POINTS", "allocation_constraints", "allocation_error", "with_allocation"]

RANK_TOLERANCE = 1e-9
"""Singular values of the residual actuator's torque within the wheels' span below this fraction of
the largest count as zero (the wheels' own span: ``Spacecraft.wheel_span``, the same fraction)."""


def _constant_jacobian(actuator: Any) -> Array | None:
    """``∂τ/∂u`` of a kind's body torque when it depends on its control alone, linearly; ``None``
    otherwise (the field, the state)."""
    u = ca.SX.sym("u", actuator.control_size)
    state = ca.SX.sym("state", actuator.state_size)
    field = ca.SX.sym("field", 3)
    torque = actuator.body_torque(u, state, field)
    if torque is None:
        return None
    jacobian = ca.jacobian(torque, u)
    if ca.depends_on(jacobian, ca.vertcat(u, state, field)):
        return None
    return np.asarray(ca.evalf(jacobian), dtype=float)


def allocation_constraints(spacecraft: Spacecraft) -> Array | None:
    """The rows ``E`` of ``E u = 0`` that make the controls the allocation of their body torque.

    Parameters
    ----------
    spacecraft : Spacecraft
        Its actuators and their layout in ``u`` (:func:`ocp.dynamics.layout.actuator_blocks`).

    Returns
    -------
    (k, nu) ndarray or None
        Orthonormal rows per block (module docstring); ``None`` when nothing is to be imposed
        (``k = 0``).
    """
    blocks = actuator_blocks(spacecraft)
    nu = sum(block.actuator.control_size for block in blocks)
    rows: list[Array] = []
    span = spacecraft.wheel_span()  # orthonormal basis of what the working wheels give
    wheels = spacecraft.wheels
    if wheels is not None and np.any(wheels.working):
        block = next(block for block in blocks if block.actuator is wheels)
        index = np.flatnonzero(wheels.working)
        _, _, right = np.linalg.svd(wheels.axes[:, index])
        for null in right[span.shape[1]:]:  # the null space of the working axes
            row = np.zeros(nu)
            row[np.arange(nu)[block.control][index]] = null
            rows.append(row)
    sink = spacecraft.residual_actuator
    for block in blocks:
        actuator = block.actuator
        if actuator is wheels or actuator.residual_rank is None:
            continue
        identity = np.eye(nu)[block.control]
        if actuator is not sink:
            rows.extend(identity)  # never commanded
            continue
        if span.shape[1] == 0:
            continue  # no wheels: the sink takes every torque
        if span.shape[1] == 3:
            rows.extend(identity)  # the wheels take every torque
            continue
        jacobian = _constant_jacobian(actuator)
        if jacobian is None:
            continue  # its share depends on the field: refused by allocation_error (module docstring)
        within = span.T @ jacobian  # its torque in the wheels' span
        _, singular, right = np.linalg.svd(within)
        rank = int(np.sum(singular > RANK_TOLERANCE * max(float(singular.max(initial=0.0)), 1e-300)))
        for direction in right[:rank]:
            row = np.zeros(nu)
            row[block.control] = direction
            rows.append(row)
    return np.vstack(rows) if rows else None


def _radau_controls(transcription: RadauCollocation, problem: OptimalControlProblem, s: Any,
                    c: Any) -> list[tuple[Any, float]]:
    """Radau collocation's controls, one per collocation point, and their positions in the interval."""
    model, d = problem.model, transcription.degree
    start = model.nx * d
    controls = ca.reshape(c[start:start + model.nu * d], model.nu, d)
    return [(controls[:, j], float(transcription.tau[j + 1])) for j in range(d)]


CONTROL_POINTS: dict[str, Callable[..., list[tuple[Any, float]]]] = {"collocation": _radau_controls}
"""Per transcription (its ``name``) whose class does not provide
:meth:`~ocp.transcription.base.Transcription.control_points`: ``points(transcription, problem, s, c)``,
the same list."""


def _control_points(transcription: Transcription, problem: OptimalControlProblem, s: Any,
                    c: Any) -> list[tuple[Any, float]] | None:
    """The controls one interval's variables hold (the transcription's own, else :data:`CONTROL_POINTS`)."""
    points = transcription.control_points(problem, s, c)
    if points is None and transcription.name in CONTROL_POINTS:
        points = CONTROL_POINTS[transcription.name](transcription, problem, s, c)
    return points


def _describes_controls(transcription: str) -> bool:
    """Whether the registered transcription says where its controls are (module docstring)."""
    cls = TRANSCRIPTIONS.get(transcription)
    return transcription in CONTROL_POINTS or (
        cls is not None and cls.control_points is not Transcription.control_points)


def allocation_error(spacecraft: Spacecraft, transcription: str) -> str | None:
    """Why a transcription cannot impose the allocation on this spacecraft's controls.

    Parameters
    ----------
    spacecraft : Spacecraft
        The actuators.
    transcription : str
        The transcription's name (``options.transcription``).

    Returns
    -------
    str or None
        The reason, or ``None`` (nothing to impose, or the transcription can: ``collocation`` and
        ``multiple_shooting`` both can). Whatever the transcription: a residual actuator whose
        torque depends on the field beside working wheels that span one or two axes (module
        docstring).
    """
    sink = spacecraft.residual_actuator
    given = spacecraft.wheel_span().shape[1]
    if sink is not None and 0 < given < 3 and _constant_jacobian(sink) is None:
        return (f"the controllers' allocation sends what the {given} working wheel axes cannot give to the "
                f"{sink.name}, whose torque depends on the field ({type(sink).__name__}: m × B, across the field); "
                f"the allocation realises only the part of that residual across the field, so a plan that uses the "
                f"{sink.name} is not what the closed loop realises, and collocation cannot impose it on its controls "
                f"(it is a condition on the attitude through the field); give the spacecraft torquers, three "
                f"independent working wheels, or the {sink.name} without wheels")
    if _describes_controls(transcription) or allocation_constraints(spacecraft) is None:
        return None
    return (f"{transcription} cannot impose the controllers' allocation (g = −A⁺ τ, wheels first) on these "
            f"actuators' controls, which the plan must follow to be what the closed loop realises (a skewed or "
            f"redundant wheel array, or other actuators beside wheels); use transcription: collocation or "
            f"multiple_shooting")


def with_allocation(transcription: Transcription, rows: Array) -> Transcription:
    """The transcription with ``rows @ u = 0`` imposed at each of its control points.

    Parameters
    ----------
    transcription : Transcription
        A transcription that says where its controls are
        (:meth:`~ocp.transcription.base.Transcription.control_points`, or an entry in
        :data:`CONTROL_POINTS`).
    rows : (k, nu) ndarray
        :func:`allocation_constraints`.

    Returns
    -------
    Transcription
        An instance of a subclass of its class, the same configuration, whose interval has the
        equalities after its own path constraints (their positions after its own), and whose first
        stage state has them on its :meth:`~ocp.transcription.base.Transcription.initial_controls`
        after the initial condition.
    """
    base = type(transcription)
    matrix = ca.DM(rows)

    class Allocated(base):  # type: ignore[valid-type,misc]
        allocation_rows = rows

        def interval(self, problem: OptimalControlProblem) -> Interval:
            inner = super().interval(problem)
            s, c = ca.SX.sym("s", inner.n_state), ca.SX.sym("c", inner.n_interval)
            t0, h, dist = ca.SX.sym("t0"), ca.SX.sym("h"), ca.SX.sym("d", 3)
            following, path, cost = inner.function(s, c, t0, h, dist)
            controls = _control_points(self, problem, s, c)
            if controls is None:
                raise ValueError(f"{self.name} does not say where its controls are: the allocation cannot be imposed")
            extra = [ca.mtimes(matrix, u) for u, _ in controls]
            function = ca.Function(inner.function.name(), [s, c, t0, h, dist],
                                   [following, ca.vertcat(path, *extra), cost])
            zeros = np.zeros(rows.shape[0] * len(controls))
            self._allocation_positions = np.repeat([position for _, position in controls], rows.shape[0])
            self._inner_interval = inner
            return Interval(function, inner.n_state, inner.n_interval, np.concatenate([inner.path_lower, zeros]),
                            np.concatenate([inner.path_upper, zeros]))

        def initial_equalities(self, problem: OptimalControlProblem, s: Any) -> Any:
            own = super().initial_equalities(problem, s)
            return ca.vertcat(own, *(ca.mtimes(matrix, u) for u in self.initial_controls(problem, s)))

        def positions(self, problem: OptimalControlProblem, interval: Interval) -> tuple[Array, Array]:
            c_position, path_position = super().positions(problem, self._inner_interval)
            return c_position, np.concatenate([path_position, self._allocation_positions])

        def __reduce__(self) -> tuple[Any, ...]:
            # a class made here has no importable name: pickle (a plan's reference keeps its
            # transcription) rebuilds it from its base class, its rows and its state
            return _rebuilt, (base, rows, dict(self.__dict__))

    Allocated.__name__ = Allocated.__qualname__ = f"{base.__name__}WithAllocation"
    allocated = object.__new__(Allocated)
    allocated.__dict__.update(transcription.__dict__)
    return allocated


def _rebuilt(base: type, rows: Array, state: dict[str, Any]) -> Transcription:
    """A pickled :func:`with_allocation` transcription, made again from its base class, its rows
    and its state."""
    allocated = with_allocation(object.__new__(base), rows)
    allocated.__dict__.update(state)
    return allocated
