"""Run a scenario: plan with every planner, track each reference in closed loop, score both.

:func:`run` returns :class:`RunResults`, whose rows carry the metrics, the reference and the
simulation, and which render to JSON, CSV and Markdown (see :mod:`scenarios.output.tables`).
"""
from __future__ import annotations

import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ocp import (
    SimulationError,
    SimulationResult,
    Simulator,
    SolverCache,
    metric_violations,
    metrics_from_reference,
    metrics_from_simulation,
)
from planners import FailedReference, Reference
from scenarios.schema.loader import ControllerSpec, Scenario


@dataclass
class Row:
    """One planner and controller pair (in regulation mode, the controller alone) and its scores.

    Parameters
    ----------
    label : str
        The planner's label, or the controller's in regulation mode; with several controllers a
        planner's rows are labelled ``"<planner label> / <controller label>"``.
    planner : str or None
        Planner registry name; ``None`` in regulation mode.
    status : str
        ``"ok"`` or ``"failed"`` (a failed planner, simulation or unphysical metrics).
    message : str
        Why it failed (empty when ok).
    plan_time_s : float or None
        Planning time [s]; ``None`` in regulation mode.
    reference_metrics : dict or None
        Metrics of the reference itself (ARCHITECTURE.md's metric keys); ``None`` without one.
    closed_loop_metrics : dict or None
        Metrics of the closed-loop simulation; ``None`` when it was not simulated.
    reference : planners.Reference or None, optional
        The planned reference.
    simulation : ocp.SimulationResult or None, optional
        The closed-loop time series.
    simulate_time_s : float, optional
        Simulation time [s].
    controller : str or None, optional
        Controller registry name.
    """

    label: str
    planner: str | None
    status: str
    message: str
    plan_time_s: float | None
    reference_metrics: dict[str, Any] | None
    closed_loop_metrics: dict[str, Any] | None
    reference: Reference | None = field(default=None, repr=False)
    simulation: SimulationResult | None = field(default=None, repr=False)
    simulate_time_s: float = 0.0
    controller: str | None = None

    def to_dict(self) -> dict[str, Any]:
        """The row as ARCHITECTURE.md's ``results.json`` writes it.

        Returns
        -------
        dict
            ``label``, ``planner``, ``controller``, ``status``, ``message``, ``plan_time_s``,
            ``reference`` and ``closed_loop`` (the two metric dicts).
        """
        return {"label": self.label, "planner": self.planner, "controller": self.controller,
                "status": self.status, "message": self.message,
                "plan_time_s": self.plan_time_s, "reference": self.reference_metrics,
                "closed_loop": self.closed_loop_metrics}


@dataclass
class RunResults:
    """Rows of a scenario run. ``to_json``, ``to_csv``, ``to_markdown``, ``to_dataframe`` and
    ``write`` render them (implemented in :mod:`scenarios.output.tables` and :mod:`scenarios.output.directory`).

    Parameters
    ----------
    scenario : scenarios.schema.loader.Scenario
        The scenario that was run.
    rows : list of Row
        One per planner and controller pair (per controller in regulation mode).
    """

    scenario: Scenario
    rows: list[Row]

    def to_dict(self) -> dict[str, Any]:
        """The results as a plain dict.

        Returns
        -------
        dict
            ``{"scenario": name, "rows": [Row.to_dict(), ...]}``.
        """
        return {"scenario": self.scenario.name, "rows": [row.to_dict() for row in self.rows]}

    def to_json(self) -> str:
        """``results.json``'s text.

        Returns
        -------
        str
        """
        from scenarios.output.tables import to_json
        return to_json(self)

    def to_csv(self) -> str:
        """``results.csv``'s text (one line per row, metrics as columns).

        Returns
        -------
        str
        """
        from scenarios.output.tables import to_csv
        return to_csv(self)

    def to_markdown(self) -> str:
        """``results.md``'s text (a Markdown table).

        Returns
        -------
        str
        """
        from scenarios.output.tables import to_markdown
        return to_markdown(self)

    def to_terminal(self) -> str:
        """The summary table ``slewbench run`` prints.

        Returns
        -------
        str
        """
        from scenarios.output.tables import to_terminal
        return to_terminal(self)

    def to_dataframe(self) -> Any:
        """The CSV table as a pandas DataFrame (needs pandas installed).

        Returns
        -------
        pandas.DataFrame
        """
        from scenarios.output.tables import to_dataframe
        return to_dataframe(self)

    def write(self, directory: str | Path, plots: bool = True, renderer: Any = None) -> None:
        """Write results.json/csv/md, time series and plots atomically.

        Parameters
        ----------
        directory : str or pathlib.Path
            Output directory (created; slewbench never overwrites files it did not write).
        plots : bool, optional
            Also write the PNG figures.
        renderer : scenarios.output.renderer.Renderer, optional
            A plot process to draw them (``None``: drawn in this process).
        """
        from scenarios.output.directory import write_results
        write_results(self, directory, plots=plots, renderer=renderer)


