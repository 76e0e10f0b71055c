"""The scenario YAML: its top-level keys, the manoeuvre, planner and controller rows, the
simulation settings, and the :class:`Scenario` it builds.

Each mapping's keys are declared here (:data:`SCENARIO`, :data:`MANEUVER`, :data:`PLANNER`,
:data:`CONTROLLER`, :data:`SIMULATION` ...; the model sections in :mod:`scenarios.schema.model`) and
every value is read through them, so the schema reference (:mod:`scenarios.schema.reference`)
lists exactly what is accepted. Every error is a :class:`~scenarios.errors.ScenarioError` naming
the YAML path and what was expected. Degrees (``*_deg``) and kilometres (``*_km``) are converted to
SI here, and so are scalar-last quaternions (``maneuver.quaternion_order: scalar_last``), so that
nothing inside the code sees the papers' conventions; attitudes written in mission terms (axis and
angle, Euler angles, a pointing target, an orbit frame) become inertial quaternions here too
(:mod:`scenarios.schema.targets`). Planners and controllers are validated
once, here: :class:`PlannerSpec` and :class:`ControllerSpec` carry the instances.
"""
from __future__ import annotations

import copy
import dataclasses
import datetime
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from controllers import CONTROLLERS, Controller
from ocp import Environment, SensorNoise, Spacecraft, quat
from ocp.dynamics.truth import TruthPlant
from ocp.errors import OptionsError, excerpt
from ocp.estimation import SensorSuite
from ocp.geometry.directions import Geometry
from ocp.metrics import DEFAULT_SETTLING_TOLERANCE_DEG
from ocp.simulation.simulator import MAX_SAMPLES, MAX_SUBSTEPS
from planners import PLANNERS, ManeuverProblem, Planner
from planners.errors import UnknownNameError
from planners.problem import MAX_BODY_RATE
from scenarios.errors import ScenarioError, in_file
from scenarios.requirements.spec import Requirements, Sensor
from scenarios.schema.checks import (
    check_compatibility,
    check_magnetometer,
    check_row_labels,
    check_work,
)
from scenarios.schema.estimation import (
    ESTIMATOR,
    MAX_MAGNETIC_NOISE_T,
    SENSORS,
    magnetic_noise,
    parse_sensor_suite,
)
from scenarios.schema.keys import (
    Described,
    Section,
    boolean,
    choice,
    custom,
    integer,
    mapping,
    number,
    vector,
)
from scenarios.schema.model import (
    ENVIRONMENT,
    ORBIT,
    SPACECRAFT,
    parse_environment,
    parse_spacecraft,
)
from scenarios.schema.node import Node
from scenarios.schema.plausibility import warn_implausible
from scenarios.schema.read import read_yaml
from scenarios.schema.requirements import (
    REQUIREMENTS,
    RunSpan,
    check_ephemeris,
    parse_epoch,
    parse_requirements,
)
from scenarios.schema.targets import AttitudeContext, attitude_key, parse_attitude
from scenarios.schema.truth import TRUTH, parse_truth

MAX_NAME = 200
"""Characters of a scenario name (the default output directory uses a sanitised, shorter stem)."""
MAX_LABEL = 100
"""Characters of a planner's or controller's label."""
MAX_DURATION_S = 1.0e8
"""Longest ``maneuver.duration`` and ``simulation.duration`` [s] (about three years): planners raise
powers of it, which must stay finite, and an epoch plus the run must be a date."""
# MAX_BODY_RATE (planners.problem): the bound on maneuver.initial.omega and maneuver.final.omega entries,
# ManeuverProblem's own on omega0 and omegaf


@dataclass
class PlannerSpec:
    """One planner row of the scenario (``planners[i]``), validated once.

    Parameters
    ----------
    name : str
        Registry name (a key of ``planners.PLANNERS``).
    label : str
        The row's label in the tables (default: the name).
    options : object
        The planner's validated ``Options`` dataclass.
    planner : Planner or None, optional
        The planner built from them (the loader passes the one it validated); ``None``
        (default): built here from ``options``.
    """

    name: str
    label: str
    options: Any
    planner: Planner = field(default=None, repr=False, compare=False)  # type: ignore[assignment]

    def __post_init__(self) -> None:
        if self.planner is None:
            self.planner = PLANNERS[self.name](self.options)
            self.options = self.planner.options


