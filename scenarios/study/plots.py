"""Figures of a trade study (matplotlib, Agg): each summary metric against each numeric grid
parameter (one line per planner, median with the 5-95 % band under Monte Carlo), heat maps over a
2-D grid (one colour scale shared by the planners), box plots, empirical CDFs and scatter plots
against each dispersed parameter across Monte Carlo samples with the heat map of their rank
correlations (:mod:`scenarios.study.robustness`), and the Pareto front of each grid point.

A band or an error bar spans the Monte Carlo samples of one design point (a planner at one grid
point), never several design points: ``metrics_vs_<path>`` draws one line per planner and
combination of the other grid parameters (:func:`metric_lines`); a Pareto panel's points are the
planners, each at the median of its samples with 5-95 % error bars, and its front runs over the
points whose every row is ``ok`` only (:func:`pareto_panels`).

Every axis names its quantity in words with its unit: a metric or requirement column by
:func:`scenarios.output.plot_data.column_quantity`, a varied scenario path by
:func:`parameter_quantity` (the schema's unit of the key; the angle in degrees for a grid of
``axis_angle`` quaternions). A quantity spanning :data:`DECADES` decades or more is drawn on a
logarithmic axis. Rows whose status is ``failed`` or ``crashed`` have no value and are marked (×,
hatched cells); ``violated`` rows completed and are drawn.

The values and statistics are the summary table's (:mod:`scenarios.study.report`): a metric's values
by :func:`~scenarios.study.report.metric_values`, so that a case that never settled counts as +inf,
and medians and percentiles by :func:`~scenarios.study.report.percentile` over them. A median,
percentile or case at +inf is drawn at the top edge of its panel (▲, a band or box reaching the
edge), a heat-map cell whose median is +inf is hatched and says ``never`` with its count."""
from __future__ import annotations

import functools
import json
import math
import re
import textwrap
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib
from matplotlib.colors import LogNorm, Normalize
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Rectangle
from matplotlib.transforms import blended_transform_factory

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from scenarios.output.names import row_stems
from scenarios.output.plot_data import axis_label, column_quantity
from scenarios.study.paths import Step, get_path, parse_path
from scenarios.study.report import COUNTED_STATUSES, counted, metric_values, percentile
from scenarios.study.types import Study

__all__ = ["DECADES", "INFINITE_WORDS", "PARETO_AXES", "PARETO_SPREAD", "PARETO_STATISTIC", "PLOTTED_STATUSES", "RECORDED",
           "DesignPoint", "MetricLine", "ParetoPanel", "figures", "metric_lines", "parameter_quantity", "pareto_front",
           "pareto_panels", "spans_decades", "write_plots"]

PARETO_AXES = ("cl.int_u", "cl.settling_time_s")
"""The two metrics of the Pareto fronts (both to be minimised)."""
PARETO_STATISTIC = 50.0
"""The percentile of its Monte Carlo samples that places a design point on a Pareto panel (the median)."""
PARETO_SPREAD = (5.0, 95.0)
"""The percentiles of its Monte Carlo samples that a design point's error bars span."""
PLOTTED_STATUSES = COUNTED_STATUSES
"""Statuses of the rows whose metrics are drawn: the motion completed (a broken requirement is a result
and its metrics stand); ``failed``, ``infeasible`` and ``crashed`` rows are marked instead. The
summary's statistics take the same rows (:data:`scenarios.study.report.COUNTED_STATUSES`)."""
DECADES = 2.0
"""A quantity whose positive values span this many decades or more (largest over smallest >= 100)
is drawn on a logarithmic axis."""
MAX_PARETO_PANELS = 30
"""Most grid points given a Pareto panel (the first ones, in grid order)."""
MAX_GROUPS = 12
"""Most (grid point, planner) groups in the box plots and CDFs; with more, each planner's cases are
pooled over the grid points (and the title says so)."""
MAX_ANNOTATED_CELLS = 64
"""Heat map panels with at most this many cells print each cell's value."""
PATH_LINE_CHARS = 28
"""About the longest line of a drawn quantity's YAML path under the sensitivity map (broken after
its dots, never cut)."""
FAILED_MARK: dict[str, Any] = {"marker": "x", "linestyle": "none", "markersize": 7, "markeredgewidth": 1.6}
"""How a grid point or case with a failed row is marked (at the bottom of the panel, in the planner's colour)."""
NEVER_MARK: dict[str, Any] = {"marker": "^", "linestyle": "none", "markersize": 8, "markeredgewidth": 1.2}
"""How a median or case at +inf (never settled) is marked (at the top of the panel, in the planner's colour)."""
EDGE = 0.97
"""Height of a +inf mark, as a fraction of the panel (0: bottom, 1: top)."""
INFINITE_WORDS: dict[str, tuple[str, str]] = {
    "settling_time_s": ("never settled", "median never reached (did not settle)"),
    "int_u2": ("+inf (an impulse)", "median +inf (an impulse)"),
    "peak_body_torque": ("+inf (an impulse)", "median +inf (an impulse)"),
}
"""What +inf means for a metric key whose null counts as +inf (:func:`scenarios.study.report.never_witness`):
key -> (words for the cases, for a median) in the plots' labels; any other key: ``+inf``."""
UNKNOWN_UNIT = "YAML units"
"""The unit given to a varied path the schema does not describe."""
DPI = 110


# --- values -----------------------------------------------------------------------------------------

def _failed(row: dict[str, Any]) -> bool:
    return not counted(row)


def _values(metric: str, rows: list[dict[str, Any]]) -> np.ndarray:
    """A metric's plotted values: the summary table's (:func:`scenarios.study.report.metric_values`
    with ``counted_only``: +inf where a case never settled, NaN without a value and where the row
    did not complete, which is marked instead)."""
    return metric_values(metric, rows, counted_only=True)


def _statistic(values: Any, q: float) -> float:
    """The summary table's percentile ``q`` (:func:`scenarios.study.report.percentile`) of the values
    that are not NaN, +inf included; NaN when there are none."""
    array = np.asarray(values, dtype=float).ravel()
    ranked = array[~np.isnan(array)]
    return percentile(ranked, q) if ranked.size else math.nan


