"""Scenario YAML schema (:doc:`/reference/schema`) and the :class:`Scenario` it builds.

Every error is a :class:`~scenarios.schema.node.ScenarioError` naming the YAML path and what was
expected. Degrees (``*_deg``) and kilometres (``*_km``) are converted to SI here, and so are
scalar-last quaternions (``maneuver.quaternion_order: scalar_last``), so that nothing inside the
code sees the papers' conventions. The model sections (``spacecraft``, ``orbit``, ``environment``)
are read by :mod:`scenarios.schema.model`.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from controllers import CONTROLLERS
from ocp import Environment, IGRFField, SensorNoise, Spacecraft, quat
from ocp.errors import OptionsError, excerpt
from ocp.simulation.simulator import MAX_SAMPLES, MAX_SUBSTEPS
from planners import PLANNERS, ManeuverProblem
from scenarios.errors import ScenarioError
from scenarios.schema.checks import check_compatibility, check_row_labels, check_work
from scenarios.schema.model import parse_environment, parse_spacecraft
from scenarios.schema.node import Node
from scenarios.schema.read import read_yaml

MAX_NAME = 200
"""Characters of a scenario name (the default output directory uses a sanitised, shorter stem)."""
MAX_LABEL = 100
"""Characters of a planner's or controller's label."""


@dataclass
class PlannerSpec:
    """One planner row of the scenario (``planners[i]``).

    Parameters
    ----------
    name : str
        Registry name (a key of ``planners.PLANNERS``).
    label : str
        The row's label in the tables (default: the name).
    options : object
        The planner's parsed ``Options`` dataclass.
    """

    name: str
    label: str
    options: Any


@dataclass
class ControllerSpec:
    """One controller of the scenario (``controller`` or ``controllers[i]``).

    Parameters
    ----------
    name : str
        Registry name (a key of ``controllers.CONTROLLERS``).
    options : object
        The controller's parsed ``Options`` dataclass.
    label : str, optional
        Its label in the tables; empty (default): the name.
    path : str, optional
        Its YAML entry (``controller`` or ``controllers[i]``), for messages.
    """

    name: str
    options: Any
    label: str = ""
    path: str = "controller"

    def __post_init__(self) -> None:
        self.label = self.label or self.name


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
        (``None``: no fine criterion).
    detumble_tolerance : float
        Rate bound [rad/s] of ``detumble_time_s``.
    compile : bool
        Build the closed loop of a symbolic law as C (``ocp.simulation.compiled``); interpreted otherwise.
    max_samples : int
        Most closed-loop samples a run may take.
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
    """

    name: str
    problem: ManeuverProblem
    planners: list[PlannerSpec]
    controllers: list[ControllerSpec]
    simulation: SimulationSpec
    source: Path | None = None

    @property
    def controller(self) -> ControllerSpec:
        """The first (or only) controller, for code written before ``controllers`` lists."""
        return self.controllers[0]

    @property
    def true_initial_state(self) -> np.ndarray:
        """The simulated initial state: the manoeuvre's with the configured errors applied."""
        p = self.problem
        q0 = quat.product(p.q0, quat.from_rotation_vector(self.simulation.initial_attitude_error))
        return np.concatenate([q0, p.omega0 + self.simulation.initial_rate_error, p.wheel_momentum0])


def _fit_field_span(data: Any, problem: ManeuverProblem, simulation: SimulationSpec, planners: list) -> ManeuverProblem:
    """Give an IGRF table without ``span_s`` the closed-loop window (twice the maneuver's when
    planners may return longer references) plus one minute."""
    field_model = problem.environment.magnetic_field
    spec = ((data.get("environment") or {}).get("magnetic_field") if isinstance(data, dict) else None)
    if not isinstance(field_model, IGRFField) or (isinstance(spec, dict) and spec.get("span_s") is not None):
        return problem
    window = max(problem.duration * (2.0 if planners else 1.0), simulation.duration or 0.0) + 60.0
    environment = dataclasses.replace(problem.environment,
                                      magnetic_field=dataclasses.replace(field_model, span=window))
    return dataclasses.replace(problem, environment=environment)


def _parse_problem(node: Node, spacecraft: Spacecraft, environment: Environment) -> ManeuverProblem:
    node.mapping()
    order = node.get("quaternion_order", "scalar_first").string(("scalar_first", "scalar_last"))

    def attitude(node: Node) -> np.ndarray:
        q = node.quaternion()
        return quat.from_scalar_last(q) if order == "scalar_last" else q

    def free_attitude(node: Node) -> np.ndarray | None:
        return None if node.is_null() else attitude(node)  # final attitude written as null: free

    initial = node.get("initial", required=True).mapping()
    final = node.get("final", required=True).mapping()
    momentum = initial.get("wheel_momentum", None).optional_vector(spacecraft.n_wheels)
    problem = ManeuverProblem(
        spacecraft=spacecraft, environment=environment,
        q0=attitude(initial.get("q", required=True)), omega0=initial.get("omega", [0.0, 0.0, 0.0]).vector(3),
        qf=free_attitude(final.get("q", required=True)), omegaf=final.get("omega", None).optional_vector(3),
        duration=node.get("duration", required=True).number(positive=True),
        wheel_momentum0=momentum, max_rate=node.get("max_rate", None).optional_number(positive=True),
    )
    for part in (initial, final, node):
        part.finish()
    return problem


def _registered(node: Node, registry: dict[str, type], kind: str) -> tuple[str, Any]:
    """``name`` and parsed ``options`` of a registry entry (planner or controller) at ``node``."""
    name = node.get("name", required=True).string()
    if name not in registry:
        raise ScenarioError(f"{node.path}.name", f"unknown {kind} {name!r}; registered: {sorted(registry)}")
    options = node.get("options", {})
    try:
        return name, registry[name](options.value, path=options.path).options
    except OptionsError as error:
        raise ScenarioError(error.path, error.message) from None


