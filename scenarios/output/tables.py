"""The table forms of result rows and the one rule for values a table cannot hold.

A row's plain form is nested (:meth:`scenarios.output.results.Row.to_dict`: ``reference`` and
``closed_loop`` metric dicts); its flat form (:func:`flatten_row`) has one column per metric and
scope, ``ref.<metric>`` and ``cl.<metric>`` (:mod:`scenarios.schema.columns`), a vector metric split into ``<metric>_x``, ``_y`` and
``_z``, then the requirement scores, ``ref.req.<name>.<field>`` and ``cl.req.<name>.<field>``
(:func:`requirement_columns`: which there are depends on the scenario's requirements), between them
the certificate of the reference's optimum (:data:`CERTIFICATE_COLUMNS`). A run's
``results.csv`` and :meth:`~scenarios.output.results.RunResults.to_dataframe`, a trade study's
``cases.csv``, :meth:`~scenarios.study.engine.SweepResults.to_dataframe` and its ``summary:`` keys
all use these columns.

Missing and non-finite numbers (NaN, ±inf: a metric that does not apply, or a failed row's) follow
one rule, applied by every writer here: JSON writes ``null`` (:func:`json_safe`), CSV an empty cell
(:func:`csv_cell`), a DataFrame NaN in a float column (:func:`data_frame`), Markdown and the
terminal ``-``.
"""
from __future__ import annotations

import csv
import html
import io
import json
import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import TYPE_CHECKING, Any

from scenarios.requirements.fields import (
    field_info,
    is_requirement_column,
    is_verdict_column,
)
from scenarios.schema.columns import (
    AXES,
    REQUIREMENT_MARK,
    SCOPES,
    SCORED_METRICS,
    VECTOR_METRICS,
    metric_columns,
)

if TYPE_CHECKING:
    import pandas

    from scenarios.output.results import RunResults
    from scenarios.requirements.spec import Requirements

__all__ = ["BUDGET_COLUMNS", "CERTIFICATE_COLUMNS", "CERTIFICATE_NUMBERS", "FLAG_COLUMNS", "IDENTITY_COLUMNS", "REFUSED_CERTIFICATE",
           "ROW_STATUSES", "RUN_COLUMNS", "breaking_fields",
           "csv_cell", "csv_text",
           "data_frame", "flatten_row", "html_table", "is_missing", "json_safe", "numeric_columns",
           "ratio_text", "refused_certificate", "requirement_columns", "requirement_units", "row_columns", "run_rows",
           "status_line", "text_cell", "to_csv",
           "to_dataframe", "to_json", "to_markdown", "to_terminal"]

RUN_COLUMNS = ("file_stem",)
"""The columns a run's ``results.csv`` (and :meth:`~scenarios.output.results.RunResults.to_dataframe`)
has after :func:`row_columns`: ``file_stem``, the stem of the row's files (``timeseries/<file_stem>.csv``,
``<file_stem>.png``; :func:`~scenarios.output.names.row_stems`). A trade study's ``cases.csv`` has it
last too: the stem of the row's files when its case is re-run in full (``slewbench sweep DIR --case N``,
:func:`scenarios.study.report.case_table`)."""
IDENTITY_COLUMNS = ("label", "planner", "controller", "status", "message", "plan_time_s", "plan_reused")
"""The columns that name a row and say how its reference was had, before its metrics: ``plan_time_s``
the planner's wall time [s], ``plan_reused`` whether the reference was reused from an earlier case of
identical planning inputs (:func:`scenarios.runner.run`'s ``references``; then ``plan_time_s`` is that
plan's), True or False, missing in the rows of a sweep stored before the column existed."""
BUDGET_COLUMNS = ("needed_duration_s",)
"""The columns after :data:`IDENTITY_COLUMNS` that say what time budget a row needs: ``needed_duration_s``
[s], for an ``infeasible`` row whose slew does not fit ``maneuver.duration``, the least budget known to be
needed (:func:`scenarios.runner.needed_duration`); empty for any other row (and in the rows of a sweep
stored before the column existed). Shown in a report only where some row has a value, as a metric is."""
FLAG_COLUMNS = ("plan_reused",)
"""The columns of :data:`IDENTITY_COLUMNS` that hold a bool: pandas' nullable ``boolean`` in a
DataFrame (``<NA>`` where missing)."""