def _infinite_words(metric: str) -> tuple[str, str]:
    """What +inf means for ``metric``: words for the cases, words for a median (:data:`INFINITE_WORDS`)."""
    return INFINITE_WORDS.get(metric.rpartition(".")[2], ("+inf", "median +inf"))


def _finite(values: Any) -> np.ndarray:
    array = np.asarray(values, dtype=float).ravel()
    return array[np.isfinite(array)]


def spans_decades(values: Any) -> bool:
    """Whether values are drawn on a logarithmic axis.

    Parameters
    ----------
    values : array_like
        The values of one axis (non-finite ones ignored).

    Returns
    -------
    bool
        At least two finite values, all positive, the largest at least ``10**DECADES`` times the smallest.
    """
    finite = _finite(values)
    return bool(finite.size > 1 and finite.min() > 0 and finite.max() >= 10.0 ** DECADES * finite.min())


def _labels(rows: list[dict[str, Any]]) -> list[str]:
    return list(dict.fromkeys(row["label"] for row in rows))


def _colors(labels: list[str]) -> dict[str, Any]:
    cycle = [f"C{k % 10}" for k in range(len(labels))]
    return dict(zip(labels, cycle))


def _numeric_axes(study: Study, rows: list[dict[str, Any]]) -> list[tuple[str, list[float]]]:
    axes = []
    for path in study.grid_paths:
        values = sorted({row[path] for row in rows if isinstance(row.get(path), (int, float))})
        if len(values) > 1 and all(isinstance(row.get(path), (int, float)) for row in rows):
            axes.append((path, values))
    return axes


def _with_values(study: Study, rows: list[dict[str, Any]]) -> list[str]:
    """The summary metrics that have a value in some row (a metric that does not apply to any row,
    such as a reference's peak actuator torque, has no panel)."""
    return [metric for metric in study.summary if (~np.isnan(_values(metric, rows))).any()]


# --- axis names -------------------------------------------------------------------------------------

KEY_WORDS = {"q": "attitude", "omega": "rate"}
"""Scenario keys that read better as words on an axis."""


def _entry(study: Study, steps: list[Step], path: str) -> Any:
    """What the base scenario holds along ``steps``; None where it holds nothing (a path the study
    sets but its base lacks)."""
    from scenarios.errors import ScenarioError

    try:
        return get_path(study.base, steps, path)
    except ScenarioError:
        return None


def _path_words(study: Study, path: str) -> str:
    """A scenario path in words: keys spaced, ``options`` and unit suffixes dropped, a list entry by
    its label (or name), the first key dropped when three or more words remain."""
    steps = parse_path(path, path)
    words: list[str] = []
    for number, step in enumerate(steps):
        if isinstance(step, str):
            if step != "options":
                words.append(KEY_WORDS.get(step, step.removesuffix("_deg").removesuffix("_s")))
            continue
        entry = _entry(study, steps[:number + 1], path)
        words.append(str(entry.get("label") or entry.get("name")) if isinstance(entry, dict)
                     else str(step[1] if isinstance(step, tuple) else step))
    if len(words) >= 3:
        words = words[1:]
    return " ".join(words).replace("_", " ")


@functools.lru_cache(maxsize=1)
def _schema_units() -> tuple[dict[str, str], dict[str, str]]:
    """Units of the scenario keys by YAML path (list indices dropped) and of the registry entries'
    options by reference key (``planners.<planner>.<option>``), from the schema reference."""
    from scenarios.schema.reference import reference_parts

    by_path, by_key = {}, {}
    for part in reference_parts():
        for entry in part.entries:
            if part.group == "Scenario file":
                by_path[re.sub(r"\[[^\]]*\]", "", entry.path)] = entry.unit
            else:
                by_key[entry.key] = entry.unit
    return by_path, by_key


_REGISTRY_KEYS = {"planners": "planners", "controller": "controller", "controllers": "controller"}
"""First key of a path into a registry entry's options -> the reference's key prefix."""


def _schema_unit(study: Study, path: str) -> str | None:
    """The unit the schema gives the key at ``path`` (empty: none); None when it does not describe it."""
    steps: list[Step] = parse_path(path, path)
    keys = [step for step in steps if isinstance(step, str)]
    by_path, by_key = _schema_units()
    if keys[0] in _REGISTRY_KEYS and "options" in keys and keys[-1] != "options":
        entry = _entry(study, steps[:steps.index("options")], path)
        name = entry.get("name") if isinstance(entry, dict) else None
        return by_key.get(f"{_REGISTRY_KEYS[keys[0]]}.{name}.{keys[-1]}")
    if keys[:2] == ["environment", "magnetic_field"] and len(keys) == 3:
        field = study.base.get("environment", {}).get("magnetic_field")
        model = field.get("model") if isinstance(field, dict) else field
        found = by_key.get(f"environment.magnetic_field.{model}.{keys[2]}")
        if found is not None:
            return found
    return by_path.get(".".join(keys))


def _vector_text(values: Any) -> str:
    return "[" + ", ".join(f"{float(v):.3g}" for v in values) + "]"


def _axis_angle_quantity(study: Study, path: str, argument: dict[str, Any]) -> tuple[str, str]:
    """``axis_angle`` quaternions are recorded as their angle [deg]: the slew angle for the final
    attitude from an initial one at the identity."""
    initial = study.base.get("maneuver", {}).get("initial", {}) or {}
    identity = [0.0, 0.0, 0.0, 1.0] if study.base.get("maneuver", {}).get("quaternion_order") == "scalar_last" \
        else [1.0, 0.0, 0.0, 0.0]
    q0 = initial.get("q") if isinstance(initial, dict) else None
    about = f"about {_vector_text(argument.get('axis', []))}"
    if path == "maneuver.final.q" and (q0 is None or np.allclose(np.asarray(q0, dtype=float), identity)):
        return f"slew angle {about}", "deg"
    return f"{_path_words(study, path)}: rotation angle {about}", "deg"


