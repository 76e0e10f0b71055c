"""Tables and files of a trade study: ``cases.csv`` (one row per case and planner),
``summary.csv`` / ``summary.md`` (statistics per planner, and per grid point when there is
Monte Carlo), the resolved ``study.yaml`` and the plots (:mod:`scenarios.study_plots`)."""
from __future__ import annotations

import csv
import io
import json
import math
import os
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from ocp import METRIC_KEYS
from scenarios.study import Study, package_version
from scenarios.yaml_node import ScenarioError

AXES = ("x", "y", "z")
VECTOR_METRICS = ("int_abs_u",)
STATISTICS = ("count", "failures", "mean", "std", "median", "p5", "p95", "min", "max")
MARKER = ".slewbench-output.json"
IDENTITY = ["label", "planner", "controller", "status", "message", "plan_time_s"]


def metric_columns() -> list[str]:
    """``ref.<metric>`` then ``cl.<metric>``; vectors split into ``_x``, ``_y``, ``_z``."""
    columns = []
    for scope in ("ref", "cl"):
        for key in METRIC_KEYS:
            if key == "plan_time_s":
                continue
            columns += [f"{scope}.{key}_{a}" for a in AXES] if key in VECTOR_METRICS else [f"{scope}.{key}"]
    return columns


def case_table(study: Study, records: dict[str, dict[str, Any]]) -> tuple[list[str], list[dict[str, Any]]]:
    """Columns and rows of ``cases.csv`` in case order; cases not in ``records`` are left out."""
    columns = ["case", "seed", *study.varied_paths, *IDENTITY, *metric_columns()]
    table = []
    for case in study.cases:
        record = records.get(case.key)
        if record is None:
            continue
        for row in record["rows"]:
            line: dict[str, Any] = {"case": case.index, "seed": case.seed, **case.varied}
            line.update({name: row.get(name) for name in IDENTITY})
            for scope in ("ref", "cl"):
                metrics = row.get(scope) or {}
                for key in METRIC_KEYS:
                    if key == "plan_time_s":
                        continue
                    value = metrics.get(key)
                    if key in VECTOR_METRICS:
                        for axis, component in zip(AXES, value or (None,) * 3):
                            line[f"{scope}.{key}_{axis}"] = component
                    else:
                        line[f"{scope}.{key}"] = value
            table.append(line)
    return columns, table


def _number(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        return None
    return float(value)


def summary_table(study: Study, rows: list[dict[str, Any]]) -> tuple[list[str], list[dict[str, Any]]]:
    """Statistics of each summary metric per planner row label (and grid point under Monte Carlo).

    ``count`` is the number of rows, ``failures`` those whose status is not ``ok``; the
    statistics are over the rows where the metric has a value (p5, p95: linear percentiles).
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
            stats = (values.mean(), values.std(ddof=1) if values.size > 1 else 0.0, np.median(values),
                     np.percentile(values, 5), np.percentile(values, 95), values.min(), values.max()) \
                if values.size else (None,) * 7
            line.update({name: None if v is None else float(v) for name, v in zip(STATISTICS[2:], stats)})
            table.append(line)
    return columns, table


def _csv(columns: list[str], rows: list[dict[str, Any]]) -> str:
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=columns, lineterminator="\n", extrasaction="ignore")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: "" if v is None else (repr(v) if isinstance(v, float) else v) for k, v in row.items()})
    return buffer.getvalue()


def _markdown(study: Study, columns: list[str], rows: list[dict[str, Any]], missing: int) -> str:
    def cell(value: Any) -> str:
        return "-" if value is None else f"{value:.4g}" if isinstance(value, float) else str(value)

    out = [f"# {study.name}", "", f"{len(study.cases)} cases ({missing} missing), "
           f"{study.samples} Monte Carlo sample(s) per grid point, slewbench {package_version()}.", "",
           "| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    out += ["| " + " | ".join(cell(row.get(c)) for c in columns) + " |" for row in rows]
    out += ["", "Units: torque N m, integrals N m s (int_u2: N² m² s), angles deg, times s, rates rad/s. "
                "std is the sample standard deviation; p5 and p95 are linear percentiles.", ""]
    return "\n".join(out)


def resolved_study(study: Study) -> dict[str, Any]:
    """The study with its base scenario inlined, its version and every case's seed."""
    data = dict(study.raw)
    data["scenario"] = study.base
    data["resolved"] = {"version": package_version(), "cases": len(study.cases),
                        "case_seeds": [case.seed for case in study.cases]}
    return data


def _write_atomic(path: Path, text: str) -> None:
    """Replace a file this sweep writes (in its own claimed directory) in one step."""
    temporary = path.with_name(f".{path.name}.partial")
    temporary.write_text(text)
    os.replace(temporary, path)


def claim_output_directory(path: str | Path) -> Path:
    """Create ``path`` with slewbench's marker, or accept an existing directory carrying it.

    Private stand-in for :func:`scenarios.outputs.claim_output_directory` (issue 11) with the same
    semantics: a regular file, a non-empty directory without the marker, or a location that
    cannot be written is a :class:`ScenarioError`.
    """
    from scenarios import outputs
    claim = getattr(outputs, "claim_output_directory", None)
    if claim is not None:
        return claim(path)
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise ScenarioError("--out", f"{path} is a file, not a directory; slewbench will not replace it")
    if path.is_dir() and not (path / MARKER).is_file() and any(path.iterdir()):
        raise ScenarioError("--out", f"{path} is a non-empty directory that slewbench did not create; "
                                     "choose another --out (slewbench never overwrites what it did not write)")
    try:
        path.mkdir(parents=True, exist_ok=True)
        if not (path / MARKER).is_file():
            (path / MARKER).write_text(json.dumps({"tool": "slewbench", "version": package_version()}) + "\n")
        probe = path / ".slewbench-write-probe"
        probe.write_text("")
        probe.unlink()
    except OSError as error:
        raise ScenarioError("--out", f"cannot write to {path}: {error.strerror or error}") from None
    return path


def write_report(results, directory: Path, plots: bool = True) -> list[str]:
    """Write the study's tables, resolved study and (``plots``) figures into ``directory``.

    ``directory`` is created with slewbench's marker, or must already carry it.

    Returns
    -------
    list of the file names written.
    """
    study = results.study
    directory = claim_output_directory(directory)
    columns, rows = case_table(study, results.records)
    summary_columns, summary = summary_table(study, rows)
    files = {"cases.csv": _csv(columns, rows), "summary.csv": _csv(summary_columns, summary),
             "summary.md": _markdown(study, summary_columns, summary, results.missing),
             "study.yaml": yaml.safe_dump(resolved_study(study), sort_keys=False, width=120)}
    for name, text in files.items():
        _write_atomic(directory / name, text)
    written = list(files)
    if plots:
        from scenarios.study_plots import write_plots
        written += write_plots(study, rows, directory)
    return written