ROW_STATUSES = ("crashed", "failed", "infeasible", "violated", "ok")
"""A row's statuses from the worst, the order tables count and sort them in: ``crashed`` (a trade
study's case that raised), ``failed`` (the planner or the simulation failed: a numerical failure), ``infeasible`` (proven that
no motion meets the problem: the planner found it cannot be met under its bounds, torque about a
failed wheel's axis, a slew longer than ``maneuver.duration``, ...; or, before planning, the end
points already break a pointing requirement or the rate requirement cannot turn the angle between
them within ``maneuver.duration``),
``violated`` (a requirement broken) and ``ok``."""

CERTIFICATE_COLUMNS = ("certificate", "certificate_verdict", "certificate_kkt_scaled", "certificate_kkt_unscaled")
"""The columns of a row's certificate (the reference's ``stats["certificate"]``, :mod:`ocp.nlp.certificate`;
the row's ``certificate`` in its plain form): its summary line, its verdict and its KKT residuals
(in the solver's scaling and unscaled); empty for a planner that writes none."""
CERTIFICATE_NUMBERS = ("certificate_kkt_scaled", "certificate_kkt_unscaled")
"""The certificate columns that hold numbers."""
_CERTIFICATE_KEYS = ("summary", "verdict", "kkt_scaled", "kkt_unscaled")
"""The certificate's keys behind :data:`CERTIFICATE_COLUMNS`, in order."""


REFUSED_CERTIFICATE = "not applicable"
"""The certificate cell of a row whose reference was refused (:func:`refused_certificate`) in the
terminal table and ``results.md``: the certificate is of the planner's optimum, not of a motion the row
tracks."""


def refused_certificate(row: Any) -> bool:
    """Whether a row's certificate is of a reference the row did not use: the planner's optimum that
    the run refused (a slew that ends after ``maneuver.duration``, ``infeasible``; one that misses its
    manoeuvre's ends, ``failed``), kept in ``results.json`` and ``results.csv`` as the planner's record.

    Parameters
    ----------
    row : scenarios.output.results.Row
        A run's row.

    Returns
    -------
    bool
        True when the row has a reference that is not ok (the run refused it, or the planner failed).
    """
    reference = getattr(row, "reference", None)
    return reference is not None and not reference.ok


def is_missing(value: Any) -> bool:
    """Whether a table value is missing: ``None``, or a non-finite number (NaN, ±inf).

    Parameters
    ----------
    value : Any
        A cell's value.

    Returns
    -------
    bool
        True for ``None`` and non-finite floats (NumPy's included).
    """
    return value is None or (isinstance(value, float) and not math.isfinite(value))



def requirement_columns(rows: Iterable[Mapping[str, Any]]) -> list[str]:
    """The requirement columns of some rows, in order: the reference's then the closed loop's, each
    in the order the rows first give them.

    Parameters
    ----------
    rows : iterable of mapping
        Rows as :meth:`scenarios.output.results.Row.to_dict` gives them (``requirements``: scope ->
        requirement name -> field -> value, or ``None``).

    Returns
    -------
    list of str
        ``ref.req.<name>.<field>`` then ``cl.req.<name>.<field>``.
    """
    found: dict[str, dict[str, None]] = {prefix: {} for _, prefix in SCOPES}
    for row in rows:
        scores = row.get("requirements") or {}
        for scope, prefix in SCOPES:
            for name, fields in (scores.get(scope) or {}).items():
                for key in fields:
                    found[prefix].setdefault(f"{prefix}.{REQUIREMENT_MARK}.{name}.{key}")
    return [column for _, prefix in SCOPES for column in found[prefix]]


def row_columns(requirements: Sequence[str] = ()) -> list[str]:
    """The columns of a flat row: :data:`IDENTITY_COLUMNS`, :data:`BUDGET_COLUMNS`,
    :func:`metric_columns`, :data:`CERTIFICATE_COLUMNS`, then the requirement columns given.

    Parameters
    ----------
    requirements : sequence of str, optional
        Requirement columns (:func:`requirement_columns` of the rows); default none.

    Returns
    -------
    list of str
        ``label, planner, controller, status, message, plan_time_s, plan_reused, needed_duration_s,
        ref.int_u2, ..., certificate, ..., ref.req...``.
    """
    return [*IDENTITY_COLUMNS, *BUDGET_COLUMNS, *metric_columns(), *CERTIFICATE_COLUMNS, *requirements]


