"""The figures of a trade study (issue 31): axes named in words with their units, one colour scale
for every planner of a heat map, failed cells and points marked, logarithmic axes where a quantity
spans decades, a Pareto front per grid point, each metric against each dispersed parameter, and
no warning on the way.

The studies are parsed as a user writes them; their case rows are made up here (values chosen so
that the expected scales, fronts and marks are known by hand), so that nothing is run."""
from __future__ import annotations

import copy
import math
import warnings

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.colors import LogNorm, Normalize
from matplotlib.image import AxesImage
from matplotlib.patches import Rectangle

from scenarios.output.plot_data import axis_label, column_quantity
from scenarios.study.plots import (
    PARETO_AXES,
    UNKNOWN_UNIT,
    figures,
    metric_lines,
    parameter_quantity,
    pareto_panels,
    write_plots,
)
from scenarios.study.spec import parse_study

BASE = {
    "name": "tiny",
    "spacecraft": {"inertia": [2.0, 3.0, 4.0], "wheels": {"max_torque": 0.05}},
    "maneuver": {"duration": 30.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.9238795, 0.3826834, 0, 0], "omega": None}},  # spin extremals: free final rate
    "planners": [{"name": "eigenaxis", "label": "smooth"},
                 {"name": "spin_extremal", "label": "spin", "options": {"weight": 0.01}}],
    "controller": {"name": "augmented_quaternion_feedback", "options": {"kp": 0.2, "kd": 0.6}},
    "simulation": {"sample_time": 1.0, "duration": 35.0},
}


def study(**parts):
    return parse_study({"study": "tiny-study", "scenario": copy.deepcopy(BASE), **parts})


def rows_of(parsed, values):
    """Case rows as ``cases.csv`` has them: ``values(case, label) -> (status, {column: value})``."""
    rows = []
    for case in parsed.cases:
        for label in ("smooth", "spin"):
            status, metrics = values(case, label)
            rows.append({"case": case.index, "seed": case.seed, **case.varied, "label": label, "status": status,
                         **metrics})
    return rows


def built(parsed, rows):
    """Every figure by name, built with warnings raised as errors (none may reach stderr)."""
    made = {}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for name, figure in figures(parsed, rows):
            figure.canvas.draw()
            made[name] = figure
    return made


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


def test_axes_name_varied_paths_and_columns_in_words_with_their_units():
    parsed = study(grid={"maneuver.final.q": {"axis_angle": {"axis": [1, 1, 1], "angle_deg": [10, 90]}},
                         "simulation.sample_time": [0.5, 1.0]},
                   zip={"planners[label=spin].options.weight": [0.001, 0.01], "controller.options.kp": [0.1, 0.2]})
    assert parameter_quantity(parsed, "maneuver.final.q") == ("slew angle about [1, 1, 1]", "deg")
    assert parameter_quantity(parsed, "simulation.sample_time") == ("simulation sample time", "s")
    assert parameter_quantity(parsed, "planners[label=spin].options.weight") == ("spin weight", "1/(N² m² s)")
    assert parameter_quantity(parsed, "controller.options.kp")[1] in ("1/s^2", "1/s²")
    assert parameter_quantity(parsed, "spacecraft.inertia[2]") == ("inertia 2", "kg m²")
    assert parameter_quantity(parsed, "simulation.sensor_noise.seed") == ("sensor noise seed", "–")
    assert parameter_quantity(parsed, "simulation.no_such_key")[1] == UNKNOWN_UNIT
    assert column_quantity("cl.final_error_deg") == ("closed-loop final error", "deg")
    assert column_quantity("ref.int_u") == ("reference ∫‖u‖ dt", "N m s")
    assert column_quantity("cl.int_abs_u_y") == ("closed-loop ∫|u_y| dt", "N m s")
    assert column_quantity("cl.req.st_sun.min_margin_deg") == ("closed-loop st_sun: min margin", "deg")
    assert column_quantity("cl.req.rate.peak_rate") == ("closed-loop rate: peak rate", "rad/s")
    assert column_quantity("ref.req.actuators.wheels_torque") == ("reference actuators: peak wheels torque / limit", "–")
    assert axis_label("closed-loop saturation fraction", "–") == "closed-loop saturation fraction (–)"
    with pytest.raises(KeyError):
        column_quantity("maneuver.final.q")