RECORDED: dict[str, Callable[[Study, str, dict[str, Any]], tuple[str, str]]] = {"axis_angle": _axis_angle_quantity}
"""Value generators (:data:`scenarios.schema.study.VALUE_GENERATORS`) whose recorded value is not the value
set into the scenario: generator name -> ``(study, path, argument) -> (words, unit)`` of what the tables record."""


def parameter_quantity(study: Study, path: str) -> tuple[str, str]:
    """What a varied scenario path's column holds, for an axis: its name in words and its unit.

    Parameters
    ----------
    study : Study
        The study (its base scenario, and its ``grid`` and ``zip`` entries as given).
    path : str
        A varied path (:attr:`Study.varied_paths`).

    Returns
    -------
    name : str
        For example ``"simulation sample time"``, ``"spin extremal weight"``, ``"slew angle about [1, 1, 1]"``.
    unit : str
        The schema's unit of the key (``"s"``, ``"1/(N² m² s)"``; ``"–"`` for a key without one), the
        unit of what a value generator records (:data:`RECORDED`), or :data:`UNKNOWN_UNIT`.
    """
    given = {**(study.raw.get("grid") or {}), **(study.raw.get("zip") or {})}.get(path)
    if isinstance(given, dict) and len(given) == 1:
        (kind, argument), = given.items()
        if kind in RECORDED and isinstance(argument, dict):
            return RECORDED[kind](study, path, argument)
    unit = _schema_unit(study, path)
    return _path_words(study, path), UNKNOWN_UNIT if unit is None else (unit or "–")


def _metric_label(metric: str) -> str:
    return axis_label(*column_quantity(metric))


def _point_text(study: Study, point: dict[str, Any]) -> str:
    """A grid point in words: ``slew angle about [1, 1, 1] 90 deg``."""
    parts = []
    for path, value in point.items():
        name, unit = parameter_quantity(study, path)
        shown = f"{value:g}" if isinstance(value, (int, float)) else str(value)
        parts.append(f"{name} {shown}" + ("" if unit in ("–", UNKNOWN_UNIT) else f" {unit}"))
    return ", ".join(parts)


# --- plot data --------------------------------------------------------------------------------------

@dataclass(frozen=True)
class MetricLine:
    """One line of ``metrics_vs_<path>.png``: a planner at one combination of the other grid
    parameters, against the values of ``path``.

    Parameters
    ----------
    label : str
        The planner row's label.
    others : dict
        The other grid paths' values, fixed along the line (empty for a one-path grid).
    xs : list of float
        The values of the plotted path, increasing.
    median, low, high : list of float
        Per x, the median and the 5 and 95 % percentiles of the metric over the Monte Carlo
        samples there (the summary's statistics; +inf where cases never settled, NaN without a
        value); ``low`` and ``high`` equal the median with one sample.
    failed : list of float
        The xs where a row failed (no value).
    """

    label: str
    others: dict[str, Any]
    xs: list[float]
    median: list[float]
    low: list[float]
    high: list[float]
    failed: list[float]


def metric_lines(study: Study, rows: list[dict[str, Any]], path: str, metric: str) -> list[MetricLine]:
    """The lines of ``metric`` against the numeric grid path ``path``: one per planner and
    combination of the other grid paths' values, each x summarised over its Monte Carlo samples
    only (a band never mixes design parameters with the dispersion).

    Parameters
    ----------
    study : Study
        The study (its grid paths).
    rows : list of dict
        The ``cases.csv`` rows.
    path : str
        A grid path whose values are numbers.
    metric : str
        A summary metric column.

    Returns
    -------
    list of MetricLine
        By planner, then by the other paths' values in the order the rows have them.
    """
    others = [other for other in study.grid_paths if other != path]
    xs = sorted({row[path] for row in rows if isinstance(row.get(path), (int, float))})
    groups: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for row in rows:
        groups.setdefault((row["label"], json.dumps([row.get(other) for other in others])), []).append(row)
    lines = []
    for label in _labels(rows):
        for (mine, key), members in groups.items():
            if mine != label:
                continue
            values = [_values(metric, [r for r in members if r.get(path) == x]) for x in xs]
            lines.append(MetricLine(
                label, dict(zip(others, json.loads(key))), list(xs), [_statistic(v, 50.0) for v in values],
                [_statistic(v, 5.0) for v in values], [_statistic(v, 95.0) for v in values],
                [x for x in xs if any(_failed(r) for r in members if r.get(path) == x)]))
    return lines


@dataclass(frozen=True)
class DesignPoint:
    """One planner at one grid point of a Pareto panel, summarised over its Monte Carlo samples.

    Parameters
    ----------
    label : str
        The planner row's label.
    x, y : float
        The :data:`PARETO_STATISTIC` percentile (the median) of :data:`PARETO_AXES` over the
        samples with a value (y +inf when most never settled; NaN when none has a value).
    x_spread, y_spread : tuple of float
        The :data:`PARETO_SPREAD` percentiles (the error bars).
    rows : int
        The samples (rows) of the design point.
    not_ok : int
        How many of them are not ``ok`` (``violated``, ``failed``, ...): with any, the point is
        marked and on no front.
    on_front : bool
        Whether the point is on its panel's front.
    """

    label: str
    x: float
    y: float
    x_spread: tuple[float, float]
    y_spread: tuple[float, float]
    rows: int
    not_ok: int
    on_front: bool


@dataclass(frozen=True)
class ParetoPanel:
    """One panel of ``pareto.png``: a grid point's design points and their front.

    Parameters
    ----------
    point : dict
        The grid paths' values (empty without a grid).
    points : list of DesignPoint
        One per planner, in the rows' order.
    front : (M, 2) ndarray
        The front (:func:`pareto_front`) of the points whose rows are all ``ok``, by increasing x.
    """

    point: dict[str, Any]
    points: list[DesignPoint]
    front: np.ndarray