def numeric_columns(requirements: Sequence[str] = ()) -> list[str]:
    """The columns of a flat row that hold numbers (float in a DataFrame).

    Parameters
    ----------
    requirements : sequence of str, optional
        Requirement columns present; default none (:func:`data_frame` takes every requirement
        column of its columns as numeric anyway).

    Returns
    -------
    list of str
        ``plan_time_s``, ``needed_duration_s``, every metric column, the certificate's KKT residuals and the requirement
        columns given but the verdicts (``<scope>.req.<name>.met``: bools).
    """
    return ["plan_time_s", *BUDGET_COLUMNS, *metric_columns(), *CERTIFICATE_NUMBERS,
            *(column for column in requirements if not is_verdict_column(column))]


def flatten_row(row: Mapping[str, Any]) -> dict[str, Any]:
    """The flat form of a row's plain form: the one way from ``reference``/``closed_loop`` metric dicts
    to ``ref.<metric>``/``cl.<metric>`` columns.

    Parameters
    ----------
    row : mapping
        A row as :meth:`scenarios.output.results.Row.to_dict` gives it (and a study stores it).

    Returns
    -------
    dict
        Keyed by :func:`row_columns` and the row's own requirement columns; a metric the row lacks
        (no reference, not simulated, crashed) is ``None``, other values are as given (the
        writers apply the non-finite rule).
    """
    flat = {name: row.get(name) for name in (*IDENTITY_COLUMNS, *BUDGET_COLUMNS)}
    for scope, prefix in SCOPES:
        metrics = row.get(scope) or {}
        for key in SCORED_METRICS:
            value = metrics.get(key)
            if key in VECTOR_METRICS:
                for axis, component in zip(AXES, value if value is not None else (None,) * len(AXES)):
                    flat[f"{prefix}.{key}_{axis}"] = component
            else:
                flat[f"{prefix}.{key}"] = value
    certificate = row.get("certificate") or {}
    for column, key in zip(CERTIFICATE_COLUMNS, _CERTIFICATE_KEYS):
        flat[column] = certificate.get(key)
    scores = row.get("requirements") or {}
    for scope, prefix in SCOPES:
        for name, fields in (scores.get(scope) or {}).items():
            for key, value in fields.items():
                flat[f"{prefix}.{REQUIREMENT_MARK}.{name}.{key}"] = value
    return flat


def json_safe(value: Any) -> Any:
    """``value`` with every missing or non-finite number as ``None`` (JSON ``null``), in nested
    dicts, lists and tuples.

    Parameters
    ----------
    value : Any
        Plain data (dicts, lists, numbers, text).

    Returns
    -------
    Any
        The same structure (tuples as lists), ready for :func:`json.dumps` without NaN.
    """
    if isinstance(value, dict):
        return {k: json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_safe(v) for v in value]
    return None if is_missing(value) else value


def csv_cell(value: Any) -> str:
    """The text of a CSV cell: empty when missing or non-finite, ``repr`` of a float (it reads
    back exactly), ``str`` otherwise.

    Parameters
    ----------
    value : Any
        The cell's value.

    Returns
    -------
    str
        The cell's text.
    """
    if is_missing(value):
        return ""
    if isinstance(value, float):
        return repr(float(value))
    return str(value)


def csv_text(columns: Sequence[str], records: Iterable[Mapping[str, Any]]) -> str:
    """A CSV table: a header of ``columns``, one line per record, cells by :func:`csv_cell`.

    Parameters
    ----------
    columns : sequence of str
        The columns, in order (a record's other keys are left out; a column it lacks is empty).
    records : iterable of mapping
        The lines.

    Returns
    -------
    str
        CSV text, one line per record after the header (LF line ends).
    """
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(columns)
    for record in records:
        writer.writerow([csv_cell(record.get(column)) for column in columns])
    return buffer.getvalue()


