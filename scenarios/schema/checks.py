"""Checks of a parsed scenario as a whole, each reported at the YAML entry it concerns: rows whose
combined labels clash, a closed-loop window over the work limit, and what planners and controllers
say they cannot take (``problem_error``, ``environment_error``, ``initial_state_error``, ...)."""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from controllers import Controller
from ocp.simulation.simulator import SUBSTEPS_PER_SAMPLE
from planners import ManeuverProblem
from scenarios.errors import ScenarioError
from scenarios.schema.labels import row_labels

if TYPE_CHECKING:
    from scenarios.schema.loader import ControllerSpec, PlannerSpec, SimulationSpec


def check_row_labels(planners: list[PlannerSpec], controllers: list[ControllerSpec]) -> None:
    """The rows' labels must be distinct (:func:`scenarios.schema.labels.row_labels`).

    Parameters
    ----------
    planners : list of PlannerSpec
        The scenario's planner rows.
    controllers : list of ControllerSpec
        The scenario's controllers.

    Raises
    ------
    ScenarioError
        At ``planners[i].label`` or ``controllers[j].label`` when two rows get the same label.
    """
    row_labels([planner.label for planner in planners], [controller.label for controller in controllers])


def check_magnetometer(problem: ManeuverProblem, simulation: SimulationSpec) -> None:
    """Refuse a magnetometer without a magnetic field to measure (no ``environment.magnetic_field``
    or no orbit): it would measure nothing and the run would go on as if it were not there.

    Parameters
    ----------
    problem : ManeuverProblem
        The manoeuvre, with its environment.
    simulation : SimulationSpec
        Its sensors (``sensors.magnetometer``) and noise (``sensor_noise.magnetic_field``).

    Raises
    ------
    ScenarioError
        At the magnetometer's key.
    """
    sensors = simulation.sensors
    if sensors is not None and sensors.magnetometer is not None:
        where = "simulation.sensors.magnetometer"
    elif simulation.noise.field_std > 0:
        where = "simulation.sensor_noise.magnetic_field"
    else:
        return
    environment = problem.environment
    if environment.magnetic_field is None or environment.orbit is None:
        missing = "environment.magnetic_field" if environment.magnetic_field is None else "an orbit (orbit:)"
        raise ScenarioError(where, f"a magnetometer needs a magnetic field to measure, and the scenario has no "
                                   f"{missing}; give one or remove the magnetometer")


def check_work(problem: ManeuverProblem, simulation: SimulationSpec) -> None:
    """Refuse a closed-loop window with more samples than ``simulation.max_samples`` (the run
    would take too long or exhaust memory); the runner checks again once a planner has chosen
    its own duration.

    Parameters
    ----------
    problem : ManeuverProblem
        The manoeuvre (its ``duration`` [s] is the window unless ``simulation.duration`` is set).
    simulation : SimulationSpec
        Sample time [s], window [s], integrator, RK4 step [s] and sample limit.

    Raises
    ------
    ScenarioError
        At ``simulation.sample_time`` (longer than the window), ``simulation.duration`` or
        ``maneuver.duration`` (too many samples) or ``simulation.max_step`` (too many RK4 sub-steps).
    """
    window = simulation.duration or problem.duration
    samples = math.ceil(window / simulation.sample_time - 1e-9)
    substeps = 1 if simulation.integrator != "rk4" else math.ceil(simulation.sample_time / simulation.max_step - 1e-9)
    where = "simulation.duration" if simulation.duration else "maneuver.duration"
    if simulation.sample_time > window:  # the law would act once (at t = 0) over the whole window, if at all
        raise ScenarioError("simulation.sample_time", f"{simulation.sample_time:g} s is longer than the closed-loop "
                            f"window ({where}, {window:g} s): the controller would hold its first command over "
                            f"the whole run; expected a sample time of at most {window:g} s (a fraction of it)")
    if samples > simulation.max_samples:
        raise ScenarioError(where, f"{window:g} s at a {simulation.sample_time:g} s sample time is {samples} samples, "
                                   f"over the limit of {simulation.max_samples}; raise simulation.max_samples "
                                   "if you mean it, or lengthen simulation.sample_time")
    if samples * substeps > SUBSTEPS_PER_SAMPLE * simulation.max_samples:
        raise ScenarioError("simulation.max_step", f"{samples} samples of {substeps} RK4 sub-steps each exceed the "
                            f"limit of {SUBSTEPS_PER_SAMPLE} x simulation.max_samples = "
                            f"{SUBSTEPS_PER_SAMPLE * simulation.max_samples} sub-steps; raise max_step or "
                            "simulation.max_samples")