def pareto_panels(study: Study, rows: list[dict[str, Any]]) -> list[ParetoPanel]:
    """The Pareto panels: per grid point, each planner is one design point at the median of its
    Monte Carlo samples; the front runs over the design points whose every row is ``ok``.

    Parameters
    ----------
    study : Study
        The study (its grid paths).
    rows : list of dict
        The ``cases.csv`` rows.

    Returns
    -------
    list of ParetoPanel
        In grid order, the grid points with some design point that has a value.
    """
    x_key, y_key = PARETO_AXES
    by_point: dict[str, list[dict[str, Any]]] = {}
    for row in rows:
        by_point.setdefault(json.dumps([row.get(p) for p in study.grid_paths]), []).append(row)
    panels = []
    for key, members in by_point.items():
        points = []
        for label in _labels(members):
            mine = [r for r in members if r["label"] == label]
            xs, ys = _values(x_key, mine), _values(y_key, mine)
            points.append(DesignPoint(
                label, _statistic(xs, PARETO_STATISTIC), _statistic(ys, PARETO_STATISTIC),
                (_statistic(xs, PARETO_SPREAD[0]), _statistic(xs, PARETO_SPREAD[1])),
                (_statistic(ys, PARETO_SPREAD[0]), _statistic(ys, PARETO_SPREAD[1])),
                len(mine), sum(r.get("status") != "ok" for r in mine), False))
        if not any(math.isfinite(p.x) and not math.isnan(p.y) for p in points):
            continue
        eligible = np.array([(p.x, p.y) for p in points if not p.not_ok]).reshape(-1, 2)
        front = pareto_front(eligible)
        points = [DesignPoint(**{**p.__dict__, "on_front": not p.not_ok and bool(
            np.any(np.all(front == (p.x, p.y), axis=1)))}) for p in points]
        panels.append(ParetoPanel(dict(zip(study.grid_paths, json.loads(key))), points, front))
    return panels


# --- figures ----------------------------------------------------------------------------------------

def _grid(count: int, width: float = 5.0, height: float = 3.8) -> tuple[Figure, list[Any]]:
    """A figure of ``count`` panels, three a row (smaller ones beyond nine), with room for a legend right."""
    cols = min(count, 3)
    rows = math.ceil(count / cols)
    if count > 9:
        width, height = 0.8 * width, 0.8 * height
    figure = plt.figure(figsize=(max(width * cols + 2.4, 8.0), height * rows + 0.9), layout="constrained")
    axes = figure.subplots(rows, cols, squeeze=False).ravel()
    for axis in axes[count:]:
        axis.set_visible(False)
    return figure, list(axes[:count])


def _title(figure: Figure, text: str) -> None:
    """The figure's title, wrapped to its width."""
    figure.suptitle(textwrap.fill(text, max(40, int((figure.get_figwidth() - 2.0) * 9))))


def _scale(axis: Any, which: str, values: Any) -> None:
    """A logarithmic x or y axis when ``values`` span :data:`DECADES` decades."""
    if spans_decades(values):
        (axis.set_xscale if which == "x" else axis.set_yscale)("log")


def _mark_failed(axis: Any, xs: list[float], color: Any) -> None:
    """× at the bottom of the panel at each x with a failed row."""
    if xs:
        axis.plot(xs, [0.03] * len(xs), color=color,
                  transform=blended_transform_factory(axis.transData, axis.transAxes),
                  clip_on=False, **FAILED_MARK)


def _mark_never(axis: Any, xs: list[float], color: Any) -> None:
    """▲ at the top of the panel at each x whose median (or case) is +inf: it never settled."""
    if xs:
        axis.plot(xs, [EDGE] * len(xs), color=color,
                  transform=blended_transform_factory(axis.transData, axis.transAxes),
                  clip_on=False, **NEVER_MARK)


def _top_edge(axis: Any, values: Any) -> float:
    """Fix the y limits around the finite ``values`` (on the axis' scale, set before), with room above
    them, and return the upper one: where a band or box reaching +inf ends."""
    finite = _finite(values)
    low, high = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
    if axis.get_yscale() == "log":
        pad = (high / low) ** 0.05
        low, high = low / pad, high * pad ** 3
    else:
        pad = 0.05 * (high - low) or 0.5 * abs(high) or 0.5
        low, high = low - pad, high + 3 * pad
    axis.set_ylim(low, high)
    return high


def _legend(figure: Figure, colors: dict[str, Any], failed: bool, extra: list[Any] | None = None,
            style: str = "o-", never: list[str] | None = None) -> None:
    """The planners' colours (the failed mark, and the +inf mark with each of the ``never`` texts)
    beside the panels."""
    line: Any = style[1:] or "none"
    handles = [Line2D([], [], color=color, marker=style[0], linestyle=line, label=label)
               for label, color in colors.items()]
    if failed:
        handles.append(Line2D([], [], color="0.3", label="failed row (no value)", **FAILED_MARK))
    handles += [Line2D([], [], color="0.3", label=text, **NEVER_MARK) for text in dict.fromkeys(never or [])]
    handles += extra or []
    figure.legend(handles=handles, loc="outside right upper", fontsize=8)


LINE_STYLES: tuple[Any, ...] = ("-", "--", ":", "-.")
LINE_MARKERS: tuple[Any, ...] = ("o", "s", "^", "D", "v", "P")
"""How the lines of ``metrics_vs_<path>`` tell the other grid parameters' values apart (a planner by its colour)."""


