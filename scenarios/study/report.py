"""Tables and files of a trade study: ``cases.csv`` (one row per case and planner),
``summary.csv`` / ``summary.md`` (statistics per planner, and per grid point when there is
Monte Carlo), ``requirements.csv`` (per planner, the fraction of cases that meet every requirement,
then of those scored that meet each requirement in each scope by its verdict ``met`` (from the rows
that count only: ``ok`` or ``violated``), each with its Wilson interval: :func:`requirement_table`;
also in ``summary.md`` and printed by ``slewbench sweep``), for a Monte Carlo study the robustness tables ``robustness.csv``, ``sensitivity.csv`` and ``worst_cases.csv`` (:mod:`scenarios.study.robustness`;
also in ``summary.md``), the resolved ``study.yaml``, the plots
(:mod:`scenarios.study.plots`) and the interactive ``report.html`` (:mod:`scenarios.study.html`).

A case's rows are flattened and written as a run's are (:mod:`scenarios.output.tables`: the same
``ref.<metric>`` and ``cl.<metric>`` columns, then the requirement columns, the same rule for
missing and non-finite values)."""
from __future__ import annotations

import json
import math
import shutil
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import yaml

from ocp.metrics import METRIC_INFO
from scenarios.output.directory import (
    new_staging,
)
from scenarios.output.names import row_stems
from scenarios.output.provenance import environment, package_version, utc_stamp
from scenarios.output.tables import (
    RUN_COLUMNS,
    csv_text,
    flatten_row,
    is_missing,
    requirement_columns,
    row_columns,
    text_cell,
)
from scenarios.requirements.fields import (
    VERDICT,
    is_requirement_column,
    is_verdict_column,
)
from scenarios.schema.columns import REQUIREMENT_MARK, SCOPES
from scenarios.study.store import claim_sweep_directory, commit_sweep_outputs
from scenarios.study.types import Study

if TYPE_CHECKING:  # the engine imports this module lazily
    from scenarios.study.engine import SweepResults

STATISTICS = ("count", "never", "no_value", "excluded", "not_ok", "mean", "std", "median", "p5", "p95", "min",
              "max")
