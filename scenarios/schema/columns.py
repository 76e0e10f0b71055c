"""The names of result metric columns: ``ref.<metric>`` and ``cl.<metric>``, and the requirement
columns ``ref.req.<name>.<field>`` and ``cl.req.<name>.<field>``.

One naming for a row's metrics wherever they appear flat: a run's ``results.csv`` and DataFrame, a
trade study's ``cases.csv``, DataFrame and ``summary:`` keys. It lives in the schema because a study's
``summary:`` keys are validated against it when the study is read; the tables
(:mod:`scenarios.output.tables`) flatten rows by it. Whether a column is a requirement's is asked
of :func:`scenarios.requirements.fields.is_requirement_column`.

May import: :mod:`ocp.metrics`; nothing else of slewbench.
"""
from __future__ import annotations

from ocp.metrics import METRIC_KEYS

__all__ = ["AXES", "REQUIREMENT_MARK", "SCOPES", "SCORED_METRICS", "VECTOR_METRICS", "metric_columns"]

SCOPES = (("reference", "ref"), ("closed_loop", "cl"))
"""(key of the nested row, prefix of its flat columns) for the reference's and the closed loop's metrics."""
VECTOR_METRICS = ("int_abs_u",)
"""Metrics whose value is a list of per-axis values, split into one column per axis."""
AXES = ("x", "y", "z")
"""Suffixes of a vector metric's per-axis columns (body axes)."""
SCORED_METRICS = tuple(key for key in METRIC_KEYS if key != "plan_time_s")
"""The metrics of a row's columns (``plan_time_s`` is a column that names the row, not a score)."""
REQUIREMENT_MARK = "req"
"""The segment after the scope prefix of a requirement column (``ref.req.<name>.<field>``)."""


def metric_columns(vectors: bool = True) -> list[str]:
    """The flat metric columns: ``ref.<metric>`` then ``cl.<metric>``, in :data:`ocp.METRIC_KEYS` order.

    Parameters
    ----------
    vectors : bool, optional
        Include the per-axis columns of vector metrics (``ref.int_abs_u_x``, ``_y``, ``_z``).

    Returns
    -------
    list of str
        The column names.
    """
    columns = []
    for _, prefix in SCOPES:
        for key in SCORED_METRICS:
            if key in VECTOR_METRICS:
                columns += [f"{prefix}.{key}_{axis}" for axis in AXES] if vectors else []
            else:
                columns.append(f"{prefix}.{key}")
    return columns
