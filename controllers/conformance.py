"""Checks every controller must pass (the controller contract of :mod:`controllers.base`), the
standard plants to run them on, and option sets that are not the defaults.

``tests/test_controller_conformance.py`` runs every check of :data:`CHECKS` on every entry of
``CONTROLLERS``, with its defaults and with the option sets of :func:`option_variants` (each option
changed alone, and all at once: defaults hide bugs, a symmetric default gain hides a transposed
matrix). A check raises :class:`~controllers.errors.ConformanceError` with a message that says
what is wrong and what to do about it; a user's law is checked with :func:`check_controller`.

A law is run on each standard plant it accepts (``environment_error`` is ``None``), in regulation
to the target (unless it ``needs_reference``) and, if it ``tracks_reference``, along a planned
reference (the first of :data:`REFERENCE_PLANNERS` that it and the plant accept); a law that
declares neither must show that it ignores the reference (``ignores_reference``). The checks and
their oracles:

* ``options``: every numeric option declares a :class:`~ocp.options.Range`; a value outside it,
  NaN, a wrong literal and an unknown key are refused naming the option's path; so is a
  combination ``__post_init__`` refuses (an :class:`~ocp.errors.InvalidOption`, not a bare
  ``ValueError``). Oracle: the declared ranges themselves.
* ``commands``: ``__call__`` returns a :class:`~ocp.Command` whose fields fit the spacecraft, with
  finite numbers, at random states and with no error at all (a ``0/0`` at the target); every
  other check calls the law the same way (:func:`checked_command`). Oracle: the spacecraft's
  actuators.
* ``symbolic``: ``__call__`` and :meth:`~controllers.base.Controller.symbolic_law` agree to 1e-12 at
  random states over successive samples (state updates included); a law without a symbolic form
  says why. Oracle: the two implementations of one law.
* ``ignores_reference``: a law that declares neither ``tracks_reference`` nor ``needs_reference``
  regulates to the target whatever the reference: given a planned reference, ``__call__`` and the
  symbolic law (the reference's rows in ``r``) command what they command in regulation to the same
  target, over successive samples at random states. Oracle: the law's own regulation commands (a
  law that reads the reference must declare ``tracks_reference``, which the other checks then
  test along a reference).
* ``pure``: same inputs, same command, bit for bit; ``reset`` clears the state; two instances run
  interleaved give what each gives alone (no state shared through the class or a module); the
  measurement and the reference are left as they were.
* ``double_cover``: ``q`` and ``−q`` are one attitude: flipping the sign of the measured quaternion,
  or of the reference's and the target's, leaves the command unchanged.
* ``allocation``: the command asks only actuators the spacecraft has, with one finite value per
  wheel and three per vector; a pure wheel law (``wheels_only``) asks nothing of torquers or
  magnetorquers; and a rigid-body law (``gyroscopic_compensation``) moves the body over a hold the
  same way whatever actuates it (torquers, three wheels, four skewed wheels, a failed wheel and
  torquers), the wheels' momentum included. Oracle: the model's own equations of motion,
  integrated here with SciPy's DOP853.
* ``at_rest``: regulating to a target at rest, a body at the target (either sign of ``q``) with no
  rate and no wheel momentum gets no command; a rate law (``needs_target_attitude`` false) gives
  none to a body at rest in a constant field. Oracle: the law's own command at a 1 deg error (or
  in a field turning at 0.01 rad/s) fixes the scale of "none".
* ``closed_loop``: from a small error the loop converges: the attitude error to the target (or the
  reference) falls to a fifth over the run; a rate law never raises the kinetic energy, and
  lowers it by a tenth if it commands anything. Oracle: the simulator's rigid-body model.
"""
from __future__ import annotations

import dataclasses
import math
import types
import typing
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from functools import cache
from typing import Any, Literal, Union

import numpy as np
from numpy.typing import NDArray
from scipy.integrate import solve_ivp

from controllers.base import Controller, SymbolicLaw
from controllers.errors import ConformanceError
from ocp import (
    ActuatorModel,
    AttitudeModel,
    CircularOrbit,
    Command,
    Environment,
    Magnetorquers,
    Measurement,
    ReactionWheels,
    SimulationError,
    Simulator,
    Spacecraft,
    TiltedDipole,
    Torquers,
    quat,
)
from ocp.dynamics.layout import measurement_vector
from ocp.errors import OptionsError
from ocp.options import Range, numeric_leaves, option_fields
from planners import PLANNERS, ManeuverProblem, Reference

__all__ = ["ALLOCATION_TOLERANCE", "CHECKS", "CONVERGED", "HOLD_FOR_ALLOCATION", "INERTIA", "INITIAL_ERROR_DEG",
           "OPTIONS_PATH", "REFERENCE_PLANNERS", "SYMBOLIC_TOLERANCE", "Plant", "accepted_plants", "check_allocation",
           "check_at_rest", "check_closed_loop", "check_commands", "check_controller", "check_double_cover",
           "check_ignores_reference", "check_options", "check_pure", "check_symbolic", "checked_command",
           "describe_options", "kinetic_energy", "option_variants", "sample_time_for", "standard_plants"]

Array = NDArray[np.float64]

REFERENCE_PLANNERS: tuple[tuple[str, Mapping[str, Any]], ...] = (
    ("eigenaxis", {"profile": "smooth"}),
    ("costate_tpbvp", {}),
)
"""Planners tried in turn for a law that tracks references: the first that the law accepts
(``planner_error``) and that plans the plant's manoeuvre gives the reference."""
OPTIONS_PATH = "controller.options"
"""The YAML path the checks give a law's options, which every refusal must name."""
SYMBOLIC_TOLERANCE = 1e-12
"""Numeric and symbolic laws agree to this, relative to the command's size (at least 1)."""
INITIAL_ERROR_DEG = 5.0
"""Attitude error the regulation loop starts from [deg] (2 deg off a reference when tracking)."""
CONVERGED = 0.2
"""The loop converges: the final error is at most this fraction of the initial one."""
HOLD_FOR_ALLOCATION = 0.005
"""Hold of the allocation check [s]: short, so that the differences a zero-order hold leaves
between actuators (second order in it, or third) stay far below what a missing gyroscopic term
gives (first order)."""
ALLOCATION_TOLERANCE = 0.05
"""Actuator sets may differ by this fraction of the rate change the wheels' ``ω × A h_w`` makes
over the hold."""


@dataclass(frozen=True, eq=False)
class Plant:
    """A spacecraft in its environment, a manoeuvre on it, a sample time and a run length.

    Parameters
    ----------
    problem : ManeuverProblem
        The spacecraft, environment and manoeuvre (rest to rest from ``q0`` to ``qf``); planners
        plan references for it.
    sample_time : float
        The controller period preferred on this plant [s] (a law whose options do not fit it gets
        a nearby one, see :func:`sample_time_for`).
    settle : float
        How long a closed loop runs [s]: in regulation, and after the end of a reference.
    """

    problem: ManeuverProblem
    sample_time: float
    settle: float

    @property
    def model(self) -> AttitudeModel:
        """AttitudeModel: the plant's model (built once)."""
        return self.problem.model

    @property
    def qf(self) -> Array:
        """(4,) ndarray: the manoeuvre's target attitude (scalar first, body to inertial)."""
        if self.problem.qf is None:
            raise ValueError("a standard plant's manoeuvre has a target attitude")
        return self.problem.qf

    @property
    def three_axis(self) -> bool:
        """bool: whether the actuators can give any body torque without a field (torquers, or
        working wheels on three independent axes)."""
        spacecraft = self.problem.spacecraft
        if spacecraft.torquers is not None:
            return True
        wheels = spacecraft.wheels
        return wheels is not None and np.linalg.matrix_rank(wheels.axes[:, wheels.working]) == 3