def _parse_planners(node: Node) -> list[PlannerSpec]:
    specs = []
    for item in node.items():
        item.mapping()
        name, options = _registered(item, PLANNERS, "planner")
        label = _label(item, name)
        item.finish()
        specs.append(PlannerSpec(name, label, options))
    return specs


def _parse_controller(node: Node) -> ControllerSpec:
    name, options = _registered(node.mapping(), CONTROLLERS, "controller")
    label = _label(node, name)
    node.finish()
    return ControllerSpec(name, options, label, node.path)


def _label(node: Node, default: str) -> str:
    """A row label: non-empty text of at most :data:`MAX_LABEL` characters."""
    label_node = node.get("label", default)
    label = label_node.string()
    if not label.strip() or len(label) > MAX_LABEL:
        raise label_node.error(f"expected a non-empty label of at most {MAX_LABEL} characters, got {excerpt(label)}")
    return label


def _parse_controllers(root: Node) -> list[ControllerSpec]:
    """``controller:`` (one) or ``controllers:`` (a non-empty list) of ``root``; distinct labels are
    checked with the rows' (:func:`~scenarios.schema.checks.check_row_labels`)."""
    if "controller" in root and "controllers" in root:
        raise ScenarioError("controllers", "give either `controller` (one) or `controllers` (a list), not both")
    if "controllers" not in root:
        return [_parse_controller(root.get("controller", required=True))]
    node = root.get("controllers")
    root.get("controller", None)  # an explicit `controller: null` next to the list is accepted
    specs = [_parse_controller(item) for item in node.items()]
    if not specs:
        raise ScenarioError("controllers", "expected at least one controller")
    return specs


def _parse_simulation(node: Node) -> SimulationSpec:
    node = node if not node.is_null() else Node({}, node.path)
    node.mapping()
    noise = node.get("sensor_noise", {}).mapping()
    spec = SimulationSpec(
        sample_time=node.get("sample_time", 1.0).number(positive=True),
        duration=node.get("duration", None).optional_number(positive=True),
        initial_attitude_error=np.deg2rad(node.get("initial_attitude_error_deg", [0.0, 0.0, 0.0]).vector(3)),
        initial_rate_error=node.get("initial_rate_error", [0.0, 0.0, 0.0]).vector(3),
        noise=SensorNoise(
            attitude_std=np.deg2rad(noise.get("attitude_deg", 0.0).number(non_negative=True)),
            rate_std=noise.get("rate", 0.0).number(non_negative=True),
            seed=noise.get("seed", 0).integer(minimum=0, maximum=2**63 - 1),
            field_std=noise.get("magnetic_field", 0.0).number(non_negative=True),
        ),
        integrator=node.get("integrator", "rk4").string(("rk4", "cvodes")),
        max_step=node.get("max_step", 0.05).number(positive=True),
        settling_tolerance_deg=node.get("settling_tolerance_deg", 0.5).number(positive=True, maximum=180.0),
        fine_settling_tolerance_deg=node.get("fine_settling_tolerance_deg", None).optional_number(positive=True, maximum=180.0),
        detumble_tolerance=node.get("detumble_tolerance", 0.01).number(positive=True),
        max_samples=node.get("max_samples", MAX_SAMPLES).integer(minimum=1, maximum=100_000_000),
        compile=node.get("compile", False).boolean(),
    )
    if spec.integrator == "rk4" and math.ceil(spec.sample_time / spec.max_step - 1e-9) > MAX_SUBSTEPS:
        raise ScenarioError(node.get("max_step").path, f"{spec.max_step:g} s gives more than {MAX_SUBSTEPS} RK4 "
                            f"sub-steps per {spec.sample_time:g} s sample; raise it to at least "
                            f"{spec.sample_time / MAX_SUBSTEPS:g} s")
    noise.finish()
    node.finish()
    return spec


def parse_scenario(data: Any, source: Path | None = None) -> Scenario:
    """Build a :class:`Scenario` from parsed YAML data, checking it as a whole.

    Parameters
    ----------
    data : object
        The parsed YAML document (a mapping; see :func:`~scenarios.schema.node.read_yaml`).
    source : Path or None, optional
        The file it came from, kept in :attr:`Scenario.source`.

    Returns
    -------
    Scenario
        The scenario, with degrees, kilometres and scalar-last quaternions converted.

    Raises
    ------
    ScenarioError
        Naming the YAML path, the value and what was expected.
    """
    root = Node(data).mapping()
    name_node = root.get("name", required=True)
    name = name_node.string()
    if not name.strip() or len(name) > MAX_NAME:
        raise name_node.error(f"expected a non-empty name of at most {MAX_NAME} characters, got {excerpt(name)}")
    spacecraft = parse_spacecraft(root.get("spacecraft", required=True))
    environment = parse_environment(root.get("orbit", None), root.get("environment", {}))
    problem = _parse_problem(root.get("maneuver", required=True), spacecraft, environment)
    planners = _parse_planners(root.get("planners", required=True))
    controllers = _parse_controllers(root)
    simulation = _parse_simulation(root.get("simulation", {}))
    root.finish()
    problem = _fit_field_span(data, problem, simulation, planners)
    check_work(problem, simulation)
    check_row_labels(planners, controllers)
    check_compatibility(problem, planners, controllers, simulation)
    return Scenario(name, problem, planners, controllers, simulation, source)


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
        The file cannot be read or is not a valid scenario (the message names the YAML path).
    """
    return parse_scenario(read_yaml(path), Path(path))