def data_frame(columns: Sequence[str], records: Iterable[Mapping[str, Any]], numeric: Iterable[str]) -> pandas.DataFrame:
    """A DataFrame of ``records`` whose ``numeric`` columns are float, NaN where missing or non-finite.

    Parameters
    ----------
    columns : sequence of str
        The columns, in order.
    records : iterable of mapping
        The lines.
    numeric : iterable of str
        The columns that hold numbers (never ``None`` in the DataFrame); the requirement columns
        (:func:`~scenarios.requirements.fields.is_requirement_column`) are numeric too, but for the
        verdicts (``<scope>.req.<name>.met``,
        :func:`~scenarios.requirements.fields.is_verdict_column`): pandas' nullable ``boolean``,
        ``<NA>`` where missing, never a float to average; so are :data:`FLAG_COLUMNS`.

    Returns
    -------
    pandas.DataFrame
        One line per record.

    Raises
    ------
    ImportError
        pandas is not installed.
    """
    try:
        import pandas
    except ImportError:
        raise ImportError("to_dataframe needs pandas: pip install pandas") from None
    verdicts = {column for column in columns if is_verdict_column(column) or column in FLAG_COLUMNS}
    numbers = (set(numeric) | {column for column in columns if is_requirement_column(column)}) & set(columns) - verdicts
    lines = [{column: (math.nan if is_missing(record.get(column)) else record.get(column)) if column in numbers
              else (None if is_missing(record.get(column)) else record.get(column)) if column in verdicts
              else record.get(column) for column in columns} for record in records]
    frame = pandas.DataFrame(lines, columns=list(columns))
    return frame.astype({column: float if column in numbers else "boolean"
                         for column in columns if column in numbers or column in verdicts})


def to_json(results: RunResults) -> str:
    """``results.json``: :meth:`RunResults.to_dict <scenarios.output.results.RunResults.to_dict>`
    (the scenario's name, frame and epoch, the rows and the provenance), non-finite numbers written
    as ``null``.

    Parameters
    ----------
    results : RunResults
        The rows of a scenario run.

    Returns
    -------
    str
        Indented JSON text.
    """
    return json.dumps(json_safe(results.to_dict()), indent=2, allow_nan=False, default=str)


def run_rows(results: RunResults) -> list[dict[str, Any]]:
    """A run's rows in their plain form (:meth:`~scenarios.output.results.Row.to_dict`), each with
    ``file_stem``: the stem of its files in the output directory (``timeseries/<file_stem>.csv``,
    ``<file_stem>.png``), :func:`~scenarios.output.names.row_stems` of the run's labels.

    Parameters
    ----------
    results : RunResults
        The rows of a scenario run.

    Returns
    -------
    list of dict
        One per row, in order.
    """
    from scenarios.output.names import row_stems

    stems = row_stems([row.label for row in results.rows])
    return [{**row.to_dict(), "file_stem": stem} for row, stem in zip(results.rows, stems)]


def to_csv(results: RunResults) -> str:
    """``results.csv``: one line per row, the columns of :func:`row_columns` with the rows'
    requirement columns, then :data:`RUN_COLUMNS` (the row's file stem).

    Parameters
    ----------
    results : RunResults
        The rows of a scenario run.

    Returns
    -------
    str
        CSV text; missing and non-finite values are empty cells.
    """
    rows = run_rows(results)
    return csv_text([*row_columns(requirement_columns(rows)), *RUN_COLUMNS],
                    ({**flatten_row(row), **{key: row[key] for key in RUN_COLUMNS}} for row in rows))


def to_dataframe(results: RunResults) -> pandas.DataFrame:
    """The CSV table as a pandas DataFrame (needs pandas installed).

    Parameters
    ----------
    results : RunResults
        The rows of a scenario run.

    Returns
    -------
    pandas.DataFrame
        One line per row, the columns of :func:`row_columns` (with the rows' requirement
        columns), then :data:`RUN_COLUMNS`; ``plan_time_s``, the metric and the requirement columns are float, NaN where
        missing or non-finite, but the verdicts (``<scope>.req.<name>.met``) and ``plan_reused``:
        pandas' nullable ``boolean``.

    Raises
    ------
    ImportError
        pandas is not installed.
    """
    rows = run_rows(results)
    requirements = requirement_columns(rows)
    return data_frame([*row_columns(requirements), *RUN_COLUMNS],
                      [{**flatten_row(row), **{key: row[key] for key in RUN_COLUMNS}} for row in rows],
                      numeric_columns(requirements))


def text_cell(value: Any) -> str:
    """A Markdown or terminal cell: ``-`` when missing or non-finite, 4 significant digits.

    Parameters
    ----------
    value : object
        A number, text, ``None`` or a list of them (a vector metric).

    Returns
    -------
    str
        The cell's text.
    """
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(text_cell(v) for v in value) + "]"
    if is_missing(value):
        return "-"
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)


