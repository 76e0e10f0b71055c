"""A trade study's ``report.html``: its tables, sortable, and the distributions of its summary metrics.

Built on the run report's page (:class:`scenarios.output.report.page.Page`): plotly.js inline, the
tables' values exactly as in the CSV files (a bool ``True`` or ``False``), opening offline. In order:

* the fraction of cases meeting every requirement per planner, then each requirement in each scope
  (``requirements.csv``), with a note when some cases were scored before per-requirement verdicts
  were stored (:func:`scenarios.study.report.verdict_note`);
* for a Monte Carlo study, the robustness tables (:mod:`scenarios.study.robustness`): the
  fractions meeting every requirement and each threshold, the rank correlations and the worst cases;
* the summary statistics (``summary.csv``), with each metric's unit;
* one step histogram per summary metric, the planner rows overlaid, each on its own bins, on a
  logarithmic axis when the values are positive and span more than :data:`LOG_SPAN`;
* a scatter of any two numeric columns of the cases, chosen by the reader (a dispersed vector
  gives one choice per component), coloured by row label;
* the cases (``cases.csv``), :data:`PAGE_SIZE` rows at a time, with a filter: the case, its row
  label and status, the summary metrics and the varied values first, then the other columns;
  columns without a value in any row are left out.
"""
from __future__ import annotations

import json
from typing import Any

import numpy as np

from scenarios.output.provenance import package_version
from scenarios.output.report.page import Column, Page, column_unit
from scenarios.output.report.run import result_columns
from scenarios.output.tables import IDENTITY_COLUMNS, is_missing, text_cell
from scenarios.schema.keys import Section
from scenarios.schema.loader import SCENARIO
from scenarios.study.paths import parse_path
from scenarios.study.report import REQUIREMENT_TEXT, metric_values, verdict_note
from scenarios.study.types import Study

__all__ = ["LOG_SPAN", "PAGE_SIZE", "ROBUSTNESS_SECTIONS", "histogram_figure", "path_unit", "study_report"]

PAGE_SIZE = 50
"""Rows of the cases table shown at once."""
LOG_SPAN = 100.0
"""A histogram's axis is logarithmic when its positive values' largest over smallest exceeds this."""
BINS = 40
"""Bins of a histogram."""
ROBUSTNESS_SECTIONS = (
    ("Robustness", ("Fraction of the completed cases meeting every requirement and each threshold of "
                    "robustness.thresholds, with the Wilson 95 % interval (robustness.csv). As in the summary, only "
                    "rows ok or violated count: a failed or infeasible row is completed and meets no threshold "
                    "whatever its values; excluded: the rows left out (failed, infeasible, crashed).")),
    ("Sensitivity", ("Spearman rank correlation of each summary metric with each drawn quantity (one per number a "
                     "dispersion draws: a whole-tensor scale is one factor; draw: value, scale, offset or principal), "
                     "over the rows ok or violated where the metric has a value, a case that never settled ranked "
                     "after every settled one; excluded: the rows left out. rho_low, rho_high: its 95 % interval; "
                     "p_value: two-sided (exact up to 8 cases, else the t approximation); p_holm: adjusted over the "
                     "group's correlations, and significant when at most 0.05 (sensitivity.csv).")),
    ("Worst cases", ("The largest values of each summary metric (smallest for an at_least threshold) among the rows "
                     "ok or violated, by case id (inf: the case never settled; excluded: the rows left out); re-run "
                     "one in full with slewbench sweep DIR --case N (worst_cases.csv).")),
)
"""Titles and explanations of the robustness sections, in the order of the robustness tables."""
_COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f")


def path_unit(path: str) -> str:
    """The unit of a scenario key a study varies, as the schema declares it.

    Parameters
    ----------
    path : str
        A scenario path (``simulation.initial_rate_error``, ``spacecraft.inertia[2]``).

    Returns
    -------
    str
        The key's unit as written in YAML (``deg``, ``rad/s``, ...); empty when it has none or
        the schema does not declare it (a planner's option).
    """
    section: Section | None = SCENARIO
    unit = ""
    try:
        steps = parse_path(path, path)
    except Exception:  # noqa: BLE001 - a path the study already checked; no unit rather than an error
        return ""
    for step in steps:
        if not isinstance(step, str):
            continue  # an index or selector: the same key's unit
        if section is None:
            return ""
        try:
            key = section[step]
        except KeyError:
            return ""
        unit, section = key.unit, key.section
    return unit


