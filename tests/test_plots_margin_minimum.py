"""The pointing-margin figures (``margins.png`` and report.html's margin traces) never contradict the
results table: each curve's "min" is the scored minimum of the row's requirement record (the table's
number, which the scoring evaluates between the samples too), drawn at its time, so that a dip the
samples miss, a violation between two samples, shows below zero.

Oracle: a motion built by hand, a rotation about the inertial z axis by θ(t) = 60.2° sin(π t / T),
whose star-tracker margin (boresight body x, keep-out 30° about inertial y) is |90° − θ| − 30° in
closed form: −0.2° at t = T/2, and +0.715° at the nearest of ten samples (none at T/2). The row's
record is written here from that closed form, as the scoring records it (``min_margin_deg``,
``min_margin_time_s``).
"""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from matplotlib.collections import PolyCollection

from ocp.geometry import PointingConstraint
from scenarios.output.plot_data import margin_series, overlay_series
from scenarios.output.plots import margin_figure, overlay_figure
from scenarios.output.report.figures import margin_figure as html_margin_figure

T = 100.0
PEAK_DEG = 60.2
KEEP_OUT = PointingConstraint("tracker_sun", [1, 0, 0], True, np.deg2rad(30.0), directions=[[0, 1, 0]],
                              description="star_tracker keep-out 30 deg about sun")


def theta_deg(t: np.ndarray) -> np.ndarray:
    return PEAK_DEG * np.sin(np.pi * np.asarray(t) / T)


def closed_form_margin_deg(t: np.ndarray) -> np.ndarray:
    """Angle of R_z(θ) x from y is |90° − θ|; the keep-out margin is that less 30°."""
    return np.abs(90.0 - theta_deg(t)) - 30.0


def about_z(theta: np.ndarray) -> np.ndarray:
    return np.stack([np.cos(theta / 2), 0 * theta, 0 * theta, np.sin(theta / 2)], axis=1)


def coarse_row(samples: int = 10, peak_deg: float = PEAK_DEG):
    """A closed loop sampled so coarsely that no sample falls at the dip (t = T/2), with the record
    of its scored minimum (closed form)."""
    t = np.linspace(0.0, T, samples)
    worst = abs(90.0 - peak_deg) - 30.0
    inside = 2.0 * (T / 2 - T / np.pi * np.arcsin(60.0 / peak_deg)) if worst < 0 else 0.0
    record = {"min_margin_deg": worst, "time_in_violation_s": inside,
              "first_violation_s": T / 2 - inside / 2 if worst < 0 else None, "min_margin_time_s": T / 2}
    return SimpleNamespace(label="coarse", planner="hand", controller=None, status="violated" if worst < 0 else "ok",
                           reference=None,
                           simulation=SimpleNamespace(t=t, q=about_z(np.deg2rad(peak_deg) * np.sin(np.pi * t / T))),
                           requirements={"closed_loop": {"tracker_sun": record}})


def results(rows, duration: float = T):
    problem = SimpleNamespace(pointing=(KEEP_OUT,), duration=duration, qf=None, spacecraft=None)
    return SimpleNamespace(scenario=SimpleNamespace(name="hand-built", problem=problem), rows=rows)


def test_the_samples_miss_the_dip():
    """The premise: every sample is clear of the cone (the least +0.715°), the motion is not."""
    row = coarse_row()
    sampled = closed_form_margin_deg(row.simulation.t)
    assert sampled.min() == pytest.approx(abs(90.0 - PEAK_DEG * np.sin(np.pi * 4 / 9)) - 30.0, abs=1e-12)
    assert sampled.min() > 0.7
    assert closed_form_margin_deg(T / 2) == pytest.approx(-0.2, abs=1e-12)


def test_the_png_legend_gives_the_scored_minimum_and_the_curve_crosses_zero():
    row = coarse_row()
    figure = margin_figure(margin_series(results([row])))
    axis = figure.axes[0]
    (curve,) = [line for line in axis.get_lines() if line.get_label().startswith("coarse, closed loop")]
    assert "min -0.2° at 50 s" in curve.get_label()
    t, margin = (np.asarray(v, dtype=float) for v in curve.get_data())
    # the samples, each on the closed form, and the scored point between them
    at = np.flatnonzero(t == T / 2)
    assert at.size == 1 and margin[at[0]] == pytest.approx(-0.2, abs=1e-12)
    others = np.delete(np.arange(t.size), at)
    np.testing.assert_allclose(margin[others], closed_form_margin_deg(t[others]), atol=1e-9)
    # the violation is filled below zero
    fills = [c for c in axis.collections if isinstance(c, PolyCollection) and len(c.get_paths())
             and c.get_paths()[0].vertices[:, 1].min() < 0]
    assert fills and min(p.vertices[:, 1].min() for c in fills for p in c.get_paths()) == pytest.approx(-0.2, abs=1e-9)
    # and the minimum is marked where the table puts it
    markers = [line for line in axis.get_lines() if line.get_marker() not in ("None", None, "")
               and line.get_linestyle() in ("None", "none", "")]
    assert any(np.allclose(m.get_xdata(), [T / 2]) and np.allclose(m.get_ydata(), [-0.2]) for m in markers)
    bottom, top = axis.get_ylim()
    assert bottom < -0.2 < 0.0 < top


