"""A run's results: its rows (a planner and controller pair and their scores) and their plain form.

:class:`Row` is one row; :meth:`Row.to_dict` is its plain, nested form, the one ``results.json``
writes and a trade study stores for each case (a crashed case's rows are :class:`Row` too).
:class:`RunResults` holds a run's rows and renders them (:mod:`scenarios.output.tables`,
:mod:`scenarios.output.writer`). The flat form of a row (``ref.<metric>``, ``cl.<metric>``
columns) is derived from :meth:`Row.to_dict` by :func:`scenarios.output.tables.flatten_row`.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import pandas

    from ocp import SimulationResult
    from planners import Reference
    from scenarios.schema.loader import Scenario

__all__ = ["Row", "RunResults"]


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
        scenario); ``"failed"`` (a failed planner or simulation, unphysical metrics, or a pointing
        requirement the end points already break); or, in a trade study, ``"crashed"`` (the case
        raised, timed out or lost its worker). Ranked crashed, failed > violated > ok.
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
        then field (:mod:`scenarios.requirements.scoring`); ``None`` when the scenario has no
        requirements.
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

    def to_dict(self) -> dict[str, Any]:
        """The row's plain, nested form: a ``results.json`` row and a trade study's stored row.

        Values are as computed (a non-finite metric stays a float); each writer applies the rule
        of :mod:`scenarios.output.tables` (JSON ``null``, an empty CSV cell, NaN in a DataFrame).

        Returns
        -------
        dict
            ``label``, ``planner``, ``controller``, ``status``, ``message``, ``plan_time_s``,
            ``reference`` and ``closed_loop`` (the two metric dicts, or ``None``) and
            ``requirements`` (the requirement scores by scope, name and field, or ``None``).
        """
        return {"label": self.label, "planner": self.planner, "controller": self.controller,
                "status": self.status, "message": self.message,
                "plan_time_s": self.plan_time_s, "reference": self.reference_metrics,
                "closed_loop": self.closed_loop_metrics, "requirements": self.requirements}


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
    """

    scenario: Scenario
    rows: list[Row]

    def to_dict(self) -> dict[str, Any]:
        """The results as a plain dict.

        Returns
        -------
        dict
            ``{"scenario": name, "frame": ..., "epoch": ..., "rows": [Row.to_dict(), ...]}``: the
            inertial frame the attitudes are in (``GCRF`` with an epoch, else ``inertial (no
            epoch)``) and the epoch (UTC, ISO 8601 with ``Z``, or ``None``).
        """
        epoch = self.scenario.epoch
        return {"scenario": self.scenario.name, "frame": self.scenario.frame,
                "epoch": None if epoch is None else epoch.isoformat() + "Z",
                "rows": [row.to_dict() for row in self.rows]}

    def status_counts(self) -> dict[str, int]:
        """How many rows have each status, in rank order (``failed``, ``violated``, ``ok``, then any other).

        Returns
        -------
        dict of str to int
            Status -> number of rows (statuses without rows left out).
        """
        order = ["crashed", "failed", "violated", "ok"]
        counts = {status: sum(row.status == status for row in self.rows) for status in order}
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

    def to_terminal(self) -> str:
        """The summary table ``slewbench run`` prints.

        Returns
        -------
        str
        """
        from scenarios.output.tables import to_terminal
        return to_terminal(self)

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
        """
        from scenarios.output.writer import write_results
        write_results(self, directory, plots=plots, renderer=renderer)