def _metric_lines(results: RunResults, requirements: bool = True,
                  certificate: str = "summary") -> list[tuple[str, list[str]]]:
    """(metric name, one formatted cell per row): the status, the plan time, the certificate's
    ``certificate`` entry (``summary`` or ``verdict``), reference metrics then closed-loop ones,
    then (``requirements``) every requirement column."""
    rows = [row.to_dict() for row in results.rows]
    lines = [("status", [row["status"] for row in rows]),
             ("plan_time_s", [text_cell(row["plan_time_s"]) for row in rows]),
             ("needed_duration_s", [text_cell(row["needed_duration_s"]) for row in rows]),
             ("certificate", [REFUSED_CERTIFICATE if refused_certificate(original) and row.get("certificate")
                              else text_cell((row.get("certificate") or {}).get(certificate))
                              for original, row in zip(results.rows, rows)])]
    for scope, prefix in SCOPES:
        for key in SCORED_METRICS:
            lines.append((f"{prefix}.{key}", [text_cell((row[scope] or {}).get(key)) for row in rows]))
    if requirements:
        flat = [flatten_row(row) for row in rows]
        lines += [(column, [_requirement_text(column, line) for line in flat]) for column in requirement_columns(rows)]
    return lines


_LIMIT_ROUNDING = 1e-9
"""How near 1 a ratio to its limit is at the limit, to rounding (the closed loop's
:data:`~scenarios.requirements.scoring.AT_LIMIT`)."""
_AT_LIMIT_TEXT = "at limit"
"""The cell of a ratio at its limit (to :data:`_LIMIT_ROUNDING`) in a scope that breaks the
requirement: a closed loop's wheel the simulator holds at its limit, where a reference at the same
ratio may meet it (it is allowed the limit itself)."""


def ratio_text(value: Any, broken: bool = False) -> str:
    """A Markdown or terminal cell of a ratio to a limit or a bound: as :func:`text_cell`, but with
    as many more digits (12 significant at most) as it takes not to read ``1`` when it is not 1
    (``0.99998``, not ``1``), and :data:`_AT_LIMIT_TEXT` for a ratio at 1 to rounding in a scope
    that breaks the requirement, so that a met and a broken value never read alike.

    Parameters
    ----------
    value : object
        The ratio (dimensionless), ``None`` or non-finite when missing.
    broken : bool, optional
        Whether the scope breaks the requirement.

    Returns
    -------
    str
        The cell's text (without the broken mark).
    """
    text = text_cell(value)
    if not isinstance(value, float) or is_missing(value) or float(text) != 1.0:
        return text
    if broken and abs(value - 1.0) <= _LIMIT_ROUNDING:
        return _AT_LIMIT_TEXT
    for digits in range(5, 13):
        shown = f"{value:.{digits}g}"
        if float(shown) != 1.0:
            return shown
    return text


def _is_ratio(column: str) -> bool:
    """Whether a requirement column holds a dimensionless ratio (a demand over its limit, a peak
    rate over its bound)."""
    try:
        return field_info(column).unit == "–"
    except KeyError:
        return False


def _requirement_text(column: str, line: Mapping[str, Any]) -> str:
    """A flat row's cell of a requirement column: a ratio by :func:`ratio_text`, broken where the
    row's verdict of that scope and requirement is False."""
    value = line.get(column)
    if not _is_ratio(column):
        return text_cell(value)
    verdict = column.rsplit(".", 1)[0] + ".met"
    return ratio_text(value, broken=line.get(verdict) is False)


_HEADLINES = (("min_margin_deg", "min margin, deg"), ("ratio", "peak rate / bound"),
              ("worst_error_deg", "worst error after T, deg"))
"""The number the terminal shows of a requirement, by the field that identifies its kind (the
actuators, which have none of these: the largest demand over its limit)."""


def _demand_ratios(values: Mapping[str, Any]) -> dict[str, Any]:
    """An actuator score's demand ratios by quantity (by their declared unit), ``None`` where not
    finite."""
    return {key: value for key, value in values.items()
            if key != "met" and field_info(f"actuators.{key}").unit == "–"}


def _headline_field(values: Mapping[str, Any] | None) -> tuple[str, str | None]:
    """(what the number is, the field that gives it) of one requirement's score: the actuators'
    is the quantity with the largest finite ratio (``None`` when none is finite)."""
    if not values:
        return "", None
    for key, words in _HEADLINES:
        if key in values:
            return words, key
    ratios = {key: value for key, value in _demand_ratios(values).items() if value is not None}
    return "peak demand / limit", max(ratios, key=ratios.__getitem__) if ratios else None