INERTIA = np.array([[19.5, 0.3, -0.2], [0.3, 19.0, 0.1], [-0.2, 0.1, 12.6]])
"""kg m^2: the three-axis plants' inertia, not principal (the spin paper's moments, coupled)."""


@cache
def _plants() -> tuple[tuple[str, Plant], ...]:
    q0 = quat.from_axis_angle(np.array([0.3, -0.5, 0.8]) / np.sqrt(0.98), 0.4)
    qf = quat.from_axis_angle(np.array([-0.6, 0.2, 0.7]) / np.sqrt(0.89), 1.2)
    pyramid = np.array([[1.0, 0.0, 0.0, 1.0], [0.0, 1.0, 0.0, 1.0], [0.0, 0.0, 1.0, 1.0]])
    orbit = CircularOrbit(600e3, np.deg2rad(97.79))
    field = Environment(orbit, magnetic_field=TiltedDipole())
    uosat = [40.45, 42.09, 42.36]   # Horri & Palmer's UoSAT-12, a failed z wheel
    ukube = np.diag([0.0109, 0.05, 0.05])   # the nano-spacecraft paper's UKube-1

    def slew(spacecraft: Spacecraft, duration: float = 100.0, environment: Environment | None = None
             ) -> ManeuverProblem:
        return ManeuverProblem(spacecraft, q0, np.zeros(3), qf, duration, omegaf=np.zeros(3),
                               environment=environment or Environment())

    return (
        ("three_wheels", Plant(slew(Spacecraft(INERTIA, wheels=ReactionWheels.from_body_axes())), 0.5, 300.0)),
        ("torquers", Plant(slew(Spacecraft(INERTIA, torquers=Torquers())), 0.5, 300.0)),
        ("skewed_wheels", Plant(slew(Spacecraft(INERTIA, wheels=ReactionWheels(pyramid))), 0.5, 300.0)),
        ("failed_wheel_and_torquers", Plant(slew(Spacecraft(
            INERTIA, wheels=ReactionWheels.from_body_axes(failed=(1,)), torquers=Torquers())), 0.5, 300.0)),
        ("two_wheels", Plant(slew(Spacecraft(uosat, wheels=ReactionWheels.from_body_axes(
            max_torque=0.02, failed=(2,))), 6000.0), 1.0, 6000.0)),
        ("magnetorquers", Plant(slew(Spacecraft(ukube, magnetorquers=Magnetorquers(0.1)), 600.0, field), 0.5, 600.0)),
        ("two_wheels_and_all", Plant(slew(Spacecraft(
            uosat, wheels=ReactionWheels.from_body_axes(max_torque=0.02, failed=(2,)), torquers=Torquers(),
            magnetorquers=Magnetorquers(10.0)), 6000.0, field), 1.0, 6000.0)),
    )


def standard_plants() -> dict[str, Plant]:
    """The plants every law is tried on (it declines those it cannot run on through ``environment_error``).

    Returns
    -------
    dict of str to Plant
        In the order a law's first plant is picked: three body-axis wheels, ideal torquers, four
        skewed wheels, a failed wheel with torquers (all on one non-principal inertia, unlimited
        actuators, a 1.2 rad slew in 100 s, 0.5 s samples); Horri & Palmer's two-wheel UoSAT-12
        (1 s samples, 6000 s, the paper's run); the UKube-1 CubeSat with magnetorquers in a sun-synchronous orbit's
        tilted-dipole field (0.5 s, 600 s); and the two-wheel UoSAT-12 with torquers and
        magnetorquers too (a pure wheel law must leave them alone).
    """
    return dict(_plants())


def accepted_plants(controller: Controller) -> dict[str, Plant]:
    """The standard plants a law accepts.

    Parameters
    ----------
    controller : Controller
        The law (its ``environment_error`` decides).

    Returns
    -------
    dict of str to Plant
        The accepted plants, in the order of :func:`standard_plants`.

    Raises
    ------
    ConformanceError
        If the law accepts none of them.
    """
    plants = {name: plant for name, plant in _plants()
              if controller.environment_error(plant.problem.spacecraft, plant.problem.environment) is None}
    if not plants:
        raise ConformanceError(f"{controller.name}: environment_error refuses every standard plant "
                               f"({', '.join(name for name, _ in _plants())}); a law must run on one of them")
    return plants


def sample_time_for(controller: Controller, preferred: float) -> float:
    """The sample time nearest ``preferred`` (itself, a divisor by 2 to 10, or 2 to 4 times it) that
    the law's options fit.

    Parameters
    ----------
    controller : Controller
        The law (its ``sample_time_error`` decides).
    preferred : float
        The plant's sample time [s].

    Returns
    -------
    float
        The sample time [s].

    Raises
    ------
    ConformanceError
        If none fits.
    """
    candidates = [preferred] + [preferred / k for k in range(2, 11)] + [preferred * k for k in range(2, 5)]
    for sample_time in candidates:
        if controller.sample_time_error(sample_time) is None:
            return sample_time
    raise ConformanceError(f"{controller.name}: sample_time_error refuses every sample time near {preferred:g} s "
                           f"({controller.sample_time_error(preferred)})")


# --------------------------------------------------------------------------------------------
# Option sets
# --------------------------------------------------------------------------------------------
_SKEW = np.array([[0.0, 1.0, -2.0], [-1.0, 0.0, 0.5], [2.0, -0.5, 0.0]])


def _gain_matrix_variant(scalar: float, inertia: Array) -> list[list[float]]:
    """A full gain matrix of the size ``scalar`` times the inertia: unequal axes and a skew part
    (its symmetric part stays positive definite), so that a transposed matrix shows."""
    scale = float(np.trace(inertia)) / 3.0
    matrix = scalar * (inertia @ np.diag([1.2, 0.9, 1.05]) + 0.1 * scale * _SKEW)
    return [[float(v) for v in row] for row in matrix]


def _numbers(default: Any, bounds: Range | None, integer: bool) -> list[Any]:
    """Candidate values of a number option other than its default, inside its range."""
    candidates: list[Any]
    if integer:
        whole = 1 if default is None else int(default)
        candidates = [whole + 1, whole - 1, 2 * whole]
    else:
        base = 1.0 if default is None else float(default)
        candidates = [2.0 * base, 0.5 * base] if base != 0.0 else [1e-3, 0.5]
    return [v for v in candidates if v != default and (bounds is None or not bounds.violation(float(v)))]


def _alternatives(annotation: Any, bounds: Range | None, default: Any, inertia: Array) -> list[list[Any]]:
    """Groups of candidate values for an option: each group gives one option set (its first value
    the options accept)."""
    origin, args = typing.get_origin(annotation), typing.get_args(annotation)
    if annotation is bool:
        return [[not default]]
    if origin is Literal:
        return [[value] for value in args if value != default]
    if origin in (Union, types.UnionType):
        groups: list[list[Any]] = [[None]] if type(None) in args and default is not None else []
        for arg in args:
            if arg is not type(None):
                groups += _alternatives(arg, bounds, default, inertia)
        return [group for group in groups if group]
    if annotation in (int, float):
        if isinstance(default, bool) or (default is not None and not isinstance(default, (int, float))):
            return []
        return [_numbers(default, bounds, annotation is int)]
    if origin is list and args and typing.get_origin(args[0]) is list:   # a matrix
        if isinstance(default, (int, float)) and not isinstance(default, bool):
            return [[_gain_matrix_variant(float(default), inertia)]]
        if isinstance(default, list):
            return [[[[2.0 * v for v in row] for row in default]]]
        return []
    if origin in (list, tuple) and args and all(arg in (float, Ellipsis) for arg in args):   # a vector
        size = bounds.size if bounds is not None and bounds.size else (len(args) if origin is tuple else 3)
        values = [1.0] * size if default is None else [2.0 * float(v) for v in default]
        values = [value * (1.0 + 0.25 * i) for i, value in enumerate(values)]
        return [[tuple(values) if origin is tuple else values]]
    return []


