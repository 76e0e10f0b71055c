"""Robustness outputs of a Monte Carlo study: how often each planner row meets its requirements and
the study's metric thresholds, how each summary metric ranks with each dispersed parameter, and the
worst cases.

Three tables, each per planner row label (and per grid point under a grid of Monte Carlo samples,
as ``summary.csv`` groups them), written as ``robustness.csv``, ``sensitivity.csv`` and
``worst_cases.csv`` and shown in ``summary.md`` and ``report.html``:

* :func:`proportion_table`: the fraction of the completed cases (not ``crashed``) that meet every
  requirement (status ``ok``, as ``requirements.csv``) and, for each ``robustness.thresholds``
  entry, whose metric is at most (or at least) its bound, each with its Wilson 95 % interval
  (:func:`scenarios.study.report.wilson_interval`). A completed row without a value does not meet
  a threshold, and neither does a ``failed`` or ``infeasible`` one whatever values it carries (it
  counts as completed and meets no criterion). Cases that share a store key (the same scenario)
  count once (:func:`scenarios.study.report.distinct_rows`).
* :func:`sensitivity_table`: Spearman's rank correlation of each summary metric with each dispersed
  parameter over the rows where the metric has a value or never reached one (a case that never
  settled ranks after every settled one, ties averaged: :func:`scenarios.study.report.metric_values`)
  with its p-value, 95 % interval and Holm-adjusted p-value over the group's correlations
  (:func:`rank_significance`, :func:`holm`). The parameters are the drawn quantities
  (:func:`parameter_columns`): one per number a dispersion draws (a whole-tensor ``scale`` is one
  factor; a vector gives one per component, ``simulation.initial_rate_error[1]``), not per element
  of the value it sets; quantities that do not vary are left out. Ties get their average rank.
* :func:`worst_table`: the ``robustness.worst`` cases with the largest value of each summary metric
  (the smallest for a metric with an ``at_least`` threshold), by case id, with their seeds, to be
  re-run in full with ``slewbench sweep DIR --case N``; a case that never settled is +inf, the
  largest.

The three take a row's metric values as ``summary.csv`` and the plots do: only from the rows that
count (:func:`scenarios.study.report.counted`, ``ok`` and ``violated``; a ``failed``,
``infeasible`` or ``crashed`` row is left out whatever values it carries,
:func:`scenarios.study.report.metric_values` with ``counted_only``), and each table has the
column ``excluded``: the group's rows left out so (the ``excluded`` of ``summary.csv``). The rows
not ok are listed by case id in ``summary.md``.

A threshold on a metric counts a case that never reached it as +inf too (it does not meet an
``at_most`` bound).
"""
from __future__ import annotations

import itertools
import json
import math
from typing import Any

import numpy as np

from scenarios.output.tables import text_cell
from scenarios.study.report import (
    EVERY_REQUIREMENT,
    INFINITY_TEXT,
    PROPORTION_STATISTICS,
    WILSON_Z,
    distinct_rows,
    excluded_count,
    group_rows,
    metric_values,
    proportion,
)
from scenarios.study.types import Study

__all__ = ["ROBUSTNESS_STATISTICS", "SENSITIVITY_STATISTICS", "WORST_COLUMNS", "crashed_counts",
           "criterion_text", "holm", "parameter_columns",
           "proportion_table", "rank_significance", "robustness_lines", "robustness_markdown", "sensitivity_table", "spearman",
           "worst_table"]

ROBUSTNESS_STATISTICS = (PROPORTION_STATISTICS[0], "excluded", *PROPORTION_STATISTICS[1:])
"""The columns of ``robustness.csv`` after the grouping keys and ``criterion``: a proportion's
(:data:`~scenarios.study.report.PROPORTION_STATISTICS`) with ``excluded`` after ``completed``
(:func:`~scenarios.study.report.excluded_count`: the ``failed`` and ``infeasible`` ones among
them are completed and meet no criterion)."""
SENSITIVITY_STATISTICS = ("cases", "excluded", "spearman_rho", "rho_low", "rho_high", "p_value", "p_holm",
                          "significant")