def _simulate(scenario: Scenario, simulator: Simulator, reference: Reference | None, row: Row,
              controller_spec: ControllerSpec | None = None) -> None:
    problem = scenario.problem
    spec = controller_spec or scenario.controller
    duration = scenario.simulation.duration or max(problem.duration, reference.duration if reference else 0.0)
    controller = spec.controller
    start = time.perf_counter()
    try:
        result = simulator.run(controller, scenario.true_initial_state, duration, reference=reference,
                               target=(problem.qf, problem.omegaf), noise=scenario.simulation.noise)
    except SimulationError as error:
        row.status, row.message = "failed", f"simulation: {error}"
        return
    finally:
        row.simulate_time_s = time.perf_counter() - start
    row.simulation = result
    row.closed_loop_metrics = metrics_from_simulation(
        result, problem.qf, problem.omegaf, reference=reference, plan_time_s=row.plan_time_s,
        duration_s=reference.duration if reference else None,
        settling_tolerance_deg=scenario.simulation.settling_tolerance_deg,
        fine_settling_tolerance_deg=scenario.simulation.fine_settling_tolerance_deg,
        detumble_tolerance=scenario.simulation.detumble_tolerance)
    _check_physical(row, "closed loop", row.closed_loop_metrics)


def _check_physical(row: Row, scope: str, metrics: dict[str, Any] | None) -> None:
    """A row whose metrics physics forbids (negative, non-finite) is failed, not "ok"."""
    problems = metric_violations(metrics)
    if problems and row.status == "ok":
        row.status = "failed"
        row.message = f"{scope} metrics are not physical ({'; '.join(problems)}): the result cannot be trusted"


def run(scenario: Scenario, progress: Callable[[str], None] | None = None,
        cache: SolverCache | None = None, simulators: SolverCache | None = None) -> RunResults:
    """Plan, simulate and score every planner of ``scenario``.

    Parameters
    ----------
    scenario : a loaded scenario.
    progress : receives a line of text per finished row.
    cache : solvers built by planners, shared across runs (a trade-study worker passes one).
    simulators : simulators (and their closed-loop functions) shared across runs, keyed by the
        model's fingerprint and the simulation settings; anything with SolverCache's ``get``
        (a trade-study worker passes a bounded one). None: a new simulator per run.

    Returns
    -------
    RunResults
        One row per planner and controller pair (in regulation mode, one per controller).
    """
    say = progress or (lambda line: None)
    spec = scenario.simulation
    model = scenario.problem.model

    def build() -> Simulator:
        return Simulator(model, spec.sample_time, spec.integrator, max_step=spec.max_step,
                         max_samples=spec.max_samples, compile=spec.compile)

    simulator = build() if simulators is None else simulators.get(
        ("simulator", model.fingerprint, spec.sample_time, spec.integrator, spec.max_step, spec.max_samples,
         spec.compile), build)
    controllers = scenario.controllers
    rows = []
    if not scenario.planners:
        for index, controller in enumerate(controllers, start=1):
            row = Row(controller.label, None, "ok", "regulation to the target", None, None, None,
                      controller=controller.name)
            _simulate(scenario, simulator, None, row, controller)
            say(f"[{index}/{len(controllers)}] {row.label}: {row.status} (simulated in {row.simulate_time_s:.2f} s)"
                + (f" - {row.message}" if row.status != "ok" else ""))
            rows.append(row)
        return RunResults(scenario, rows)
    total = len(scenario.planners) * len(controllers)
    for planner_spec in scenario.planners:
        planner = planner_spec.planner.with_cache(cache)
        try:
            reference = planner.plan(scenario.problem)
        except Exception as error:  # a planner bug must not lose the other rows
            traceback.print_exc()
            reference = FailedReference(planner_spec.name, f"planner raised {type(error).__name__}: {error}")
        reference_metrics = None
        if reference.ok:
            reference_metrics = metrics_from_reference(
                reference, scenario.problem.qf, scenario.problem.omegaf,
                settling_tolerance_deg=spec.settling_tolerance_deg,
                fine_settling_tolerance_deg=spec.fine_settling_tolerance_deg,
                inertia=scenario.problem.spacecraft.inertia, detumble_tolerance=spec.detumble_tolerance,
                initial_omega=scenario.problem.omega0)
        for controller in controllers:
            label = planner_spec.label if len(controllers) == 1 else f"{planner_spec.label} / {controller.label}"
            row = Row(label, planner_spec.name, reference.status, reference.message,
                      reference.plan_time_s, None if reference_metrics is None else dict(reference_metrics), None,
                      reference, controller=controller.name)
            if reference.ok:
                _check_physical(row, "reference", row.reference_metrics)
                _simulate(scenario, simulator, reference, row, controller)
            rows.append(row)
            say(f"[{len(rows)}/{total}] {row.label}: {row.status} "
                f"(planned in {(row.plan_time_s or 0.0) * 1e3:.1f} ms, simulated in {row.simulate_time_s:.2f} s)"
                + (f" - {row.message}" if row.status != "ok" else ""))
    return RunResults(scenario, rows)