"""The columns of ``summary.csv`` after the grouping keys and ``metric`` (:func:`summary_table`)."""
COUNTED_STATUSES = ("ok", "violated")
"""Statuses of the rows whose metric values the study's statistics (``summary.csv``) and plots take:
the motion completed (a broken requirement is a result, and its metrics stand). A ``failed`` row (a
failed planner or simulation, metrics that are not physical), an ``infeasible`` one and a
``crashed`` one are left out whatever values they carry (:func:`metric_values` with
``counted_only``), and ``summary.csv`` counts them (``excluded``)."""
PROPORTION_STATISTICS = ("completed", "met", "fraction_met", "wilson_low", "wilson_high")
"""The statistics of a proportion (:func:`proportion`): rows that completed (not ``crashed``), those
meeting the criterion, their fraction and its Wilson 95 % interval; ``robustness.csv`` adds
``excluded``, ``requirements.csv`` ``excluded``, ``scored``, ``not_scored`` and ``no_verdict``
(:data:`REQUIREMENT_STATISTICS`)."""
REQUIREMENT_STATISTICS = ("completed", "excluded", "scored", "not_scored", "no_verdict", *PROPORTION_STATISTICS[1:])
"""The columns of ``requirements.csv`` after the grouping keys and ``criterion``
(:func:`requirement_table`): the rows that completed (not ``crashed``), the group's rows left out
because they do not count (:func:`excluded_count`: ``failed``, ``infeasible``, ``crashed``, as in
``robustness.csv``), those scored against the criterion, the rows that count without a score of it,
those scored before per-requirement verdicts were stored (no verdict to count), those meeting it,
the fraction of the scored ones and its Wilson 95 % interval."""
EVERY_REQUIREMENT = "every requirement"
"""The criterion of the rows whose status is ``ok`` (``requirements.csv``, ``robustness.csv``)."""
WILSON_Z = 1.959963984540054
"""The standard normal quantile of 97.5 %: a two-sided 95 % interval."""
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
        (:func:`scenarios.output.tables.row_columns`, with the stored rows' requirement columns),
        then :data:`~scenarios.output.tables.RUN_COLUMNS` (``file_stem``).
    rows : list of dict
        One per case and planner (and controller), keyed by column: the stored row flattened by
        :func:`scenarios.output.tables.flatten_row`, and its ``file_stem``: the stem of its files when
        the case is re-run in full (``slewbench sweep DIR --case N`` writes
        ``cases/N/timeseries/<file_stem>.csv``), :func:`~scenarios.output.names.row_stems` of the
        case's labels, as a run records it.
    """
    table = []
    stored = []
    for case in study.cases:
        record = records.get(case.key)
        if record is None:
            continue
        stems = row_stems([str(row.get("label")) for row in record["rows"]])
        for row, stem in zip(record["rows"], stems):
            stored.append(row)
            table.append({"case": case.index, "seed": case.seed, **case.varied, **flatten_row(row), "file_stem": stem})
    columns = ["case", "seed", *study.varied_paths, *row_columns(requirement_columns(stored)), *RUN_COLUMNS]
    return columns, table


def _number(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or is_missing(value):
        return None
    return float(value)


def never_witness(column: str) -> str | None:
    """The column whose value makes a null of ``column`` mean "never reached" (the worst outcome).

    A metric column ``ref.<key>`` or ``cl.<key>`` whose :class:`ocp.metrics.MetricInfo` declares
    ``null_worst_when`` (``settling_time_s``: ``final_error_deg``) has as witness the same scope's
    column of that key: a row with a final error and without a settling time never settled.

    Parameters
    ----------
    column : str
        A ``cases.csv`` column.

    Returns
    -------
    str or None
        The witness column (``cl.final_error_deg`` for ``cl.settling_time_s``); None for a column
        whose null only means that it does not apply.
    """
    scope, _, key = column.partition(".")
    info = METRIC_INFO.get(key)
    return None if info is None or info.null_worst_when is None else f"{scope}.{info.null_worst_when}"


def counted(row: dict[str, Any]) -> bool:
    """Whether a row's metric values count in the study's statistics and plots (:data:`COUNTED_STATUSES`).

    Parameters
    ----------
    row : dict
        A ``cases.csv`` row (:func:`case_table`).

    Returns
    -------
    bool
        True for a row ``ok`` or ``violated``.
    """
    return row.get("status") in COUNTED_STATUSES


def excluded_count(rows: list[dict[str, Any]]) -> int:
    """The rows whose values the study's tables leave out (``excluded`` in ``summary.csv``,
    ``requirements.csv`` and the robustness tables).

    Parameters
    ----------
    rows : list of dict
        A group's ``cases.csv`` rows.

    Returns
    -------
    int
        The rows that do not count (:func:`counted`: ``failed``, ``infeasible``, ``crashed``),
        whatever values they carry.
    """
    return sum(not counted(row) for row in rows)


def metric_values(column: str, rows: list[dict[str, Any]], counted_only: bool = False) -> np.ndarray:
    """A metric column's values as the study's statistics, rankings and correlations take them.

    Parameters
    ----------
    column : str
        A ``cases.csv`` column.
    rows : list of dict
        The ``cases.csv`` rows (:func:`case_table`).
    counted_only : bool, optional
        NaN also in every row that does not count (:func:`counted`: ``failed``, ``infeasible``,
        ``crashed``), whatever its value: the values of ``summary.csv`` and of the plots.

    Returns
    -------
    (len(rows),) ndarray
        The row's number; +inf where the metric never reached its value (a null of a metric that
        declares ``null_worst_when``, :func:`never_witness`, in a row where the witness has a
        value: a case that never settled); NaN where the row has no value (the metric does not
        apply, a failed planner, a crashed case) or, with ``counted_only``, does not count.
    """
    witness = never_witness(column)
    values = np.full(len(rows), math.nan)
    for k, row in enumerate(rows):
        if counted_only and not counted(row):
            continue
        value = _number(row.get(column))
        if value is not None:
            values[k] = value
        elif witness is not None and _number(row.get(witness)) is not None:
            values[k] = math.inf
    return values


def percentile(values: np.ndarray, q: float) -> float:
    """The linear percentile ``q`` of ``values``, which may hold +inf (a case that never settled).

    As ``numpy.percentile`` (linear interpolation between the two nearest ordered values); a
    percentile that interpolates towards +inf is +inf.

    Parameters
    ----------
    values : (n,) ndarray
        Finite numbers and +inf, n >= 1.
    q : float
        The percentile, 0 to 100.

    Returns
    -------
    float
    """
    if np.isfinite(values).all():
        return float(np.percentile(values, q))
    ordered = np.sort(values)
    position = q / 100.0 * (ordered.size - 1)
    low = math.floor(position)
    fraction = position - low
    if fraction == 0.0 or low + 1 >= ordered.size:
        return float(ordered[low])
    if math.isinf(ordered[low + 1]):
        return math.inf
    return float(ordered[low] + (ordered[low + 1] - ordered[low]) * fraction)


def summary_table(study: Study, rows: list[dict[str, Any]]) -> tuple[list[str], list[dict[str, Any]]]:
    """Statistics of each summary metric per planner row label (and grid point under Monte Carlo).

    The statistics take the rows that count (:data:`COUNTED_STATUSES`, ``ok`` and ``violated``),
    as the plots do: the values are :func:`metric_values` with ``counted_only``. ``count`` is the
    number of rows where the metric has a value, ``never`` those where it never reached one (a
    settling time whose motion still ends outside the band; None for a metric whose null only
    means that it does not apply), ``no_value`` the other rows (the metric does not apply, or the
    row does not count); the three add up to the group's rows. ``excluded`` counts the rows left
    out because they do not count (``failed``, ``infeasible``, ``crashed``: part of ``no_value``,
    whatever values they carry), ``not_ok`` the rows whose status is not ``ok`` (``violated``, ``failed``,
    ``infeasible``, ``crashed``). ``mean`` and
    ``std`` are over the ``count`` rows with a value; ``median``, ``p5``, ``p95`` (linear
    percentiles), ``min`` and ``max`` are over those and the ``never`` rows taken as +inf
    (:func:`percentile`), so that a percentile reached by cases that never settled is +inf.

    Parameters
    ----------
    study : Study
        The study (its summary metrics, grid paths and samples).
    rows : list of dict
        The ``cases.csv`` rows (:func:`case_table`).

    Returns
    -------
    columns : list of str
        The grouping keys, ``metric`` and :data:`STATISTICS`.
    rows : list of dict
        One per group and summary metric; a statistic without values is None, an infinite one
        ``math.inf`` (written ``inf``: :func:`shown_infinity`).
    """
    keys, groups = group_rows(study, rows)
    columns = [*keys, "metric", *STATISTICS]
    table = []
    for members in groups.values():
        for metric in study.summary:
            values = metric_values(metric, members, counted_only=True)
            finite = values[np.isfinite(values)]
            ranked = values[~np.isnan(values)]
            never = int(np.isinf(values).sum())
            line = {k: members[0].get(k) for k in keys}
            line.update(metric=metric, count=int(finite.size), never=never if never_witness(metric) else None,
                        no_value=int(np.isnan(values).sum()), excluded=excluded_count(members),
                        not_ok=sum(r["status"] != "ok" for r in members))
            mean = std = None
            if finite.size:
                mean, std = float(finite.mean()), float(finite.std(ddof=1)) if finite.size > 1 else 0.0
            line.update(mean=mean, std=std)
            if ranked.size:
                line.update(median=percentile(ranked, 50.0), p5=percentile(ranked, 5.0), p95=percentile(ranked, 95.0),
                            min=float(ranked.min()), max=float(ranked.max()))
            else:
                line.update(dict.fromkeys(("median", "p5", "p95", "min", "max")))
            table.append(line)
    return columns, table


INFINITY_TEXT = "inf"
"""How the written tables (CSV, Markdown, ``report.html``) show a statistic or a worst value that is
+inf (a case that never settled), where the one rule for non-finite values
(:mod:`scenarios.output.tables`) would leave the cell empty, as if there were no value."""


def shown_infinity(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The rows with +inf written as :data:`INFINITY_TEXT` (pandas reads it back as ``inf``).

    Parameters
    ----------
    rows : list of dict
        Table rows.

    Returns
    -------
    list of dict
        Copies of the rows that hold +inf, the others as they are.
    """
    return [{k: INFINITY_TEXT if isinstance(v, float) and v == math.inf else v for k, v in row.items()}
            if any(isinstance(v, float) and v == math.inf for v in row.values()) else row for row in rows]