def _vector(value: Any) -> Any:
    """A dispersed vector recorded as JSON text (``"[0.1, -0.2, 0.3]"``) as its list; else the value."""
    if isinstance(value, str) and value.startswith("["):
        try:
            parsed = json.loads(value)
        except ValueError:
            return value
        if isinstance(parsed, list) and all(isinstance(v, (int, float)) for v in parsed):
            return parsed
    return value


def _values(rows: list[dict[str, Any]], column: str, label: str) -> np.ndarray:
    """The finite values of ``column`` in the rows of ``label`` that count in the summary's statistics
    (:func:`scenarios.study.report.metric_values` with ``counted_only``: a failed row is left out)."""
    values = metric_values(column, [row for row in rows if row.get("label") == label], counted_only=True)
    return values[np.isfinite(values)]


def _edges(values: np.ndarray, log: bool) -> np.ndarray:
    """:data:`BINS` bins over the values' range (log-spaced on a logarithmic axis; a range of one
    value widened by 0.1 % about it)."""
    low, high = float(values.min()), float(values.max())
    if high - low <= 1e-12 * max(abs(low), abs(high), 1e-300):
        half = max(abs(low) * 1e-3, 1e-12)
        low, high = (low / 1.001, high * 1.001) if log else (low - half, high + half)
    return np.geomspace(low, high, BINS + 1) if log else np.linspace(low, high, BINS + 1)


def histogram_figure(column: str, rows: list[dict[str, Any]], labels: list[str]) -> dict[str, Any]:
    """A step histogram of one metric column, one curve per row label on its own bins.

    Parameters
    ----------
    column : str
        A metric column of ``cases.csv`` (``cl.final_error_deg``).
    rows : list of dict
        The cases' rows (:func:`scenarios.study.report.case_table`).
    labels : list of str
        The row labels, in order.

    Returns
    -------
    dict
        A plotly figure: per label, the count of its cases in each of :data:`BINS` bins over its
        own range (the rows ``ok`` or ``violated`` with a finite value, as the summary's statistics
        take them) (so that rows whose values lie decades apart are each resolved), drawn as a
        closed step curve; the axis is logarithmic, and the bins log-spaced, when every value is
        positive and they span more than :data:`LOG_SPAN`.
    """
    values = {label: _values(rows, column, label) for label in labels}
    present = [v for v in values.values() if v.size]
    everything = np.concatenate(present) if present else np.zeros(0)
    unit = column_unit(column)
    log = bool(everything.size) and everything.min() > 0 and everything.max() > LOG_SPAN * everything.min()
    data = []
    for k, label in enumerate(labels):
        if not values[label].size:
            continue
        edges = _edges(values[label], log)
        counts, _ = np.histogram(values[label], bins=edges)
        data.append({"type": "scatter", "mode": "lines", "name": f"{label} ({values[label].size} cases)",
                     "x": np.concatenate([edges[:1], edges]), "y": np.concatenate([[0], counts, [0]]).astype(float),
                     "line": {"shape": "hv", "color": _COLOURS[k % len(_COLOURS)], "width": 1.8},
                     "fill": "tozeroy", "opacity": 0.6,
                     "hovertemplate": f"from %{{x:.4g}} {unit}: %{{y}} cases<extra>{label}</extra>"})
    title = f"{column} ({unit})" if unit else column
    layout = {"title": {"text": title, "font": {"size": 14}}, "height": 320,
              "margin": {"l": 60, "r": 20, "t": 45, "b": 45}, "hovermode": "closest",
              "legend": {"orientation": "h", "y": -0.25},
              "xaxis": {"title": {"text": title}, "type": "log" if log else "linear", "exponentformat": "power"},
              "yaxis": {"title": {"text": f"cases per bin ({BINS} bins per row)"}, "rangemode": "tozero"}}
    return {"data": data, "layout": layout}


def _columns(names: list[str], rows: list[dict[str, Any]]) -> list[Column]:
    """:func:`~scenarios.output.report.run.result_columns`, a statistic written ``inf`` (a case that never
    settled, :data:`scenarios.study.report.INFINITY_TEXT`) keeping its column numeric."""
    from scenarios.study.report import INFINITY_TEXT
    return result_columns(names, [{k: None if v == INFINITY_TEXT else v for k, v in row.items()} for row in rows])


def _cells(names: list[str], rows: list[dict[str, Any]]) -> list[list[Any]]:
    """The values of a table's cells: a bool (a verdict ``<scope>.req.<name>.met``, ``significant``)
    as the CSV files and ``summary.md`` write it (:func:`~scenarios.output.tables.text_cell`:
    ``True``, ``False``), every other value as it is (the page formats numbers)."""
    return [[text_cell(value) if isinstance(value := row.get(name), bool) else value for name in names]
            for row in rows]