def _accepted(cls: type[Controller], options: Mapping[str, Any]) -> bool:
    try:
        cls(options, path=OPTIONS_PATH)
    except OptionsError:
        return False
    return True


def _single_changes(cls: type[Controller], inertia: Array) -> Iterator[tuple[str, list[Any]]]:
    """``(option, candidate values)`` for each option set that changes one option."""
    defaults = {f.name: getattr(cls.Options(), f.name) for f in dataclasses.fields(cls.Options)}
    for name, (annotation, bounds) in option_fields(cls.Options).items():
        for group in _alternatives(annotation, bounds, defaults[name], inertia):
            yield name, group


def option_variants(cls: type[Controller], inertia: Array = INERTIA) -> list[dict[str, Any]]:
    """Option sets to check a law with, beyond its defaults.

    Parameters
    ----------
    cls : type
        A controller class.
    inertia : (3, 3) ndarray, optional
        Inertia [kg m^2] that a scalar gain multiplies, for the size of a matrix gain (default the
        three-axis plants' :data:`INERTIA`).

    Returns
    -------
    list of dict
        The defaults (``{}``) first; then each option changed alone: a boolean flipped, every other
        value of a literal, ``None`` for an optional number that has a default, a number doubled or
        halved (the first the options accept, within the declared range), a scalar gain as a full
        non-symmetric matrix; then all options changed at once (their first change each), when the
        options accept that.
    """
    variants: list[dict[str, Any]] = [{}]
    together: dict[str, Any] = {}
    for name, group in _single_changes(cls, inertia):
        for value in group:
            if _accepted(cls, {name: value}):
                variants.append({name: value})
                together.setdefault(name, value)
                break
    if len(together) > 1 and _accepted(cls, together):
        variants.append(together)
    return variants


def describe_options(options: Mapping[str, Any]) -> str:
    """A short label of an option set, for test ids and messages.

    Parameters
    ----------
    options : mapping
        Option names to values.

    Returns
    -------
    str
        ``defaults``, or ``name=value`` pairs (a matrix shown as ``matrix``).
    """
    if not options:
        return "defaults"
    return ",".join(f"{k}={'matrix' if isinstance(v, list) and v and isinstance(v[0], list) else v}"
                    for k, v in options.items())


# --------------------------------------------------------------------------------------------
# Runs
# --------------------------------------------------------------------------------------------
def _fresh(controller: Controller) -> Controller:
    """A new instance of the law with the same options (checks never reuse the caller's)."""
    return type(controller)(controller.options, path=OPTIONS_PATH)


def _label(controller: Controller) -> str:
    changed = {f.name: getattr(controller.options, f.name) for f in dataclasses.fields(controller.options)
               if getattr(controller.options, f.name) != getattr(type(controller.options)(), f.name)}
    return f"{controller.name} ({describe_options(changed)})"


def _raised_in_allocate(error: BaseException) -> bool:
    """Whether ``error`` was raised inside :meth:`Controller.allocate` (the law passed it a bad torque)."""
    frames = []
    traceback = error.__traceback__
    while traceback is not None:
        frames.append(traceback.tb_frame.f_code)
        traceback = traceback.tb_next
    return any(code.co_name in ("allocate", "_allocate") and code.co_filename.replace("\\", "/").endswith(
        "controllers/allocation.py") for code in frames)


def checked_command(controller: Controller, t: float, measurement: Measurement, reference: Any,
                    where: str = "") -> Command:
    """Call the law once and check what it returns: a :class:`~ocp.Command` whose fields fit
    the spacecraft of its last ``reset`` and hold finite numbers.

    Every check calls the law through this, so that a wrong type, a wrong shape or a NaN is named
    as such, not as whatever it breaks further on (a disagreement, a reset that seems not to
    clear the state, a Python error in the actuator model).

    Parameters
    ----------
    controller : Controller
        The law, after ``reset``.
    t : float
        Sample instant [s].
    measurement : Measurement
        The sample's measurement.
    reference : Reference or None
        What the law tracks (``None``: regulation to its target).
    where : str, optional
        Where it runs (plant, mode), for the message.

    Returns
    -------
    Command
        The law's command.

    Raises
    ------
    ConformanceError
        If the law raises (its exception chained), returns something other than a ``Command``,
        or a field of it has the wrong shape or a non-finite value.
    """
    label = f"{_label(controller)}{where}"
    try:
        command = controller(t, measurement, reference)
    except ConformanceError:
        raise
    except Exception as error:
        hint = ("; the law's call to Controller.allocate(u, measurement) failed: u must be the rigid-body torque, "
                "3 numbers [N m] in body axes" if _raised_in_allocate(error) else "")
        raise ConformanceError(f"{label}: __call__ raised {type(error).__name__}: {error} at t = {t:g} s{hint}") \
            from error
    if not isinstance(command, Command):
        raise ConformanceError(
            f"{label}: __call__ returned {type(command).__name__} at t = {t:g} s; it must return an ocp.Command "
            f"(Controller.allocate(u, measurement) maps a rigid-body torque u to one; or Command(wheel_torque=..., "
            f"dipole=..., torque=...))")
    spacecraft = controller.spacecraft
    n_wheels = 0 if spacecraft is None else spacecraft.n_wheels
    fields: list[tuple[str, Any, int | None]] = [("wheel_torque", command.wheel_torque, n_wheels),
                                                  ("dipole", command.dipole, 3), ("torque", command.torque, 3)]
    fields += [(f"other[{name!r}]", value, None) for name, value in (command.other or {}).items()]
    for field, value, size in fields:
        if value is None:
            continue
        try:
            array = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            raise ConformanceError(f"{label}: Command.{field} at t = {t:g} s is {type(value).__name__}, "
                                   f"not numbers") from None
        if size is not None and array.shape != (size,):
            raise ConformanceError(
                f"{label}: Command.{field} at t = {t:g} s has shape {array.shape}; expected ({size},)"
                + (" (one torque per wheel, N m)" if field == "wheel_torque" else " (body axes)"))
        if not np.all(np.isfinite(array)):
            raise ConformanceError(
                f"{label}: non-finite command at t = {t:g} s: Command.{field} = {array.tolist()} (measured "
                f"q = {np.round(measurement.q, 6).tolist()}, ω = {np.round(measurement.omega, 6).tolist()} rad/s); "
                f"a law must give finite numbers at every state (a division by a vanishing norm, 0/0 at the "
                f"target, an arcsin outside [-1, 1])")
    return command


@dataclass
class _Mode:
    """One way of running a law on a plant: regulation (``reference`` None) or tracking."""

    name: str
    plant_name: str
    plant: Plant
    reference: Any
    target: tuple[Array | None, Array | None]


_references: dict[tuple[int, str], Reference | None] = {}