def wilson_interval(successes: int, trials: int, z: float = WILSON_Z) -> tuple[float, float] | None:
    """The Wilson score interval of a binomial proportion.

    ``(p + z²/2n ± z √(p(1 − p)/n + z²/4n²)) / (1 + z²/n)`` with ``p = successes / trials``: unlike the
    normal approximation it stays inside [0, 1] and is sensible at 0 and n successes.

    Parameters
    ----------
    successes : int
        Trials that succeeded, 0 to ``trials``.
    trials : int
        Trials, non-negative.
    z : float, optional
        Standard normal quantile (default :data:`WILSON_Z`: 95 %).

    Returns
    -------
    (float, float) or None
        Lower and upper bound; ``None`` without trials.
    """
    if trials <= 0:
        return None
    p = successes / trials
    scale = 1.0 + z * z / trials
    centre = (p + z * z / (2 * trials)) / scale
    half = z / scale * math.sqrt(p * (1.0 - p) / trials + z * z / (4.0 * trials * trials))
    # at 0 (n) successes the bound is 0 (1) exactly, not the rounding of centre -/+ half
    return 0.0 if successes == 0 else max(0.0, centre - half), 1.0 if successes == trials else min(1.0, centre + half)


def proportion(met: int, completed: int) -> dict[str, Any]:
    """The statistics of :data:`PROPORTION_STATISTICS` for ``met`` successes among ``completed`` cases.

    Parameters
    ----------
    met : int
        Cases meeting the criterion, 0 to ``completed``.
    completed : int
        Cases that completed (non-negative).

    Returns
    -------
    dict
        ``completed``, ``met``, ``fraction_met``, ``wilson_low`` and ``wilson_high``
        (:func:`wilson_interval`); the last three are None without completed cases.
    """
    interval = wilson_interval(met, completed)
    return {"completed": completed, "met": met, "fraction_met": met / completed if completed else None,
            "wilson_low": None if interval is None else interval[0],
            "wilson_high": None if interval is None else interval[1]}