@dataclass
class ControllerSpec:
    """One controller of the scenario (``controller`` or ``controllers[i]``), validated once.

    Parameters
    ----------
    name : str
        Registry name (a key of ``controllers.CONTROLLERS``).
    options : object
        The controller's validated ``Options`` dataclass.
    label : str, optional
        Its label in the tables; empty (default): the name.
    path : str, optional
        Its YAML entry (``controller`` or ``controllers[i]``), for messages.
    controller : Controller or None, optional
        The law built from the options (the loader passes the one it validated; a run resets it,
        see :meth:`Controller.reset`); ``None`` (default): built here from ``options``.
    """

    name: str
    options: Any
    label: str = ""
    path: str = "controller"
    controller: Controller = field(default=None, repr=False, compare=False)  # type: ignore[assignment]

    def __post_init__(self) -> None:
        self.label = self.label or self.name
        if self.controller is None:
            self.controller = CONTROLLERS[self.name](self.options)
            self.options = self.controller.options


@dataclass
class SimulationSpec:
    """Closed-loop settings (the ``simulation`` keys, in SI units).

    Parameters
    ----------
    sample_time : float
        Zero-order-hold sample time of the controller [s].
    duration : float or None
        Closed-loop window [s]; ``None``: the manoeuvre's, or the reference's if longer.
    initial_attitude_error : (3,) ndarray
        Rotation vector applied to the initial attitude in body axes [rad]
        (``initial_attitude_error_deg`` in YAML).
    initial_rate_error : (3,) ndarray
        Added to the initial body rate [rad/s], body frame.
    noise : SensorNoise
        Attitude [rad], rate [rad/s] and magnetometer [T] noise and its seed (``sensor_noise``).
    integrator : {"rk4", "cvodes"}
        Integrator of the closed loop.
    max_step : float
        Longest RK4 sub-step [s].
    settling_tolerance_deg, fine_settling_tolerance_deg : float, float or None
        Attitude-error tolerances [deg] of ``settling_time_s`` and ``fine_settling_time_s``
        (``None``: no fine criterion). The loader gives the first ``requirements.final.error_deg``
        when the key is unset and the scenario states that requirement.
    detumble_tolerance : float
        Rate bound [rad/s] of ``detumble_time_s``.
    compile : bool
        Build the closed loop of a symbolic law as C (``ocp.simulation.compiled``); interpreted otherwise.
    max_samples : int
        Most closed-loop samples a run may take.
    sensors : SensorSuite or None
        Gyro, star tracker, magnetometer and estimator (``sensors``, ``estimator``); ``None``:
        the measurement is ``noise``'s alone.
    """

    sample_time: float = 1.0
    duration: float | None = None
    initial_attitude_error: np.ndarray = field(default_factory=lambda: np.zeros(3))
    initial_rate_error: np.ndarray = field(default_factory=lambda: np.zeros(3))
    noise: SensorNoise = field(default_factory=SensorNoise)
    integrator: str = "rk4"
    max_step: float = 0.05
    settling_tolerance_deg: float = 0.5
    fine_settling_tolerance_deg: float | None = None
    detumble_tolerance: float = 0.01
    compile: bool = False
    max_samples: int = MAX_SAMPLES
    sensors: SensorSuite | None = None

    def true_initial_state(self, problem: ManeuverProblem) -> np.ndarray:
        """The simulated initial state of ``problem``: its own with the configured errors applied.

        Parameters
        ----------
        problem : ManeuverProblem
            The manoeuvre.

        Returns
        -------
        (7 + n_w,) ndarray
            ``[q0 ⊗ exp(initial_attitude_error / 2), ω0 + initial_rate_error, h_w0]``.
        """
        q0 = quat.product(problem.q0, quat.from_rotation_vector(self.initial_attitude_error))
        return np.concatenate([q0, problem.omega0 + self.initial_rate_error, problem.wheel_momentum0])