def _check_actuated(problem: ManeuverProblem, controller: ControllerSpec) -> None:
    """Refuse a law that steers the attitude (to a target or along a reference) on a spacecraft
    without a working actuator: every wheel failed (or none) and no torquers or magnetorquers. A
    law that steers nothing (``none``: a torque-free run) or only damps the rate (``bdot``,
    ``tdfc``, which check their magnetorquers in ``environment_error``) is left alone."""
    law = controller.controller
    if not (law.needs_target_attitude or law.needs_reference or law.tracks_reference):
        return
    spacecraft = problem.spacecraft
    if spacecraft.wheel_span().shape[1] > 0 or spacecraft.residual_actuator is not None:
        return
    wheels = spacecraft.wheels
    steer = (f"{controller.path}.name {controller.name!r} has nothing to steer with: the spacecraft has no "
             "working actuator (no spacecraft.torquers or spacecraft.magnetorquers either)")
    if wheels is None or wheels.count == 0:
        raise ScenarioError("spacecraft.wheels", f"null (no wheels): {steer}; give actuators, or use controller "
                                                 "'none' for a torque-free run")
    failed = [int(index) for index in np.flatnonzero(~wheels.working)]
    raise ScenarioError("spacecraft.wheels.failed",
                        f"{failed}: every one of the {wheels.count} wheels is failed, so {steer}; leave at least one "
                        "wheel working or add actuators, or use controller 'none' for a torque-free run")


def rate_bound_notes(problem: ManeuverProblem, simulation: SimulationSpec, max_rate: float) -> list[str]:
    """What ``slewbench validate`` notes about a boundary rate above the rate requirement: every
    row then breaks it (a unit slip, deg/s typed as rad/s, shows here).

    The rates checked are ``maneuver.initial.omega`` and ``maneuver.final.omega`` (every row's
    reference and closed loop start or end there) and the closed loop's true initial rate
    ``maneuver.initial.omega + simulation.initial_rate_error`` (every row's closed loop starts
    there), each noted once.

    Parameters
    ----------
    problem : ManeuverProblem
        The manoeuvre: ``omega0`` and ``omegaf`` [rad/s], body axes (``omegaf`` ``None``: free).
    simulation : SimulationSpec
        Its ``initial_rate_error`` [rad/s], body axes.
    max_rate : float
        The bound on ``‖ω‖`` of ``requirements.rate.max`` [rad/s].

    Returns
    -------
    list of str
        One line per rate above the bound (empty when none is).
    """
    notes = []
    for where, rate in (("initial", problem.omega0), ("final", problem.omegaf)):
        if rate is not None and float(np.linalg.norm(rate)) > max_rate:
            notes.append(f"every row breaks the rate requirement: maneuver.{where}.omega has ‖ω‖ = "
                         f"{float(np.linalg.norm(rate)):.4g} rad/s, above {max_rate:g} rad/s")
    true_rate = float(np.linalg.norm(problem.omega0 + simulation.initial_rate_error))
    if np.any(simulation.initial_rate_error) and true_rate > max_rate >= float(np.linalg.norm(problem.omega0)):
        notes.append(f"every row's closed loop breaks the rate requirement: simulation.initial_rate_error "
                     f"{simulation.initial_rate_error.tolist()} starts it at ‖ω‖ = {true_rate:.4g} rad/s "
                     f"(maneuver.initial.omega plus the error), above {max_rate:g} rad/s (the key is in rad/s)")
    return notes


def reads_the_simulated_start(controllers: list[ControllerSpec]) -> bool:
    """Whether :func:`check_compatibility` reads the start as simulated (the planned start with
    ``simulation.initial_attitude_error_deg`` and ``simulation.initial_rate_error`` applied): it does
    for a law defined on part of the attitudes, one that overrides
    :meth:`controllers.Controller.initial_attitude_error` (the two-wheel laws). Those two keys are
    then not independent of the rest of the scenario (:data:`scenarios.schema.study.INDEPENDENT_KEYS`),
    and a study checks every case of such a scenario with the whole loader.

    Parameters
    ----------
    controllers : list of ControllerSpec
        The scenario's controllers, each with its validated law.

    Returns
    -------
    bool
    """
    return any(type(spec.controller).initial_attitude_error is not Controller.initial_attitude_error
               for spec in controllers)