def test_an_initial_attitude_away_from_the_identity_is_no_slew_angle():
    data = copy.deepcopy(BASE)
    data["maneuver"]["initial"]["q"] = [0, 1, 0, 0]
    parsed = parse_study({"study": "s", "scenario": data,
                          "grid": {"maneuver.final.q": {"axis_angle": {"axis": [0, 0, 1], "angle_deg": [10, 90]}}}})
    assert parameter_quantity(parsed, "maneuver.final.q") == ("final attitude: rotation angle about [0, 0, 1]", "deg")


def heat_map_study(spin_value, failed_cell):
    """3 x 2 grid; smooth's metric 1..6, spin's ``spin_value(k)``; one spin case failed."""
    parsed = study(grid={"maneuver.duration": [30.0, 40.0, 50.0], "simulation.sample_time": [0.5, 1.0]},
                   summary=["cl.final_error_deg", "ref.peak_actuator_torque"])

    def values(case, label):
        k = case.index + 1
        if label == "spin" and case.index == failed_cell:
            return "failed", {"cl.final_error_deg": None}
        return "ok", {"cl.final_error_deg": float(k) if label == "smooth" else spin_value(k),
                      "ref.peak_actuator_torque": None}  # a metric no row has: no panel, no warning

    return parsed, rows_of(parsed, values)


@pytest.mark.parametrize("spin_value,norm", [(lambda k: 100.0 * k, LogNorm), (lambda k: k + 1.0, Normalize)])
def test_heat_maps_share_one_colour_scale_and_mark_the_failed_cell(spin_value, norm):
    parsed, rows = heat_map_study(spin_value, failed_cell=3)
    made = built(parsed, rows)
    assert "heatmap_cl.final_error_deg.png" in made and "heatmap_ref.peak_actuator_torque.png" not in made
    figure = made["heatmap_cl.final_error_deg.png"]
    panels = [axis for axis in figure.axes if axis.get_title() in ("smooth", "spin")]
    images = [next(a for a in axis.get_children() if isinstance(a, AxesImage)) for axis in panels]
    finite = [float(k) for k in range(1, 7)] + [spin_value(k) for k in (1, 2, 3, 5, 6)]
    for image in images:  # one scale: the smallest and largest cell of every planner
        assert type(image.norm) is norm
        assert (image.norm.vmin, image.norm.vmax) == (min(finite), max(finite))
    assert len([a for a in figure.axes if a.get_label() == "<colorbar>"]) == 1
    spin = panels[[a.get_title() for a in panels].index("spin")]
    # case 3 is duration 40 (x index 1), sample time 1.0 (y index 1): its cell is hatched and says so
    hatched = [p for p in spin.patches if isinstance(p, Rectangle) and p.get_hatch()]
    assert [(p.get_x(), p.get_y()) for p in hatched] == [(0.5, 0.5)]
    assert "failed" in [t.get_text() for t in spin.texts]
    assert spin.get_xlabel() == "maneuver duration (s)" and spin.get_ylabel() == "simulation sample time (s)"