"""The columns of ``sensitivity.csv`` after the grouping keys, ``metric``, ``parameter`` and ``draw``:
the rows that count with a value of the metric or that never reached one (+inf, the largest rank),
the group's rows left out (:func:`~scenarios.study.report.excluded_count`), the rank correlation
(None when either side does not vary), its 95 % interval and two-sided p-value (:func:`rank_significance`), the p-value
adjusted over the group's correlations (:func:`holm`) and whether that is at most
:data:`SIGNIFICANCE`."""
SIGNIFICANCE = 0.05
"""The level of ``significant`` in ``sensitivity.csv``: Holm-adjusted p-value at most this."""
EXACT_CASES = 8
"""Up to this many cases a rank correlation's p-value is exact (its ``n!`` pairings enumerated)."""
PERMUTATION_CASES = 50
"""Below this many cases (and above :data:`EXACT_CASES`) the p-value is a permutation test's over
:data:`PERMUTATIONS` random pairings (the t distribution's approximation underestimates it by
1.2-4 times at 9 cases, a reviewer's enumeration of all 9! pairings); from it on, the t distribution."""
PERMUTATIONS = 20000
"""Random pairings of the permutation test (fixed seed: the same study gives the same p-values);
its p-value ``(1 + k) / (1 + PERMUTATIONS)`` is never below ``5e-5``."""
SMALL_SAMPLE = 30
"""Below this many cases ``summary.md`` says how large a rank correlation must be to be significant."""
WORST_COLUMNS = ("metric", "rank", "case", "seed", "value", "status", "excluded")
"""The columns of ``worst_cases.csv`` after the grouping keys (``excluded``: the group's rows left
out of the ranking, :func:`~scenarios.study.report.excluded_count`)."""
MIN_CASES = 3
"""Fewest rows a rank correlation is computed from."""
NOT_OK_LISTED = 20
"""Rows not ok named per group in ``summary.md`` (the rest are counted)."""


def criterion_text(metric: str, sense: str, bound: float) -> str:
    """A threshold as the tables name it: ``cl.final_error_deg <= 0.1``.

    Parameters
    ----------
    metric : str
        The metric column.
    sense : {"at_most", "at_least"}
        How the metric compares with the bound.
    bound : float
        The bound, in the metric's unit.

    Returns
    -------
    str
        The metric, ``<=`` or ``>=``, and the bound (``%g``).
    """
    return f"{metric} {'<=' if sense == 'at_most' else '>='} {bound:g}"


def proportion_table(study: Study, rows: list[dict[str, Any]]) -> tuple[list[str], list[dict[str, Any]]]:
    """Per group: the fraction of completed cases meeting every requirement, then each threshold.

    Parameters
    ----------
    study : Study
        The study (its grid paths, samples and ``thresholds``).
    rows : list of dict
        The ``cases.csv`` rows (:func:`scenarios.study.report.case_table`).

    Returns
    -------
    columns : list of str
        The grouping keys, ``criterion`` and :data:`ROBUSTNESS_STATISTICS`.
    rows : list of dict
        One per group and criterion (:data:`scenarios.study.report.EVERY_REQUIREMENT` first); the fraction and its
        interval are None without completed cases. A threshold is met only by a row that counts
        (``ok`` or ``violated``): a ``failed`` or ``infeasible`` row is completed and meets none,
        whatever its values; ``excluded`` counts the group's rows left out so (crashed ones too).
    """
    keys, groups = group_rows(study, distinct_rows(study, rows))  # a case shared by several counts once
    table = []
    for members in groups.values():
        completed = [r for r in members if r["status"] != "crashed"]
        criteria = [(EVERY_REQUIREMENT, sum(r["status"] == "ok" for r in completed))]
        for metric, (sense, bound) in study.thresholds.items():
            # +inf: never settled; NaN: no value, or a row that does not count (it meets nothing)
            values = metric_values(metric, completed, counted_only=True)
            with np.errstate(invalid="ignore"):
                meets = values <= bound if sense == "at_most" else values >= bound
            criteria.append((criterion_text(metric, sense, bound), int(np.sum(meets & ~np.isnan(values)))))
        excluded = excluded_count(members)
        for criterion, met in criteria:
            line = {k: members[0].get(k) for k in keys}
            line.update(criterion=criterion, **proportion(met, len(completed)), excluded=excluded)
            table.append(line)
    return [*keys, "criterion", *ROBUSTNESS_STATISTICS], table