@dataclass
class Scenario:
    """A parsed, validated scenario.

    Parameters
    ----------
    name : str
        The scenario's name.
    problem : ManeuverProblem
        Spacecraft, environment and manoeuvre (SI units, scalar-first quaternions).
    planners : list of PlannerSpec
        The planner rows (empty: regulation to ``maneuver.final``).
    controllers : list of ControllerSpec
        The controllers (at least one).
    simulation : SimulationSpec
        Closed-loop settings.
    source : Path or None, optional
        The file it was read from; ``None`` for data parsed in memory.
    requirements : Requirements, optional
        What every row is scored against (``requirements``; default none). The pointing
        requirements' constraints, tabulated for the run, are ``problem.pointing``.
    epoch : datetime.datetime or None, optional
        The instant of t = 0, UTC (``epoch``); ``None``: none.
    euler_sequence : str, optional
        The Euler sequence of the figures (``plots.euler_sequence``; default ``"321"``).
    data : dict or None, optional
        A copy of the YAML data it was parsed from (recorded in ``results.json``); ``None`` for a
        scenario built in code.
    truth : TruthPlant or None, optional
        The simulated plant where it differs from the design model (``truth``; built on
        ``problem.model``); ``None`` (default): the design model is the plant.
    inapplicable : dict, optional
        Planner row index -> why that planner cannot take the problem (its ``problem_error``): the
        row fails without planning, naming it (a study's case, parsed with
        ``inapplicable_rows=True``); empty (default): every planner takes it.
    """

    name: str
    problem: ManeuverProblem
    planners: list[PlannerSpec]
    controllers: list[ControllerSpec]
    simulation: SimulationSpec
    source: Path | None = None
    requirements: Requirements = field(default_factory=Requirements)
    epoch: datetime.datetime | None = None
    euler_sequence: str = "321"
    data: dict[str, Any] | None = field(default=None, repr=False, compare=False)
    truth: TruthPlant | None = field(default=None, repr=False, compare=False)
    inapplicable: dict[int, str] = field(default_factory=dict, compare=False)

    @property
    def frame(self) -> str:
        """The inertial frame the attitudes and directions are in: with an epoch, ``GCRF (epoch
        2027-03-20T12:00:00Z)`` (the Earth-centred frame of the ephemeris,
        :class:`~ocp.geometry.directions.Geometry`), and the conversion an orbit went through
        when it was not given in it (``GCRF (epoch ...Z; SGP4 TEME -> GCRF)`` for a TLE); else
        ``inertial (no epoch)``: an Earth-centred inertial frame tied to no date."""
        if self.epoch is None:
            return "inertial (no epoch)"
        route = getattr(self.problem.environment.orbit, "frame", None)
        details = "; ".join(part for part in (f"epoch {self.epoch.isoformat()}Z", route() if route else "") if part)
        return f"{Geometry(self.epoch, None).frame} ({details})"

    @property
    def controller(self) -> ControllerSpec:
        """The first (or only) controller, for code written before ``controllers`` lists."""
        return self.controllers[0]

    @property
    def true_initial_state(self) -> np.ndarray:
        """The simulated initial state: the manoeuvre's with the configured errors applied
        (:meth:`SimulationSpec.true_initial_state`)."""
        return self.simulation.true_initial_state(self.problem)


def _table_window(duration: float, run: float | None, planned: bool) -> float:
    """How far what follows the run is tabulated (a field, a direction): the closed-loop window
    (twice the maneuver's when planners may return longer references) plus one minute [s]
    (:func:`~scenarios.schema.requirements.check_ephemeris` clips it to the ephemeris' end)."""
    return max(duration * (2.0 if planned else 1.0), run or 0.0) + 60.0


def _run_span(root: Node) -> RunSpan:
    """The run's lengths, read before the sections that consume the ephemeris (an attitude
    target, a sensor's exclusion cone, a requirement's direction) so that one check covers them."""
    duration = MANEUVER["duration"].value(SCENARIO["maneuver"].value(root))
    simulation = SCENARIO["simulation"].node(root)
    run = SIMULATION["duration"].value(simulation) if isinstance(simulation.value, dict) else None
    planners = SCENARIO["planners"].node(root).value
    table = _table_window(duration, run, isinstance(planners, list) and len(planners) > 0)
    return RunSpan(duration, run or duration, run is not None, table)


def _fit_field_span(problem: ManeuverProblem, window: float) -> ManeuverProblem:
    """Give a field whose extent follows the run (``for_window``: an IGRF table without ``span_s``)
    the tabulated window [s]."""
    field_model = problem.environment.magnetic_field
    for_window = getattr(field_model, "for_window", None)
    if for_window is None:
        return problem
    fitted = for_window(window)
    if fitted is field_model:
        return problem
    environment = dataclasses.replace(problem.environment, magnetic_field=fitted)
    return dataclasses.replace(problem, environment=environment)


def _check_orbit_window(orbit: Any, window: float) -> None:
    """Refuse a run that leaves a tabulated orbit's window (``valid_until``: a TLE's table)."""
    valid_until = getattr(orbit, "valid_until", None)
    if valid_until is not None and window > valid_until + 1e-9:
        raise ScenarioError("orbit.span_s", f"the orbit is tabulated up to t = {valid_until:g} s, the run (with its "
                                            f"margin) reaches {window:g} s; raise span_s")


def _name(node: Node) -> str:
    name = node.string()
    if not name.strip() or len(name) > MAX_NAME:
        raise node.error(f"expected a non-empty name of at most {MAX_NAME} characters, got {excerpt(name)}")
    return name


def _label(node: Node) -> str | None:
    """A row label: non-empty text of at most :data:`MAX_LABEL` characters (``None`` when missing:
    the caller uses the registry name)."""
    if isinstance(node.value, Described):
        return None
    label = node.string()
    if not label.strip() or len(label) > MAX_LABEL:
        raise node.error(f"expected a non-empty label of at most {MAX_LABEL} characters, got {excerpt(label)}")
    return label