def test_the_line_plots_mark_failed_points_and_take_a_log_axis_over_decades():
    parsed, rows = heat_map_study(lambda k: 10.0 ** -k, failed_cell=3)
    figure = built(parsed, rows)["metrics_vs_maneuver.duration.png"]
    (panel,) = [a for a in figure.axes if a.get_ylabel() == "closed-loop final error (deg)"]
    assert panel.get_yscale() == "log" and panel.get_xscale() == "linear"
    marks = [line for line in panel.get_lines() if line.get_marker() == "x"]
    assert len(marks) == 1 and list(marks[0].get_xdata()) == [40.0]  # spin's failed case, at its duration
    assert "failed row (no value)" in [t.get_text() for t in figure.legends[0].get_texts()]
    # one line per planner and sample time (never a median over the other grid parameter): smooth's k
    # at sample time 0.5 s is 1, 3, 5 and at 1 s 2, 4, 6
    smooth = [line for line in panel.get_lines() if line.get_color() == "C0" and line.get_marker() != "x"]
    assert [list(line.get_ydata()) for line in smooth] == [[1.0, 3.0, 5.0], [2.0, 4.0, 6.0]]
    assert smooth[0].get_linestyle() != smooth[1].get_linestyle()
    assert {"simulation sample time 0.5 s", "simulation sample time 1 s"} <= {
        t.get_text() for t in figure.legends[0].get_texts()}
    assert not panel.collections  # one case per line and point: no band


def test_each_grid_point_has_its_own_pareto_front():
    """Pooled over the points, the second point's cases are all dominated by the first's."""
    parsed = study(grid={"maneuver.duration": [30.0, 40.0]})
    table = {(0, "smooth"): (1.0, 10.0), (0, "spin"): (2.0, 5.0), (1, "smooth"): (10.0, 100.0), (1, "spin"): (20.0, 50.0)}
    rows = rows_of(parsed, lambda case, label: ("ok", dict(zip(PARETO_AXES, table[(case.index, label)]))))
    figure = built(parsed, rows)["pareto.png"]
    panels = [a for a in figure.axes if a.get_xlabel()]
    assert [a.get_title() for a in panels] == ["maneuver duration 30 s", "maneuver duration 40 s"]
    for axis, point in zip(panels, (0, 1)):
        (front,) = [line for line in axis.get_lines() if line.get_color() == "k" and line.get_linestyle() == "-"]
        expected = sorted(table[(point, label)] for label in ("smooth", "spin"))
        np.testing.assert_allclose(np.c_[front.get_xdata(), front.get_ydata()], expected)
        assert axis.get_xlabel() == "closed-loop ∫‖u‖ dt (N m s)" and axis.get_ylabel() == "closed-loop settling time (s)"


def design_study():
    """Grid: 2 durations x 2 gains (kp), 5 Monte Carlo samples each (a user's slew angle x kp study)."""
    return study(grid={"maneuver.duration": [30.0, 40.0], "controller.options.kp": [0.1, 0.2]},
                 monte_carlo={"samples": 5, "seed": 2, "dispersions": {
                     "simulation.initial_attitude_error_deg": {"normal": {"mean": [0, 0, 0], "std": [1, 1, 1]}}}},
                 summary=["cl.final_error_deg", "cl.settling_time_s", "cl.int_u"])


def sample_of(parsed):
    return {case.index: case.index % parsed.samples for case in parsed.cases}