def parameter_columns(study: Study, rows: list[dict[str, Any]]) -> list[tuple[str, str, np.ndarray]]:
    """The drawn quantities of the dispersions as numbers, one column per quantity drawn.

    A dispersion gives one parameter per number it draws (:attr:`Study.parameters
    <scenarios.study.types.Study.parameters>`), not per element of the value it sets: a
    whole-tensor ``scale`` is one factor, however many elements it multiplies; a vector gives one
    per component (``simulation.initial_rate_error[0]``), a matrix one per independent element
    (``truth.spacecraft.inertia[0][1]``, the upper triangle of a symmetric tensor), a ``principal``
    dispersion its moment factors and rotation components.

    Parameters
    ----------
    study : Study
        The expanded study (its cases' draws; ``case_seed`` draws none).
    rows : list of dict
        The ``cases.csv`` rows.

    Returns
    -------
    list of (str, str, ndarray)
        The parameter's name, what the number is (``value``, ``scale``, ``offset``,
        ``principal``) and its value in each row (NaN for a row of no case of the study);
        parameters that take one value in every row are left out.
    """
    drawn = {case.index: case.drawn for case in study.cases}
    columns = []
    for name, draw in study.parameters.items():
        values = np.array([drawn.get(row["case"], {}).get(name, math.nan) if isinstance(row.get("case"), int)
                           else math.nan for row in rows], dtype=float)
        finite = values[np.isfinite(values)]
        if finite.size and np.ptp(finite) > 0:
            columns.append((name, draw, values))
    return columns


def _ranks(values: np.ndarray) -> np.ndarray:
    """Ranks from 1, ties given the average of the ranks they span."""
    order = np.argsort(values, kind="mergesort")
    ordered = values[order]
    ranks = np.empty(values.size)
    start = 0
    while start < values.size:
        stop = start + 1
        while stop < values.size and ordered[stop] == ordered[start]:
            stop += 1
        ranks[order[start:stop]] = (start + stop + 1) / 2.0  # the mean of ranks start+1 .. stop
        start = stop
    return ranks


def spearman(x: np.ndarray, y: np.ndarray) -> float | None:
    """Spearman's rank correlation: the Pearson correlation of the ranks (ties averaged).

    Parameters
    ----------
    x, y : (n,) ndarray
        Paired values; pairs with a NaN (no value) are left out, +inf ranks after every finite
        value (a case that never settled), several +inf tie.

    Returns
    -------
    float or None
        In [-1, 1]; None with fewer than :data:`MIN_CASES` pairs or when either side's ranks do
        not vary.
    """
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    keep = ~np.isnan(x) & ~np.isnan(y)
    if keep.sum() < MIN_CASES:
        return None
    rx, ry = _ranks(x[keep]), _ranks(y[keep])
    rx, ry = rx - rx.mean(), ry - ry.mean()
    scale = math.sqrt(float(np.dot(rx, rx)) * float(np.dot(ry, ry)))
    if scale == 0.0:
        return None
    return max(-1.0, min(1.0, float(np.dot(rx, ry)) / scale))