def _registered(registry: dict[str, Any], kind: str) -> Any:
    def read(node: Node) -> str:
        name = node.string()
        if name not in registry:  # the registries' own message, with its "did you mean"
            raise node.error(str(UnknownNameError(kind, name, registry)))
        return name
    return read


INITIAL = Section((
    attitude_key("q", "Initial attitude, body to inertial: a quaternion (scalar first unless ``quaternion_order: "
                 "scalar_last``), or a mapping of one form (``axis_angle``, ``euler``, ``point`` ...; the user guide's "
                 "page on manoeuvres); its instant is t = 0."),
    vector("omega", "Initial body rate, body frame.", 3, unit="rad/s", default=[0.0, 0.0, 0.0],
           magnitude=MAX_BODY_RATE),
    custom("wheel_momentum", "Initial spin momentum of each wheel; ``null``: zero.",
           "list of numbers (one per wheel) or null", None, unit="N m s", default=None),
), "The state at t = 0.")

FINAL = Section((
    attitude_key("q", "Target attitude, written as ``initial.q`` is (its instant is ``duration``; ``frame: initial`` "
                 "is relative to the initial attitude); ``null``: free (rate acquisition; the attitude metrics are "
                 "then null). Only laws that need no target attitude accept it without planners.", nullable=True),
    vector("omega", "Target body rate, body frame; ``null``: free.", 3, unit="rad/s", default=None, nullable=True,
           magnitude=MAX_BODY_RATE),
), "The state at t = ``duration``.")

MANEUVER = Section((
    choice("quaternion_order", "Order of every quaternion of the scenario as written; ``scalar_last`` for "
           "quaternions copied from papers written scalar last.", ("scalar_first", "scalar_last"),
           default="scalar_first"),
    mapping("initial", "The initial state.", INITIAL),
    mapping("final", "The target state.", FINAL),
    number("duration", "Manoeuvre time T, the time budget of every planner (a planner minimising time ends its slew "
           "within it; a slew that takes longer is ``infeasible``).", unit="s", positive=True,
           maximum=MAX_DURATION_S),
    number("max_rate", "Bound on the body-rate norm ‖ω‖, for the planners that take one; ``null``: "
           "``requirements.rate.max`` if given, else none. Given with ``requirements.rate``, it must not exceed "
           "it (a tighter planning bound leaves the closed loop room).",
           unit="rad/s", default=None, positive=True, nullable=True),
), "The slew: boundary states, duration and rate bound.")

PLANNER = Section((
    custom("name", "The planner (its options are listed per planner below).", "text",
           _registered(PLANNERS, "planner"), choices=PLANNERS),
    custom("label", f"The row's label in the tables (unique, at most {MAX_LABEL} characters).", "text", _label,
           default=Described("the planner's name")),
    custom("options", "The planner's options (see its entry below).", "mapping", None, default={}),
), "One row of the table: a planner, its label and its options.")

CONTROLLER = Section((
    custom("name", "The feedback law (its options are listed per controller below).", "text",
           _registered(CONTROLLERS, "controller"), choices=CONTROLLERS),
    custom("label", f"Its label in the tables (unique, at most {MAX_LABEL} characters).", "text", _label,
           default=Described("the controller's name")),
    custom("options", "The controller's options (see its entry below).", "mapping", None, default={}),
), "A tracking or regulating controller and its options.")

SENSOR_NOISE = Section((
    number("attitude_deg", "Standard deviation of the attitude measurement error per axis (at most 180: a noise "
           "beyond half a turn measures no attitude).", unit="deg", default=0.0, non_negative=True, maximum=180.0),
    number("rate", "Standard deviation of the rate measurement error per axis.", unit="rad/s", default=0.0,
           non_negative=True),
    integer("seed", "Seed of the noise (the magnetometer's on a stream of its own).", default=0, minimum=0,
            maximum=2**63 - 1),
    custom("magnetic_field", "Standard deviation of the magnetometer error per body axis, white per sample (at most "
           f"{MAX_MAGNETIC_NOISE_T:g}).", "number", magnetic_noise, unit="T", default=0.0,
           bounds=f">= 0 and <= {MAX_MAGNETIC_NOISE_T:g}"),
), "Measurement noise, white and Gaussian.")