def _headline(values: Mapping[str, Any] | None) -> tuple[str, Any]:
    """(what the number is, the number) of one requirement's score."""
    words, key = _headline_field(values)
    return words, None if key is None or values is None else values[key]


def _over(value: Any, bound: float | None) -> bool:
    """Whether a recorded value exceeds a bound beyond rounding (:data:`_LIMIT_ROUNDING`, the
    scoring's :data:`~planners.base.REQUIREMENT_TOLERANCE`)."""
    return bound is not None and isinstance(value, (int, float)) and value > bound * (1.0 + _LIMIT_ROUNDING)


def _actuator_breaches(scope: str, values: Mapping[str, Any], requirements: Requirements | None) -> list[str]:
    """The fields of an actuator score that break it (:func:`scenarios.requirements.scoring.score_reference`,
    :func:`~scenarios.requirements.scoring.closed_loop_wheels`): a rate jump (any), an unrealised
    torque over its allowed, a demand that is not finite, a ratio over the allowed (the
    reference's ``1 − margin``, the closed loop's limit)."""
    breaches = [key for key, value in _demand_ratios(values).items()
                if value is None and values.get(f"{key}_time_s") is not None]
    if isinstance(values.get("rate_jump"), (int, float)) and values["rate_jump"] > 0.0:  # only jumps are recorded
        breaches.append("rate_jump")
    if values.get("unrealised_torque") is None and values.get("unrealised_torque_time_s") is not None:
        breaches.append("unrealised_torque")
    elif _over(values.get("unrealised_torque"), values.get("unrealised_torque_allowed")):
        breaches.append("unrealised_torque")
    if scope == "closed_loop":
        allowed = 1.0 - _LIMIT_ROUNDING  # the closed loop breaks at its limit (scoring.AT_LIMIT)
        over = [key for key, value in _demand_ratios(values).items() if value is not None and value >= allowed]
    else:
        bound = requirements.actuators.allowed if requirements is not None and requirements.actuators else None
        over = [key for key, value in _demand_ratios(values).items() if _over(value, bound)]
    return over + breaches


def _final_breaches(scope: str, values: Mapping[str, Any], requirements: Requirements | None) -> list[str]:
    """The fields of a final score that break it: the error or the rate error over its bound."""
    final = requirements.final if requirements is not None else None
    if final is None:
        return []
    return [key for key, bound in (("worst_error_deg", final.error_deg), ("worst_rate_error", final.rate))
            if _over(values.get(key), bound)]


_BREACHES: dict[str, Callable[[str, Mapping[str, Any], Requirements | None], list[str]]] = {
    "actuators": _actuator_breaches, "final": _final_breaches}
"""Requirement name -> the fields of its score that break it, where the score has fields other
than its headline's that may (the pointing requirements and ``rate`` break by their headline
alone)."""


def breaking_fields(name: str, scope: str, values: Mapping[str, Any] | None,
                    requirements: Requirements | None = None) -> list[str]:
    """The fields of one scope's score of a requirement that break it, by the numbers recorded
    (``results.json``'s, ``results.csv``'s columns ``<scope>.req.<name>.<field>``).

    Parameters
    ----------
    name : str
        The requirement's name (a pointing requirement's, ``actuators``, ``rate``, ``final``).
    scope : str
        ``reference`` or ``closed_loop``.
    values : mapping or None
        The score's fields (the verdict ``met`` among them).
    requirements : Requirements, optional
        The scenario's requirements, for the bounds the fields are held to (``1 − margin``, the
        final error's and rate's); without them, only the breaches the fields show themselves (a
        rate jump, an unrealised torque over its allowed, a number not finite).

    Returns
    -------
    list of str
        Field names, in column order of their kind (the demand ratios, then ``rate_jump``,
        ``unrealised_torque``); where the score is not met and no field shows why, its headline
        field (the number the terminal shows); empty when met.
    """
    if not values or values.get("met") is not False:
        return []
    rule = _BREACHES.get(name)
    found = [] if rule is None else rule(scope, values, requirements)
    headline = _headline_field(values)[1]
    return found or ([headline] if headline is not None else [])


_BROKEN = " ✗"
"""Appended to a requirement's terminal cell in a scope that breaks it: the headline number alone
may look harmless where another field breaks the requirement (a reference at 0.12 of its torque
limit whose rate jumps: an impulse)."""


_RATIO_HEADLINES = ("peak rate / bound", "peak demand / limit")
"""The headlines (:func:`_headline`) that are ratios to a limit or a bound (:func:`ratio_text`)."""