def _planned(plant: Plant, name: str, options: Mapping[str, Any]) -> Reference | None:
    key = (id(plant), f"{name}{sorted(options.items())}")
    if key not in _references:
        planner = PLANNERS[name](options)
        reference = None
        if planner.problem_error(plant.problem) is None:
            reference = planner.plan(plant.problem)
        _references[key] = reference if reference is not None and reference.ok else None
    return _references[key]


def _reference(controller: Controller, plant: Plant) -> Reference | None:
    for name, options in REFERENCE_PLANNERS:
        if name in PLANNERS and controller.planner_error(name, PLANNERS[name](options).options) is None:
            reference = _planned(plant, name, options)
            if reference is not None:
                return reference
    return None


def _modes(controller: Controller, plant: Plant) -> list[_Mode]:
    """Regulation (unless the law needs a reference) and tracking (if it tracks references and a
    reference can be planned on the plant)."""
    problem = plant.problem
    target = (problem.qf if controller.needs_target_attitude else None, np.zeros(3))
    name = next(key for key, value in _plants() if value is plant)
    modes = [] if controller.needs_reference else [_Mode("regulation", name, plant, None, target)]
    if controller.tracks_reference or controller.needs_reference:
        reference = _reference(controller, plant)
        if reference is not None:
            modes.append(_Mode("tracking", name, plant, reference, (problem.qf, np.zeros(3))))
    return modes


def _first_modes(controller: Controller) -> list[_Mode]:
    """The modes on the first accepted plant that offers all the law's modes."""
    for plant in accepted_plants(controller).values():
        modes = _modes(controller, plant)
        wanted = (not controller.needs_reference) + bool(controller.tracks_reference or controller.needs_reference)
        if len(modes) == wanted:
            return modes
    planners = ", ".join(name for name, _ in REFERENCE_PLANNERS)
    raise ConformanceError(f"{_label(controller)}: no standard plant it accepts gives a reference it can track "
                           f"(tried {planners}); planner_error must accept one of them")


def _random_measurement(rng: np.random.Generator, controller: Controller, plant: Plant, t: float) -> Measurement:
    spacecraft = plant.problem.spacecraft
    field = rng.normal(0.0, 3e-5, 3) if plant.problem.environment.magnetic_field is not None else None
    measurement = Measurement(t, quat.random_unit(rng), rng.normal(0.0, 0.05, 3),
                              rng.normal(0.0, 0.5, spacecraft.n_wheels), field)
    if controller.needs_field_rate and field is not None:
        measurement.field_rate_inertial = rng.normal(0.0, 1e-7, 3)
    return measurement


def _copy(measurement: Measurement) -> Measurement:
    copies: dict[str, Any] = {f.name: np.array(getattr(measurement, f.name)) for f in dataclasses.fields(measurement)
                              if isinstance(getattr(measurement, f.name), np.ndarray)}
    return dataclasses.replace(measurement, **copies)


def _times(mode: _Mode, rng: np.random.Generator, sample_time: float, count: int) -> Array:
    """Successive sample instants, starting inside the reference (or at a random time)."""
    duration = mode.reference.duration if mode.reference is not None else mode.plant.problem.duration
    return float(rng.uniform(0.0, 0.8 * duration)) + sample_time * np.arange(count, dtype=float)


def _commands(controller: Controller, mode: _Mode, sample_time: float, measurements: list[Measurement],
              reference: Any = None, target: Any = None) -> list[Array]:
    """Reset the law and run it over ``measurements``; the commands as vectors ``u``."""
    controller.reset(mode.plant.problem.spacecraft, sample_time,
                     target=mode.target if target is None else target)
    reference = mode.reference if reference is None else reference
    where = f" on {mode.plant_name} ({mode.name})"
    return [controller.command_vector(checked_command(controller, m.t, m, reference, where)) for m in measurements]


def _sequence(rng: np.random.Generator, controller: Controller, mode: _Mode, sample_time: float,
              count: int = 5) -> list[Measurement]:
    return [_random_measurement(rng, controller, mode.plant, float(t)) for t in _times(mode, rng, sample_time, count)]


class _FlippedReference:
    """A reference whose quaternion has the other sign (the same attitudes)."""

    def __init__(self, reference: Any) -> None:
        self._reference = reference

    def __getattr__(self, name: str) -> Any:
        return getattr(self._reference, name)

    def sample(self, t: Any) -> Any:
        sample = self._reference.sample(t)
        return sample._replace(q=-sample.q)


# --------------------------------------------------------------------------------------------
# The checks
# --------------------------------------------------------------------------------------------
def _bad_values(annotation: Any, bounds: Range) -> list[Any]:
    """Values of an option outside its declared range (in the option's shape)."""
    origin, args = typing.get_origin(annotation), typing.get_args(annotation)
    kinds = [arg for arg in args if arg is not type(None)] if origin in (Union, types.UnionType) else [annotation]
    integer = all(kind is int for kind in kinds)
    numbers: list[float] = []
    if bounds.ge is not None:
        numbers.append(bounds.ge - 1 if integer else bounds.ge - 0.5 * max(1.0, abs(bounds.ge)))
    if bounds.gt is not None:
        numbers.append(bounds.gt)
    if bounds.le is not None:
        numbers.append(bounds.le + 1 if integer else bounds.le + 0.5 * max(1.0, abs(bounds.le)))
    if bounds.lt is not None:
        numbers.append(bounds.lt)
    if not integer:
        numbers.append(math.nan)
        if bounds.finite:
            numbers.append(math.inf)
    if any(kind in (int, float) for kind in kinds):
        return [int(v) if integer else v for v in numbers]
    kind = kinds[0]
    inner = typing.get_args(kind)
    if typing.get_origin(kind) is list and inner and typing.get_origin(inner[0]) is list:
        rows, cols = bounds.shape or (3, 3)
        return [[[v if (i, j) == (0, 0) else 0.0 for j in range(cols)] for i in range(rows)] for v in numbers]
    size = bounds.size or (len(inner) if typing.get_origin(kind) is tuple else 3)
    return [[v] + [1.0] * (size - 1) for v in numbers]


def check_options(controller: Controller) -> None:
    """Options are declared with their ranges, and refusals name the option's path.

    Parameters
    ----------
    controller : Controller
        The law (its class's ``Options`` is checked).

    Raises
    ------
    ConformanceError
        If ``Options`` is not a frozen dataclass, a numeric option declares no ``Range``, a value
        outside the range (or NaN, infinity, a wrong literal, an unknown key) is accepted or
        refused without the option's path ``controller.options.<name>``, or a combination that
        ``__post_init__`` refuses is refused without naming an option.
    """
    cls = type(controller)
    label = controller.name
    if not dataclasses.is_dataclass(cls.Options) or not cls.Options.__dataclass_params__.frozen:  # type: ignore[attr-defined]
        raise ConformanceError(f"{label}: Options must be a @dataclass(frozen=True): a law must not change its "
                               f"options while it runs")
    trials: list[tuple[str, Any]] = [("no_such_option", 1.0)]
    for name, (annotation, bounds) in option_fields(cls.Options).items():
        if numeric_leaves(annotation) and bounds is None:
            raise ConformanceError(f"{label}: option {name!r} holds numbers but declares no range; write "
                                   f"{name}: Annotated[{getattr(annotation, '__name__', annotation)}, Range(...)] "
                                   f"(ocp.options.Range: ge, gt, le, lt, size, shape)")
        if bounds is not None:
            trials += [(name, value) for value in _bad_values(annotation, bounds)]
        if typing.get_origin(annotation) is Literal or Literal in {typing.get_origin(a) for a in typing.get_args(annotation)}:
            trials.append((name, "not_a_choice"))
    for name, value in trials:
        try:
            cls({name: value}, path=OPTIONS_PATH)
        except OptionsError as error:
            if not error.path.startswith(f"{OPTIONS_PATH}.{name}"):
                raise ConformanceError(f"{label}: {name} = {value!r} is refused at {error.path!r}, not at the "
                                       f"option's path {OPTIONS_PATH}.{name}") from None
            continue
        raise ConformanceError(f"{label}: {name} = {value!r} is accepted but lies outside the option's declared "
                               f"type or range; declare the range with Annotated[..., Range(...)]")
    for name, group in _single_changes(cls, INERTIA):
        for value in group:
            try:
                cls({name: value}, path=OPTIONS_PATH)
            except OptionsError as error:
                if error.path == OPTIONS_PATH:
                    raise ConformanceError(
                        f"{label}: {name} = {value!r} is refused without naming an option ({error.message}); "
                        f"__post_init__ must raise ocp.errors.InvalidOption(option, message), not ValueError") from None