def _lines(study: Study, rows: list[dict[str, Any]]) -> Iterator[tuple[str, Figure]]:
    metrics = _with_values(study, rows)
    axes_1d = _numeric_axes(study, rows)
    if not metrics:
        return
    spread = study.samples > 1
    labels = _labels(rows)
    colors = _colors(labels)
    for (path, xs), stem in zip(axes_1d, row_stems([path for path, _ in axes_1d])):
        figure, axes = _grid(len(metrics))
        any_failed = False
        never: list[str] = []
        combinations: dict[str, int] = {}  # the other grid paths' values -> their style
        for axis, metric in zip(axes, metrics):
            drawn: list[float] = []
            bands = []
            for line in metric_lines(study, rows, path, metric):
                text = _point_text(study, line.others)
                style = combinations.setdefault(text, len(combinations))
                axis.plot(line.xs, line.median, color=colors[line.label], ms=4,  # +inf: no point, a mark at the top
                          linestyle=LINE_STYLES[style % len(LINE_STYLES)],
                          marker=LINE_MARKERS[style % len(LINE_MARKERS)])
                drawn += line.median
                unsettled = [x for x, value in zip(line.xs, line.median) if value == math.inf]
                _mark_never(axis, unsettled, colors[line.label])
                if unsettled:
                    never.append(_infinite_words(metric)[1])
                if spread:
                    bands.append((colors[line.label], line.xs, line.low, line.high))
                    drawn += line.low + line.high
                _mark_failed(axis, line.failed, colors[line.label])
                any_failed |= bool(line.failed)
            _scale(axis, "x", xs)
            _scale(axis, "y", drawn)
            top = _top_edge(axis, drawn) if math.inf in drawn else math.inf
            for color, line_xs, low, high in bands:  # a percentile at +inf: the band reaches the top edge
                axis.fill_between(line_xs, np.minimum(low, top), np.minimum(high, top), color=color, alpha=0.12,
                                  lw=0)
            axis.set_xlabel(axis_label(*parameter_quantity(study, path)))
            axis.set_ylabel(_metric_label(metric))
            axis.grid(alpha=0.3)
        styles = [Line2D([], [], color="0.3", linestyle=LINE_STYLES[k % len(LINE_STYLES)],
                         marker=LINE_MARKERS[k % len(LINE_MARKERS)], label=text)
                  for text, k in combinations.items() if text]
        _legend(figure, colors, any_failed, styles, never=never)
        infinite = "; a case that never settled counts as +inf: ▲ and a band at the top edge" if never else ""
        each = "one line per planner and value of the other grid parameters" if len(study.grid_paths) > 1 else ""
        _title(figure, f"{study.name}: median over the Monte Carlo samples (band 5-95 % of the samples"
                       f"{infinite}){'; ' + each if each else ''}" if spread else
               f"{study.name}{': ' + each if each else ''}")
        yield f"metrics_vs_{stem}.png", figure


def _cell_text(value: float) -> str:
    return f"{value:.3g}"


def _heat_maps(study: Study, rows: list[dict[str, Any]]) -> Iterator[tuple[str, Figure]]:
    axes_2d = _numeric_axes(study, rows)
    if len(study.grid_paths) != 2 or len(axes_2d) != 2:
        return
    (px, xs), (py, ys) = axes_2d
    labels = _labels(rows)
    cells = {(label, x, y): [] for label in labels for x in xs for y in ys}  # type: dict[tuple, list]
    for row in rows:
        cells[(row["label"], row[px], row[py])].append(row)
    for metric, stem in zip(study.summary, row_stems(study.summary)):
        values = {key: _values(metric, members) for key, members in cells.items()}
        grids = {label: np.array([[_statistic(values[(label, x, y)], 50.0) for x in xs] for y in ys])
                 for label in labels}
        medians = np.concatenate([grid.ravel() for grid in grids.values()])
        if np.isnan(medians).all():
            continue
        finite = _finite(medians)
        if not finite.size:  # every median +inf: a scale for the colour bar only
            finite = np.array([0.0, 1.0])
        norm = (LogNorm(finite.min(), finite.max()) if spans_decades(finite)
                else Normalize(finite.min(), finite.max() if finite.max() > finite.min() else finite.min() + 1.0))
        figure, axes = _grid(len(labels), 4.6, 3.9)
        image = None
        for axis, label in zip(axes, labels):
            grid = grids[label]
            image = axis.imshow(np.where(np.isinf(grid), math.nan, grid), origin="lower", aspect="auto", cmap="viridis",
                                norm=norm)
            for j, y in enumerate(ys):
                for i, x in enumerate(xs):
                    members = cells[(label, x, y)]
                    failures = sum(_failed(r) for r in members)
                    unsettled = int(np.isinf(values[(label, x, y)]).sum())
                    if np.isnan(grid[j, i]):
                        axis.add_patch(Rectangle((i - 0.5, j - 0.5), 1, 1, facecolor="0.92", edgecolor="0.45",
                                                 hatch="xx", lw=0))
                        axis.text(i, j, "failed" if failures else "no value", ha="center", va="center", fontsize=7,
                                  color="0.25")
                        continue
                    if grid[j, i] == math.inf:  # most cases never settled: the median is +inf
                        axis.add_patch(Rectangle((i - 0.5, j - 0.5), 1, 1, facecolor="0.8", edgecolor="0.35",
                                                 hatch="//", lw=0))
                        axis.text(i, j, f"never\n{unsettled} of {len(members)}", ha="center", va="center",
                                  fontsize=7, color="k", fontweight="bold")
                    else:
                        if grid.size <= MAX_ANNOTATED_CELLS:
                            shade = image.cmap(image.norm(grid[j, i]))
                            axis.text(i, j, _cell_text(grid[j, i]), ha="center", va="center", fontsize=7,
                                      color="k" if 0.299 * shade[0] + 0.587 * shade[1] + 0.114 * shade[2] > 0.5
                                      else "w")
                        if unsettled:
                            axis.text(i - 0.45, j + 0.45, f"never {unsettled}", ha="left", va="top", fontsize=7,
                                      color="tab:red", fontweight="bold")
                    if failures:
                        axis.text(i + 0.45, j + 0.45, f"× {failures}", ha="right", va="top", fontsize=7,
                                  color="tab:red", fontweight="bold")
            axis.set_xticks(range(len(xs)), [f"{x:.3g}" for x in xs])
            axis.set_yticks(range(len(ys)), [f"{y:.3g}" for y in ys])
            axis.set_xlabel(axis_label(*parameter_quantity(study, px)))
            axis.set_ylabel(axis_label(*parameter_quantity(study, py)))
            axis.set_title(label)
        assert image is not None  # one panel per planner, at least one
        figure.colorbar(image, ax=axes, label=_metric_label(metric))
        never = (f"; never n: cases at +inf ({_infinite_words(metric)[0]}), a cell hatched // when they make "
                 "the median" if any(np.isinf(v).any() for v in values.values()) else "")
        _title(figure, f"{study.name}: median per grid point (one colour scale for every planner; "
                       f"× n: rows that failed; hatched ×: no value{never})")
        yield f"heatmap_{stem}.png", figure