def test_a_tiny_violation_between_samples_shows_below_the_zero_line():
    """keep_out_melton_scaled's size: the closed loop dips 0.0009° into the cone while the margins
    elsewhere reach 15°; the marked minimum lies more than a marker's height (7 pt, 8.75 px at
    90 dpi) below the zero line."""
    peak = 60.0009  # margin |90 − 60.0009| − 30 = −0.0009 deg
    row = coarse_row(samples=10, peak_deg=peak)
    figure = margin_figure(margin_series(results([row])))
    axis = figure.axes[0]
    (curve,) = [line for line in axis.get_lines() if line.get_label().startswith("coarse, closed loop")]
    assert "min -0.0009° at 50 s" in curve.get_label()
    figure.canvas.draw()
    (_, y_dip), (_, y_zero) = axis.transData.transform([[T / 2, -0.0009], [T / 2, 0.0]])
    assert y_zero - y_dip > 8.75


def test_the_legend_min_is_the_record_when_the_record_has_no_time():
    """A record without ``min_margin_time_s``: the legend still gives the table's minimum."""
    row = coarse_row()
    row.requirements["closed_loop"]["tracker_sun"]["min_margin_time_s"] = None
    figure = margin_figure(margin_series(results([row])))
    (curve,) = [line for line in figure.axes[0].get_lines() if line.get_label().startswith("coarse, closed loop")]
    assert "min -0.2°" in curve.get_label() and " at " not in curve.get_label()


def test_the_time_axis_ends_with_the_run_not_the_duration_bound():
    """A minimum-time problem's duration is a bound (10 s here); the run covers 3 s."""
    row = coarse_row()
    row.simulation.t = row.simulation.t * 0.03
    row.requirements["closed_loop"]["tracker_sun"]["min_margin_time_s"] = 1.5
    figure = margin_figure(margin_series(results([row], duration=10.0)))
    assert figure.axes[-1].get_xlim() == pytest.approx((0.0, 3.0))


def test_the_report_margin_trace_gives_the_scored_minimum_and_draws_it():
    row = coarse_row()
    figure = html_margin_figure(KEEP_OUT, [row])
    (trace,) = [t for t in figure["data"] if t.get("mode") == "lines" and t["name"].startswith("coarse: ")]
    assert trace["name"] == "coarse: min -0.2° at 50 s"
    x = np.asarray(trace["x"], dtype=float)
    y = np.asarray(trace["y"], dtype=float)
    assert y.min() == pytest.approx(-0.2, abs=1e-12) and x[np.argmin(y)] == T / 2
    np.testing.assert_allclose(y[x != T / 2], closed_form_margin_deg(x[x != T / 2]), atol=1e-9)
    (marker,) = [t for t in figure["data"] if t.get("mode") == "markers"]
    assert list(marker["x"]) == [T / 2] and list(marker["y"]) == [pytest.approx(-0.2, abs=1e-12)]


def test_the_comparison_legend_marks_a_violated_row():
    """comparison.png: a violated row says so in the legend (with its recorded time in violation)
    and carries markers; an ok row neither."""
    bad = coarse_row()
    good = coarse_row(peak_deg=59.0)
    good.label = "clear"
    for row in (bad, good):
        row.simulation.omega = np.zeros((row.simulation.t.size, 3))
        row.simulation.applied_torque = np.zeros((row.simulation.t.size - 1, 3))  # one per interval
        row.simulation.wheel_momentum = np.zeros((row.simulation.t.size, 0))
    problem = SimpleNamespace(pointing=(KEEP_OUT,), duration=T, qf=about_z(np.zeros(1))[0], omegaf=None,
                              spacecraft=SimpleNamespace(wheels=None))
    series = overlay_series(SimpleNamespace(scenario=SimpleNamespace(name="hand-built", problem=problem),
                                            rows=[bad, good]))
    figure = overlay_figure(series)
    legend = figure.legends[0]
    texts = [t.get_text() for t in legend.get_texts()]
    inside = bad.requirements["closed_loop"]["tracker_sun"]["time_in_violation_s"]
    assert "VIOLATED" in texts[0] and f"tracker_sun violated cl {inside:.3g} s" in " ".join(texts[0].split())
    assert "VIOLATED" not in texts[1] and "OK" not in texts[1]
    handles = legend.legend_handles
    assert handles[0].get_marker() not in ("None", None, "") and handles[1].get_marker() in ("None", None, "")