def check_compatibility(problem: ManeuverProblem, planners: list[PlannerSpec],
                        controllers: list[ControllerSpec] | ControllerSpec,
                        simulation: SimulationSpec | None = None,
                        inapplicable: dict[int, str] | None = None) -> None:
    """What each planner and controller say they cannot take, reported at their YAML entries.

    Parameters
    ----------
    problem : ManeuverProblem
        The manoeuvre, with its spacecraft and environment.
    planners : list of PlannerSpec
        The planner rows (empty: regulation mode), each with its validated planner.
    controllers : list of ControllerSpec or ControllerSpec
        The controllers (one spec is accepted as a list of one), each with its validated law.
    simulation : SimulationSpec or None, optional
        Closed-loop settings; ``None`` skips the sample-time checks.
    inapplicable : dict or None, optional
        ``None`` (default): a planner's ``problem_error`` is raised. A dict (a study's case): it
        receives planner row index -> that reason instead, and the other checks go on.

    Raises
    ------
    ScenarioError
        At ``planners[i]`` (``problem_error``), ``<controller path>.name`` (environment, planner or
        reference needed), ``spacecraft.wheels.failed`` (a law that steers the attitude on a
        spacecraft without a working actuator), ``maneuver.<key>`` (initial or final state; ``simulation.initial_attitude_error_deg`` where the planned
        start is in a law's domain and the simulated one is not),
        ``<controller path>.options.<option>`` (sample time) or ``maneuver.final.q`` (a target
        attitude needed in regulation mode).
    """
    if not isinstance(controllers, list):  # one ControllerSpec
        controllers = [controllers]
    for index, spec in enumerate(planners):
        error = spec.planner.problem_error(problem)
        if error and inapplicable is not None:
            inapplicable[index] = error
        elif error:
            raise ScenarioError(f"planners[{index}]", error)
    for controller in controllers:
        law = controller.controller
        where = f"{controller.path}.name"
        error = law.environment_error(problem.spacecraft, problem.environment)
        if error:
            raise ScenarioError(where, error)
        _check_actuated(problem, controller)
        momentum0 = problem.wheel_momentum0
        if momentum0 is None:  # ManeuverProblem fills it in; its field's type still admits None
            momentum0 = np.zeros(problem.spacecraft.n_wheels)
        state = law.initial_state_error(problem.spacecraft, problem.omega0, momentum0, problem.omegaf)
        if not state:  # a law defined on part of the attitudes, from the start as simulated
            start = problem.initial_state if simulation is None else simulation.true_initial_state(problem)
            state = law.initial_attitude_error(problem.spacecraft, start[:4], start[4:7], problem.qf)
        if state and state[0] == "initial.q" and simulation is not None \
                and not law.initial_attitude_error(problem.spacecraft, problem.q0, problem.omega0, problem.qf):
            # the planned start is in the law's domain: the simulated start's errors take it out
            given = np.round(np.rad2deg(simulation.initial_attitude_error), 6).tolist()
            raise ScenarioError("simulation.initial_attitude_error_deg",
                                f"{given} deg takes the start as simulated (maneuver.initial.q turned by it, "
                                f"maneuver.initial.omega plus simulation.initial_rate_error) out of the domain of "
                                f"{controller.path}: {state[1]} ({controller.path} is {controller.name!r})")
        if state:
            raise ScenarioError(f"maneuver.{state[0]}", f"{state[1]} ({controller.path} is {controller.name!r})")
        if simulation is not None:
            timing = law.sample_time_error(simulation.sample_time)
            if timing:
                raise ScenarioError(f"{controller.path}.options.{timing[0]}",
                                    f"{timing[1]} (simulation.sample_time is {simulation.sample_time:g} s)")
            # The run's length where the load knows it: simulation.duration, else in regulation the
            # manoeuvre's (with planners the window also covers the reference, known after planning).
            window = (("simulation.duration", simulation.duration) if simulation.duration is not None
                      else ("maneuver.duration", problem.duration) if not planners else None)
            length = law.run_length_error(window[1]) if window is not None else None
            if length and window is not None:
                raise ScenarioError(f"{controller.path}.options.{length[0]}",
                                    f"{length[1]} ({window[0]} is {window[1]:g} s)")
        if not planners and problem.qf is None and law.needs_target_attitude:
            raise ScenarioError("maneuver.final.q", f"regulation (no planners) with controller {controller.name!r} "
                                "needs a target attitude; only laws that need none (e.g. bdot, tdfc, none) "
                                "accept a free final attitude")
        if not planners and law.needs_reference:
            raise ScenarioError(where, f"controller {controller.name} tracks a reference; give planners")
        for index, spec in enumerate(planners):
            error = law.planner_error(spec.name, spec.options)
            if error:
                raise ScenarioError(where, f"{error} (planners[{index}] is {spec.name!r})")
