"""A run's results: its rows (a planner and controller pair and their scores) and their plain form.

:class:`Row` is one row; :meth:`Row.to_dict` is its plain, nested form, the one ``results.json``
writes and a trade study stores for each case (a crashed case's rows are :class:`Row` too).
:class:`RunResults` holds a run's rows and renders them (:mod:`scenarios.output.tables`,
:mod:`scenarios.output.writer`). The flat form of a row (``ref.<metric>``, ``cl.<metric>``
columns) is derived from :meth:`Row.to_dict` by :func:`scenarios.output.tables.flatten_row`.
"""
from __future__ import annotations

import datetime
import os
import textwrap
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ocp.errors import excerpt
from scenarios.output.provenance import run_provenance
from scenarios.output.tables import (
    ROW_STATUSES,
    html_table,
    is_missing,
    run_rows,
    status_line,
    text_cell,
)

if TYPE_CHECKING:
    import pandas

    from ocp import SimulationResult
    from planners import Reference
    from scenarios.schema.loader import Scenario

__all__ = ["HEADLINE_METRICS", "Row", "RunResults"]

HEADLINE_METRICS = (("final_error_deg", "settling_time_s", "int_u", "peak_actuator_torque"),
                    ("final_rate", "detumble_time_s", "int_u", "int_dipole"))
"""The metrics a row's repr and a run's notebook table show (those with a value; closed loop, else
the reference's): a slew's, or, when the row has no ``final_error_deg`` (a free final attitude,
detumbling), a rate acquisition's. Units in :data:`ocp.metrics.METRIC_INFO`."""
_MESSAGE_CHARS = 100
"""Characters of a row's message in a repr."""


def _short(message: str) -> str:
    """A message on one line, cut to :data:`_MESSAGE_CHARS`."""
    return textwrap.shorten(message, _MESSAGE_CHARS, placeholder=" ...")