def _exact_p(x: np.ndarray, y: np.ndarray) -> float:
    """The exact two-sided permutation p-value of Spearman's rho: the fraction of the ``n!``
    pairings of the ranks whose correlation is at least as large in magnitude."""
    rx, ry = _ranks(x), _ranks(y)
    rx, ry = rx - rx.mean(), ry - ry.mean()
    scale = math.sqrt(float(np.dot(rx, rx)) * float(np.dot(ry, ry)))
    pairings = np.array(list(itertools.permutations(range(x.size))))
    rhos = np.abs(ry[pairings] @ rx) / scale
    return float(np.mean(rhos >= abs(float(np.dot(rx, ry))) / scale - 1e-12))


def _permutation_p(x: np.ndarray, y: np.ndarray) -> float:
    """The two-sided permutation p-value of Spearman's rho over :data:`PERMUTATIONS` random
    pairings of the ranks, ``(1 + k) / (1 + PERMUTATIONS)`` with ``k`` the pairings at least as
    correlated in magnitude (seeded: reproducible)."""
    rx, ry = _ranks(x), _ranks(y)
    rx, ry = rx - rx.mean(), ry - ry.mean()
    scale = math.sqrt(float(np.dot(rx, rx)) * float(np.dot(ry, ry)))
    pairings = np.random.default_rng(0).permuted(np.tile(np.arange(x.size), (PERMUTATIONS, 1)), axis=1)
    rhos = np.abs(ry[pairings] @ rx) / scale
    hits = int(np.sum(rhos >= abs(float(np.dot(rx, ry))) / scale - 1e-12))
    return (1.0 + hits) / (1.0 + PERMUTATIONS)


def critical_rho(n: int) -> float | None:
    """The least magnitude of a rank correlation over ``n`` untied pairs whose two-sided p-value
    is at most :data:`SIGNIFICANCE`, by :func:`rank_significance`'s method: exact up to
    :data:`EXACT_CASES` pairs, so the same threshold; below :data:`PERMUTATION_CASES` from the
    same :data:`PERMUTATIONS` seeded pairings, but applied to the identity ranking where a test
    applies them against its own second ranking, which gives another sample of the same null: a
    ranking at exactly this magnitude can read p slightly above :data:`SIGNIFICANCE` (0.0519 at 25
    pairs, 0.0503 at 35: the Monte Carlo error of 20000 pairings); above, the t approximation, the
    same threshold.

    Parameters
    ----------
    n : int
        The number of pairs.

    Returns
    -------
    float or None
        That magnitude; ``None`` when no correlation over ``n`` pairs can be significant (up to 4
        pairs: a perfect ranking has p = 2/n!, at least 1/12).
    """
    from scipy.special import stdtrit  # lazily: only a study's report needs it

    if n < MIN_CASES:
        return None
    ranks = np.arange(n, dtype=float) - (n - 1) / 2.0
    scale = float(np.dot(ranks, ranks))
    if n < PERMUTATION_CASES:
        pairings = (np.array(list(itertools.permutations(range(n)))) if n <= EXACT_CASES else
                    np.random.default_rng(0).permuted(np.tile(np.arange(n), (PERMUTATIONS, 1)), axis=1))
        null = np.sort(np.abs(ranks[pairings] @ ranks) / scale)[::-1]
        offset = 0 if n <= EXACT_CASES else 1  # the permutation test counts the observed pairing
        for value in np.unique(null)[::-1]:
            if (offset + np.sum(null >= value - 1e-12)) / (offset + null.size) > SIGNIFICANCE:
                larger = null[null > value + 1e-12]
                return float(larger.min()) if larger.size else None
        return None
    t = float(stdtrit(n - 2, 1.0 - SIGNIFICANCE / 2.0))
    return t / math.sqrt(n - 2 + t * t)