def _sample_groups(study: Study, rows: list[dict[str, Any]]) -> tuple[list[tuple[str, Any, list[dict[str, Any]]]], str]:
    """Groups of Monte Carlo cases: per grid point and planner when there are few, else per planner
    (pooled over the grid points); each ``(name, planner label, rows)``, and a note for the title."""
    labels = _labels(rows)
    points = list(dict.fromkeys(json.dumps([row.get(p) for p in study.grid_paths]) for row in rows))
    if len(points) <= 1 or len(points) * len(labels) > MAX_GROUPS:
        note = f"; pooled over {len(points)} grid points" if len(points) > 1 else ""
        return [(label, label, [r for r in rows if r["label"] == label]) for label in labels], note
    groups = []
    for point in points:
        values = dict(zip(study.grid_paths, json.loads(point)))
        members = [r for r in rows if json.dumps([r.get(p) for p in study.grid_paths]) == point]
        for label in labels:
            groups.append((f"{label}\n{_point_text(study, values)}", label,
                           [r for r in members if r["label"] == label]))
    return groups, ""


def _monte_carlo(study: Study, rows: list[dict[str, Any]]) -> Iterator[tuple[str, Figure]]:
    if study.samples <= 1:
        return
    metrics = _with_values(study, rows)
    if not metrics:
        return
    groups, note = _sample_groups(study, rows)
    colors = _colors(_labels(rows))
    figure, axes = _grid(len(metrics))
    never: list[str] = []
    for axis, metric in zip(axes, metrics):
        data = [_values(metric, members) for _, _, members in groups]
        boxes = {k + 1: _box(values) for k, values in enumerate(data) if (~np.isnan(values)).any()}
        shown = np.concatenate([[b[s] for s in BOX_STATISTICS] + list(b["fliers"]) for b in boxes.values()] or [[]])
        _scale(axis, "y", shown)
        if math.inf in shown:  # a percentile at +inf: the box or whisker reaches the top edge
            top = _top_edge(axis, shown)
            for position, box in boxes.items():
                box.update({s: min(box[s], top) for s in BOX_STATISTICS})
                if box["med"] == top:
                    _mark_never(axis, [position], colors[groups[position - 1][1]])
                    never.append(_infinite_words(metric)[1])
        if boxes:
            axis.bxp(list(boxes.values()), positions=list(boxes), showfliers=True)
        words = _infinite_words(metric)[0]
        names = [name + (f"\n{int(np.isinf(values).sum())} of {values.size} {words}" if np.isinf(values).any() else "")
                 for (name, _, _), values in zip(groups, data)]
        axis.set_xticks(range(1, len(groups) + 1), names, rotation=20, fontsize=7, ha="right")
        axis.set_xlim(0.5, len(groups) + 0.5)
        axis.set_ylabel(_metric_label(metric))
        axis.grid(alpha=0.3)
    if never:
        figure.legend(handles=[Line2D([], [], color="0.3", label=text, **NEVER_MARK) for text in dict.fromkeys(never)],
                      loc="outside right upper", fontsize=8)
    _title(figure, f"{study.name}: {study.samples} Monte Carlo samples per grid point{note} (box 25-75 %, whiskers "
                   "5-95 %, as the summary's p5 and p95" + ("; a case that never settled counts as +inf: a box or "
                                                            "whisker at the top edge reaches it)" if never else ")"))
    yield "boxplots.png", figure
    figure, axes = _grid(len(metrics))
    for axis, metric in zip(axes, metrics):
        words = _infinite_words(metric)[0]
        counted: list[Any] = []
        for name, label, members in groups:
            values = _values(metric, members)
            finite = np.sort(values[np.isfinite(values)])
            counts = [f"{n} {text}" for n, text in ((int(np.isinf(values).sum()), words),
                                                    (int(np.isnan(values).sum()), "without a value")) if n]
            text = name.replace("\n", ", ") + (f" ({', '.join(counts)})" if counts else "")
            if finite.size:  # over every case of the group: failed and unsettled ones keep the curve below 1
                fraction = np.arange(1, finite.size + 1) / len(members)
                curve = axis.step(finite, fraction, where="post", color=colors[label], label=text)
            elif np.isinf(values).any():  # no case settled: no curve, the legend says why
                curve = axis.plot([], [], color=colors[label], label=text)
            else:
                continue
            counted += curve if counts else []
        _scale(axis, "x", np.concatenate([_finite(_values(metric, m)) for _, _, m in groups]))
        axis.set_xlabel(_metric_label(metric))
        axis.set_ylabel("fraction of cases ≤ x (–)")
        axis.set_ylim(0.0, 1.02)
        axis.grid(alpha=0.3)
        if counted:  # the groups whose curve stops below 1, and why
            axis.legend(handles=counted, loc="lower right", fontsize=6)
    plain = list(dict.fromkeys((name.replace("\n", ", "), label) for name, label, _ in groups))
    figure.legend(handles=[Line2D([], [], color=colors[label], label=name) for name, label in plain],
                  loc="outside right upper", fontsize=8)
    _title(figure, f"{study.name}: empirical CDFs over every case (a failed case has no value, one that never "
                   f"settled is +inf: both keep the curve below 1){note}")
    yield "cdf.png", figure
    yield from _scatter(study, rows, metrics, colors)
    yield from _sensitivity(study, rows)


BOX_STATISTICS = ("whislo", "q1", "med", "q3", "whishi")
"""The statistics of a box, at the percentiles :data:`BOX_PERCENTILES`."""
BOX_PERCENTILES = (5.0, 25.0, 50.0, 75.0, 95.0)


def _box(values: np.ndarray) -> dict[str, Any]:
    """A box of ``Axes.bxp`` from values that are not all NaN: whiskers at 5 and 95 %, box 25-75 %, median,
    as the summary table (:func:`_statistic`), +inf included; fliers: the finite values beyond the whiskers."""
    ranked = values[~np.isnan(values)]
    box: dict[str, Any] = {s: _statistic(ranked, q) for s, q in zip(BOX_STATISTICS, BOX_PERCENTILES)}
    finite = ranked[np.isfinite(ranked)]
    box["fliers"] = finite[(finite < box["whislo"]) | (finite > box["whishi"])]
    return box