def test_the_pareto_front_runs_over_design_points_at_their_median_and_never_through_a_row_not_ok():
    """A user saw each grid point's front drawn through single Monte Carlo samples of both planners,
    with violated rows on it unmarked. Settling times by hand: smooth 10 + k, spin 4 + k for the
    samples k = 0..4 (median: 12 and 6), ∫‖u‖ smooth 1 + 0.1 k, spin 3 + 0.1 k (median 1.2, 3.2).
    At kp 0.2 and duration 40 s spin's sample 4 is violated: spin is then on no front, even though
    its median dominates nothing less; at kp 0.1, duration 30 s, smooth's sample 0 (the fastest
    single case of the panel, 0.5 s) is violated too."""
    parsed = design_study()
    sample = sample_of(parsed)

    def values(case, label):
        k = sample[case.index]
        kp, duration = case.varied["controller.options.kp"], case.varied["maneuver.duration"]
        settling, effort = (10.0 + k, 1.0 + 0.1 * k) if label == "smooth" else (4.0 + k, 3.0 + 0.1 * k)
        status = "ok"
        if label == "spin" and (kp, duration, k) == (0.2, 40.0, 4):
            status = "violated"
        if label == "smooth" and (kp, duration, k) == (0.1, 30.0, 0):
            status, settling, effort = "violated", 0.5, 0.1  # dominates every other case of its panel
        return status, {"cl.settling_time_s": settling, "cl.int_u": effort, "cl.final_error_deg": 0.01}

    rows = rows_of(parsed, values)
    panels = pareto_panels(parsed, rows)
    assert [panel.point for panel in panels] == [
        {"maneuver.duration": d, "controller.options.kp": kp} for d in (30.0, 40.0) for kp in (0.1, 0.2)]
    for panel in panels:
        by_label = {point.label: point for point in panel.points}
        assert set(by_label) == {"smooth", "spin"} and all(point.rows == 5 for point in panel.points)
        smooth, spin = by_label["smooth"], by_label["spin"]
        assert (spin.x, spin.y) == pytest.approx((3.2, 6.0))
        violated_smooth = panel.point == {"maneuver.duration": 30.0, "controller.options.kp": 0.1}
        violated_spin = panel.point == {"maneuver.duration": 40.0, "controller.options.kp": 0.2}
        # smooth's median over its samples: 0.5 takes sample 0's place at the low end, the median stays 12
        assert (smooth.x, smooth.y) == pytest.approx((1.2, 12.0))
        assert (smooth.not_ok, spin.not_ok) == (int(violated_smooth), int(violated_spin))
        ok = [p for p in (smooth, spin) if not p.not_ok]
        # neither planner dominates the other (smooth: less effort; spin: settles sooner): both on the front when ok
        np.testing.assert_allclose(sorted(map(tuple, panel.front.tolist())), sorted((p.x, p.y) for p in ok))
        assert [p.on_front for p in (smooth, spin)] == [not violated_smooth, not violated_spin]
        # every point of the front is a design point's median, none a single sample
        medians = {(round(p.x, 9), round(p.y, 9)) for p in panel.points}
        assert all((round(x, 9), round(y, 9)) in medians for x, y in panel.front.tolist())
        assert smooth.x_spread[0] <= smooth.x <= smooth.x_spread[1] and spin.y_spread[0] <= 6.0 <= spin.y_spread[1]
    figure = built(parsed, rows)["pareto.png"]
    legend = [t.get_text() for t in figure.legends[0].get_texts()]
    assert "a row not ok (violated, failed): on no front" in legend


def test_metric_lines_band_spans_one_design_points_samples_only():
    """A user's 5-95 % band mixed the other design parameter (kp) with the plant's dispersion. Here
    the final error is 10 j + k for kp number j (0, 1) and sample k (0..4): each line (planner, kp)
    has the median 10 j + 2 and a band within [10 j, 10 j + 4]; mixed, the bands would span 0 to 14."""
    parsed = design_study()
    sample = sample_of(parsed)
    rows = rows_of(parsed, lambda case, label: ("ok", {
        "cl.final_error_deg": 10.0 * [0.1, 0.2].index(case.varied["controller.options.kp"]) + sample[case.index],
        "cl.settling_time_s": 5.0, "cl.int_u": 1.0}))
    lines = metric_lines(parsed, rows, "maneuver.duration", "cl.final_error_deg")
    assert [(line.label, line.others) for line in lines] == [
        (label, {"controller.options.kp": kp}) for label in ("smooth", "spin") for kp in (0.1, 0.2)]
    for line in lines:
        j = [0.1, 0.2].index(line.others["controller.options.kp"])
        assert line.xs == [30.0, 40.0] and line.median == [10.0 * j + 2] * 2 and not line.failed
        assert all(10.0 * j <= low < 10.0 * j + 2 < high <= 10.0 * j + 4 for low, high in zip(line.low, line.high))
    figure = built(parsed, rows)["metrics_vs_maneuver.duration.png"]
    (panel,) = [a for a in figure.axes if a.get_ylabel() == "closed-loop final error (deg)"]
    bands = [collection.get_paths()[0].vertices[:, 1] for collection in panel.collections]
    assert len(bands) == 4 and all(np.ptp(band) <= 4.0 for band in bands)


