"""Rendering run results: JSON, flat CSV, Markdown, terminal text (layouts: :doc:`/outputs`)."""
from __future__ import annotations

import csv
import io
import json
import math
from typing import TYPE_CHECKING, Any

from ocp import METRIC_KEYS

if TYPE_CHECKING:
    import pandas

    from scenarios.runner import RunResults

AXES = ("x", "y", "z")
SCOPES = (("reference", "ref"), ("closed_loop", "cl"))


def _clean(value: Any) -> Any:
    """JSON-safe value: non-finite floats become null."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_clean(v) for v in value]
    return value


def to_json(results: RunResults) -> str:
    """``results.json`` (layout: :doc:`/outputs`), non-finite numbers written as ``null``.

    Parameters
    ----------
    results : RunResults
        The rows of a scenario run.

    Returns
    -------
    str
        Indented JSON text.
    """
    return json.dumps(_clean(results.to_dict()), indent=2)


def flat_columns() -> list[str]:
    """CSV columns: row identity, then every metric per scope (vectors split per axis).

    Returns
    -------
    list of str
        ``label, planner, controller, status, message, plan_time_s``, then ``ref_<metric>`` and
        ``cl_<metric>`` for every metric key (``int_abs_u`` as ``_x``, ``_y``, ``_z``).
    """
    columns = ["label", "planner", "controller", "status", "message", "plan_time_s"]
    for _, prefix in SCOPES:
        for key in METRIC_KEYS:
            if key in ("plan_time_s",):
                continue
            if key == "int_abs_u":
                columns += [f"{prefix}_{key}_{axis}" for axis in AXES]
            else:
                columns.append(f"{prefix}_{key}")
    return columns


def flat_rows(results: RunResults) -> list[dict[str, Any]]:
    """The rows as flat records keyed by :func:`flat_columns` (the CSV and DataFrame table).

    Parameters
    ----------
    results : RunResults
        The rows of a scenario run.

    Returns
    -------
    list of dict
        One record per row; a metric a row lacks is ``None``. Values are in the units of the
        metrics page (:doc:`/metrics`).
    """
    table = []
    for row in results.rows:
        record = {"label": row.label, "planner": row.planner or "", "controller": row.controller or "",
                  "status": row.status,
                  "message": row.message, "plan_time_s": row.plan_time_s}
        for scope, prefix in SCOPES:
            metrics = getattr(row, f"{scope}_metrics") or {}
            for key in METRIC_KEYS:
                if key == "plan_time_s":
                    continue
                value = metrics.get(key)
                if key == "int_abs_u":
                    for axis, component in zip(AXES, value or (None, None, None)):
                        record[f"{prefix}_{key}_{axis}"] = component
                else:
                    record[f"{prefix}_{key}"] = value
        table.append(record)
    return table


def to_csv(results: RunResults) -> str:
    """``results.csv``: :func:`flat_rows` under the :func:`flat_columns` header.

    Parameters
    ----------
    results : RunResults
        The rows of a scenario run.

    Returns
    -------
    str
        CSV text; missing and non-finite values are empty cells.
    """
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=flat_columns(), lineterminator="\n")
    writer.writeheader()
    for record in flat_rows(results):
        writer.writerow({k: "" if v is None or (isinstance(v, float) and not math.isfinite(v)) else v
                         for k, v in record.items()})
    return buffer.getvalue()


def to_dataframe(results: RunResults) -> pandas.DataFrame:
    """The CSV table as a pandas DataFrame (needs pandas installed).

    Parameters
    ----------
    results : RunResults
        The rows of a scenario run.

    Returns
    -------
    pandas.DataFrame
        One row per result row, the columns of :func:`flat_columns`.

    Raises
    ------
    ImportError
        pandas is not installed.
    """
    try:
        import pandas
    except ImportError:
        raise ImportError("to_dataframe needs pandas: pip install pandas") from None
    return pandas.DataFrame(flat_rows(results), columns=flat_columns())


def _format(value: Any) -> str:
    if value is None:
        return "-"
    if isinstance(value, list):
        return "[" + ", ".join(_format(v) for v in value) + "]"
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)


def _metric_lines(results: RunResults) -> list[tuple[str, list[str]]]:
    """(metric name, one formatted cell per row), reference metrics then closed-loop ones."""
    lines = [("status", [row.status for row in results.rows]),
             ("plan_time_s", [_format(row.plan_time_s) for row in results.rows])]
    for scope, prefix in SCOPES:
        for key in METRIC_KEYS:
            if key == "plan_time_s":
                continue
            cells = [_format((getattr(row, f"{scope}_metrics") or {}).get(key)) for row in results.rows]
            lines.append((f"{prefix}.{key}", cells))
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