def rank_significance(rho: float | None, n: int, x: np.ndarray | None = None,
                      y: np.ndarray | None = None) -> dict[str, float | None]:
    """The significance of a rank correlation ``rho`` over ``n`` pairs.

    The p-value is two-sided, of the hypothesis that the two do not rank together: exact over
    :data:`EXACT_CASES` pairs or fewer when the pairs ``x``, ``y`` are given (every pairing of their
    ranks enumerated: 3 cases ranked perfectly have p = 1/3), a permutation test's below
    :data:`PERMUTATION_CASES` pairs (:data:`PERMUTATIONS` random pairings), else from the t distribution with
    ``n - 2`` degrees of freedom of ``rho sqrt((n - 2) / (1 - rho²))`` (as ``scipy.stats.spearmanr``),
    a perfect ranking taking ``2 / n!``, its exact value without ties. The 95 % interval is
    Fisher's ``tanh(atanh(rho) ± 1.96 se)`` with the Bonett-Wright standard error for Spearman's
    rho, ``se = sqrt((1 + rho²/2) / (n - 3))``.

    Parameters
    ----------
    rho : float or None
        The rank correlation (None: none, then every statistic is None).
    n : int
        The pairs it is over.
    x, y : (n,) ndarray or None, optional
        The pairs themselves (no NaN), for the exact p-value of a few cases.

    Returns
    -------
    dict
        ``p_value`` (None below :data:`MIN_CASES` pairs), ``rho_low`` and ``rho_high`` (None below
        4 pairs).
    """
    from scipy.special import stdtr  # lazily: only a study's report needs it

    out: dict[str, float | None] = {"rho_low": None, "rho_high": None, "p_value": None}
    if rho is None or n < MIN_CASES:
        return out
    if n <= EXACT_CASES and x is not None and y is not None:
        out["p_value"] = _exact_p(x, y)
    elif n < PERMUTATION_CASES and x is not None and y is not None:
        out["p_value"] = _permutation_p(x, y)
    elif abs(rho) >= 1.0:
        out["p_value"] = 2.0 / math.factorial(n)
    else:
        t = abs(rho) * math.sqrt((n - 2) / (1.0 - rho * rho))
        out["p_value"] = float(min(1.0, 2.0 * stdtr(n - 2, -t)))
    if n >= 4:
        z = math.atanh(max(-1.0 + 1e-15, min(1.0 - 1e-15, rho)))
        half = WILSON_Z * math.sqrt((1.0 + rho * rho / 2.0) / (n - 3))
        out["rho_low"], out["rho_high"] = math.tanh(z - half), math.tanh(z + half)
    return out


def holm(p_values: list[float | None]) -> list[float | None]:
    """Holm's step-down adjustment of a family of p-values (None left out of the family).

    Parameters
    ----------
    p_values : list of float or None
        The family's p-values.

    Returns
    -------
    list of float or None
        Each adjusted p-value, ``max over j <= k of min(1, (m - j + 1) p_(j))`` for the k-th smallest
        of the ``m`` given: at most 0.05 controls the chance of any false finding in the family at
        5 %.
    """
    given = sorted((p, k) for k, p in enumerate(p_values) if p is not None)
    out: list[float | None] = [None] * len(p_values)
    running = 0.0
    for rank, (p, k) in enumerate(given):
        running = max(running, min(1.0, (len(given) - rank) * p))
        out[k] = running
    return out