SIMULATION = Section((
    number("sample_time", "Zero-order-hold sample time of the controller; at most the closed-loop window "
           "(``simulation.duration``, else ``maneuver.duration``).", unit="s", default=1.0, positive=True),
    number("duration", "Closed-loop window of every row. ``null`` (the default): each row runs for "
           "``maneuver.duration`` (every planner's slew ends within it), a row without a planner too. After its duration a "
           "reference continues as the torque-free motion of its final state.", unit="s", default=None,
           positive=True, nullable=True, maximum=MAX_DURATION_S),
    vector("initial_attitude_error_deg", "Rotation vector applied to the true initial attitude, body axes.", 3,
           unit="deg", default=[0.0, 0.0, 0.0], magnitude=1e6),
    vector("initial_rate_error", "Added to the true initial body rate, body frame (each entry within "
           f"±{MAX_BODY_RATE:g}, ``maneuver.initial.omega``'s bound).", 3, unit="rad/s", default=[0.0, 0.0, 0.0],
           magnitude=MAX_BODY_RATE),
    mapping("sensor_noise", "Measurement noise.", SENSOR_NOISE, default={}),
    mapping("sensors", "Sensor models (gyro, star tracker, magnetometer); absent or ``null``: the measurement is "
            "``sensor_noise``'s.", SENSORS, default=None, null="none"),
    mapping("estimator", "An attitude estimator in the loop; absent or ``null``: none.", ESTIMATOR, default=None,
            null="none"),
    choice("integrator", "Integrator of the closed loop.", ("rk4", "cvodes"), default="rk4"),
    number("max_step", f"Longest RK4 sub-step (at most {MAX_SUBSTEPS} sub-steps per sample).", unit="s",
           default=0.05, positive=True),
    number("settling_tolerance_deg", "Attitude-error tolerance of the metric ``settling_time_s``. ``null`` (the "
           "default): ``requirements.final.error_deg`` when the scenario states it (a row that misses the "
           f"requirement has not settled), else {DEFAULT_SETTLING_TOLERANCE_DEG:g}.", unit="deg", default=None,
           positive=True, maximum=180.0, nullable=True),
    number("fine_settling_tolerance_deg", "A second, finer tolerance (metric ``fine_settling_time_s``); "
           "``null``: none.", unit="deg", default=None, positive=True, maximum=180.0, nullable=True),
    number("detumble_tolerance", "Rate bound of the metric ``detumble_time_s``.", unit="rad/s", default=0.01,
           positive=True),
    integer("max_samples", "Most closed-loop samples a run may take (with 20 RK4 sub-steps per allowed sample).",
            default=MAX_SAMPLES, minimum=1, maximum=100_000_000),
    boolean("compile", "Build the closed loop of a symbolic law as C (needs a C compiler); interpreted "
            "otherwise.", default=False),
), "Closed-loop settings.")

def _euler_sequence(node: Node) -> str:
    """An Euler sequence: one of :data:`ocp.quat.EULER_SEQUENCES` (an unquoted ``321`` is read as the text)."""
    value = node.value
    text = str(value) if isinstance(value, int) and not isinstance(value, bool) else value
    if text not in quat.EULER_SEQUENCES:
        raise node.error(f"expected an Euler sequence, one of {list(quat.EULER_SEQUENCES)}, got {excerpt(value)}")
    return text


PLOTS = Section((
    custom("euler_sequence", "The Euler sequence of the row figures' attitude panel: body axes "
           "in the order of the rotations from the inertial frame (``\"321\"``: yaw about z, pitch, roll).",
           "text", _euler_sequence, default="321", choices=quat.EULER_SEQUENCES),
), "How the figures show a run.")

SCENARIO = Section((
    custom("name", f"The scenario's name (at most {MAX_NAME} characters; the default output directory is "
           "``results/<name>``, sanitised).", "text", _name),
    custom("epoch", "The instant of t = 0, UTC, ISO 8601 (``2027-03-20T12:00:00Z``): places the orbit in the GCRF "
           "and gives the Sun and the Moon (JPL DE421), checked against the ephemeris over the run; a magnetic "
           "field model with an epoch of its own (IGRF) takes it when not given one. ``null``: none (the frame "
           "is an inertial one tied to no date).", "text or null", parse_epoch, unit="UTC", default=None),
    custom("spacecraft", "The rigid body and its actuators.", "mapping", None, section=SPACECRAFT),
    custom("orbit", "The orbit: ``type`` (``circular``, ``keplerian``, ``tle``, ...) and its keys; absent or "
           "``null``: none.", "mapping or null", None, default=None,
           section=ORBIT),
    custom("environment", "Gravity gradient, magnetic field and disturbance torque; absent or ``null``: none.",
           "mapping or null", None, default={}, section=ENVIRONMENT),
    custom("maneuver", "The slew to plan and track.", "mapping", None, section=MANEUVER),
    custom("planners", "The planner rows; ``[]``: regulation to ``maneuver.final`` by the controllers alone.",
           "list of mappings", None, section=PLANNER, entries=True),
    custom("controller", "The controller (give either ``controller`` or ``controllers``).", "mapping", None,
           default=Described("required unless ``controllers`` is given"), section=CONTROLLER),
    custom("controllers", "Several controllers compared row by row (one row per planner and controller); "
           "labels unique.", "list of mappings", None, default=None, section=CONTROLLER, entries=True),
    mapping("simulation", "Closed-loop settings.", SIMULATION, default={}, null="defaults"),
    mapping("plots", "How the figures show a run.", PLOTS, default={}, null="defaults"),
    custom("requirements", "What every row is scored against: pointing cones, the actuators' margin, a rate "
           "limit, the final error (the user guide's page on requirements). Absent: the actuators' limits only "
           "(``actuators`` with margin 0); ``null``: none.", "mapping or null",
           None, default={}, section=REQUIREMENTS),
    custom("truth", "The simulated plant where it differs from the design model (the user guide's section on the "
           "truth model): only the closed loop integrates it; planners and controllers keep the design values. "
           "Absent or ``null``: the design model is the plant.", "mapping or null", None, default=None,
           section=TRUTH),
), "A scenario file.")