def _path_lines(path: str, width: int = PATH_LINE_CHARS) -> str:
    """A YAML path on lines of at most about ``width`` characters, broken after its dots: whole, so
    that two drawn quantities that differ early in their path stay told apart (a tester read
    ``…raft.inertia.principal_moments_scale[0]`` for ``truth.spacecraft.inertia....``)."""
    lines: list[str] = []
    for part in re.split(r"(?<=\.)", path):
        if lines and len(lines[-1]) + len(part) <= width:
            lines[-1] += part
        else:
            lines.append(part)
    return "\n".join(lines)


def _sensitivity(study: Study, rows: list[dict[str, Any]]) -> Iterator[tuple[str, Figure]]:
    """The rank correlations of ``sensitivity.csv`` as one heat map per group (at most
    :data:`MAX_GROUPS`): summary metrics down, the drawn quantities
    (:func:`scenarios.study.robustness.parameter_columns`) across, -1 to 1."""
    from scenarios.study.robustness import sensitivity_table

    columns, table = sensitivity_table(study, rows)
    if not table:
        return
    keys = columns[:columns.index("metric")]
    groups: dict[str, dict[tuple[str, str], Any]] = {}
    for line in table:
        name = ", ".join(str(line.get(k)) for k in keys)
        groups.setdefault(name, {})[(line["metric"], line["parameter"])] = line["spearman_rho"]
    metrics = list(dict.fromkeys(line["metric"] for line in table))
    parameters = list(dict.fromkeys(line["parameter"] for line in table))
    shown = list(groups.items())[:MAX_GROUPS]
    figure, axes = _grid(len(shown), max(4.0, 0.9 * len(parameters) + 2.5), max(3.0, 0.45 * len(metrics) + 2.0))
    images = []
    for axis, (name, values) in zip(axes, shown):
        matrix = np.array([[math.nan if values.get((m, q)) is None else values[(m, q)] for q in parameters]
                           for m in metrics])
        images.append(axis.imshow(matrix, cmap="RdBu_r", vmin=-1.0, vmax=1.0, aspect="auto"))
        if matrix.size <= MAX_ANNOTATED_CELLS:
            for (i, j), value in np.ndenumerate(matrix):
                axis.text(j, i, "–" if math.isnan(value) else f"{value:.2f}", ha="center", va="center", fontsize=7,
                          color="white" if abs(value) > 0.6 else "black")  # NaN > 0.6 is False: black
        axis.set_xticks(range(len(parameters)), [_path_lines(q) for q in parameters], rotation=30,
                        ha="right", fontsize=7)
        axis.set_yticks(range(len(metrics)), metrics, fontsize=7)
        axis.set_title(name, fontsize=9)
    figure.colorbar(images[0], ax=axes, label="Spearman rank correlation (–)")
    more = f" (the first {len(shown)} of {len(groups)} groups)" if len(shown) < len(groups) else ""
    _title(figure, f"{study.name}: rank correlation of each summary metric with each drawn quantity "
                   f"(sensitivity.csv; –: the metric does not vary){more}")
    yield "sensitivity.png", figure


def _dispersed(study: Study, row: dict[str, Any], path: str) -> float:
    """A dispersed value as a number: a scalar, or a vector's norm (stored as JSON text)."""
    value = row.get(path)
    if isinstance(value, str):
        try:
            value = json.loads(value)
        except ValueError:
            return math.nan
    if isinstance(value, list):
        try:
            return float(np.linalg.norm(np.asarray(value, dtype=float)))
        except (TypeError, ValueError):
            return math.nan
    return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else math.nan


def _scatter(study: Study, rows: list[dict[str, Any]], metrics: list[str],
             colors: dict[str, Any]) -> Iterator[tuple[str, Figure]]:
    """Each summary metric against each dispersed parameter (a vector's norm); case seeds are not parameters."""
    dispersions = (study.raw.get("monte_carlo") or {}).get("dispersions") or {}
    paths = [p for p in study.mc_paths if dispersions.get(p) != "case_seed"]
    for path, stem in zip(paths, row_stems(paths)):
        xs = np.array([_dispersed(study, r, path) for r in rows])
        if not np.isfinite(xs).any():
            continue
        vector = any(isinstance(r.get(path), (str, list)) for r in rows)
        name, unit = parameter_quantity(study, path)
        figure, axes = _grid(len(metrics))
        any_failed = False
        never: list[str] = []
        for axis, metric in zip(axes, metrics):
            ys = _values(metric, rows)
            for label, color in colors.items():
                mine = np.array([r["label"] == label for r in rows])
                axis.plot(xs[mine], ys[mine], ".", color=color, ms=4, alpha=0.6)  # +inf: a mark at the top instead
                failed = mine & np.array([_failed(r) for r in rows])
                _mark_failed(axis, list(xs[failed]), color)
                any_failed |= bool(failed.any())
                unsettled = mine & np.isinf(ys)
                _mark_never(axis, list(xs[unsettled]), color)
                if unsettled.any():
                    never.append(f"case {_infinite_words(metric)[0]}")
            _scale(axis, "x", xs)
            _scale(axis, "y", ys)
            axis.set_xlabel(axis_label(f"‖{name}‖" if vector else name, unit))
            axis.set_ylabel(_metric_label(metric))
            axis.grid(alpha=0.3)
        _legend(figure, colors, any_failed, style=".", never=never)
        _title(figure, f"{study.name}: each case against {'the norm of ' if vector else ''}{name}")
        yield f"scatter_{stem}.png", figure


