"""Every axis of every figure says what it shows (issue 31): the figures of every shipped scenario
and of a small study of each shipped study kind (a 1-D grid, a 2-D grid, Monte Carlo) are built,
drawn and walked; each axis whose tick labels are numbers has a label ending in a unit in
parentheses, and no label is a dotted YAML path (``maneuver.final.q``, ``cl.int_u``).

Scenarios that take long run in the slow set as shipped; the default set runs the quick ones as
shipped and the long regulation scenarios with a shorter duration (their figures have the same
panels). The study plots are built with warnings raised as errors."""
from __future__ import annotations

import copy
import re
import warnings
from pathlib import Path

import matplotlib.pyplot as plt
import pytest

import scenarios
from scenarios.output.plot_data import (
    MarginSeries,
    OverlaySeries,
    RowSeries,
    SkySeries,
    plot_jobs,
)
from scenarios.output.plots import RowFigure, margin_figure, overlay_figure, sky_figure
from scenarios.schema import parse_scenario, read_yaml
from scenarios.study.engine import sweep
from scenarios.study.plots import figures
from scenarios.study.report import case_table
from scenarios.study.spec import parse_study
from tests.test_sweep import InlineExecutor

ROOT = Path(__file__).resolve().parents[1] / "scenarios"
SHIPPED = sorted(p.name for p in ROOT.glob("*.yaml") if not p.name.startswith("study_"))
QUICK = ["biggs_horri_spin_repoint_low.yaml", "biggs_horri_spin_repoint_wheels.yaml", "collocation_keep_out.yaml",
         "eigenaxis_demo.yaml", "nano_eigenaxis_pd.yaml", "nano_natural_vs_eigenaxis.yaml"]
"""The default set: each kind of figure (wheels along the axes, torquers, pointing requirements, a
planner that fails) in a few seconds; every other shipped scenario runs in the slow set."""
SHORTENED = {"nano_detumble.yaml": 600.0}
"""A long regulation scenario also run in the default set with this ``maneuver.duration`` [s]
(magnetorquers, no reference, no target attitude)."""
STUDIES = ["study_planners_vs_slew_angle.yaml", "study_spin_weight_sample_time.yaml", "study_spin_monte_carlo.yaml"]

UNIT = re.compile(r"\(((?:[^()]|\([^()]*\))+)\)\s*$")
"""A unit in parentheses at the end of a label: ``time (s)``, ``quaternion (–)``."""
DOTTED = re.compile(r"\b[A-Za-z_]\w*(\[[^\]]*\])?(\.[A-Za-z_]\w*(\[[^\]]*\])?)+")
"""A dotted path: ``maneuver.final.q``, ``cl.int_u``, ``planners[label=x].options.weight``."""
NUMBER = re.compile(r"[-−+]?(\d+\.?\d*|\.\d+)([eE][-−+]?\d+)?°?|\$\\mathdefault\{[^$]*\}\$")
"""A tick label that is a number (plain, with a degree sign, or matplotlib's ``10^{-3}``)."""


def axis_labels(figure):
    """(axes, 'x' or 'y', numeric tick labels?, label) of every visible axis, after a draw. A row
    figure places its value-axis labels as text left of the panel (drawn once): those count."""
    figure.canvas.draw()
    for axes in figure.axes:
        if not axes.get_visible():
            continue
        for which, axis in (("x", axes.xaxis), ("y", axes.yaxis)):
            numeric = any(tick.get_visible() and NUMBER.fullmatch(tick.get_text().strip())
                          for tick in axis.get_ticklabels())
            label = axis.get_label_text()
            if not label and which == "y":
                placed = [t.get_text() for t in axes.texts if t.get_rotation() == 90 and t.get_position()[0] < 0]
                label = placed[0] if placed else ""
            yield axes, which, bool(numeric), label