def check_commands(controller: Controller, seed: int = 6) -> None:
    """The law returns a :class:`~ocp.Command` that fits the spacecraft, with finite numbers.

    Run before the checks that compare commands: a NaN reads there as a disagreement or as a
    state that ``reset`` does not clear, and a wrong return as a Python error deep in the
    actuator model. On every standard plant the law accepts, in each of its modes: three
    successive samples at random states, then samples with no error at all (at the target at
    rest in regulation, on the reference when tracking), where a ``0/0`` hides.

    Parameters
    ----------
    controller : Controller
        The law, with the options to check.
    seed : int, optional
        Seed of the random states.

    Raises
    ------
    ConformanceError
        If the law raises, returns another type, a field of the wrong shape (a 4-vector body
        torque, one wheel torque too many) or a non-finite value; the message names the plant,
        the mode and the time.
    """
    rng = np.random.default_rng(seed)
    for plant_name, plant in accepted_plants(controller).items():
        for mode in _modes(controller, plant):
            law = _fresh(controller)
            sample_time = sample_time_for(law, plant.sample_time)
            law.reset(plant.problem.spacecraft, sample_time, target=mode.target)
            where = f" on {plant_name} ({mode.name})"
            for measurement in _sequence(rng, law, mode, sample_time, 3):
                checked_command(law, measurement.t, measurement, mode.reference, where)
            law.reset(plant.problem.spacecraft, sample_time, target=mode.target)
            wheels = np.zeros(plant.problem.spacecraft.n_wheels)
            field = np.array([2e-5, -1e-5, 3e-5]) if plant.problem.environment.magnetic_field is not None else None
            for t in _times(mode, rng, sample_time, 2):
                if mode.reference is not None:
                    state = mode.reference.sample(float(t))
                    q, omega = np.array(state.q), np.array(state.omega)
                else:
                    q, omega = (plant.qf if mode.target[0] is None else mode.target[0]).copy(), np.zeros(3)
                exact = Measurement(float(t), q, omega, wheels.copy(), None if field is None else field.copy())
                if law.needs_field_rate and field is not None:
                    exact.field_rate_inertial = np.zeros(3)
                checked_command(law, float(t), exact, mode.reference, f"{where}, with no error")


def _agree(value: Array, expected: Array) -> bool:
    """Whether two commands (or two law states) are one, to :data:`SYMBOLIC_TOLERANCE` of the
    expected one's size (at least 1)."""
    scale = max(1.0, float(np.max(np.abs(expected), initial=0.0)))
    return bool(np.allclose(value, expected, rtol=0.0, atol=SYMBOLIC_TOLERANCE * scale))


def _other_target(target: tuple[Array | None, Array | None]) -> tuple[Array, Array | None]:
    """A target unlike ``target`` (another attitude; another final rate where one is given)."""
    omega = target[1]
    return quat.normalize(np.array([0.3, -0.4, 0.5, 0.7])), None if omega is None else np.asarray(omega) + 0.05


def _built_before(law: Controller, plant: Plant, sample_time: float, mode: _Mode) -> SymbolicLaw:
    """The symbolic law of a law that needs no target, built while it had another target, after
    which ``law`` is reset to ``mode.target``: the simulator reuses one build for every target of
    such a law (:meth:`~controllers.base.Controller.symbolic_key` leaves the target out), so it
    must agree with ``__call__`` under the target it was not built for."""
    law.reset(plant.problem.spacecraft, sample_time, target=_other_target(mode.target))
    symbolic = law.symbolic_law()
    law.reset(plant.problem.spacecraft, sample_time, target=mode.target)
    return symbolic


def check_symbolic(controller: Controller, seed: int = 1) -> None:
    """The numeric law (``__call__``) and its symbolic form agree at random states.

    On every standard plant the law accepts, in each of its modes, four successive samples at
    random states: ``u`` and the state update ``z_next`` of the symbolic law equal the command and
    :meth:`~controllers.base.Controller.state_vector` of ``__call__`` to :data:`SYMBOLIC_TOLERANCE`,
    and ``state0`` equals the state after ``reset``. A law that needs no target attitude
    (``needs_target_attitude`` False) has its symbolic law built under another target: it must bake
    none in (the simulator reuses its build for every target).

    Parameters
    ----------
    controller : Controller
        The law, with the options to check.
    seed : int, optional
        Seed of the random states.

    Raises
    ------
    ConformanceError
        At the first disagreement (plant, mode, sample, both values), or if a law without a
        symbolic form does not say why.
    """
    rng = np.random.default_rng(seed)
    for plant_name, plant in accepted_plants(controller).items():
        law = _fresh(controller)
        sample_time = sample_time_for(law, plant.sample_time)
        law.reset(plant.problem.spacecraft, sample_time, target=(plant.problem.qf, np.zeros(3)))
        reason = law.symbolic_error()
        if reason is not None:
            if not isinstance(reason, str) or len(reason) < 20:
                raise ConformanceError(f"{_label(law)}: symbolic_error must say why there is no symbolic form, "
                                       f"got {reason!r}")
            try:
                law.symbolic_law()
            except NotImplementedError:
                continue
            raise ConformanceError(f"{_label(law)}: symbolic_error gives a reason but symbolic_law() does not "
                                   f"raise NotImplementedError")
        for mode in _modes(controller, plant):
            if law.needs_target_attitude:
                law.reset(plant.problem.spacecraft, sample_time, target=mode.target)
                symbolic = law.symbolic_law()
            else:  # its symbolic key leaves the target out: one build serves every target
                symbolic = _built_before(law, plant, sample_time, mode)
            z = symbolic.state0
            if not np.array_equal(z, law.state_vector()):
                raise ConformanceError(f"{_label(law)} on {plant_name}: SymbolicLaw.state0 {z.tolist()} differs from "
                                       f"state_vector() after reset {law.state_vector().tolist()}")
            for k, measurement in enumerate(_sequence(rng, law, mode, sample_time, 4)):
                t = measurement.t
                rows = law.reference_rows(mode.reference, np.array([t, t + sample_time])).ravel()
                u, z_next = (v.full().ravel() for v in symbolic.function(t, measurement_vector(measurement), z, rows))
                expected = law.command_vector(checked_command(law, t, measurement, mode.reference,
                                                              f" on {plant_name}, {mode.name}, sample {k}"))
                if not _agree(u, expected):
                    raise ConformanceError(
                        f"{_label(law)} on {plant_name}, {mode.name}, sample {k}: the symbolic law gives u = "
                        f"{np.round(u, 12).tolist()} but __call__ gives {np.round(expected, 12).tolist()}; _law must "
                        f"compute what __call__ computes, for every option")
                state = law.state_vector()
                if not _agree(z_next, state):
                    raise ConformanceError(
                        f"{_label(law)} on {plant_name}, {mode.name}, sample {k}: z_next = {np.round(z_next, 12).tolist()} "
                        f"but state_vector() after __call__ is {np.round(state, 12).tolist()}")
                z = z_next