def _requirement_cell(name: str, scope: str, values: Mapping[str, Any] | None,
                      requirements: Requirements | None = None) -> str:
    """One scope's terminal cell of a requirement: its headline number, marked when not met, and
    the fields that break it where the headline's is not the one (``0.2513 ✗ rate_jump``: a small
    demand ratio on a reference whose rate jumps), a field with no number said ``not finite``."""
    words, number = _headline(values)
    broken = values is not None and values.get("met") is False
    cell = ratio_text(number, broken) if words in _RATIO_HEADLINES else text_cell(number)
    if not broken:
        return cell
    assert values is not None
    fields = breaking_fields(name, scope, values, requirements)
    shown = [] if fields == [_headline_field(values)[1]] else fields
    said = [f"{key} not finite" if values.get(key) is None else key for key in shown]
    return cell + _BROKEN + (" " + ", ".join(said) if said else "")


def _requirement_lines(results: RunResults) -> list[tuple[str, list[str]]]:
    """One line per requirement for the terminal: its headline number, ``reference | closed loop``,
    each marked ``✗`` where that scope breaks the requirement (with the fields that break it where
    the number shown is not the one, :func:`breaking_fields`)."""
    scores = [row.requirements or {} for row in results.rows]
    requirements = getattr(results.scenario, "requirements", None)
    names: dict[str, None] = {}
    for row in scores:
        for scope, _ in SCOPES:
            names.update(dict.fromkeys(row.get(scope) or {}))
    lines = []
    for name in names:
        words = next((_headline(row.get(scope, {}).get(name))[0] for row in scores for scope, _ in SCOPES
                      if row.get(scope, {}).get(name)), "")
        cells = [" | ".join(_requirement_cell(name, scope, row.get(scope, {}).get(name), requirements)
                            for scope, _ in SCOPES)
                 for row in scores]
        lines.append((f"req.{name} ({words}; ref | cl)", cells))
    return lines


def status_line(results: RunResults) -> str:
    """``rows: 4 (1 ok, 3 violated)``: the rows by status, in rank order.

    Parameters
    ----------
    results : RunResults
        The rows of a scenario run.

    Returns
    -------
    str
    """
    counts = results.status_counts()
    return f"rows: {len(results.rows)} (" + ", ".join(f"{n} {status}" for status, n in counts.items()) + ")"


def requirement_units(columns: Iterable[str]) -> str:
    """The units of some requirement columns, in words (the units line of ``results.md``).

    Each field's unit is its declaration's (:func:`scenarios.requirements.fields.field_info`); the
    fields named ``*_deg`` in degrees and ``*_s`` in seconds are said once by their suffix, the
    others by name under their unit, a ratio with what it divides.

    Parameters
    ----------
    columns : iterable of str
        Requirement columns (``ref.req.<name>.<field>``, ``cl.req.<name>.<field>``).

    Returns
    -------
    str
        For example ``requirement fields: *_deg deg, *_s s; rad/s: peak_rate; ratios (–): ratio
        (peak rate / bound)``; empty for no column.
    """
    suffixes: dict[str, None] = {}
    named: dict[str, dict[str, None]] = {}
    for column in columns:
        field = column.split(".")[-1]
        try:
            info = field_info(column)
        except KeyError:  # a field the declaration lacks (tests/test_requirement_fields.py holds it complete)
            named.setdefault("no declared unit", {}).setdefault(field)
            continue
        suffix = {"deg": "_deg", "s": "_s"}.get(info.unit)
        if suffix is not None and field.endswith(suffix):
            suffixes.setdefault(f"*{suffix} {info.unit}")
        elif info.unit == "–":
            named.setdefault("ratios", {}).setdefault(f"{field} ({info.words})")
        else:
            named.setdefault(info.unit, {}).setdefault(field)
    ratios = named.pop("ratios", {})
    parts = ([", ".join(suffixes)] if suffixes else []) + [f"{unit}: {', '.join(fields)}" for unit, fields in named.items()]
    parts += [f"ratios (–): {', '.join(ratios)}"] if ratios else []
    return "requirement fields: " + "; ".join(parts) if parts else ""