def _parse_problem(node: Node, spacecraft: Spacecraft, environment: Environment, sensors: dict[str, Sensor],
                   epoch: datetime.datetime | None) -> ManeuverProblem:
    node.mapping()
    order = MANEUVER["quaternion_order"].value(node)
    duration = MANEUVER["duration"].value(node)
    initial, final = MANEUVER["initial"].value(node), MANEUVER["final"].value(node)
    # the attitudes' forms (scenarios.schema.targets): t = 0 for the initial, the duration for the final
    context = AttitudeContext(Geometry(epoch, environment.orbit), sensors, order == "scalar_last", 0.0)
    q0 = parse_attitude(initial["q"], context)
    final_context = dataclasses.replace(context, time=duration, initial=q0)
    qf = None if final["q"].is_null() else parse_attitude(final["q"], final_context)  # null: a free final attitude
    momentum = initial["wheel_momentum"].optional_vector(spacecraft.n_wheels)
    problem = ManeuverProblem(
        spacecraft=spacecraft, environment=environment, q0=q0, omega0=initial["omega"], qf=qf,
        omegaf=final["omega"], duration=duration, wheel_momentum0=momentum, max_rate=MANEUVER["max_rate"].value(node),
    )
    node.finish()
    return problem


def _validated(node: Node, registry: dict[str, Any], section: Section) -> tuple[str, str | None, Any]:
    """``(name, label or None, instance)`` of a planner or controller entry, its options validated
    by the registered class (once: the instance travels to the checks and the runner)."""
    values = section.read(node)
    options = values["options"]
    try:
        instance = registry[values["name"]](options.value, path=options.path)
    except OptionsError as error:
        raise ScenarioError(error.path, error.message) from None
    return values["name"], values["label"], instance


def _parse_planners(node: Node) -> list[PlannerSpec]:
    specs = []
    for item in node.items():
        name, label, planner = _validated(item, PLANNERS, PLANNER)
        specs.append(PlannerSpec(name, label or name, planner.options, planner))  # labels: checks.check_row_labels
    return specs


def _parse_controller(node: Node) -> ControllerSpec:
    if isinstance(node.value, Described):
        raise ScenarioError(node.path, "required key is missing")
    name, label, controller = _validated(node, CONTROLLERS, CONTROLLER)
    return ControllerSpec(name, controller.options, label or name, node.path, controller)


def _parse_controllers(root: Node) -> list[ControllerSpec]:
    """``controller:`` (one) or ``controllers:`` (a non-empty list) of ``root``; distinct labels are
    checked with the rows' (:func:`~scenarios.schema.checks.check_row_labels`)."""
    if "controller" in root and "controllers" in root:
        raise ScenarioError("controllers", "give either `controller` (one) or `controllers` (a list), not both")
    if "controllers" not in root:
        SCENARIO["controllers"].value(root)  # an explicit `controllers: null` next to `controller` is accepted
        return [_parse_controller(SCENARIO["controller"].value(root))]
    node = SCENARIO["controllers"].value(root)
    root.get("controller", None)  # an explicit `controller: null` next to the list is accepted (its
    # default, "required unless controllers is given", is in words)
    specs = [_parse_controller(item) for item in node.items()]
    if not specs:
        raise ScenarioError("controllers", "expected at least one controller")
    return specs


