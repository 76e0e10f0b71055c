"""The table forms of result rows and the one rule for values a table cannot hold.

A row's plain form is nested (:meth:`scenarios.output.results.Row.to_dict`: ``reference`` and
``closed_loop`` metric dicts); its flat form (:func:`flatten_row`) has one column per metric and
scope, ``ref.<metric>`` and ``cl.<metric>`` (:mod:`scenarios.schema.columns`), a vector metric split into ``<metric>_x``, ``_y`` and
``_z``. A run's ``results.csv`` and :meth:`~scenarios.output.results.RunResults.to_dataframe`, a
trade study's ``cases.csv``, :meth:`~scenarios.study.engine.SweepResults.to_dataframe` and its
``summary:`` keys all use these columns.

Missing and non-finite numbers (NaN, ±inf: a metric that does not apply, or a failed row's) follow
one rule, applied by every writer here: JSON writes ``null`` (:func:`json_safe`), CSV an empty cell
(:func:`csv_cell`), a DataFrame NaN in a float column (:func:`data_frame`), Markdown and the
terminal ``-``.
"""
from __future__ import annotations

import csv
import io
import json
import math
from collections.abc import Iterable, Mapping, Sequence
from typing import TYPE_CHECKING, Any

from scenarios.schema.columns import (
    AXES,
    SCOPES,
    SCORED_METRICS,
    VECTOR_METRICS,
    metric_columns,
)

if TYPE_CHECKING:
    import pandas

    from scenarios.output.results import RunResults

IDENTITY_COLUMNS = ("label", "planner", "controller", "status", "message", "plan_time_s")
"""The columns that name a row, before its metrics."""


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



def row_columns() -> list[str]:
    """The columns of a flat row: :data:`IDENTITY_COLUMNS`, then :func:`metric_columns`.

    Returns
    -------
    list of str
        ``label, planner, controller, status, message, plan_time_s, ref.int_u2, ...``.
    """
    return [*IDENTITY_COLUMNS, *metric_columns()]


def numeric_columns() -> list[str]:
    """The columns of a flat row that hold numbers (float in a DataFrame).

    Returns
    -------
    list of str
        ``plan_time_s`` and every metric column.
    """
    return ["plan_time_s", *metric_columns()]


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
        Keyed by :func:`row_columns`; a metric the row lacks (no reference, not simulated, crashed)
        is ``None``, other values are as given (the writers apply the non-finite rule).
    """
    flat = {name: row.get(name) for name in IDENTITY_COLUMNS}
    for scope, prefix in SCOPES:
        metrics = row.get(scope) or {}
        for key in SCORED_METRICS:
            value = metrics.get(key)
            if key in VECTOR_METRICS:
                for axis, component in zip(AXES, value if value is not None else (None,) * len(AXES)):
                    flat[f"{prefix}.{key}_{axis}"] = component
            else:
                flat[f"{prefix}.{key}"] = value
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
        The columns that hold numbers (never ``None`` in the DataFrame).

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
    numbers = set(numeric) & set(columns)
    lines = [{column: (math.nan if is_missing(record.get(column)) else record.get(column)) if column in numbers
              else record.get(column) for column in columns} for record in records]
    frame = pandas.DataFrame(lines, columns=list(columns))
    return frame.astype({column: float for column in columns if column in numbers})


def to_json(results: RunResults) -> str:
    """``results.json``: ``{"scenario": name, "rows": [Row.to_dict(), ...]}``, non-finite numbers
    written as ``null``.

    Parameters
    ----------
    results : RunResults
        The rows of a scenario run.

    Returns
    -------
    str
        Indented JSON text.
    """
    return json.dumps(json_safe(results.to_dict()), indent=2, allow_nan=False)


def to_csv(results: RunResults) -> str:
    """``results.csv``: one line per row, the columns of :func:`row_columns`.

    Parameters
    ----------
    results : RunResults
        The rows of a scenario run.

    Returns
    -------
    str
        CSV text; missing and non-finite values are empty cells.
    """
    return csv_text(row_columns(), (flatten_row(row.to_dict()) for row in results.rows))


def to_dataframe(results: RunResults) -> pandas.DataFrame:
    """The CSV table as a pandas DataFrame (needs pandas installed).

    Parameters
    ----------
    results : RunResults
        The rows of a scenario run.

    Returns
    -------
    pandas.DataFrame
        One line per row, the columns of :func:`row_columns`; ``plan_time_s`` and the metric
        columns are float, NaN where missing or non-finite.

    Raises
    ------
    ImportError
        pandas is not installed.
    """
    return data_frame(row_columns(), [flatten_row(row.to_dict()) for row in results.rows], numeric_columns())


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


def _metric_lines(results: RunResults) -> list[tuple[str, list[str]]]:
    """(metric name, one formatted cell per row), reference metrics then closed-loop ones."""
    rows = [row.to_dict() for row in results.rows]
    lines = [("status", [row["status"] for row in rows]),
             ("plan_time_s", [text_cell(row["plan_time_s"]) for row in rows])]
    for scope, prefix in SCOPES:
        for key in SCORED_METRICS:
            lines.append((f"{prefix}.{key}", [text_cell((row[scope] or {}).get(key)) for row in rows]))
    return lines


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
    out += ["", "Units: torque N m, integrals N m s (int_u2: N² m² s), angles deg, times s, rates rad/s.", ""]
    out += [f"- **{row.label}** ({row.planner or 'regulation'}, {row.controller or '-'}): {row.message}"
            for row in results.rows]
    return "\n".join(out) + "\n"


def to_terminal(results: RunResults) -> str:
    """A fixed-width table with metrics as lines and planners as columns, then the messages.

    Parameters
    ----------
    results : RunResults
        The rows of a scenario run.

    Returns
    -------
    str
        Plain text for a terminal.
    """
    lines = _metric_lines(results)
    labels = [row.label for row in results.rows]
    name_width = max(len(name) for name, _ in lines)
    widths = [max(len(label), *(len(cells[i]) for _, cells in lines)) for i, label in enumerate(labels)]
    header = " " * name_width + "  " + "  ".join(label.rjust(w) for label, w in zip(labels, widths))
    body = [name.ljust(name_width) + "  " + "  ".join(c.rjust(w) for c, w in zip(cells, widths)) for name, cells in lines]
    messages = [f"{row.label}: {row.message}" for row in results.rows if row.message]
    return "\n".join([f"scenario: {results.scenario.name}", header, *body, "", *messages])
