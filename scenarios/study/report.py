"""Tables and files of a trade study: ``cases.csv`` (one row per case and planner),
``summary.csv`` / ``summary.md`` (statistics per planner, and per grid point when there is
Monte Carlo), the resolved ``study.yaml`` and the plots (:mod:`scenarios.study.plots`).

A case's rows are flattened and written as a run's are (:mod:`scenarios.output.tables`: the same
``ref.<metric>`` and ``cl.<metric>`` columns, the same rule for missing and non-finite values)."""
from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import yaml

from scenarios.output.directory import (
    new_staging,
)
from scenarios.output.tables import (
    csv_text,
    flatten_row,
    is_missing,
    row_columns,
    text_cell,
)
from scenarios.study.store import claim_sweep_directory, commit_sweep_outputs
from scenarios.study.types import Study, package_version

if TYPE_CHECKING:  # the engine imports this module lazily
    from scenarios.study.engine import SweepResults

STATISTICS = ("count", "failures", "mean", "std", "median", "p5", "p95", "min", "max")
_DUMPER = getattr(yaml, "CSafeDumper", yaml.SafeDumper)  # libyaml's emitter when built: same text, 3x faster


def case_table(study: Study, records: dict[str, dict[str, Any]]) -> tuple[list[str], list[dict[str, Any]]]:
    """Columns and rows of ``cases.csv`` in case order.

    Parameters
    ----------
    study : Study
        The expanded study.
    records : dict
        Case key -> stored record (``status``, ``rows``, ...); cases not in it are left out.

    Returns
    -------
    columns : list of str
        ``case``, ``seed``, the varied paths, then a run's columns
        (:func:`scenarios.output.tables.row_columns`).
    rows : list of dict
        One per case and planner (and controller), keyed by column: the stored row flattened by
        :func:`scenarios.output.tables.flatten_row`.
    """
    columns = ["case", "seed", *study.varied_paths, *row_columns()]
    table = []
    for case in study.cases:
        record = records.get(case.key)
        if record is None:
            continue
        for row in record["rows"]:
            table.append({"case": case.index, "seed": case.seed, **case.varied, **flatten_row(row)})
    return columns, table


def _number(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or is_missing(value):
        return None
    return float(value)


def summary_table(study: Study, rows: list[dict[str, Any]]) -> tuple[list[str], list[dict[str, Any]]]:
    """Statistics of each summary metric per planner row label (and grid point under Monte Carlo).

    ``count`` is the number of rows, ``failures`` those whose status is not ``ok``; the
    statistics are over the rows where the metric has a value (p5, p95: linear percentiles).

    Parameters
    ----------
    study : Study
        The study (its summary metrics, grid paths and samples).
    rows : list of dict
        The ``cases.csv`` rows (:func:`case_table`).

    Returns
    -------
    columns : list of str
        The grouping keys, ``metric`` and the statistics.
    rows : list of dict
        One per group and summary metric; a statistic without values is None.
    """
    by_point = study.samples > 1 and bool(study.grid_paths)
    keys = (study.grid_paths if by_point else []) + ["label"]
    groups: dict[tuple, list[dict[str, Any]]] = {}
    for row in rows:
        groups.setdefault(tuple(json.dumps(row.get(k)) for k in keys), []).append(row)
    columns = [*keys, "metric", *STATISTICS]
    table = []
    for members in groups.values():
        for metric in study.summary:
            values = np.array([v for v in (_number(r.get(metric)) for r in members) if v is not None])
            line = {k: members[0].get(k) for k in keys}
            line.update(metric=metric, count=len(members), failures=sum(r["status"] != "ok" for r in members))
            if values.size:
                p5, p95 = np.percentile(values, (5, 95))
                stats: tuple = (values.mean(), values.std(ddof=1) if values.size > 1 else 0.0, np.median(values),
                                p5, p95, values.min(), values.max())
            else:
                stats = (None,) * 7
            line.update({name: None if v is None else float(v) for name, v in zip(STATISTICS[2:], stats)})
            table.append(line)
    return columns, table


def _markdown(study: Study, columns: list[str], rows: list[dict[str, Any]], missing: int) -> str:
    out = [f"# {study.name}", "", f"{len(study.cases)} cases ({missing} missing), "
           f"{study.samples} Monte Carlo sample(s) per grid point, slewbench {package_version()}.", "",
           "| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    out += ["| " + " | ".join(text_cell(row.get(c)) for c in columns) + " |" for row in rows]
    out += ["", "Units: torque N m, integrals N m s (int_u2: N² m² s), angles deg, times s, rates rad/s. "
                "std is the sample standard deviation; p5 and p95 are linear percentiles.", ""]
    return "\n".join(out)


def resolved_study(study: Study) -> dict[str, Any]:
    """The study as ``study.yaml`` records it.

    Parameters
    ----------
    study : Study
        The expanded study.

    Returns
    -------
    dict
        The study mapping with its base scenario inlined and a ``resolved`` entry: the version,
        the number of cases and every case's seed.
    """
    data = dict(study.raw)
    data["scenario"] = study.base
    data["resolved"] = {"version": package_version(), "cases": len(study.cases),
                        "case_seeds": [case.seed for case in study.cases]}
    return data


def write_report(results: SweepResults, directory: str | Path, plots: bool = True) -> list[str]:
    """Write the study's tables, resolved study and (``plots``) figures into ``directory``.

    ``directory`` is claimed (created with slewbench's marker, or already carrying it); the files
    are staged inside it and committed together, replacing only files slewbench listed there.

    Parameters
    ----------
    results : SweepResults
        The study and its records.
    directory : str or Path
        The output directory.
    plots : bool, optional
        Also draw the PNG figures (``plots/``).

    Returns
    -------
    list of str
        The file names written (relative to ``directory``).
    """
    study = results.study
    directory = claim_sweep_directory(directory)
    columns, rows = case_table(study, results.records)
    summary_columns, summary = summary_table(study, rows)
    files = {"cases.csv": csv_text(columns, rows), "summary.csv": csv_text(summary_columns, summary),
             "summary.md": _markdown(study, summary_columns, summary, results.missing),
             "study.yaml": yaml.dump(resolved_study(study), Dumper=_DUMPER, sort_keys=False, width=120)}
    staging = new_staging(directory)
    try:
        for name, text in files.items():
            (staging / name).write_text(text)
        if plots:
            from scenarios.study.plots import write_plots
            (staging / "plots").mkdir()
            write_plots(study, rows, staging / "plots")
        return commit_sweep_outputs(directory, staging)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