def check_ignores_reference(controller: Controller, seed: int = 7) -> None:
    """A law that does not declare ``tracks_reference`` ignores the reference.

    ``tracks_reference = False`` (the default) declares that the law regulates to the target
    whatever the reference; the other checks then run it in regulation alone, so a law that reads
    the reference without declaring it would have its tracking unchecked (and the simulator, which
    gives every law the reference, would run it). On every standard plant the law accepts where a
    reference is planned (:data:`REFERENCE_PLANNERS`), over four successive samples at random
    states inside the reference: ``__call__`` given the reference commands what it commands in
    regulation to the same target, and so does the symbolic law given the reference's rows ``r``
    instead of the target's (its ``u`` and ``z_next``). Laws that declare ``tracks_reference`` or
    ``needs_reference`` are not checked here (the other checks run them along a reference).

    Parameters
    ----------
    controller : Controller
        The law, with the options to check.
    seed : int, optional
        Seed of the random states.

    Raises
    ------
    ConformanceError
        If a command (or the symbolic law's state update) with the reference differs from the
        one in regulation by more than :data:`SYMBOLIC_TOLERANCE` of its size (plant, sample, both
        values), naming the law and saying to declare ``tracks_reference = True``.
    """
    if controller.tracks_reference or controller.needs_reference:
        return
    rng = np.random.default_rng(seed)
    meaning = ("tracks_reference = False declares that the law regulates to the target whatever the reference; "
               "if it follows a reference, set tracks_reference = True on the class (the checks then run it "
               "along a reference too)")
    for plant_name, plant in accepted_plants(controller).items():
        reference = _reference(controller, plant)
        if reference is None:
            continue
        regulation = _modes(controller, plant)[0]
        tracking = dataclasses.replace(regulation, name="given a reference", reference=reference)
        law = _fresh(controller)
        sample_time = sample_time_for(law, plant.sample_time)
        sequence = _sequence(rng, law, tracking, sample_time, 4)
        given = _commands(law, tracking, sample_time, sequence)
        regulated = _commands(law, regulation, sample_time, sequence)
        for k, (measurement, u, expected) in enumerate(zip(sequence, given, regulated)):
            if not _agree(u, expected):
                raise ConformanceError(
                    f"{_label(law)} on {plant_name}, sample {k} (t = {measurement.t:g} s): __call__ gives u = "
                    f"{np.round(u, 12).tolist()} along a planned reference ({reference.planner}) but "
                    f"{np.round(expected, 12).tolist()} regulating to the same target: the law reads the reference. "
                    f"{meaning}")
        if law.symbolic_error() is not None:
            continue
        law.reset(plant.problem.spacecraft, sample_time, target=regulation.target)
        symbolic = law.symbolic_law()
        z_given = z_regulated = symbolic.state0
        for k, measurement in enumerate(sequence):
            t, y = measurement.t, measurement_vector(measurement)
            times = np.array([t, t + sample_time])
            u, z_given = (v.full().ravel() for v in symbolic.function(
                t, y, z_given, law.reference_rows(reference, times).ravel()))
            expected, z_regulated = (v.full().ravel() for v in symbolic.function(
                t, y, z_regulated, law.reference_rows(None, times).ravel()))
            for what, value, wanted in (("u", u, expected), ("z_next", z_given, z_regulated)):
                if not _agree(value, wanted):
                    raise ConformanceError(
                        f"{_label(law)} on {plant_name}, sample {k} (t = {t:g} s): the symbolic law gives {what} = "
                        f"{np.round(value, 12).tolist()} with a planned reference's rows r ({reference.planner}) but "
                        f"{np.round(wanted, 12).tolist()} with the target's, while __call__ ignores the reference; "
                        f"the simulator gives the law the reference in r: _law must compute what __call__ computes. "
                        f"{meaning}")


def check_pure(controller: Controller, seed: int = 2) -> None:
    """Same inputs, same commands: no hidden inputs, ``reset`` clears the state, nothing shared
    between instances, inputs left unchanged.

    Parameters
    ----------
    controller : Controller
        The law, with the options to check.
    seed : int, optional
        Seed of the random states.

    Raises
    ------
    ConformanceError
        If a second run after ``reset`` differs, an instance run interleaved with another differs
        from the same instance run alone, or the law modifies the measurement or the reference.
    """
    rng = np.random.default_rng(seed)
    for mode in _first_modes(controller):
        law, other = _fresh(controller), _fresh(controller)
        sample_time = sample_time_for(law, mode.plant.sample_time)
        sequence = _sequence(rng, law, mode, sample_time, 6)
        others = _sequence(rng, law, mode, sample_time, 6)
        copies = [_copy(m) for m in sequence]
        first = _commands(law, mode, sample_time, sequence)
        for before, after in zip(copies, sequence):
            for name, a, b in zip(("t", "q", "omega", "wheel_momentum", "field_body", "field_rate_inertial"),
                                  dataclasses.astuple(before), dataclasses.astuple(after)):
                if not (a is None and b is None) and not np.array_equal(a, b):
                    raise ConformanceError(f"{_label(law)}: __call__ changed measurement.{name} from {a} to {b}; a law "
                                           f"must not modify its inputs (copy them)")
        again = _commands(law, mode, sample_time, sequence)
        if not np.array_equal(np.array(first), np.array(again)):
            raise ConformanceError(f"{_label(law)} ({mode.name}): the same measurements after reset() give other "
                                   f"commands ({np.array(first).tolist()} then {np.array(again).tolist()}); reset must "
                                   f"clear every state the law keeps")
        law.reset(mode.plant.problem.spacecraft, sample_time, target=mode.target)
        other.reset(mode.plant.problem.spacecraft, sample_time, target=mode.target)
        interleaved = []
        for mine, theirs in zip(sequence, others):
            where = f" on {mode.plant_name} ({mode.name})"
            interleaved.append(law.command_vector(checked_command(law, mine.t, mine, mode.reference, where)))
            checked_command(other, theirs.t, theirs, mode.reference, where)
        if not np.array_equal(np.array(first), np.array(interleaved)):
            raise ConformanceError(f"{_label(law)} ({mode.name}): run beside another instance it gives other commands "
                                   f"than alone; keep the law's state on the instance (not on the class or the module)")
        if mode.reference is not None:
            times = np.array([m.t for m in sequence])
            before_sample = [np.array(a) for a in mode.reference.sample(times)]
            _commands(_fresh(controller), mode, sample_time, sequence)
            if any(not np.array_equal(a, b) for a, b in zip(before_sample, mode.reference.sample(times))):
                raise ConformanceError(f"{_label(law)}: running the law changed the reference it was given")


