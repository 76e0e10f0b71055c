"""A run's ``report.html``: its rows as a sortable table and its figures, interactive.

The page (:class:`~scenarios.output.report.page.Page`) holds, in order: the sign-off record
(:func:`~scenarios.output.report.record.add_record`: the provenance, the plant (design and truth
model), the sensors and estimator, and the requirements with, per row, their bounds, the values
achieved and the verdicts), the rows table (identity,
status and message, then the requirement and the metric columns of ``results.csv`` with their
units; columns without a value in any row left out), each simulated row against time
(:func:`~scenarios.output.report.figures.row_figure`), each pointing requirement's margin
(:func:`~scenarios.output.report.figures.margin_figure`) and boresight on the celestial sphere
(:func:`~scenarios.output.report.figures.sky_figure`), and the attitude in 3-D of a row chosen
from a list (:func:`~scenarios.output.report.figures.attitude_figure`).
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ocp.metrics import METRIC_INFO
from scenarios.output.report.figures import (
    attitude_figure,
    margin_figure,
    row_figure,
    sky_figure,
)
from scenarios.output.report.page import Column, Page, column_unit
from scenarios.output.report.record import add_record
from scenarios.output.tables import (
    IDENTITY_COLUMNS,
    ROW_STATUSES,
    flatten_row,
    is_missing,
    requirement_columns,
    row_columns,
)
from scenarios.requirements.fields import is_requirement_column

if TYPE_CHECKING:
    from scenarios.output.results import RunResults

__all__ = ["result_columns", "run_page", "run_report"]



def result_columns(names: list[str], rows: list[dict[str, Any]]) -> list[Column]:
    """The table columns of flat result rows: units, numeric columns and meanings.

    Parameters
    ----------
    names : list of str
        Column names (``results.csv``'s, or ``cases.csv``'s).
    rows : list of dict
        The flat rows (:func:`scenarios.output.tables.flatten_row`), to tell numbers from text.

    Returns
    -------
    list of Column
        One per name: the unit of :func:`~scenarios.output.report.page.column_unit`, numeric when
        every value present is a number, the metric's meaning from :data:`ocp.metrics.METRIC_INFO`,
        and the status order for ``status``.
    """
    columns = []
    for name in names:
        present = [row.get(name) for row in rows if not is_missing(row.get(name))]
        numeric = bool(present) and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in present)
        metric = name.split(".")[-1]
        info = METRIC_INFO.get(metric) if name.count(".") == 1 else None
        columns.append(Column(name, column_unit(name), numeric, info.meaning if info else "",
                              ROW_STATUSES if name == "status" else ()))
    return columns


def run_report(results: RunResults) -> str:
    """The HTML of a run's interactive report (module docstring).

    Parameters
    ----------
    results : RunResults
        The run (its rows with their references and simulations, and its scenario).

    Returns
    -------
    str
        A self-contained HTML document.
    """
    return run_page(results).render()


def run_page(results: RunResults) -> Page:
    """The page of a run's interactive report (:func:`run_report`), to render as text or as the
    bytes of its file (:meth:`~scenarios.output.report.page.Page.render_bytes`).

    Parameters
    ----------
    results : RunResults
        The run (its rows with their references and simulations, and its scenario).

    Returns
    -------
    Page
        The page, with every section, table and figure.
    """
    scenario = results.scenario
    flat = [flatten_row(row.to_dict()) for row in results.rows]
    everything = row_columns(requirement_columns([row.to_dict() for row in results.rows]))
    ordered = ([c for c in everything if c in IDENTITY_COLUMNS] + [c for c in everything if is_requirement_column(c)]
               + [c for c in everything if c not in IDENTITY_COLUMNS and not is_requirement_column(c)])
    names = [name for name in ordered if name in IDENTITY_COLUMNS or any(not is_missing(row.get(name)) for row in flat)]
    counts = ", ".join(f"{n} {status}" for status, n in results.status_counts().items())
    frame = (f"attitudes in the frame {scenario.frame}, times in seconds from the epoch (UTC)"
             if scenario.epoch is not None else "attitudes in an inertial frame tied to no date (no epoch)")
    lines = [f"{len(results.rows)} rows ({counts}); {frame}."]
    if scenario.source is not None:
        lines.append(f"Scenario file: {scenario.source.name}")
    page = Page(f"{scenario.name}: slewbench run", lines)
    add_record(page, results)
    page.section("Rows", "One row per planner and controller; click a header to sort (again to reverse). "
                         "ref.* columns score the reference, cl.* the closed loop; req.<name>.<field> columns "
                         "score the requirements. Missing values: -.")
    page.table("rows", result_columns(names, flat), [[row.get(name) for name in names] for row in flat])
    simulated = [row for row in results.rows if row.simulation is not None]
    if simulated:
        page.section("Time histories", "Drag to zoom (all panels share the time axis), double-click to reset; "
                                       "click a legend entry to hide a curve.")
        for k, row in enumerate(results.rows):
            if row.simulation is not None:
                page.figure(f"row-{k}", row_figure(row, scenario))
    constraints = list(scenario.problem.pointing)
    if constraints and simulated:
        page.section("Pointing margins", "Margin of each pointing requirement against time: the angle from the "
                                         "cone's edge, negative inside a keep-out cone (or outside a keep-in one).")
        for k, constraint in enumerate(constraints):
            page.figure(f"margin-{k}", margin_figure(constraint, results.rows))
        page.section("Celestial sphere", "The constrained boresight's direction in the inertial frame, with the "
                                         "cone about its direction.")
        for k, constraint in enumerate(constraints):
            page.figure(f"sky-{k}", sky_figure(constraint, results.rows, scenario.frame))
    if simulated:
        page.section("Attitude in 3-D", "Body axes (x red, y green, z blue) and the constrained sensors' "
                                        "boresights in the inertial frame; drag to turn, use the slider or play.")
        page.choice("attitude", "row", [(row.label, attitude_figure(row, scenario)) for row in simulated])
    return page
