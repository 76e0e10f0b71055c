"""Scenario YAML schema (ARCHITECTURE.md, "Scenario YAML") and the :class:`Scenario` it builds.

Every error is a :class:`~scenarios.yaml_node.ScenarioError` naming the YAML path and what was
expected. Degrees (``*_deg``) and kilometres (``*_km``) are converted to SI here, and so are
scalar-last quaternions (``maneuver.quaternion_order: scalar_last``), so that nothing inside the
code sees the papers' conventions.
"""
from __future__ import annotations

import dataclasses
import datetime
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from controllers import CONTROLLERS
from ocp import (CircularOrbit, Environment, IGRFField, Magnetorquers, ModelError, ReactionWheels, SensorNoise,
                 Spacecraft, TiltedDipole, Torquers, quat)
from ocp.options import OptionsError, excerpt
from ocp.simulator import MAX_SAMPLES, MAX_SUBSTEPS
from planners import PLANNERS, ManeuverProblem
from scenarios.checks import check_compatibility, check_row_labels, check_work
from scenarios.yaml_node import Node, ScenarioError, read_yaml


MAX_NAME = 200
MAX_LABEL = 100
"""Characters of a planner's or controller's label."""
"""Characters of a scenario name (the default output directory uses a sanitised, shorter stem)."""


@dataclass
class PlannerSpec:
    """One planner row: registry ``name``, table ``label`` and its parsed options."""

    name: str
    label: str
    options: Any


@dataclass
class ControllerSpec:
    """One controller: registry ``name``, parsed ``options`` and table ``label`` (default: the
    name); ``path`` is its YAML entry (``controller`` or ``controllers[i]``), for messages."""

    name: str
    options: Any
    label: str = ""
    path: str = "controller"

    def __post_init__(self) -> None:
        self.label = self.label or self.name


@dataclass
class SimulationSpec:
    """Closed-loop settings: sample time (s), window (s, ``None``: the manoeuvre's, or the
    reference's if longer), errors applied to the true initial state (rad, rad/s), noise."""

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
    """Build the closed loop of a symbolic law as C (``ocp.compiled``); interpreted otherwise."""
    max_samples: int = MAX_SAMPLES


@dataclass
class Scenario:
    """A parsed, validated scenario."""

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


def _model_part(node: Node, build: Callable[..., Any], **kwargs: Any) -> Any:
    """Call a model constructor, turning its ModelError into a ScenarioError at ``node.path``."""
    try:
        return build(**kwargs)
    except ModelError as error:
        raise ScenarioError(f"{node.path}.{error.field}" if node.path else error.field, error.message) from None


def _limits(node: Node, key: str) -> Any:
    child = node.get(key, None)
    return None if child.is_null() else child.vector(allow_scalar=True)


def parse_spacecraft(node: Node) -> Spacecraft:
    node.mapping()
    inertia_node = node.get("inertia", required=True)
    inertia = inertia_node.value
    if isinstance(inertia, list) and inertia and all(isinstance(row, list) for row in inertia):
        inertia = np.array([Node(row, f"{inertia_node.path}[{i}]").vector(3) for i, row in enumerate(inertia)])
    else:
        inertia = inertia_node.vector(3)
    wheels_node = node.get("wheels", {})
    wheels = None
    if not wheels_node.is_null():
        wheels_node.mapping()
        axes = wheels_node.get("axes", None)
        axes = np.eye(3) if axes.is_null() else np.array([row.vector(3) for row in axes.items()]).T
        failed = [item.integer() for item in wheels_node.get("failed", []).items()]
        wheels = _model_part(
            wheels_node, ReactionWheels, axes=axes, max_torque=_limits(wheels_node, "max_torque"),
            max_momentum=_limits(wheels_node, "max_momentum"), spin_inertia=_limits(wheels_node, "spin_inertia"),
            failed=tuple(failed),
        )
        wheels_node.finish()
    magnetorquers = torquers = None
    mtq = node.get("magnetorquers", None)
    if not mtq.is_null():
        magnetorquers = _model_part(mtq.mapping(), Magnetorquers, max_dipole=_limits(mtq, "max_dipole"),
                                    saturation=mtq.get("saturation", "per_axis").string(("per_axis", "scale")))
        mtq.finish()
    trq = node.get("torquers", None)
    if not trq.is_null():
        torquers = _model_part(trq.mapping(), Torquers, max_torque=_limits(trq, "max_torque"))
        trq.finish()
    spacecraft = _model_part(node, Spacecraft, inertia=inertia, wheels=wheels, magnetorquers=magnetorquers,
                             torquers=torquers)
    node.finish()
    return spacecraft


def parse_environment(orbit_node: Node, node: Node) -> Environment:
    orbit = None
    if not orbit_node.is_null():
        orbit_node.mapping()
        orbit = _model_part(
            orbit_node, CircularOrbit,
            altitude=orbit_node.get("altitude_km", required=True).number() * 1e3,
            inclination=np.deg2rad(orbit_node.get("inclination_deg", 0.0).number()),
            raan=np.deg2rad(orbit_node.get("raan_deg", 0.0).number()),
            arg_latitude=np.deg2rad(orbit_node.get("arg_latitude_deg", 0.0).number()),
        )
        orbit_node.finish()
    node = node if not node.is_null() else Node({}, node.path)
    node.mapping()
    field_node = node.get("magnetic_field", None)
    magnetic_field = None
    if not field_node.is_null():
        if isinstance(field_node.value, str):
            field_node.string(("tilted_dipole", "none"))
            magnetic_field = TiltedDipole()
        else:
            field_node.mapping()
            model = field_node.get("model", "tilted_dipole").string(("tilted_dipole", "igrf"))
            magnetic_field = (_igrf_field(field_node, orbit) if model == "igrf"
                              else _tilted_dipole(field_node))
            field_node.finish()
    environment = _model_part(
        node, Environment, orbit=orbit,
        gravity_gradient=node.get("gravity_gradient", False).boolean(),
        magnetic_field=magnetic_field,
        disturbance_torque=node.get("disturbance_torque", [0.0, 0.0, 0.0]).vector(3),
    )
    node.finish()
    return environment