def _parse_simulation(values: dict[str, Any], path: str, sensors: dict[str, Sensor] | None = None,
                      geometry: Geometry | None = None, max_step_given: bool = True) -> SimulationSpec:
    noise = values["sensor_noise"]
    spec = SimulationSpec(
        sample_time=values["sample_time"], duration=values["duration"],
        initial_attitude_error=np.deg2rad(values["initial_attitude_error_deg"]),
        initial_rate_error=values["initial_rate_error"],
        noise=SensorNoise(attitude_std=np.deg2rad(noise["attitude_deg"]), rate_std=noise["rate"],
                          seed=noise["seed"], field_std=noise["magnetic_field"]),
        integrator=values["integrator"], max_step=values["max_step"],
        settling_tolerance_deg=(DEFAULT_SETTLING_TOLERANCE_DEG if values["settling_tolerance_deg"] is None
                                else values["settling_tolerance_deg"]),  # requirements.final's: _settling_band
        fine_settling_tolerance_deg=values["fine_settling_tolerance_deg"],
        detumble_tolerance=values["detumble_tolerance"], max_samples=values["max_samples"], compile=values["compile"],
        sensors=parse_sensor_suite(values["sensors"], values["estimator"], noise, path,
                                   (sensors or {})["star_tracker"].boresight if "star_tracker" in (sensors or {}) else None,
                                   geometry),
    )
    if spec.integrator == "rk4" and math.ceil(spec.sample_time / spec.max_step - 1e-9) > MAX_SUBSTEPS:
        if not max_step_given:  # the sample time the user set is what is too long for the default step
            raise ScenarioError(f"{path}.sample_time", f"{spec.sample_time:g} s needs more than {MAX_SUBSTEPS} RK4 "
                                f"sub-steps of the default {path}.max_step ({spec.max_step:g} s); lower sample_time "
                                f"to at most {spec.max_step * MAX_SUBSTEPS:g} s, or set {path}.max_step to at "
                                f"least {spec.sample_time / MAX_SUBSTEPS:g} s")
        raise ScenarioError(f"{path}.max_step", f"{spec.max_step:g} s gives more than {MAX_SUBSTEPS} RK4 "
                            f"sub-steps per {spec.sample_time:g} s sample; raise it to at least "
                            f"{spec.sample_time / MAX_SUBSTEPS:g} s")
    return spec


def parse_scenario(data: Any, source: Path | None = None, *, inapplicable_rows: bool = False) -> Scenario:
    """Build a :class:`Scenario` from parsed YAML data, checking it as a whole.

    Parameters
    ----------
    data : object
        The parsed YAML document (a mapping; see :func:`~scenarios.schema.read.read_yaml`), or one
        built in Python: numpy numbers and arrays and tuples are accepted wherever the YAML takes a
        number or a list (:func:`scenarios.schema.node.plain_value`).
    source : Path or None, optional
        The file it came from, kept in :attr:`Scenario.source`.
    inapplicable_rows : bool, optional
        False (default): a planner that cannot take the problem (``problem_error``) is an error at
        ``planners[i]``, as ``slewbench run`` refuses it. True (a study's case): it is recorded in
        :attr:`Scenario.inapplicable` and its rows fail, naming the reason, while the other
        planners run.

    Returns
    -------
    Scenario
        The scenario, with degrees, kilometres and scalar-last quaternions converted.

    Raises
    ------
    ScenarioError
        Naming the YAML path, the value and what was expected.

    Warns
    -----
    PlausibilityWarning
        One per value that looks like a unit or layout slip (the findings of ``slewbench validate``),
        when called from outside :mod:`scenarios` (:func:`scenarios.schema.plausibility.warn_implausible`:
        a study's cases and the command line report them their own way).
    """
    root = Node(data).mapping()
    name = SCENARIO["name"].value(root)
    epoch = SCENARIO["epoch"].value(root)
    spacecraft, sensors = parse_spacecraft(SCENARIO["spacecraft"].value(root))
    environment = parse_environment(SCENARIO["orbit"].value(root), SCENARIO["environment"].value(root), epoch)
    span = check_ephemeris(epoch, _run_span(root))  # before every consumer of the ephemeris
    problem = _parse_problem(SCENARIO["maneuver"].value(root), spacecraft, environment, sensors, epoch)
    planners = _parse_planners(SCENARIO["planners"].value(root))
    controllers = _parse_controllers(root)
    given = root.value.get("simulation")
    simulation = _parse_simulation(SCENARIO["simulation"].value(root), "simulation", sensors,
                                   Geometry(epoch, environment.orbit),
                                   max_step_given=isinstance(given, dict) and given.get("max_step") is not None)
    plots = SCENARIO["plots"].value(root)
    requirements_node = SCENARIO["requirements"].value(root)
    truth_node = SCENARIO["truth"].value(root)
    root.finish()
    problem = _fit_field_span(problem, span.table)
    _check_orbit_window(environment.orbit, span.table)
    requirements, constraints = parse_requirements(requirements_node, sensors, Geometry(epoch, environment.orbit),
                                                   span, problem.qf is None, problem.omegaf is None)
    problem = _with_requirements(problem, requirements, constraints)
    simulation = _settling_band(simulation, requirements, isinstance(given, dict)
                                and given.get("settling_tolerance_deg") is not None)
    truth = parse_truth(truth_node, problem.model)
    check_work(problem, simulation)
    check_magnetometer(problem, simulation)
    check_row_labels(planners, controllers)
    inapplicable: dict[int, str] | None = {} if inapplicable_rows else None
    check_compatibility(problem, planners, controllers, simulation, inapplicable)
    scenario = Scenario(name, problem, planners, controllers, simulation, source, requirements, epoch,
                        euler_sequence=plots["euler_sequence"], data=copy.deepcopy(root.value), truth=truth,
                        inapplicable=inapplicable or {})
    warn_implausible(scenario)  # called from a script: one warning per finding
    return scenario