def pareto_front(points: np.ndarray) -> np.ndarray:
    """The points not dominated by another (both smaller or equal, one smaller), sorted by x.

    Parameters
    ----------
    points : (N, 2) ndarray
        Rows of (x, y), both to be minimised (for example ∫‖u‖ [N m s] and settling time [s]);
        rows with a non-finite value are left out.

    Returns
    -------
    (M, 2) ndarray
        The front, by increasing x (and decreasing y).
    """
    points = points[np.all(np.isfinite(points), axis=1)]
    order = points[np.lexsort((points[:, 1], points[:, 0]))]
    front, best = [], math.inf
    for x, y in order:
        if y < best:
            front.append((x, y))
            best = y
    return np.array(front).reshape(-1, 2)


NOT_OK_MARK: dict[str, Any] = {"marker": "o", "mfc": "white", "ms": 7, "mew": 1.6, "linestyle": "none"}
"""How a design point with a row not ok is drawn on a Pareto panel (hollow, in the planner's colour)."""


def _pareto(study: Study, rows: list[dict[str, Any]]) -> Iterator[tuple[str, Figure]]:
    x_key, y_key = PARETO_AXES
    labels = _labels(rows)
    colors = _colors(labels)
    panels = pareto_panels(study, rows)
    if not panels:
        return
    shown = panels[:MAX_PARETO_PANELS]
    figure, axes = _grid(len(shown), 4.6, 3.6)
    words = _infinite_words(y_key)[1]
    any_never = any_not_ok = False
    samples = study.samples > 1
    for axis, panel in zip(axes, shown):
        notes: list[str] = []
        drawn = [point for point in panel.points if not (math.isnan(point.x) or math.isnan(point.y))]
        notes += [f"{point.label}: no value" for point in panel.points if point not in drawn]
        every = np.array([(x, y) for p in drawn for x, y in ((p.x, p.y), (p.x_spread[0], p.y_spread[0]),
                                                              (p.x_spread[1], p.y_spread[1]))]).reshape(-1, 2)
        _scale(axis, "x", every[:, 0])
        _scale(axis, "y", every[:, 1])
        top = _top_edge(axis, every[:, 1]) if np.isinf(every[:, 1]).any() else math.inf
        for point in drawn:
            color = colors[point.label]
            if point.y == math.inf:  # the median never settled: at the top edge, on no front
                _mark_never(axis, [point.x], color)
                any_never = True
                notes.append(f"{point.label}: {words}")
                continue
            style = NOT_OK_MARK if point.not_ok else {"marker": "o", "ms": 6, "linestyle": "none"}
            spread = ({"xerr": [[point.x - point.x_spread[0]], [point.x_spread[1] - point.x]],
                       "yerr": [[point.y - point.y_spread[0]], [min(point.y_spread[1], top) - point.y]]}
                      if samples else {})
            axis.errorbar([point.x], [point.y], color=color, elinewidth=0.8, capsize=2, **spread, **style)
            if point.not_ok:
                any_not_ok = True
                axis.annotate(f"{point.not_ok}/{point.rows} not ok", (point.x, point.y), textcoords="offset points",
                              xytext=(5, 4), fontsize=7, color="tab:red")
        if notes:
            axis.text(0.98, 0.02, "\n".join(notes), transform=axis.transAxes, ha="right", va="bottom", fontsize=7,
                      color="0.3")
        if len(panel.front):
            axis.step(panel.front[:, 0], panel.front[:, 1], where="post", color="k", lw=1.2)
            axis.plot(panel.front[:, 0], panel.front[:, 1], "o", mfc="none", mec="k", ms=11)
        axis.set_xlabel(_metric_label(x_key))
        axis.set_ylabel(_metric_label(y_key))
        if study.grid_paths:
            axis.set_title(_point_text(study, panel.point), fontsize=8)
        axis.grid(alpha=0.3)
    extra = [Line2D([], [], color="k", marker="o", mfc="none", ms=11, label="Pareto front (design points all ok)")]
    if any_not_ok:
        extra.append(Line2D([], [], color="0.3", label="a row not ok (violated, failed): on no front", **NOT_OK_MARK))
    _legend(figure, colors, False, extra, style="o", never=[f"{words} (on no front)"] if any_never else [])
    more = f" (the first {len(shown)} of {len(panels)} grid points)" if len(shown) < len(panels) else ""
    each = f"planners at the median of {study.samples} samples (bars 5-95 %)" if samples else "planners"
    _title(figure, f"{study.name}: {each}, front over those with every row ok"
           + (" per grid point" if study.grid_paths else "") + more)
    yield "pareto.png", figure


def figures(study: Study, rows: list[dict[str, Any]]) -> Iterator[tuple[str, Figure]]:
    """Every figure that applies to the study, one at a time (the caller closes each).

    Parameters
    ----------
    study : Study
        The study (its grid paths, samples and summary metrics choose the figures).
    rows : list of dict
        The ``cases.csv`` rows (:func:`scenarios.study.report.case_table`).

    Yields
    ------
    name : str
        The PNG's file name.
    figure : matplotlib.figure.Figure
        The figure (pyplot's: close it with ``matplotlib.pyplot.close``).
    """
    yield from _lines(study, rows)
    yield from _heat_maps(study, rows)
    yield from _monte_carlo(study, rows)
    yield from _pareto(study, rows)


def _save(figure: Figure, directory: Path, name: str) -> str:
    temporary = directory / f".{name}.partial.png"
    try:
        figure.savefig(temporary, dpi=DPI)
    finally:
        plt.close(figure)
    temporary.replace(directory / name)
    return name


def write_plots(study: Study, rows: list[dict[str, Any]], directory: Path, progress: Any = None) -> list[str]:
    """Every figure that applies to the study (:func:`figures`), as PNG files.

    Parameters
    ----------
    study : Study
        The study (its grid paths, samples and summary metrics choose the figures).
    rows : list of dict
        The ``cases.csv`` rows (:func:`scenarios.study.report.case_table`).
    directory : Path
        Where the PNG files are written (an existing folder).
    progress : object, optional
        Told of each file written, ``progress.advance()``
        (:func:`scenarios.study.engine.write_progress`); None (default): nothing is.

    Returns
    -------
    list of str
        The file names written in ``directory``.
    """
    written = []
    for name, figure in figures(study, rows):
        written.append(_save(figure, directory, name))
        if progress is not None:
            progress.advance()
    return written