def _tilted_dipole(node: Node) -> TiltedDipole:
    defaults = TiltedDipole()
    return TiltedDipole(
        strength=node.get("strength", defaults.strength).number(positive=True),
        tilt=np.deg2rad(node.get("tilt_deg", np.rad2deg(defaults.tilt)).number()),
        pole_longitude=np.deg2rad(node.get("pole_longitude_deg", np.rad2deg(defaults.pole_longitude)).number()),
        greenwich_angle=np.deg2rad(node.get("greenwich_angle_deg", 0.0).number()),
    )


def _igrf_field(node: Node, orbit: CircularOrbit | None) -> IGRFField:
    """``{model: igrf, epoch, step_s, span_s, greenwich_angle_deg}``; without ``span_s`` the table
    spans a provisional second, fitted to the closed-loop window by :func:`_fit_field_span`."""
    if orbit is None:
        raise ScenarioError(node.path, "the IGRF field is tabulated along the orbit; give `orbit:`")
    epoch_node = node.get("epoch", "2025-01-01")
    epoch = epoch_node.value
    if not isinstance(epoch, (str, datetime.date)):
        raise epoch_node.error(f"expected a date like 2025-01-01, got {str(epoch)[:40]!r}")
    greenwich = node.get("greenwich_angle_deg", None).optional_number()
    return _model_part(
        node, IGRFField, orbit=orbit, epoch=str(epoch),
        span=node.get("span_s", None).optional_number(positive=True) or 1.0,
        step=node.get("step_s", 30.0).number(positive=True, maximum=120.0),  # cubic spline error ~3e-4 at 120 s
        greenwich_angle=None if greenwich is None else float(np.deg2rad(greenwich)),
    )


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


def parse_problem(node: Node, spacecraft: Spacecraft, environment: Environment) -> ManeuverProblem:
    node.mapping()
    order = node.get("quaternion_order", "scalar_first").string(("scalar_first", "scalar_last"))

    def attitude(parent: Node, free: bool = False) -> np.ndarray | None:
        node = parent.get("q", required=True)
        if free and node.is_null():  # final attitude written as null: free
            return None
        q = node.quaternion()
        return quat.from_scalar_last(q) if order == "scalar_last" else q

    initial = node.get("initial", required=True).mapping()
    final = node.get("final", required=True).mapping()
    momentum = initial.get("wheel_momentum", None).optional_vector(spacecraft.n_wheels)
    problem = ManeuverProblem(
        spacecraft=spacecraft, environment=environment,
        q0=attitude(initial), omega0=initial.get("omega", [0.0, 0.0, 0.0]).vector(3),
        qf=attitude(final, free=True), omegaf=final.get("omega", None).optional_vector(3),
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


def parse_planners(node: Node) -> list[PlannerSpec]:
    specs, labels = [], set()
    for item in node.items():
        item.mapping()
        name, options = _registered(item, PLANNERS, "planner")
        label = _label(item, name)
        if label in labels:
            raise ScenarioError(f"{item.path}.label", f"duplicate label {label!r}; give each row its own label")
        labels.add(label)
        item.finish()
        specs.append(PlannerSpec(name, label, options))
    return specs


def parse_controller(node: Node) -> ControllerSpec:
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


def parse_controllers(root: Node) -> list[ControllerSpec]:
    """``controller:`` (one) or ``controllers:`` (a non-empty list, labels unique)."""
    if "controller" in root and "controllers" in root:
        raise ScenarioError("controllers", "give either `controller` (one) or `controllers` (a list), not both")
    if "controllers" not in root:
        return [parse_controller(root.get("controller", required=True))]
    node = root.get("controllers")
    root.get("controller", None)  # an explicit `controller: null` next to the list is accepted
    specs = [parse_controller(item) for item in node.items()]
    if not specs:
        raise ScenarioError("controllers", "expected at least one controller")
    labels: set[str] = set()
    for spec in specs:
        if spec.label in labels:
            raise ScenarioError(f"{spec.path}.label", f"duplicate label {spec.label!r}; give each controller its own label")
        labels.add(spec.label)
    return specs


def parse_simulation(node: Node) -> SimulationSpec:
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
    """Build a :class:`Scenario` from parsed YAML data."""
    root = Node(data).mapping()
    name_node = root.get("name", required=True)
    name = name_node.string()
    if not name.strip() or len(name) > MAX_NAME:
        raise name_node.error(f"expected a non-empty name of at most {MAX_NAME} characters, got {excerpt(name)}")
    spacecraft = parse_spacecraft(root.get("spacecraft", required=True))
    environment = parse_environment(root.get("orbit", None), root.get("environment", {}))
    problem = parse_problem(root.get("maneuver", required=True), spacecraft, environment)
    planners = parse_planners(root.get("planners", required=True))
    controllers = parse_controllers(root)
    simulation = parse_simulation(root.get("simulation", {}))
    root.finish()
    problem = _fit_field_span(data, problem, simulation, planners)
    check_work(problem, simulation)
    check_row_labels(planners, controllers)
    check_compatibility(problem, planners, controllers, simulation)
    return Scenario(name, problem, planners, controllers, simulation, source)


def load(path: str | Path) -> Scenario:
    """Read and validate a scenario file."""
    return parse_scenario(read_yaml(path), Path(path))