def to_markdown(results: RunResults) -> str:
    """``results.md``: one column per row (planner), one line per metric, then the messages.

    Parameters
    ----------
    results : RunResults
        The rows of a scenario run.

    Returns
    -------
    str
        Markdown text with a units line.
    """
    labels = [row.label for row in results.rows]
    out = [f"# {results.scenario.name}", "", "| metric | " + " | ".join(labels) + " |",
           "|---|" + "---|" * len(labels)]
    out += [f"| {name} | " + " | ".join(cells) + " |" for name, cells in _metric_lines(results)]
    units = "Units: torque N m, integrals N m s (int_u2: N² m² s), angles deg, times s, rates rad/s"
    fields = requirement_units(requirement_columns([{"requirements": row.requirements} for row in results.rows]))
    out += ["", f"{units}. {fields[:1].upper()}{fields[1:]}." if fields else f"{units}.", "", status_line(results), ""]
    out += [f"- **{row.label}** ({row.planner or 'regulation'}, {row.controller or '-'}): {row.message}"
            for row in results.rows]
    return "\n".join(out) + "\n"


def _applies(cells: Sequence[str]) -> bool:
    """Whether some cell of a terminal line holds a value (not only ``-``, as in ``-``,
    ``[-, -, -]`` or ``- | -``)."""
    return any(set(cell) - set("-|[], ") for cell in cells)


def to_terminal(results: RunResults, all_metrics: bool = False) -> str:
    """A fixed-width table with metrics as lines and planners as columns, one line per requirement
    (its headline number, ``reference | closed loop``), then the messages and the rows by status.

    Parameters
    ----------
    results : RunResults
        The rows of a scenario run.
    all_metrics : bool, optional
        Keep the lines that are ``-`` for every row (metrics that apply to no row); by default
        they are left out and a closing line says how many.

    Returns
    -------
    str
        Plain text for a terminal.
    """
    lines = _metric_lines(results, requirements=False, certificate="verdict") + _requirement_lines(results)
    hidden = [] if all_metrics else [name for name, cells in lines if not _applies(cells)]
    lines = [(name, cells) for name, cells in lines if name not in hidden]
    labels = [row.label for row in results.rows]
    name_width = max(len(name) for name, _ in lines)
    widths = [max(len(label), *(len(cells[i]) for _, cells in lines)) for i, label in enumerate(labels)]
    header = " " * name_width + "  " + "  ".join(label.rjust(w) for label, w in zip(labels, widths))
    body = [name.ljust(name_width) + "  " + "  ".join(c.rjust(w) for c, w in zip(cells, widths)) for name, cells in lines]
    messages = [f"{row.label}: {row.message}" for row in results.rows if row.message]
    summaries = [(row, (row.to_dict().get("certificate") or {}).get("summary")) for row in results.rows]
    messages += [f"{row.label} certificate: " + (f"{REFUSED_CERTIFICATE}, its reference was refused ({row.status}: the "
                                                 f"message above); the planner's own optimum had {summary}"
                                                 if refused_certificate(row) else summary)
                 for row, summary in summaries if summary]
    note = [f"({len(hidden)} metrics with no value in any row not shown; --all-metrics shows them)"] if hidden else []
    if any(_BROKEN in cell for name, cells in lines if name.startswith("req.") for cell in cells):
        note.append(f"({_BROKEN.strip()}: that scope breaks the requirement; the messages below say how)")
    if any(part.partition(_BROKEN)[2].strip() for name, cells in lines if name.startswith("req.") for cell in cells
           for part in cell.split(" | ")):  # a field named after a scope's mark
        note.append(f"({_BROKEN.strip()} FIELD: the field that breaks it where the number shown does not, as in "
                    "results.md and results.csv, <scope>.req.<name>.FIELD)")
    return "\n".join([f"scenario: {results.scenario.name}", header, *body, *note, "", *messages, "",
                      status_line(results)])


def html_table(columns: Sequence[str], records: Iterable[Sequence[Any]], caption: str = "") -> str:
    """A small HTML table (for a notebook's ``_repr_html_``): a header and one line per record, cells
    by :func:`text_cell`, every text escaped.

    Parameters
    ----------
    columns : sequence of str
        The header.
    records : iterable of sequence
        The lines, one value per column.
    caption : str, optional
        A caption above the table; empty: none.

    Returns
    -------
    str
        ``<table>...</table>``.
    """
    head = "".join(f"<th>{html.escape(column)}</th>" for column in columns)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(text_cell(value))}</td>" for value in record) + "</tr>"
                   for record in records)
    title = f"<caption>{html.escape(caption)}</caption>" if caption else ""
    return f"<table>{title}<thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"