def check(figure, name):
    """Every numeric axis has a unit; no label is a dotted path. Returns the labels seen."""
    seen = []
    for axes, which, numeric, label in axis_labels(figure):
        where = f"{name}: {which} axis of the panel titled {axes.get_title()!r}"
        if label:
            seen.append(label)
            assert not DOTTED.search(label), f"{where}: a dotted path as its label: {label!r}"
        if numeric:
            assert label, f"{where}: numbers without a label"
            assert UNIT.search(label), f"{where}: no unit in its label {label!r}"
    return seen


def run_figures(results):
    """The figures of a run, built and drawn in memory (as :func:`scenarios.output.plots.draw_jobs` draws them)."""
    made = []
    for name, series in plot_jobs(results):
        if isinstance(series, RowSeries):
            figure = RowFigure(*series.shape)
            figure.prepare(series)
            made.append((name, figure.figure))
        else:
            build = {OverlaySeries: overlay_figure, MarginSeries: margin_figure, SkySeries: sky_figure}[type(series)]
            made.append((name, build(series)))
    return made


def run_shipped(name, duration=None):
    data = read_yaml(ROOT / name)
    if duration is not None:
        data["maneuver"]["duration"] = duration
        if (data.get("simulation") or {}).get("duration"):
            data["simulation"]["duration"] = duration
    return scenarios.run(parse_scenario(data, ROOT / name))


def check_run(name, duration=None):
    made = run_figures(run_shipped(name, duration))
    assert any(n == "comparison.png" for n, _ in made)
    labels = []
    for file_name, figure in made:
        labels += check(figure, f"{name} {file_name}")
    return labels


@pytest.mark.parametrize("name", QUICK)
def test_every_axis_of_a_quick_shipped_scenario_has_a_unit_and_no_yaml_path(name):
    labels = check_run(name)
    assert "time (s)" in labels and "Euler 3-2-1 (deg)" in labels and "body rate (deg/s)" in labels


@pytest.mark.parametrize("name", sorted(SHORTENED))
def test_every_axis_of_a_shortened_regulation_scenario_has_a_unit(name):
    labels = check_run(name, SHORTENED[name])
    assert "dipole (A m²)" in labels and "body rate (deg/s)" in labels  # the magnetorquers' and the rate's panels


@pytest.mark.slow
@pytest.mark.parametrize("name", [n for n in SHIPPED if n not in QUICK])
def test_every_axis_of_every_other_shipped_scenario_has_a_unit_and_no_yaml_path(name):
    check_run(name)




def small(data):
    """A shipped study cut down: the first and last value of each grid entry, three Monte Carlo samples."""
    data = copy.deepcopy(data)
    for entries in (data.get("grid") or {}, data.get("zip") or {}):
        for path, given in entries.items():
            if isinstance(given, list):
                entries[path] = [given[0], given[-1]]
            elif "axis_angle" in given:
                angles = given["axis_angle"]["angle_deg"]
                given["axis_angle"]["angle_deg"] = [angles[0], angles[-1]]
    if data.get("monte_carlo"):
        data["monte_carlo"]["samples"] = 3
    return data


@pytest.mark.parametrize("name", STUDIES)
def test_every_axis_of_a_small_shipped_study_has_a_unit_and_no_yaml_path(name):
    study = parse_study(small(read_yaml(ROOT / name)), ROOT / name)
    rows = case_table(study, sweep(study, InlineExecutor(), workers=1).records)[1]
    names, labels = [], []
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no warning reaches stderr (issue 31: 13 "All-NaN slice")
        for file_name, figure in figures(study, rows):
            try:
                names.append(file_name)
                labels += check(figure, f"{name} {file_name}")
            finally:
                plt.close(figure)
    assert "pareto.png" in names
    if study.samples > 1:
        assert {"boxplots.png", "cdf.png"} <= set(names) and any(n.startswith("scatter_") for n in names)
    if "maneuver.final.q" in study.grid_paths:
        assert "slew angle about [1, 1, 1] (deg)" in labels
    if len(study.grid_paths) == 2:
        assert any(n.startswith("heatmap_") for n in names)