def _settling_band(simulation: SimulationSpec, requirements: Requirements, given: bool) -> SimulationSpec:
    """``settling_time_s``'s band: ``simulation.settling_tolerance_deg`` when given, else
    ``requirements.final.error_deg`` when stated (else the default the simulation already has)."""
    final = requirements.final
    if given or final is None or final.error_deg is None:
        return simulation
    return dataclasses.replace(simulation, settling_tolerance_deg=float(final.error_deg))


def _with_requirements(problem: ManeuverProblem, requirements: Requirements,
                       constraints: tuple) -> ManeuverProblem:
    """The problem the planners get: the pointing constraints, the actuator margin, and the rate
    bound of ``requirements.rate`` unless ``maneuver.max_rate`` is given (and no looser)."""
    max_rate = problem.max_rate
    if requirements.rate is not None:
        if max_rate is None:
            max_rate = requirements.rate.max_rate
        elif max_rate > requirements.rate.max_rate:
            raise ScenarioError("maneuver.max_rate", f"{max_rate:g} rad/s exceeds requirements.rate.max "
                                f"({requirements.rate.max_rate:g} rad/s): the planners would plan past the "
                                "requirement; lower it or leave it out (the requirement's bound then applies)")
    margin = None if requirements.actuators is None else requirements.actuators.margin
    required = None if requirements.rate is None else requirements.rate.max_rate  # planned rate_margin below
    return dataclasses.replace(problem, pointing=constraints, actuator_margin=margin, max_rate=max_rate,
                               rate_requirement=required)


def load(path: str | Path) -> Scenario:
    """Read and validate a scenario file.

    Parameters
    ----------
    path : str or Path
        The scenario YAML file.

    Returns
    -------
    Scenario
        The parsed scenario.

    Raises
    ------
    ScenarioError
        The file cannot be read or is not a valid scenario: its :attr:`~scenarios.errors.ScenarioError.file`
        is ``path``, its text names the file and the YAML path (``FILE: name: required key is
        missing``); a study or slew-table file names the command that runs it.
    TypeError
        ``path`` is not a path (a mapping already read goes to :func:`parse_scenario`).

    Warns
    -----
    PlausibilityWarning
        One per value that looks like a unit or layout slip, as :func:`parse_scenario`.
    """
    if not isinstance(path, (str, os.PathLike)):  # as load_study: not pathlib's "expected str, bytes or ..."
        raise TypeError(f"path must be a str or os.PathLike, got {type(path).__name__}"
                        + ("; a scenario mapping already read: scenarios.parse_scenario(data)"
                           if isinstance(path, dict) else ""))
    try:
        data = read_yaml(path)
        if isinstance(data, dict):
            for key, command in OTHER_FILES.items():
                if key in data:
                    raise ScenarioError(key, f"{path} is a {key} file, not a scenario: run it with "
                                             f"`slewbench {command} {path}`")
        refuse_unmarked_base(data, path)
        return parse_scenario(data, Path(path))
    except ScenarioError as error:
        raise in_file(error, path) from None


OTHER_FILES = {"study": "sweep", "table": "table"}
"""The top-level key of a file that is not a scenario, and the command that reads it."""
BASE_KEY = "scenario"
"""The top-level key of a study file that holds (or names) its base scenario; no scenario has it."""


def refuse_unmarked_base(data: Any, path: str | Path) -> None:
    """Refuse a file with a base scenario (:data:`BASE_KEY`) but none of :data:`OTHER_FILES`'s keys:
    a study that lost its ``study:`` line, which read as a scenario would only say that ``name``
    is missing.

    Parameters
    ----------
    data : Any
        The file's YAML data.
    path : str or Path
        The file, named in the message.

    Raises
    ------
    ScenarioError
        At the top level, naming what a study file needs and the command that runs it.
    """
    if isinstance(data, dict) and BASE_KEY in data and not any(key in data for key in OTHER_FILES):
        raise ScenarioError("", f"{path} reads as a study file without its `study: NAME` key: a top-level "
                                f"`{BASE_KEY}:` is a study's base scenario (no scenario has one); add the key and run "
                                f"it with `slewbench {OTHER_FILES['study']}`")