@dataclass
class Row:
    """One planner and controller pair (in regulation mode, the controller alone) and its scores.

    Parameters
    ----------
    label : str
        The row's label (:func:`scenarios.schema.labels.row_labels`): the planner's label, or the
        controller's in regulation mode; with several controllers ``"<planner label> / <controller
        label>"``.
    planner : str or None
        Planner registry name; ``None`` in regulation mode.
    status : str
        ``"ok"``; ``"violated"`` (the reference or the closed loop breaks a requirement of the
        scenario); ``"infeasible"`` (proven that no motion meets the problem: before planning, a
        pointing requirement the end points already break or a rate requirement that cannot turn
        the angle within ``maneuver.duration``; or by the planner under its bounds, a slew longer
        than ``maneuver.duration`` included); ``"failed"`` (a failed planner or simulation, or
        unphysical metrics); or, in a trade study, ``"crashed"`` (the case raised, timed out or lost
        its worker). Ranked as :data:`~scenarios.output.tables.ROW_STATUSES`: crashed > failed >
        infeasible > violated > ok.
    message : str
        Why it failed or what it breaks, and what its planner does not honour (may be empty when ok).
    plan_time_s : float or None
        Planning time [s]; ``None`` in regulation mode and for a crashed case.
    reference_metrics : dict or None
        Metrics of the reference itself (keys of :data:`ocp.METRIC_KEYS`); ``None`` without one.
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
    requirements : dict or None, optional
        The requirement scores by scope (``reference``, ``closed_loop``), then requirement name,
        then field (:mod:`scenarios.requirements.scoring`), the verdict ``met`` (a bool) first;
        ``None`` when the scenario has no requirements.
    plan_reused : bool, optional
        Whether the row's reference was not planned for it but reused from an earlier run's
        identical planning inputs (a trade study's worker, :func:`scenarios.runner.run`'s
        ``references``); its ``plan_time_s`` is then that earlier plan's. Default False (planned
        for the row, or no planner: regulation mode, a crashed case).
    needed_duration_s : float or None, optional
        For an ``infeasible`` row whose slew does not fit ``maneuver.duration`` (its time budget),
        the least budget known to be needed [s], above it
        (:func:`scenarios.runner.needed_duration`): the refused reference's own duration, or a
        lower bound proven before or instead of planning; None (default) for any other row.
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
    requirements: dict[str, dict[str, dict[str, Any]]] | None = None
    plan_reused: bool = False
    needed_duration_s: float | None = None

    def to_dict(self) -> dict[str, Any]:
        """The row's plain, nested form: a ``results.json`` row and a trade study's stored row.

        Values are as computed (a non-finite metric stays a float); each writer applies the rule
        of :mod:`scenarios.output.tables` (JSON ``null``, an empty CSV cell, NaN in a DataFrame).

        Returns
        -------
        dict
            ``label``, ``planner``, ``controller``, ``status``, ``message``, ``plan_time_s``,
            ``plan_reused``, ``needed_duration_s``, ``reference`` and ``closed_loop`` (the two metric dicts, or ``None``) and
            ``requirements`` (the requirement scores by scope, name and field, or ``None``) and
            ``certificate`` (the reference's ``stats["certificate"]``, :mod:`ocp.nlp.certificate`,
            or ``None``: no reference, or a planner that writes none).
        """
        certificate = None if self.reference is None else self.reference.stats.get("certificate")
        return {"label": self.label, "planner": self.planner, "controller": self.controller,
                "status": self.status, "message": self.message,
                "plan_time_s": self.plan_time_s, "plan_reused": self.plan_reused,
                "needed_duration_s": self.needed_duration_s, "reference": self.reference_metrics,
                "closed_loop": self.closed_loop_metrics, "requirements": self.requirements,
                "certificate": None if certificate is None else dict(certificate)}

    def headline(self) -> dict[str, Any]:
        """The row's key numbers: the :data:`HEADLINE_METRICS` it has a value for.

        Returns
        -------
        dict
            Metric key -> value (:data:`HEADLINE_METRICS`), from the closed loop when it was
            simulated, else from the reference (empty for a failed row without either).
        """
        metrics = self.closed_loop_metrics or self.reference_metrics or {}
        keys = HEADLINE_METRICS[0] if not is_missing(metrics.get("final_error_deg")) else HEADLINE_METRICS[1]
        return {key: metrics[key] for key in keys if not is_missing(metrics.get(key))}

    def __repr__(self) -> str:
        pair = " / ".join(name for name in (self.planner or "regulation", self.controller) if name)
        numbers = ", ".join(f"{key}={text_cell(value)}" for key, value in self.headline().items())
        message = _short(self.message) if self.status != "ok" else ""
        return (f"<Row {self.label!r}: {self.status} ({pair})" + (f"; {numbers}" if numbers else "")
                + (f"; {message}" if message else "") + ">")

    def _repr_html_(self) -> str:
        return _rows_html([self], caption=f"Row {self.label}")


@dataclass
class RunResults:
    """Rows of a scenario run. ``to_json``, ``to_csv``, ``to_markdown``, ``to_dataframe`` and
    ``write`` render them (implemented in :mod:`scenarios.output.tables` and
    :mod:`scenarios.output.writer`).

    Parameters
    ----------
    scenario : scenarios.schema.loader.Scenario
        The scenario that was run.
    rows : list of Row
        One per planner and controller pair (per controller in regulation mode).
    finished : datetime.datetime, optional
        When the run finished, UTC (default: when the results were made), recorded in
        ``results.json``'s provenance.
    """

    scenario: Scenario
    rows: list[Row]
    finished: datetime.datetime = field(default_factory=lambda: datetime.datetime.now(datetime.timezone.utc),
                                        compare=False)

    def to_dict(self) -> dict[str, Any]:
        """The results as a plain dict.

        Returns
        -------
        dict
            ``{"scenario": name, "frame": ..., "epoch": ..., "rows": [Row.to_dict(), ...],
            "provenance": {...}}``, each row with ``file_stem`` too, the stem of its files in
            the output directory (:func:`~scenarios.output.tables.run_rows`): the inertial frame
            the attitudes are in (:attr:`Scenario.frame <scenarios.schema.loader.Scenario.frame>`: ``GCRF (epoch ...Z)``
            with an epoch, else ``inertial (no epoch)``), the epoch (UTC, ISO 8601 with ``Z``, or
            ``None``) and what produced the results
            (:func:`~scenarios.output.provenance.run_provenance`: versions, platform, date, seeds
            and the scenario's YAML data).
        """
        epoch = self.scenario.epoch
        return {"scenario": self.scenario.name, "frame": self.scenario.frame,
                "epoch": None if epoch is None else epoch.isoformat() + "Z",
                "rows": run_rows(self),
                "provenance": run_provenance(self.scenario, self.finished)}

    def __repr__(self) -> str:
        lines = [f"<RunResults {self.scenario.name!r}: {status_line(self)}"]
        lines += [f"  {row!r}" for row in self.rows]
        return "\n".join(lines) + ">"

    def _repr_html_(self) -> str:
        return _rows_html(self.rows, caption=f"{self.scenario.name}: {status_line(self)}")

    def status_counts(self) -> dict[str, int]:
        """How many rows have each status, in rank order (:data:`~scenarios.output.tables.ROW_STATUSES`,
        then any other).

        Returns
        -------
        dict of str to int
            Status -> number of rows (statuses without rows left out).
        """
        counts = {status: sum(row.status == status for row in self.rows) for status in ROW_STATUSES}
        for row in self.rows:
            counts.setdefault(row.status, sum(other.status == row.status for other in self.rows))
        return {status: count for status, count in counts.items() if count}

    def to_json(self) -> str:
        """``results.json``'s text (non-finite numbers written as ``null``).

        Returns
        -------
        str
        """
        from scenarios.output.tables import to_json
        return to_json(self)

    def to_csv(self) -> str:
        """``results.csv``'s text (one line per row, the columns of
        :func:`scenarios.output.tables.row_columns`).

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

    def to_terminal(self, all_metrics: bool = False) -> str:
        """The summary table ``slewbench run`` prints.

        Parameters
        ----------
        all_metrics : bool, optional
            Also the metrics that have no value in any row (left out by default).

        Returns
        -------
        str
        """
        from scenarios.output.tables import to_terminal
        return to_terminal(self, all_metrics=all_metrics)

    def to_dataframe(self) -> pandas.DataFrame:
        """The CSV table as a pandas DataFrame (needs pandas installed); numeric columns are float,
        with NaN where a value is missing or non-finite.

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

        Raises
        ------
        TypeError
            ``directory`` is not a path, or ``plots`` not a bool (as
            :meth:`scenarios.study.engine.SweepResults.write`).
        scenarios.output.directory.OutputError
            The directory is not slewbench's to write (:doc:`/outputs`).
        """
        if not isinstance(directory, (str, os.PathLike)):
            raise TypeError(f"directory must be a str or os.PathLike, got {type(directory).__name__}")
        if not isinstance(plots, bool):  # plots="no" drew them
            raise TypeError(f"plots must be True or False, got {excerpt(plots)}")
        from scenarios.output.writer import write_results
        write_results(self, directory, plots=plots, renderer=renderer)


def _rows_html(rows: list[Row], caption: str) -> str:
    """Rows as a small HTML table: label, planner, controller, status, planning time, the headline
    metrics any row has, and the message cut short."""
    headlines = [row.headline() for row in rows]
    keys = list(dict.fromkeys(key for numbers in headlines for key in numbers))
    columns = ["label", "planner", "controller", "status", "plan_time_s", *keys, "message"]
    records = [[row.label, row.planner or "regulation", row.controller, row.status, row.plan_time_s,
                *(numbers.get(key) for key in keys), _short(row.message)] for row, numbers in zip(rows, headlines)]
    return html_table(columns, records, caption)