def sensitivity_table(study: Study, rows: list[dict[str, Any]]) -> tuple[list[str], list[dict[str, Any]]]:
    """Spearman's rank correlation of each summary metric with each dispersed parameter, per group.

    Parameters
    ----------
    study : Study
        The study (its summary metrics and dispersions).
    rows : list of dict
        The ``cases.csv`` rows.

    Returns
    -------
    columns : list of str
        The grouping keys, ``metric``, ``parameter``, ``draw`` and :data:`SENSITIVITY_STATISTICS`.
    rows : list of dict
        One per group, summary metric and drawn quantity (:func:`parameter_columns`); empty
        without dispersed parameters. Over the rows that count (``ok``, ``violated``: the values of
        ``summary.csv``); ``excluded`` counts the group's others. Each correlation has its
        p-value and 95 % interval (:func:`rank_significance`); ``p_holm`` is its p-value adjusted
        over the group's correlations (:func:`holm`) and ``significant`` whether that is at most
        :data:`SIGNIFICANCE`.
    """
    keys, groups = group_rows(study, rows)
    table = []
    parameters = parameter_columns(study, rows)
    position = {id(row): k for k, row in enumerate(rows)}
    for members in groups.values():
        index = np.array([position[id(r)] for r in members], dtype=int)
        excluded = excluded_count(members)
        lines = []
        for metric in study.summary:
            # never settled: +inf, the largest rank; a row that does not count: NaN, left out
            values = metric_values(metric, members, counted_only=True)
            for name, draw, column in parameters:
                line = {k: members[0].get(k) for k in keys}
                cases = int(np.sum(~np.isnan(values) & ~np.isnan(column[index])))
                rho = spearman(column[index], values)
                keep = ~np.isnan(values) & ~np.isnan(column[index])
                line.update(metric=metric, parameter=name, draw=draw, cases=cases, excluded=excluded,
                            spearman_rho=rho, **rank_significance(rho, cases, column[index][keep], values[keep]))
                lines.append(line)
        for line, adjusted in zip(lines, holm([line["p_value"] for line in lines])):
            line["p_holm"] = adjusted
            line["significant"] = None if adjusted is None else adjusted <= SIGNIFICANCE
        table += lines
    return [*keys, "metric", "parameter", "draw", *SENSITIVITY_STATISTICS], table


def worst_table(study: Study, rows: list[dict[str, Any]]) -> tuple[list[str], list[dict[str, Any]]]:
    """The ``study.worst`` worst cases of each summary metric, per group.

    Parameters
    ----------
    study : Study
        The study (its summary metrics, ``worst`` and ``thresholds``).
    rows : list of dict
        The ``cases.csv`` rows.

    Returns
    -------
    columns : list of str
        The grouping keys and :data:`WORST_COLUMNS`.
    rows : list of dict
        Per group and metric, ranks 1 to ``worst`` among the rows that count (``ok``,
        ``violated``: the values of ``summary.csv``) with a value or that never reached one
        (``value`` +inf: a case that never settled, :func:`scenarios.study.report.metric_values`):
        the largest values first (the smallest for a metric with an ``at_least`` threshold); ties
        in case order; ``excluded``: the group's rows left out (``failed``, ``infeasible``,
        ``crashed``, whatever their values). A metric with one value in every row of the group
        lists none.
    """
    keys, groups = group_rows(study, rows)
    table = []
    for members in groups.values():
        excluded = excluded_count(members)
        for metric in study.summary:
            least = study.thresholds.get(metric, ("at_most", 0.0))[0] == "at_least"
            values = metric_values(metric, members, counted_only=True)
            valued = [(float(v), r) for v, r in zip(values, members) if not math.isnan(v)]
            if len({v for v, _ in valued}) < 2:
                continue  # one value in every row: no case is worse than another
            valued.sort(key=lambda pair: pair[0] if least else -pair[0])  # stable: ties keep case order
            for rank, (value, row) in enumerate(valued[:study.worst], start=1):
                line = {k: members[0].get(k) for k in keys}
                line.update(metric=metric, rank=rank, case=row["case"], seed=row.get("seed"), value=value,
                            status=row["status"], excluded=excluded)
                table.append(line)
    return [*keys, *WORST_COLUMNS], table