def distinct_rows(study: Study, rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The rows of the study's distinct cases: of cases that share a store key (the same scenario:
    a degenerate dispersion such as ``uniform: [a, a]``, a grid value given twice), the first.

    Cases with one key are one simulation, stored once: counting each as a sample would count one
    deterministic outcome several times and narrow the Wilson interval without information. The
    proportions (``requirements.csv``, ``robustness.csv``) are over these rows.

    Parameters
    ----------
    study : Study
        The expanded study (its cases' keys).
    rows : list of dict
        The ``cases.csv`` rows (:func:`case_table`).

    Returns
    -------
    list of dict
        The rows whose case is the first of its key (all rows when every case has its own key; a
        row without a case of the study is kept).
    """
    keys = {case.index: case.key for case in study.cases}
    first: dict[str, int] = {}
    for case in study.cases:
        first.setdefault(case.key, case.index)
    if len(first) == len(keys):
        return rows
    return [row for row in rows if row.get("case") not in keys or first[keys[row["case"]]] == row["case"]]


def collapse_note(study: Study) -> str | None:
    """What the outputs say of a study whose cases collapse to fewer distinct ones (:func:`distinct_rows`).

    Parameters
    ----------
    study : Study
        The expanded study.

    Returns
    -------
    str or None
        ``note: the 20 cases are 1 distinct case ...``; None when every case has its own key.
    """
    distinct = len({case.key for case in study.cases})
    if distinct == len(study.cases):
        return None
    return (f"note: the {len(study.cases)} cases are {distinct} distinct case{'s' if distinct != 1 else ''} (cases with "
            "the same scenario share one store key and one simulation: a dispersion that draws one value, a "
            "repeated grid value); the proportions and their Wilson intervals count each distinct case once")


def group_rows(study: Study, rows: list[dict[str, Any]]) -> tuple[list[str], dict[tuple, list[dict[str, Any]]]]:
    """The grouping keys of the study's tables and the rows of each group.

    Parameters
    ----------
    study : Study
        The study (its grid paths and samples).
    rows : list of dict
        The ``cases.csv`` rows (:func:`case_table`).

    Returns
    -------
    keys : list of str
        The grid paths under a grid of Monte Carlo samples, then ``label``.
    groups : dict
        The keys' values (as JSON text) -> the group's rows, in the order first met.
    """
    by_point = study.samples > 1 and bool(study.grid_paths)
    keys = (study.grid_paths if by_point else []) + ["label"]
    groups: dict[tuple, list[dict[str, Any]]] = {}
    for row in rows:
        groups.setdefault(tuple(json.dumps(row.get(k)) for k in keys), []).append(row)
    return keys, groups


def requirement_criterion(name: str, scope: str) -> str:
    """How ``requirements.csv`` names one requirement in one scope: ``st_sun (closed loop)``.

    Parameters
    ----------
    name : str
        The requirement's name (a pointing requirement's, ``actuators``, ``rate``, ``final``).
    scope : str
        ``reference`` or ``closed_loop``.

    Returns
    -------
    str
        The name and the scope in words, as a row's message names a broken requirement.
    """
    return f"{name} ({scope.replace('_', ' ')})"


def requirement_verdicts(rows: list[dict[str, Any]]) -> list[tuple[str, str]]:
    """The verdict columns of the requirements some ``cases.csv`` rows were scored against: per
    requirement, in the order the rows first give them, its reference's then its closed loop's.

    Parameters
    ----------
    rows : list of dict
        The ``cases.csv`` rows (:func:`case_table`).

    Returns
    -------
    list of (str, str)
        ``(criterion, column)``: :func:`requirement_criterion` and ``<scope>.req.<name>.met``, for
        each requirement and scope with a requirement column in some row
        (:func:`~scenarios.requirements.fields.is_requirement_column`), whether or not the verdict
        itself was stored (a store written before verdicts were has the scores only).
    """
    names: dict[str, None] = {}
    scoped: set[tuple[str, str]] = set()
    for column in dict.fromkeys(column for row in rows for column in row):  # in the order first given
        if is_requirement_column(column):
            prefix, _, name, _ = column.split(".")
            names.setdefault(name)
            scoped.add((prefix, name))
    return [(requirement_criterion(name, scope), f"{prefix}.{REQUIREMENT_MARK}.{name}.{VERDICT}")
            for name in names for scope, prefix in SCOPES if (prefix, name) in scoped]


def _scored_without_verdict(row: dict[str, Any], verdict_of: dict[str, str]) -> set[str]:
    """The verdict columns a row lacks although it carries a value of that requirement's score in
    that scope (``verdict_of``: each score column's verdict column): the row was scored before
    per-requirement verdicts were stored."""
    scored = {verdict_of[column] for column, value in row.items() if column in verdict_of and not is_missing(value)}
    return {column for column in scored if not isinstance(row.get(column), bool)}


def requirement_table(study: Study, rows: list[dict[str, Any]]) -> tuple[list[str], list[dict[str, Any]]]:
    """Per planner row label (and grid point under Monte Carlo): how many cases meet every requirement,
    then each requirement in each scope, with the fraction and its Wilson 95 % interval
    (:func:`wilson_interval`).

    The first criterion, :data:`EVERY_REQUIREMENT`, is met by a row whose status is ``ok``, among the
    completed rows (not ``crashed``: a ``failed``, ``infeasible`` or ``violated`` row completed and
    does not meet it), as in ``robustness.csv``. Then one criterion per requirement and scope
    (:func:`requirement_criterion`, ``st_sun (closed loop)``), read from the verdict the scoring
    stored with the row's scores (the column ``<scope>.req.<name>.met``, never the message), and
    only from the rows that count (:func:`counted`: ``ok`` or ``violated``, as the summary's
    statistics and the robustness tables take them; a ``failed`` row may carry a verdict on a
    motion that is not physical, and is left out whatever it carries). ``scored`` counts the rows
    that count with that verdict, ``met`` those where it is true, and the fraction is of the
    scored rows; ``not_scored`` counts the rows that count without a score of it (no closed loop),
    ``no_verdict`` those with its score but no verdict (a store written before verdicts were
    stored: re-run those cases to count them). ``excluded`` is the group's rows that do not count
    (:func:`excluded_count`: ``failed``, ``infeasible``, ``crashed``), the ``excluded`` of
    ``robustness.csv``. Cases that share a store key count once (:func:`distinct_rows`).

    Parameters
    ----------
    study : Study
        The study (its grid paths and samples).
    rows : list of dict
        The ``cases.csv`` rows (:func:`case_table`).

    Returns
    -------
    columns : list of str
        The grouping keys, ``criterion`` and :data:`REQUIREMENT_STATISTICS`.
    rows : list of dict
        One per group and criterion (:data:`EVERY_REQUIREMENT` first, whose ``scored`` is
        ``completed`` and ``not_scored`` and ``no_verdict`` 0); the fraction and the interval are
        None without a completed (scored) row.
    """
    distinct = distinct_rows(study, rows)
    verdicts = requirement_verdicts(distinct)
    keys, groups = group_rows(study, distinct)
    verdict_of = {column: f"{column.rsplit('.', 1)[0]}.{VERDICT}" for column in set().union(*distinct)
                  if is_requirement_column(column) and not is_verdict_column(column)}
    table = []
    for members in groups.values():
        completed = [r for r in members if r["status"] != "crashed"]
        counting = [r for r in members if counted(r)]
        stale = [_scored_without_verdict(r, verdict_of) for r in counting]
        criteria = [(EVERY_REQUIREMENT, len(completed), 0, 0, sum(r["status"] == "ok" for r in completed))]
        for criterion, column in verdicts:
            scored = [r[column] for r in counting if isinstance(r.get(column), bool)]
            no_verdict = sum(column in missing for missing in stale)
            criteria.append((criterion, len(scored), len(counting) - len(scored) - no_verdict, no_verdict,
                             sum(scored)))
        for criterion, scored_count, not_scored, no_verdict, met in criteria:
            line = {k: members[0].get(k) for k in keys}
            line.update(criterion=criterion, **proportion(met, scored_count))
            line.update(completed=len(completed), excluded=excluded_count(members), scored=scored_count,
                        not_scored=not_scored, no_verdict=no_verdict)
            table.append(line)
    return [*keys, "criterion", *REQUIREMENT_STATISTICS], table


NO_VERDICT_TEXT = "scored before per-requirement verdicts were stored"
"""What the outputs say of rows whose requirement scores have no verdict (``no_verdict`` in
``requirements.csv``: a store written by an earlier slewbench)."""
RERUN_TEXT = ("re-run the cases to count them (the study into a new directory: a resumed sweep keeps the "
              "stored cases)")
"""How to count the verdicts of those rows."""


def verdict_note(requirements: tuple[list[str], list[dict[str, Any]]]) -> str | None:
    """What ``summary.md`` and ``report.html`` say when some rows' requirements could not be counted
    one by one, because they were scored before per-requirement verdicts were stored.

    Parameters
    ----------
    requirements : (list of str, list of dict)
        :func:`requirement_table`.

    Returns
    -------
    str or None
        ``note: ...`` naming the criteria with ``no_verdict`` rows and what to do; None when every
        scored row has its verdicts.
    """
    criteria = list(dict.fromkeys(line["criterion"] for line in requirements[1] if line.get("no_verdict")))
    if not criteria:
        return None
    return (f"note: some cases were {NO_VERDICT_TEXT} (no_verdict), so {', '.join(criteria)} "
            f"{'is' if len(criteria) == 1 else 'are'} not counted in them: {RERUN_TEXT}")


def requirement_lines(requirements: tuple[list[str], list[dict[str, Any]]]) -> list[str]:
    """The requirement counts ``slewbench sweep`` prints, one line per group and criterion.

    Parameters
    ----------
    requirements : (list of str, list of dict)
        :func:`requirement_table`.

    Returns
    -------
    list of str
        ``  eigenaxis: st_sun (closed loop) met in 13 of 16 cases``, then, for one requirement in one
        scope, ``, 2 not scored`` (rows that count without its score), ``, 1 left out (failed,
        infeasible or crashed)`` and ``, 3 scored before per-requirement verdicts were stored; re-run
        the cases ...`` when there are such rows; without a scored row ``no case scored (4
        completed, 1 left out: ...)``, or ``not counted: 4 cases scored before per-requirement
        verdicts were stored; re-run the cases ...``; ``no completed case`` when every case crashed.
    """
    columns, table = requirements
    keys = columns[:columns.index("criterion")]
    lines = []
    for line in table:
        group = ", ".join(text_cell(line.get(k)) for k in keys)
        head = f"  {group}: {line['criterion']}"
        if not line["completed"]:
            lines.append(f"{head}: no completed case")
            continue
        stale, left = line["no_verdict"], line["excluded"] if line["criterion"] != EVERY_REQUIREMENT else 0
        if not line["scored"]:
            if stale:
                lines.append(f"{head}: not counted: {stale} case{'s' if stale != 1 else ''} {NO_VERDICT_TEXT}; "
                             f"{RERUN_TEXT}")
            else:
                lines.append(f"{head}: no case scored ({line['completed']} completed"
                             + (f", {left} left out: failed, infeasible or crashed" if left else "") + ")")
            continue
        parts = [f"{line['not_scored']} not scored"] if line["not_scored"] else []
        parts += [f"{left} left out (failed, infeasible or crashed)"] if left else []
        parts += [f"{stale} {NO_VERDICT_TEXT}"] if stale else []
        lines.append(f"{head} met in {line['met']} of {line['scored']} case{'s' if line['scored'] != 1 else ''}"
                     + "".join(f", {part}" for part in parts) + (f"; {RERUN_TEXT}" if stale else ""))
    return lines


REQUIREMENT_TEXT = ("every requirement: rows whose status is ok among the completed ones (not crashed); then each "
                    "requirement in each scope, by its verdict (met), from the rows ok or violated only, as in the "
                    "summary: the rows where it is met among those scored there. excluded: the rows left out "
                    "(failed, infeasible, crashed) whatever verdicts they carry; not_scored: rows ok or violated "
                    f"without its score; no_verdict: rows {NO_VERDICT_TEXT}. With the Wilson 95 % interval of the "
                    "fraction.")
"""The explanation of the requirements table in ``summary.md`` and ``report.html``."""


def _table_lines(columns: list[str], rows: list[dict[str, Any]]) -> list[str]:
    return (["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
            + ["| " + " | ".join(text_cell(row.get(c)) for c in columns) + " |" for row in rows])


def _markdown(study: Study, columns: list[str], rows: list[dict[str, Any]], missing: int,
              requirements: tuple[list[str], list[dict[str, Any]]] | None = None, robustness: str = "") -> str:
    note = collapse_note(study)
    out = [f"# {study.name}", "", (f"{len(study.cases)} cases ({missing} missing), "
                                   f"{study.samples} Monte Carlo sample(s) per grid point, slewbench "
                                   f"{package_version()}."), "", *([note, ""] if note else [])]
    out += _table_lines(columns, rows)
    out += ["", ("Units: torque N m, integrals N m s (int_u2: N² m² s), angles deg, times s, rates rad/s. "
                 "The statistics take the rows ok or violated, as the plots do: a failed, infeasible or crashed "
                 "row is left out whatever values it has (excluded counts them). "
                 "count: rows with a value; never: rows that never reached one (a case that never settled); "
                 "no_value: the other rows (excluded ones included). mean and std (sample standard deviation) are "
                 "over the count rows; median, p5, p95 (linear percentiles), min and max over those and the never "
                 "rows as inf; not_ok: rows whose status is not ok (violated, failed, infeasible or crashed)."), ""]
    if requirements is not None:
        note = verdict_note(requirements)
        out += ["## Cases meeting the requirements", "", REQUIREMENT_TEXT, "", *([note, ""] if note else [])]
        out += _table_lines(*requirements) + [""]
    if robustness:
        out += [robustness]
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
        The study mapping with its base scenario inlined and a ``resolved`` entry: slewbench's
        version, the date (UTC), Python, the platform and the numerical libraries
        (:func:`~scenarios.output.provenance.environment`), the number of cases and every case's
        seed.
    """
    data = dict(study.raw)
    data["scenario"] = study.base
    run_environment = environment()
    data["resolved"] = {"version": run_environment.pop("slewbench"), "date_utc": utc_stamp(), **run_environment,
                        "cases": len(study.cases), "case_seeds": [case.seed for case in study.cases]}
    return data


ROBUSTNESS_FILES = ("robustness.csv", "sensitivity.csv", "worst_cases.csv")
"""The robustness tables of a Monte Carlo study (:mod:`scenarios.study.robustness`), in the order of
:func:`robustness_tables`."""

Table = tuple[list[str], list[dict[str, Any]]]


def robustness_tables(study: Study, rows: list[dict[str, Any]]) -> tuple[Table, Table, Table] | None:
    """The robustness tables of a study with Monte Carlo samples or thresholds.

    Parameters
    ----------
    study : Study
        The study.
    rows : list of dict
        The ``cases.csv`` rows (:func:`case_table`).

    Returns
    -------
    tuple or None
        The proportions, the rank correlations and the worst cases
        (:func:`scenarios.study.robustness.proportion_table`, ``sensitivity_table``,
        ``worst_table``), written as :data:`ROBUSTNESS_FILES`; None for a study with neither
        Monte Carlo samples nor ``robustness.thresholds``.
    """
    if study.samples <= 1 and not study.mc_paths and not study.thresholds:
        return None
    from scenarios.study.robustness import (
        proportion_table,
        sensitivity_table,
        worst_table,
    )
    return proportion_table(study, rows), sensitivity_table(study, rows), worst_table(study, rows)


def write_report(results: SweepResults, directory: str | Path, plots: bool = True, progress: bool = False) -> list[str]:
    """Write the study's tables, resolved study and (``plots``) figures and ``report.html`` into ``directory``.

    ``directory`` is claimed (created with slewbench's marker, or already carrying it); the files
    are staged inside it and committed together, replacing only files slewbench listed there.

    Parameters
    ----------
    results : SweepResults
        The study and its records.
    directory : str or Path
        The output directory.
    plots : bool, optional
        Also draw the PNG figures (``plots/``) and write the interactive ``report.html``
        (:mod:`scenarios.study.html`).
    progress : bool, optional
        Show the files written so far on standard error as a sweep shows its cases
        (:func:`scenarios.study.engine.write_progress`: a bar on a terminal, elsewhere a line at most
        every 30 s). Default False.

    Returns
    -------
    list of str
        The file names written (relative to ``directory``).
    """
    from scenarios.study.engine import write_progress

    study = results.study
    directory = claim_sweep_directory(directory)
    meter = write_progress(study.name, progress)
    try:
        files: dict[str, str] = {}

        def add(name: str, text: str) -> None:
            files[name] = text
            meter.advance()

        columns, rows = case_table(study, results.records)
        add("cases.csv", csv_text(columns, rows))
        summary_columns, summary = summary_table(study, rows)
        summary = shown_infinity(summary)  # +inf (never settled) written "inf", not an empty cell
        add("summary.csv", csv_text(summary_columns, summary))
        requirements = requirement_table(study, rows)
        add("requirements.csv", csv_text(*requirements))
        robustness = robustness_tables(study, rows)
        if robustness is not None:
            robustness = tuple((names, shown_infinity(table)) for names, table in robustness)  # type: ignore[assignment]
            for name, table in zip(ROBUSTNESS_FILES, robustness):
                add(name, csv_text(*table))
        markdown = ""
        if robustness is not None:
            from scenarios.study.robustness import robustness_markdown
            markdown = robustness_markdown(study, rows, *robustness)
        add("summary.md", _markdown(study, summary_columns, summary, results.missing, requirements, markdown))
        add("study.yaml", yaml.dump(resolved_study(study), Dumper=_DUMPER, sort_keys=False, width=120))
        staging = new_staging(directory)
        try:
            for name, text in files.items():
                (staging / name).write_text(text)
            if plots:
                from scenarios.study.html import study_report
                from scenarios.study.plots import write_plots
                (staging / "plots").mkdir()
                write_plots(study, rows, staging / "plots", progress=meter)
                (staging / "report.html").write_text(study_report(study, (columns, rows), (summary_columns, summary),
                                                                  requirements, results.missing, robustness),
                                                     encoding="utf-8")
                meter.advance()
            return commit_sweep_outputs(directory, staging)
        finally:
            shutil.rmtree(staging, ignore_errors=True)
    finally:
        meter.close()