def check_double_cover(controller: Controller, seed: int = 3) -> None:
    """``q`` and ``−q`` are the same attitude: the command does not depend on their sign.

    Parameters
    ----------
    controller : Controller
        The law, with the options to check.
    seed : int, optional
        Seed of the random states.

    Raises
    ------
    ConformanceError
        If negating the measured quaternions, or the reference's and the target's, changes a
        command by more than 1e-12 of its size.
    """
    rng = np.random.default_rng(seed)
    for mode in _first_modes(controller):
        sample_time = sample_time_for(controller, mode.plant.sample_time)
        sequence = _sequence(rng, controller, mode, sample_time, 4)
        plain = np.array(_commands(_fresh(controller), mode, sample_time, sequence))
        flipped = [dataclasses.replace(m, q=-m.q) for m in sequence]
        target = mode.target if mode.target[0] is None else (-mode.target[0], mode.target[1])
        reference = None if mode.reference is None else _FlippedReference(mode.reference)
        scale = max(1e-300, float(np.max(np.abs(plain), initial=0.0)))
        for what, commands in (
                ("the measured quaternion", _commands(_fresh(controller), mode, sample_time, flipped)),
                ("the reference's and the target's quaternion",
                 _commands(_fresh(controller), mode, sample_time, sequence, reference=reference, target=target))):
            difference = float(np.max(np.abs(np.array(commands) - plain), initial=0.0))
            if difference > 1e-12 * scale:
                raise ConformanceError(
                    f"{_label(controller)} ({mode.name}): negating {what} changes the command by {difference:.3g} "
                    f"(of {scale:.3g}); q and −q are one attitude: take the error quaternion in the hemisphere "
                    f"of non-negative scalar part")


def _applied(plant: Plant, command: Command, x: Array, hold: float) -> Array:
    model = plant.model
    actuators = ActuatorModel(model.spacecraft, model.control_slices, model.nu)
    return actuators.apply(command, x[7:], hold)[0]


def _after_hold(plant: Plant, x: Array, u: Array, t: float, hold: float) -> Array:
    """The model's state after holding ``u`` over ``[t, t + hold]`` (DOP853, tight tolerances)."""
    model = plant.model
    p = model.default_parameters

    def rhs(s: float, y: Array) -> Array:
        return np.asarray(model.rhs(y, u, s, p)).ravel()

    solution = solve_ivp(rhs, (t, t + hold), x, method="DOP853", rtol=1e-12, atol=1e-14)
    return np.asarray(solution.y[:, -1])


def _check_command_fits(controller: Controller, plant_name: str, plant: Plant, command: Command) -> None:
    spacecraft = plant.problem.spacecraft
    for field, size, present in (("wheel_torque", spacecraft.n_wheels, spacecraft.wheels is not None),
                                 ("dipole", 3, spacecraft.magnetorquers is not None),
                                 ("torque", 3, spacecraft.torquers is not None)):
        value = getattr(command, field)
        if value is None:
            continue
        array = np.asarray(value, dtype=float)
        if array.shape != (size,) or not np.all(np.isfinite(array)):
            raise ConformanceError(f"{_label(controller)} on {plant_name}: Command.{field} = {array.tolist()}; "
                                   f"expected {size} finite numbers")
        if not present and np.any(array != 0):
            raise ConformanceError(f"{_label(controller)} on {plant_name}: the command asks {field} of a spacecraft "
                                   f"that has none; allocate through Controller.allocate")
        if controller.wheels_only and field != "wheel_torque" and np.any(array != 0):
            raise ConformanceError(f"{_label(controller)} on {plant_name}: a pure wheel law (wheels_only) asks "
                                   f"{field} = {array.tolist()}; it must leave torquers and magnetorquers alone")


def check_allocation(controller: Controller, seed: int = 4) -> None:
    """Commands fit the actuators, and a rigid-body law moves the body the same whatever actuates it.

    Parameters
    ----------
    controller : Controller
        The law, with the options to check.
    seed : int, optional
        Seed of the random states.

    Raises
    ------
    ConformanceError
        If a command asks an actuator the spacecraft lacks, has the wrong size or a non-finite
        value, a ``wheels_only`` law asks torquers or magnetorquers, or (a law with
        ``gyroscopic_compensation``) the body rate after a hold of :data:`HOLD_FOR_ALLOCATION`
        differs between three-axis actuator sets by more than :data:`ALLOCATION_TOLERANCE` of
        what the wheels' ``ω × A h_w`` would change.
    """
    rng = np.random.default_rng(seed)
    plants = accepted_plants(controller)
    for plant_name, plant in plants.items():
        for mode in _modes(controller, plant):
            law = _fresh(controller)
            sample_time = sample_time_for(law, plant.sample_time)
            law.reset(plant.problem.spacecraft, sample_time, target=mode.target)
            for measurement in _sequence(rng, law, mode, sample_time, 3):
                _check_command_fits(law, plant_name, plant, checked_command(
                    law, measurement.t, measurement, mode.reference, f" on {plant_name} ({mode.name})"))
    full = {name: plant for name, plant in plants.items() if plant.three_axis}
    if not controller.gyroscopic_compensation or controller.wheels_only or not full:
        return
    base_name = next(iter(full))
    inertia = full[base_name].problem.spacecraft.inertia
    full = {name: plant for name, plant in full.items() if np.array_equal(plant.problem.spacecraft.inertia, inertia)}
    if len(full) < 2:
        return
    for mode in _modes(controller, full[base_name]):
        for _ in range(3):
            t = float(_times(mode, rng, HOLD_FOR_ALLOCATION, 1)[0])
            q, omega = quat.random_unit(rng), rng.normal(0.0, 0.05, 3)
            outcomes = {}
            for plant_name, plant in full.items():
                spacecraft = plant.problem.spacecraft
                h = rng.normal(0.0, 2.0, spacecraft.n_wheels)
                x = np.concatenate([q, omega, h])
                field = None
                if plant.model.field_body is not None:
                    field = np.asarray(plant.model.field_body(x, t)).ravel()
                law = _fresh(controller)
                law.reset(spacecraft, sample_time_for(law, HOLD_FOR_ALLOCATION), target=mode.target)
                hold = law.sample_time
                command = checked_command(law, t, Measurement(t, q.copy(), omega.copy(), h.copy(), field),
                                          mode.reference, f" on {plant_name} ({mode.name})")
                if all(getattr(command, f) is None for f in ("wheel_torque", "dipole", "torque")):
                    return   # a law that commands nothing allocates nothing
                after = _after_hold(plant, x, _applied(plant, command, x, hold), t, hold)
                gyroscopic = np.linalg.solve(spacecraft.inertia, np.cross(omega, spacecraft.wheel_axes @ h))
                outcomes[plant_name] = (after[4:7] - omega, float(np.linalg.norm(gyroscopic)) * hold)
            change, _ = outcomes[base_name]
            for plant_name, (other, wheel_effect) in outcomes.items():
                reach = max(wheel_effect, outcomes[base_name][1])
                difference = float(np.linalg.norm(other - change))
                if difference > ALLOCATION_TOLERANCE * reach + 1e-9 * float(np.linalg.norm(change)):
                    raise ConformanceError(
                        f"{_label(controller)} ({mode.name}): over a {hold:g} s hold the rate changes by "
                        f"{np.round(other, 9).tolist()} rad/s on {plant_name} but by {np.round(change, 9).tolist()} on "
                        f"{base_name} (difference {difference:.3g}, the wheels' ω × A h_w alone gives {reach:.3g}); "
                        f"compute the rigid-body torque u and map it with Controller.allocate (gyroscopic_compensation "
                        f"adds ω × A h_w), or declare gyroscopic_compensation = False")