def study_report(study: Study, cases: tuple[list[str], list[dict[str, Any]]],
                 summary: tuple[list[str], list[dict[str, Any]]],
                 requirements: tuple[list[str], list[dict[str, Any]]], missing: int,
                 robustness: tuple[tuple[list[str], list[dict[str, Any]]], ...] | None = None) -> str:
    """The HTML of a study's interactive report (module docstring).

    Parameters
    ----------
    study : Study
        The expanded study.
    cases : (list of str, list of dict)
        Columns and rows of ``cases.csv`` (:func:`scenarios.study.report.case_table`).
    summary : (list of str, list of dict)
        Columns and rows of ``summary.csv`` (:func:`scenarios.study.report.summary_table`).
    requirements : (list of str, list of dict)
        Columns and rows of ``requirements.csv`` (:func:`scenarios.study.report.requirement_table`).
    missing : int
        Cases of the study without a record.
    robustness : tuple of (list of str, list of dict), or None, optional
        The robustness tables of a Monte Carlo study (:func:`scenarios.study.report.robustness_tables`:
        proportions, rank correlations, worst cases); None: no robustness sections.

    Returns
    -------
    str
        A self-contained HTML document.
    """
    names, rows = cases
    rows = [{**row, **{path: _vector(row.get(path)) for path in study.varied_paths}} for row in rows]
    labels = list(dict.fromkeys(str(row.get("label")) for row in rows))
    varied = study.varied_paths
    lines = [(f"{len(study.cases)} cases ({missing} missing), {study.samples} Monte Carlo sample(s) per grid point, "
              f"{len(rows)} rows; slewbench {package_version()}."),
             "Varied: " + (", ".join(varied) if varied else "nothing") + "."]
    page = Page(f"{study.name}: slewbench trade study", lines)
    page.section("Cases meeting the requirements", REQUIREMENT_TEXT)
    note = verdict_note(requirements)
    if note:
        page.text(note)
    page.table("requirements", result_columns(requirements[0], requirements[1]), _cells(*requirements))
    if robustness is not None:
        for (title, text), (keys, table), key in zip(ROBUSTNESS_SECTIONS, robustness, ("robustness", "sensitivity",
                                                                                     "worst")):
            if table:
                page.section(title, text)
                page.table(key, _columns(keys, table), _cells(keys, table))
    metric = summary[0].index("metric") + 1
    summary_names = [*summary[0][:metric], "unit", *summary[0][metric:]]
    summary_rows = [{**row, "unit": column_unit(row["metric"])} for row in summary[1]]
    page.section("Summary", "Statistics of each summary metric per planner row (count: rows with a value; never: rows "
                            "that never reached one, a case that never settled; no_value: the other rows). Only rows ok "
                            "or violated count, as in the plots: excluded counts the failed, infeasible and crashed "
                            "ones, left out whatever their values. mean and std (sample standard deviation) are over "
                            "the count rows; median, p5, p95 (linear percentiles), min and max over those and the "
                            "never rows as inf; not_ok: rows whose status is not ok (violated, failed, infeasible or "
                            "crashed).")
    page.table("summary", _columns(summary_names, summary_rows), _cells(summary_names, summary_rows))
    if study.summary and rows:
        page.section("Distributions", "Cases per bin of each summary metric, one curve per planner row.")
        for k, column in enumerate(study.summary):
            page.figure(f"histogram-{k}", histogram_figure(column, rows, labels))
    first_columns = ["case", "label", "status", *study.summary, *varied]
    ordered = [name for name in first_columns if name in names] + [name for name in names if name not in first_columns]
    shown = [name for name in ordered if name in IDENTITY_COLUMNS or name in ("case", "seed")
             or any(not is_missing(row.get(name)) for row in rows)]
    if rows:
        first = next((path for path in varied if any(isinstance(row.get(path), float) for row in rows)), None)
        vector = next((path for path in varied if any(isinstance(row.get(path), list) for row in rows)), None)
        x = first or (f"{vector}[0]" if vector else "case")
        y = study.summary[0] if study.summary else "plan_time_s"
        page.section("Explore", "Any two numeric columns of the cases against each other, one colour per planner row.")
        page.explorer("explorer", "cases", "label", x, y)
    page.section("Cases", "One row per case and planner, as in cases.csv; click a header to sort, type to filter.")
    columns = [Column(c.key, path_unit(c.key) if c.key in varied else c.unit, c.numeric, c.meaning, c.order)
               for c in result_columns(shown, rows)]
    page.table("cases", columns, _cells(shown, rows), page_size=PAGE_SIZE)
    return page.render()