def monte_carlo_study():
    return study(monte_carlo={"samples": 40, "seed": 3, "dispersions": {
        "simulation.initial_attitude_error_deg": {"normal": {"mean": [0, 0, 0], "std": [1.0, 1.0, 1.0]}},
        "simulation.initial_rate_error": {"uniform": {"low": [0, 0, 0], "high": [0.001, 0.002, 0.0]}},
        "simulation.sensor_noise.seed": "case_seed"}},
        summary=["cl.final_error_deg", "cl.int_u"])


def test_monte_carlo_cdfs_and_box_plots_go_logarithmic_over_decades_and_count_failed_cases():
    parsed = monte_carlo_study()
    rng = np.random.default_rng(5)

    def values(case, label):
        if label == "spin" and case.index % 10 == 0:
            return "crashed", {}
        return "ok", {"cl.final_error_deg": 10.0 ** rng.uniform(-4, 0), "cl.int_u": rng.uniform(10.0, 12.0)}

    rows = rows_of(parsed, values)
    made = built(parsed, rows)
    cdf = made["cdf.png"]
    (error,) = [a for a in cdf.axes if a.get_xlabel() == "closed-loop final error (deg)"]
    (effort,) = [a for a in cdf.axes if a.get_xlabel() == "closed-loop ∫‖u‖ dt (N m s)"]
    assert error.get_xscale() == "log" and effort.get_xscale() == "linear"
    spin = next(line for line in error.get_lines() if line.get_label().startswith("spin"))
    assert spin.get_ydata()[-1] == pytest.approx(36 / 40)  # 4 of 40 crashed: the curve stops at 0.9
    assert spin.get_label() == "spin (4 without a value)"
    box = made["boxplots.png"]
    assert [a.get_yscale() for a in box.axes if a.get_ylabel()] == ["log", "linear"]


def test_each_metric_is_drawn_against_each_dispersed_parameter_but_the_seed():
    parsed = monte_carlo_study()
    rows = rows_of(parsed, lambda case, label: ("ok", {"cl.final_error_deg": 1.0 + case.index,
                                                       "cl.int_u": 2.0 + case.index}))
    made = built(parsed, rows)
    names = sorted(n for n in made if n.startswith("scatter_"))
    assert names == ["scatter_simulation.initial_attitude_error_deg.png", "scatter_simulation.initial_rate_error.png"]
    figure = made["scatter_simulation.initial_attitude_error_deg.png"]
    (panel,) = [a for a in figure.axes if a.get_ylabel() == "closed-loop final error (deg)"]
    assert panel.get_xlabel() == "‖simulation initial attitude error‖ (deg)"
    smooth = panel.get_lines()[0]
    norms = [math.sqrt(sum(v * v for v in case.scenario["simulation"]["initial_attitude_error_deg"]))
             for case in parsed.cases]
    np.testing.assert_allclose(smooth.get_xdata(), norms)
    np.testing.assert_allclose(smooth.get_ydata(), [1.0 + case.index for case in parsed.cases])
    rate = made["scatter_simulation.initial_rate_error.png"]
    assert {a.get_xlabel() for a in rate.axes if a.get_xlabel()} == {"‖simulation initial rate error‖ (rad/s)"}


