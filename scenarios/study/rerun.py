"""A stored sweep read back, and one of its cases re-run in full for inspection.

:func:`stored_results` reads a sweep directory's store (its study, as stored, and its records);
:func:`rerun_case` runs one case again from the study's stored resolved scenario, in this process,
and returns the full :class:`~scenarios.output.results.RunResults` (references, simulations, time
series: what ``slewbench run`` writes), and :func:`row_differences` compares its rows with the stored
ones column by column (``slewbench sweep DIR --case N`` prints it). A case run again by the same
slewbench gives the stored rows exactly: a worker's solver, simulator and reference caches do not
change a result (a reused reference is the one a fresh plan gives, for a planner that declares
``deterministic``).
"""
from __future__ import annotations

import math
import sqlite3
from pathlib import Path
from typing import Any

from scenarios.errors import OutputError, ScenarioError
from scenarios.output.directory import MARKER, read_manifest
from scenarios.output.results import RunResults
from scenarios.output.tables import flatten_row, is_missing
from scenarios.study.engine import SweepResults
from scenarios.study.spec import parse_study
from scenarios.study.store import STORE_NAME, SweepStore, is_sweep_store

__all__ = ["PROCESS_COLUMNS", "rerun_case", "row_differences", "stored_results"]

PROCESS_COLUMNS = ("plan_time_s", "plan_reused")
"""Columns that describe how the process computed the row, not the case: the planner's wall time,
and whether the worker reused an earlier case's reference (a re-run plans afresh, to the same
reference); left out of :func:`row_differences`."""


def stored_results(directory: str | Path) -> tuple[SweepResults, str]:
    """The study and records stored in a sweep directory.

    Parameters
    ----------
    directory : str or Path
        A directory ``slewbench sweep`` wrote (its marker and ``sweep.sqlite``).

    Returns
    -------
    results : SweepResults
        The stored study (parsed with the stored version, so its cases have the stored keys) and
        the stored records of its cases (a store resumed with a changed study also holds the
        earlier study's cases, which are left out).
    version : str
        The version of slewbench that stored it.

    Raises
    ------
    OutputError
        The directory holds no slewbench sweep, its store cannot be read, or the study stored in
        it is not valid any more.
    """
    out = Path(directory)
    try:
        if read_manifest(out) is None or not is_sweep_store(out):
            raise OutputError(out, f"holds no slewbench sweep ({STORE_NAME} and {MARKER} expected)")
        with SweepStore(out, create=False) as store:
            data, version = store.get_meta("study"), store.get_meta("version")
            records = store.records()
    except (ValueError, OSError, sqlite3.Error) as error:
        raise OutputError(out, f"its sweep store cannot be read: {error}") from None
    if not isinstance(version, str):
        raise OutputError(out, "its sweep store has no version of slewbench; it cannot be read")
    try:
        study = parse_study(data, version=version)
    except ScenarioError as error:
        raise OutputError(out, f"the study stored in it is not valid ({error}); it cannot be read") from None
    keys = {case.key for case in study.cases}
    return SweepResults(study, {key: record for key, record in records.items() if key in keys}), version


def rerun_case(results: SweepResults, index: int, progress: Any = None) -> RunResults:
    """Run case ``index`` of a study again, in full, from its resolved scenario.

    Parameters
    ----------
    results : SweepResults
        The study (:func:`stored_results`).
    index : int
        The case's number (``case`` in ``cases.csv``), from 0.
    progress : callable or None, optional
        Receives a line of text per finished row (as :func:`scenarios.runner.run`).

    Returns
    -------
    RunResults
        Every row with its reference and simulation, to be written as a run
        (:meth:`~scenarios.output.results.RunResults.write`).

    Raises
    ------
    ScenarioError
        At ``--case``: ``index`` is not a case of the study.
    """
    from scenarios.runner import run
    from scenarios.schema.loader import parse_scenario

    cases = results.study.cases
    if isinstance(index, bool) or not isinstance(index, int) or not 0 <= index < len(cases):
        raise ScenarioError("--case", f"expected a case of the study, 0 to {len(cases) - 1}, got {index!r}")
    return run(parse_scenario(cases[index].scenario, inapplicable_rows=True), progress=progress)


def _same(stored: Any, now: Any) -> bool:
    if is_missing(stored) and is_missing(now):
        return True
    if isinstance(stored, float) and isinstance(now, float) and math.isnan(stored) and math.isnan(now):
        return True
    return bool(stored == now)


def row_differences(stored: list[dict[str, Any]], rerun: RunResults) -> list[str]:
    """The columns in which a re-run's rows differ from the stored rows of the case.

    Parameters
    ----------
    stored : list of dict
        The case's stored rows (a record's ``rows``).
    rerun : RunResults
        The case run again (:func:`rerun_case`).

    Returns
    -------
    list of str
        ``"<label>: <column> stored <value>, now <value>"`` per differing column (the status, the
        message and every metric and requirement column, exactly; :data:`PROCESS_COLUMNS` left
        out); empty when they agree. A different number or order of rows is one line.
    """
    now = [flatten_row(row.to_dict()) for row in rerun.rows]
    before = [flatten_row(row) for row in stored]
    if [row.get("label") for row in before] != [row.get("label") for row in now]:
        return [f"rows: stored {[row.get('label') for row in before]}, now {[row.get('label') for row in now]}"]
    differences = []
    for old, new in zip(before, now):
        for column in dict.fromkeys([*old, *new]):
            if column in PROCESS_COLUMNS or _same(old.get(column), new.get(column)):
                continue
            differences.append(f"{old.get('label')}: {column} stored {old.get(column)!r}, now {new.get(column)!r}")
    return differences