def check_at_rest(controller: Controller, seed: int = 5) -> None:
    """No error, no command: at the target at rest (attitude laws), or at rest in a constant field
    (rate laws).

    Parameters
    ----------
    controller : Controller
        The law, with the options to check (laws that need a reference are not checked).
    seed : int, optional
        Seed of the constant field.

    Raises
    ------
    ConformanceError
        If a command at the target (``q_f`` or ``−q_f``, zero rate, zero wheel momentum, a constant
        field) exceeds 1e-9 of the command the law gives at a 1 deg error (a rate law: in a field
        turning at 0.01 rad/s).
    """
    rng = np.random.default_rng(seed)
    modes = [mode for mode in _first_modes(controller) if mode.reference is None]
    for mode in modes:
        plant = mode.plant
        sample_time = sample_time_for(controller, plant.sample_time)
        spacecraft = plant.problem.spacecraft
        field = rng.normal(0.0, 3e-5, 3) if plant.problem.environment.magnetic_field is not None else None
        times = sample_time * np.arange(6, dtype=float)
        q_target = plant.qf if mode.target[0] is None else mode.target[0]
        wheels = np.zeros(spacecraft.n_wheels)

        def at(q: Array, omega: Array, fields: list[Array | None], times: Array = times,
               wheels: Array = wheels) -> list[Measurement]:
            return [Measurement(float(s), q, omega, wheels, f) for s, f in zip(times, fields)]

        still = [field] * len(times)
        if controller.needs_target_attitude:
            off = quat.product(q_target, quat.from_axis_angle(np.array([0.0, 0.6, 0.8]), np.deg2rad(1.0)))
            scale = np.array(_commands(_fresh(controller), mode, sample_time, at(off, np.zeros(3), still)))
            what = "a 1 deg error"
        else:
            rate = 0.01 * np.array([0.0, 0.6, 0.8])
            turning = [None if field is None else quat.rotation_matrix(quat.from_rotation_vector(-rate * s)) @ field
                       for s in times]
            scale = np.array(_commands(_fresh(controller), mode, sample_time, at(q_target, rate, turning)))
            what = "a field turning at 0.01 rad/s"
        size = float(np.max(np.abs(scale), initial=0.0))   # 0 for a law that never acts: then exactly none
        for q in (q_target, -q_target):
            commands = np.array(_commands(_fresh(controller), mode, sample_time, at(q, np.zeros(3), still)))
            worst = float(np.max(np.abs(commands), initial=0.0))
            if worst > 1e-9 * size:
                raise ConformanceError(
                    f"{_label(controller)} ({mode.name}): at the target at rest it commands {worst:.3g} (at {what}: "
                    f"{size:.3g}); with no error a regulator must command nothing (a bias, or a term that does not "
                    f"vanish with the error)")


def kinetic_energy(inertia: Array, omega: Array) -> Array:
    """Rotational kinetic energy of the body.

    Parameters
    ----------
    inertia : (3, 3) ndarray
        Inertia [kg m^2], body axes.
    omega : (N, 3) ndarray
        Body rates [rad/s], body axes.

    Returns
    -------
    (N,) ndarray
        ``½ ωᵀ I ω`` [J].
    """
    return 0.5 * np.einsum("ni,ij,nj->n", omega, inertia, omega)


def check_closed_loop(controller: Controller) -> None:
    """From a small error the loop converges (attitude laws), or loses energy (rate laws).

    On the first standard plant the law accepts, with the simulator's Python loop (the law's
    ``__call__``): in regulation from :data:`INITIAL_ERROR_DEG` off the target at rest, and
    tracking from 2 deg off the reference's start, the attitude error at the end (the plant's
    ``settle`` time, after the reference's end when tracking) is at most :data:`CONVERGED` of the
    initial one. A rate law (``needs_target_attitude`` false) starts tumbling at 0.2 rad/s: the
    kinetic energy at the end is not above the initial, and at most 0.9 of it if the law
    commanded anything.

    Parameters
    ----------
    controller : Controller
        The law, with the options to check.

    Raises
    ------
    ConformanceError
        With the initial and final errors (or energies), or if the simulation diverges.
    """
    for mode in _first_modes(controller):
        plant, problem = mode.plant, mode.plant.problem
        law = _fresh(controller)
        simulator = Simulator(plant.model, sample_time_for(law, plant.sample_time), python_loop=True)
        axis = np.array([0.0, 0.6, 0.8])
        h0 = np.zeros(problem.spacecraft.n_wheels)
        if not controller.needs_target_attitude:
            omega0 = 0.2 * np.array([1.0, -2.0, 1.5]) / np.linalg.norm([1.0, -2.0, 1.5])
            x0, duration = np.concatenate([problem.q0, omega0, h0]), plant.settle
        elif mode.reference is None:
            q0 = quat.product(plant.qf, quat.from_axis_angle(axis, np.deg2rad(INITIAL_ERROR_DEG)))
            x0, duration = np.concatenate([q0, np.zeros(3), h0]), plant.settle
        else:
            start = mode.reference.sample(0.0)
            q0 = quat.product(start.q, quat.from_axis_angle(axis, np.deg2rad(2.0)))
            x0, duration = np.concatenate([q0, start.omega, h0]), mode.reference.duration + plant.settle
        try:
            result = simulator.run(law, x0, duration, reference=mode.reference, target=mode.target)
        except SimulationError as error:
            raise ConformanceError(f"{_label(controller)} ({mode.name}): the closed loop diverged: {error}") from None
        if not controller.needs_target_attitude:
            energy = kinetic_energy(problem.spacecraft.inertia, result.omega)
            acted = bool(np.any(result.applied_u != 0))
            limit = 0.9 * energy[0] if acted else energy[0] * (1 + 1e-9)
            if not energy[-1] <= limit:
                raise ConformanceError(
                    f"{_label(controller)}: tumbling at 0.2 rad/s on {mode.plant_name}, the kinetic energy goes "
                    f"from {energy[0]:.4g} J to {energy[-1]:.4g} J in {duration:g} s; a rate law must "
                    + ("remove energy (check the sign of the law)" if acted else "not add energy"))
            continue
        wanted = problem.qf if mode.reference is None else mode.reference.q(result.t)
        angle = np.rad2deg(quat.error_angle(result.q, np.asarray(wanted, dtype=float)))
        if not angle[-1] <= CONVERGED * angle[0]:
            raise ConformanceError(
                f"{_label(controller)} ({mode.name}): from an attitude error of {angle[0]:.3g} deg the error is "
                f"{angle[-1]:.3g} deg after {duration:g} s (largest {np.max(angle):.3g} deg); the loop must converge "
                f"to at most {CONVERGED:g} of the initial error")


CHECKS: dict[str, Callable[[Controller], None]] = {
    "options": check_options,
    "commands": check_commands,
    "symbolic": check_symbolic,
    "ignores_reference": check_ignores_reference,
    "pure": check_pure,
    "double_cover": check_double_cover,
    "allocation": check_allocation,
    "at_rest": check_at_rest,
    "closed_loop": check_closed_loop,
}
"""Every check, by name, in the order :func:`check_controller` runs them (``commands`` before those
that compare commands): ``check(controller)`` raises :class:`ConformanceError`."""


def check_controller(controller: Controller) -> None:
    """Run every check of :data:`CHECKS` on a law.

    Parameters
    ----------
    controller : Controller
        The law with the options to check (it is not modified: the checks run fresh instances
        with its options).

    Raises
    ------
    ConformanceError
        At the first failed check, with what to fix.
    """
    for check in CHECKS.values():
        check(controller)