def test_write_plots_writes_every_figure_and_leaves_none_open(tmp_path):
    parsed, rows = heat_map_study(lambda k: 2.0 * k, failed_cell=0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        written = write_plots(parsed, rows, tmp_path)
    assert sorted(written) == sorted(p.name for p in tmp_path.iterdir())
    assert {"heatmap_cl.final_error_deg.png", "metrics_vs_maneuver.duration.png",
            "metrics_vs_simulation.sample_time.png"} <= set(written)
    assert plt.get_fignums() == []


def test_grid_points_with_samples_count_their_failed_rows_and_group_the_box_plots():
    parsed = study(grid={"maneuver.duration": [30.0, 40.0], "simulation.sample_time": [0.5, 1.0]},
                   monte_carlo={"samples": 3, "seed": 1, "dispersions": {
                       "simulation.initial_attitude_error_deg": {"normal": {"mean": [0, 0, 0], "std": [1, 1, 1]}}}},
                   summary=["cl.final_error_deg"])

    def values(case, label):  # the first sample of the last grid point fails for spin
        if label == "spin" and case.index == 9:
            return "failed", {}
        return "ok", {"cl.final_error_deg": 1.0 + case.index}

    made = built(parsed, rows_of(parsed, values))
    heat = made["heatmap_cl.final_error_deg.png"]
    spin = next(a for a in heat.axes if a.get_title() == "spin")
    marks = [t for t in spin.texts if t.get_text().startswith("×")]
    assert [(m.get_text(), round(m.get_position()[0]), round(m.get_position()[1])) for m in marks] == [("× 1", 1, 1)]
    cell = next(t for t in spin.texts if t.get_position() == (1, 1))  # the median of the two samples left
    assert cell.get_text() == f"{(11.0 + 12.0) / 2:.3g}"
    box = made["boxplots.png"]
    (panel,) = [a for a in box.axes if a.get_ylabel()]
    groups = [t.get_text() for t in panel.get_xticklabels()]
    assert len(groups) == 8 and groups[0] == "smooth\nmaneuver duration 30 s, simulation sample time 0.5 s"


# --- cases that never settled (+inf, as the summary table counts them) -----------------------------

NEVER = None
"""A settling time that was never reached: null, while the final error has a value."""
SETTLING = {("smooth", 30.0): [3.0, 1.0, NEVER, 5.0, 2.0],  # 1 of 5 never: median of [1, 2, 3, 5, inf] = 3
            ("smooth", 40.0): [4.0, 6.0, 8.0, 10.0, 12.0],
            ("spin", 30.0): [NEVER, 7.0, NEVER, NEVER, 9.0],  # 3 of 5 never: median +inf
            ("spin", 40.0): [2.0, 2.0, "failed", 2.0, 2.0]}
"""Settling times [s] of 5 Monte Carlo samples per (planner, maneuver duration); ``"failed"``: a failed row."""


def never_study():
    """2 durations x 5 samples, settling times from :data:`SETTLING`; ∫‖u‖ = 1 + sample."""
    parsed = study(grid={"maneuver.duration": [30.0, 40.0]},
                   monte_carlo={"samples": 5, "seed": 4, "dispersions": {
                       "simulation.initial_attitude_error_deg": {"normal": {"mean": [0, 0, 0], "std": [1, 1, 1]}}}},
                   summary=["cl.final_error_deg", "cl.settling_time_s"])
    sample = {}
    for case in parsed.cases:
        duration = case.varied["maneuver.duration"]
        sample[case.index] = sum(other.varied["maneuver.duration"] == duration
                                 for other in parsed.cases if other.index < case.index)

    def values(case, label):
        k = sample[case.index]
        settling = SETTLING[(label, case.varied["maneuver.duration"])][k]
        if settling == "failed":
            return "failed", {}
        return "ok", {"cl.final_error_deg": 0.1 + k, "cl.settling_time_s": settling, "cl.int_u": 1.0 + k}

    return parsed, rows_of(parsed, values), sample


def test_a_median_that_never_settled_is_marked_at_the_top_and_the_band_reaches_it():
    from scenarios.study.report import summary_table

    parsed, rows, _ = never_study()
    figure = built(parsed, rows)["metrics_vs_maneuver.duration.png"]
    (panel,) = [a for a in figure.axes if a.get_ylabel() == "closed-loop settling time (s)"]
    smooth, spin = [line for line in panel.get_lines() if line.get_marker() == "o"]
    # medians by hand: [1, 2, 3, 5, inf] -> 3; [4 .. 12] -> 8; [7, 9, inf, inf, inf] -> inf; [2, 2, 2, 2] -> 2
    assert list(smooth.get_ydata()) == [3.0, 8.0]
    assert list(spin.get_ydata()) == [math.inf, 2.0]
    (never,) = [line for line in panel.get_lines() if line.get_marker() == "^"]
    assert list(never.get_xdata()) == [30.0] and never.get_color() == spin.get_color()
    texts = [t.get_text() for t in figure.legends[0].get_texts()]
    assert "median never reached (did not settle)" in texts and "failed row (no value)" in texts
    (failed,) = [line for line in panel.get_lines() if line.get_marker() == "x"]
    assert list(failed.get_xdata()) == [40.0]
    # 5-95 % bands: smooth at 30 from 1 + 0.2 (2 - 1) = 1.2 to +inf (the top edge), at 40 from 4.4 to 11.6;
    # spin at 30 from 7 + 0.2 (9 - 7) = 7.4 to the top edge
    top = panel.get_ylim()[1]
    assert top > 12.0
    bands = [collection.get_paths()[0].vertices for collection in panel.collections]
    for vertices, corners in zip(bands, ([(30.0, 1.2), (30.0, top), (40.0, 4.4), (40.0, 11.6)],
                                         [(30.0, 7.4), (30.0, top), (40.0, 2.0)])):
        for corner in corners:
            assert np.isclose(vertices, corner).all(axis=1).any(), corner
    # the summary table has the same medians
    _, summary = summary_table(parsed, rows)
    medians = {(line["label"], line["maneuver.duration"]): line["median"] for line in summary
               if line["metric"] == "cl.settling_time_s"}
    assert [medians[("smooth", x)] for x in (30.0, 40.0)] == list(smooth.get_ydata())
    assert [medians[("spin", x)] for x in (30.0, 40.0)] == list(spin.get_ydata())


def test_cdfs_box_plots_scatter_and_pareto_count_the_cases_that_never_settled():
    parsed, rows, sample = never_study()
    made = built(parsed, rows)
    (cdf,) = [a for a in made["cdf.png"].axes if a.get_xlabel() == "closed-loop settling time (s)"]
    labels = {line.get_label(): line for line in cdf.get_lines()}
    assert set(labels) == {"smooth, maneuver duration 30 s (1 never settled)", "smooth, maneuver duration 40 s",
                           "spin, maneuver duration 30 s (3 never settled)",
                           "spin, maneuver duration 40 s (1 without a value)"}
    spin = labels["spin, maneuver duration 30 s (3 never settled)"]
    assert list(spin.get_xdata()) == [7.0, 9.0] and list(spin.get_ydata()) == [0.2, 0.4]  # of 5 cases
    assert {t.get_text() for t in cdf.get_legend().get_texts()} == {
        "smooth, maneuver duration 30 s (1 never settled)", "spin, maneuver duration 30 s (3 never settled)",
        "spin, maneuver duration 40 s (1 without a value)"}

    (box,) = [a for a in made["boxplots.png"].axes if a.get_ylabel() == "closed-loop settling time (s)"]
    assert [t.get_text() for t in box.get_xticklabels()] == [
        "smooth\nmaneuver duration 30 s\n1 of 5 never settled", "spin\nmaneuver duration 30 s\n3 of 5 never settled",
        "smooth\nmaneuver duration 40 s", "spin\nmaneuver duration 40 s"]
    (never,) = [line for line in box.get_lines() if line.get_marker() == "^"]
    assert list(never.get_xdata()) == [2]  # spin at 30 s: median +inf
    flat = [line for line in box.get_lines() if len(line.get_ydata()) == 2 and line.get_ydata()[0] == line.get_ydata()[1]]
    assert any(list(line.get_ydata()) == [3.0, 3.0] and np.mean(line.get_xdata()) == 1 for line in flat)  # smooth 30

    figure = made["scatter_simulation.initial_attitude_error_deg.png"]
    (scatter,) = [a for a in figure.axes if a.get_ylabel() == "closed-loop settling time (s)"]
    norm = {case.index: math.sqrt(sum(v * v for v in case.scenario["simulation"]["initial_attitude_error_deg"]))
            for case in parsed.cases}
    unsettled = {label: sorted(norm[case.index] for case in parsed.cases
                               if SETTLING[(label, case.varied["maneuver.duration"])][sample[case.index]] is NEVER)
                 for label in ("smooth", "spin")}
    assert [len(found) for found in unsettled.values()] == [1, 3]
    colour = {"smooth": "C0", "spin": "C1"}
    marks = {line.get_color(): sorted(line.get_xdata()) for line in scatter.get_lines() if line.get_marker() == "^"}
    assert marks == {colour[label]: found for label, found in unsettled.items()}
    assert "case never settled" in [t.get_text() for t in figure.legends[0].get_texts()]

    # Pareto: each planner at its median over the samples; spin at 30 s has a median +inf (at the top
    # edge, on no front), spin at 40 s a failed row (marked, on no front)
    pareto = made["pareto.png"]
    notes = {a.get_title(): [t.get_text() for t in a.texts] for a in pareto.axes if a.get_xlabel()}
    assert notes == {"maneuver duration 30 s": ["spin: median never reached (did not settle)"],
                     "maneuver duration 40 s": ["1/5 not ok"]}


def test_a_heat_map_cell_whose_median_never_settled_is_hatched_and_counted():
    parsed = study(grid={"maneuver.duration": [30.0, 40.0], "simulation.sample_time": [0.5, 1.0]},
                   monte_carlo={"samples": 3, "seed": 2, "dispersions": {
                       "simulation.initial_attitude_error_deg": {"normal": {"mean": [0, 0, 0], "std": [1, 1, 1]}}}},
                   summary=["cl.settling_time_s"])
    spin = {(30.0, 0.5): [NEVER, NEVER, NEVER], (40.0, 0.5): [NEVER, 5.0, NEVER],
            (30.0, 1.0): [2.0, 4.0, NEVER], (40.0, 1.0): [1.0, 2.0, 3.0]}  # medians: inf, inf, 4, 2
    seen: dict = {}

    def values(case, label):
        point = (case.varied["maneuver.duration"], case.varied["simulation.sample_time"])
        k = seen.setdefault((label, point), [])
        k.append(case.index)
        settling = spin[point][len(k) - 1] if label == "spin" else 10.0 + len(k)
        return "ok", {"cl.final_error_deg": 0.2, "cl.settling_time_s": settling}

    made = built(parsed, rows_of(parsed, values))
    figure = made["heatmap_cl.settling_time_s.png"]
    panel = next(a for a in figure.axes if a.get_title() == "spin")
    texts = {(round(t.get_position()[0]), round(t.get_position()[1]), t.get_text()) for t in panel.texts}
    assert {(0, 0, "never\n3 of 3"), (1, 0, "never\n2 of 3"), (0, 1, "4"), (1, 1, "2")} <= texts
    assert (0, 1, "never 1") in {(round(t.get_position()[0] + 0.45), round(t.get_position()[1] - 0.45), t.get_text())
                                 for t in panel.texts}
    hatched = sorted((p.get_x(), p.get_y()) for p in panel.patches if isinstance(p, Rectangle) and p.get_hatch() == "//")
    assert hatched == [(-0.5, -0.5), (0.5, -0.5)]
    image = next(a for a in panel.get_children() if isinstance(a, AxesImage))
    assert (image.norm.vmin, image.norm.vmax) == (2.0, 12.0)  # finite medians only: spin 2, 4; smooth 12