def _lines(columns: list[str], rows: list[dict[str, Any]]) -> list[str]:
    return (["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
            + ["| " + " | ".join(text_cell(row.get(c)) for c in columns) + " |" for row in rows])


def _not_ok(study: Study, rows: list[dict[str, Any]]) -> list[str]:
    """One line per group with rows not ok: their case ids and statuses."""
    keys, groups = group_rows(study, rows)
    lines = []
    for members in groups.values():
        bad = [r for r in members if r["status"] != "ok"]
        if not bad:
            continue
        named = ", ".join(f"{r['case']} ({r['status']})" for r in bad[:NOT_OK_LISTED])
        more = f" and {len(bad) - NOT_OK_LISTED} more" if len(bad) > NOT_OK_LISTED else ""
        group = ", ".join(f"{k}={text_cell(members[0].get(k))}" for k in keys)
        lines.append(f"* {group}: {len(bad)} of {len(members)} not ok: case {named}{more}")
    return lines


def robustness_markdown(study: Study, rows: list[dict[str, Any]],
                        proportions: tuple[list[str], list[dict[str, Any]]],
                        sensitivity: tuple[list[str], list[dict[str, Any]]],
                        worst: tuple[list[str], list[dict[str, Any]]]) -> str:
    """The robustness sections of ``summary.md``.

    Parameters
    ----------
    study : Study
        The study.
    rows : list of dict
        The ``cases.csv`` rows (for the cases not ok).
    proportions, sensitivity, worst : (list of str, list of dict)
        :func:`proportion_table`, :func:`sensitivity_table` and :func:`worst_table`.

    Returns
    -------
    str
        Markdown: the proportions, the cases not ok by id, the rank correlations (one column per
        parameter) and the worst cases.
    """
    out = ["## Robustness", "",
           ("Fraction of the completed cases (not crashed) meeting every requirement (status ok) and each "
            "threshold of `robustness.thresholds`, with the Wilson 95 % interval. As in the summary, only rows ok or "
            "violated count: a failed or infeasible row meets no threshold whatever its values, and the sensitivity "
            "and worst cases leave it out; excluded counts the rows left out (failed, infeasible, crashed)."), ""]
    out += _lines(*proportions) + [""]
    not_ok = _not_ok(study, rows)
    if not_ok:
        out += ["Rows not ok, by case id (re-run one in full with `slewbench sweep DIR --case N`):", "", *not_ok, ""]
    columns, table = sensitivity
    if table:
        headers = list(dict.fromkeys(f"{line['parameter']} ({line['draw']})" for line in table))
        keys = columns[:columns.index("metric")]
        wide: dict[tuple, dict[str, Any]] = {}
        for line in table:
            entry = wide.setdefault(tuple(json.dumps(line.get(k)) for k in keys) + (line["metric"],),
                                    {**{k: line.get(k) for k in keys}, "metric": line["metric"]})
            entry[f"{line['parameter']} ({line['draw']})"] = _correlation_cell(line)
        out += ["## Sensitivity", "", ("Spearman rank correlation of each summary metric (rows) with each drawn "
                                       "quantity (columns: one per number a dispersion draws, a whole-tensor scale "
                                       "one factor; its kind after the name), over the rows ok or violated where the "
                                       "metric has a value, a case that never settled ranked after every settled "
                                       "one; empty: the metric does not vary. In brackets the two-sided p-value "
                                       "(exact up to 8 cases, else the t approximation); * : significant at 5 % after Holm's correction over the "
                                       "group's correlations (sensitivity.csv: the 95 % intervals, p_holm). A "
                                       "correlation without * may be chance at this many cases."),
                ""]
        out += _small_sample_notes(keys, table)
        out += _lines([*keys, "metric", *headers], list(wide.values())) + [""]
    if worst[1]:
        out += ["## Worst cases", "", (f"The {study.worst} largest values of each summary metric (smallest for "
                                       "an at_least threshold) among the rows ok or violated, by case id; inf: the "
                                       "case never settled."), ""]
        out += _lines(*worst) + [""]
    return "\n".join(out)


def _correlation_cell(line: dict[str, Any]) -> str | None:
    """A correlation as ``summary.md`` shows it: ``-0.962 (p 2e-09) *``."""
    rho = line.get("spearman_rho")
    if rho is None or rho == "":
        return None
    p = line.get("p_value")
    return f"{rho:.3g}" + ("" if p is None else f" (p {p:.2g})") + (" *" if line.get("significant") else "")


def _small_sample_notes(keys: list[str], table: list[dict[str, Any]]) -> list[str]:
    """A note per group with fewer than :data:`SMALL_SAMPLE` cases: the smallest rank correlation
    significant at 5 % with that many (before the correction for the number of correlations)."""
    notes = []
    seen: set[tuple[str, ...]] = set()
    for line in table:
        group = tuple(json.dumps(line.get(k)) for k in keys)
        n = int(line.get("cases") or 0)
        if group in seen or not MIN_CASES <= n < SMALL_SAMPLE:
            continue
        seen.add(group)
        critical = critical_rho(n)
        family = sum(1 for other in table if tuple(json.dumps(other.get(k)) for k in keys) == group
                     and other.get("p_value") is not None)
        name = ", ".join(text_cell(line.get(k)) for k in keys)
        plural = "correlation" if family == 1 else "correlations"
        if critical is None:
            notes.append(f"Note ({name}): only {n} cases. No rank correlation over so few can be significant at 5 %; "
                         f"a larger sample narrows the intervals.")
        else:
            notes.append(f"Note ({name}): only {n} cases. A rank correlation must reach about {critical:.2f} in "
                         f"magnitude to be significant at 5 % on its own, more after the correction for the {family} "
                         f"{plural}; a larger sample narrows the intervals.")
    return notes + ([""] if notes else [])


def crashed_counts(study: Study, rows: list[dict[str, Any]]) -> dict[tuple[str, ...], int]:
    """The ``crashed`` rows of each group of the robustness tables.

    Parameters
    ----------
    study : Study
        The study (its grid paths and samples).
    rows : list of dict
        The ``cases.csv`` rows.

    Returns
    -------
    dict
        The group's key values, as :func:`scenarios.study.report.group_rows` keys them (JSON text)
        -> its rows whose status is ``crashed``.
    """
    _, groups = group_rows(study, rows)
    return {group: sum(r["status"] == "crashed" for r in members) for group, members in groups.items()}


def robustness_lines(proportions: tuple[list[str], list[dict[str, Any]]],
                     worst: tuple[list[str], list[dict[str, Any]]],
                     crashed: dict[tuple[str, ...], int] | None = None) -> list[str]:
    """The robustness summary ``slewbench sweep`` prints: per group, each criterion's fraction with
    its Wilson interval, and the worst cases of each summary metric by id.

    Parameters
    ----------
    proportions, worst : (list of str, list of dict)
        :func:`proportion_table` and :func:`worst_table`.
    crashed : dict or None, optional
        :func:`crashed_counts` of the same rows, to count the crashed cases of a group that has
        no completed case; None: they are not counted.

    Returns
    -------
    list of str
        One line per group and criterion (``  fast: every requirement 98/100 = 0.98 [0.930, 0.994]``),
        one line for a group without a completed case (``  30.0, smooth: no completed case (3 crashed)``),
        then one per group and metric (``  fast: worst cl.int_u: case 17, 3, 55``; a case that never
        settled is marked, ``case 4 (never), 8``).
    """
    columns, table = proportions
    keys = columns[:columns.index("criterion")]

    def group(line: dict[str, Any]) -> str:
        return ", ".join(text_cell(line.get(k)) for k in keys)

    lines = []
    empty: set[tuple[str, ...]] = set()
    for line in table:
        if line["fraction_met"] is None:
            key = tuple(json.dumps(line.get(k)) for k in keys)
            if key not in empty:  # one line per group, not per criterion
                empty.add(key)
                count = None if crashed is None else crashed.get(key)
                lines.append(f"  {group(line)}: no completed case" + ("" if count is None else f" ({count} crashed)"))
            continue
        lines.append(f"  {group(line)}: {line['criterion']} {line['met']}/{line['completed']} = "
                     f"{line['fraction_met']:.3g} [{line['wilson_low']:.3f}, {line['wilson_high']:.3f}]")
    listed: dict[tuple[str, str], list[str]] = {}
    for line in worst[1]:
        never = line["value"] == math.inf or line["value"] == INFINITY_TEXT
        listed.setdefault((group(line), line["metric"]), []).append(f"{line['case']}{' (never)' if never else ''}")
    lines += [f"  {name}: worst {metric}: case {', '.join(cases)}" for (name, metric), cases in listed.items()]
    return lines
