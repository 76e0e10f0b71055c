"""Figures of a trade study (matplotlib, Agg): a summary metric against each numeric 1-D grid
parameter (one line per planner, median with the 5-95 % band under Monte Carlo), heat maps over a
2-D grid, box plots and empirical CDFs across Monte Carlo samples, and a Pareto front per planner."""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from scenarios.output.names import row_stems
from scenarios.output.tables import is_missing
from scenarios.study.types import Study

PARETO_AXES = ("cl.int_u", "cl.settling_time_s")


def _value(row: dict[str, Any], key: str) -> float:
    """A plotted value: NaN when missing or non-finite (the tables' rule) or when the row is not ok."""
    value = row.get(key)
    if row.get("status") != "ok" or isinstance(value, bool) or not isinstance(value, (int, float)) or is_missing(value):
        return math.nan
    return float(value)


def _labels(rows: list[dict[str, Any]]) -> list[str]:
    return list(dict.fromkeys(row["label"] for row in rows))


def _numeric_axes(study: Study, rows: list[dict[str, Any]]) -> list[tuple[str, list[float]]]:
    axes = []
    for path in study.grid_paths:
        values = sorted({row[path] for row in rows if isinstance(row.get(path), (int, float))})
        if len(values) > 1 and all(isinstance(row.get(path), (int, float)) for row in rows):
            axes.append((path, values))
    return axes


def _grid(count: int) -> tuple[plt.Figure, Any]:
    cols = min(count, 3)
    fig, axes = plt.subplots(math.ceil(count / cols), cols, figsize=(5 * cols, 3.8 * math.ceil(count / cols)),
                             squeeze=False)
    for axis in axes.flat[count:]:
        axis.set_visible(False)
    return fig, axes.flat


def _save(fig: plt.Figure, directory: Path, name: str) -> str:
    fig.tight_layout()
    temporary = directory / f".{name}.partial.png"
    fig.savefig(temporary, dpi=110)
    plt.close(fig)
    temporary.replace(directory / name)
    return name


def _lines(study: Study, rows: list[dict[str, Any]], directory: Path) -> list[str]:
    written = []
    axes_1d = _numeric_axes(study, rows)
    for (path, xs), stem in zip(axes_1d, row_stems([path for path, _ in axes_1d])):
        fig, axes = _grid(len(study.summary))
        for axis, metric in zip(axes, study.summary):
            for label in _labels(rows):
                per_x = [[_value(r, metric) for r in rows if r["label"] == label and r[path] == x] for x in xs]
                median = [np.nanmedian(v) if np.isfinite(v).any() else np.nan for v in per_x]
                line, = axis.plot(xs, median, "o-", label=label)
                if study.samples > 1 or len(study.grid_paths) > 1:
                    low = [np.nanpercentile(v, 5) if np.isfinite(v).any() else np.nan for v in per_x]
                    high = [np.nanpercentile(v, 95) if np.isfinite(v).any() else np.nan for v in per_x]
                    axis.fill_between(xs, low, high, color=line.get_color(), alpha=0.15)
            axis.set_xlabel(path)
            axis.set_ylabel(metric)
            axis.grid(alpha=0.3)
        axes[0].legend(fontsize=8)
        fig.suptitle(f"{study.name}: median over the other parameters and samples (band 5-95 %)"
                     if study.samples > 1 or len(study.grid_paths) > 1 else study.name)
        written.append(_save(fig, directory, f"metrics_vs_{stem}.png"))
    return written


def _heat_maps(study: Study, rows: list[dict[str, Any]], directory: Path) -> list[str]:
    axes_2d = _numeric_axes(study, rows)
    if len(study.grid_paths) != 2 or len(axes_2d) != 2:
        return []
    (px, xs), (py, ys) = axes_2d
    written = []
    for metric, stem in zip(study.summary, row_stems(study.summary)):
        labels = _labels(rows)
        fig, axes = _grid(len(labels))
        for axis, label in zip(axes, labels):
            grid = np.array([[np.nanmedian([_value(r, metric) for r in rows if r["label"] == label
                                            and r[px] == x and r[py] == y] or [np.nan]) for x in xs] for y in ys])
            image = axis.imshow(grid, origin="lower", aspect="auto", cmap="viridis")
            axis.set_xticks(range(len(xs)), [f"{x:.3g}" for x in xs])
            axis.set_yticks(range(len(ys)), [f"{y:.3g}" for y in ys])
            axis.set_xlabel(px)
            axis.set_ylabel(py)
            axis.set_title(label)
            fig.colorbar(image, ax=axis, label=metric)
        written.append(_save(fig, directory, f"heatmap_{stem}.png"))
    return written


def _monte_carlo(study: Study, rows: list[dict[str, Any]], directory: Path) -> list[str]:
    if study.samples <= 1:
        return []
    labels = _labels(rows)
    fig, axes = _grid(len(study.summary))
    for axis, metric in zip(axes, study.summary):
        data = [[v for v in (_value(r, metric) for r in rows if r["label"] == label) if math.isfinite(v)]
                for label in labels]
        axis.boxplot([d or [np.nan] for d in data], showfliers=True)
        axis.set_xticks(range(1, len(labels) + 1), labels, rotation=20, fontsize=8)
        axis.set_ylabel(metric)
        axis.grid(alpha=0.3)
    fig.suptitle(f"{study.name}: {study.samples} Monte Carlo samples per grid point")
    written = [_save(fig, directory, "boxplots.png")]
    fig, axes = _grid(len(study.summary))
    for axis, metric in zip(axes, study.summary):
        for label in labels:
            values = np.sort([v for v in (_value(r, metric) for r in rows if r["label"] == label) if math.isfinite(v)])
            if values.size:
                axis.step(values, np.arange(1, values.size + 1) / values.size, where="post", label=label)
        axis.set_xlabel(metric)
        axis.set_ylabel("fraction of cases ≤ x")
        axis.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle(f"{study.name}: empirical CDFs")
    written.append(_save(fig, directory, "cdf.png"))
    return written


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


def _pareto(study: Study, rows: list[dict[str, Any]], directory: Path) -> list[str]:
    x_key, y_key = PARETO_AXES
    fig, axis = plt.subplots(figsize=(7, 5))
    for label in _labels(rows):
        points = np.array([[_value(r, x_key), _value(r, y_key)] for r in rows if r["label"] == label])
        if not np.isfinite(points).all(axis=1).any():
            continue
        line, = axis.step(*pareto_front(points).T, where="post", lw=1.5)
        axis.scatter(points[:, 0], points[:, 1], s=10, alpha=0.4, color=line.get_color(), label=label)
    axis.set_xlabel(f"{x_key} (N m s)")
    axis.set_ylabel(f"{y_key} (s)")
    axis.set_title(f"{study.name}: cases and Pareto front per planner")
    axis.grid(alpha=0.3)
    axis.legend(fontsize=8)
    return [_save(fig, directory, "pareto.png")]


def write_plots(study: Study, rows: list[dict[str, Any]], directory: Path) -> list[str]:
    """Every figure that applies to the study.

    Parameters
    ----------
    study : Study
        The study (its grid paths, samples and summary metrics choose the figures).
    rows : list of dict
        The ``cases.csv`` rows (:func:`scenarios.study.report.case_table`).
    directory : Path
        Where the PNG files are written (an existing folder).

    Returns
    -------
    list of str
        The file names written in ``directory``.
    """
    return (_lines(study, rows, directory) + _heat_maps(study, rows, directory)
            + _monte_carlo(study, rows, directory) + _pareto(study, rows, directory))
