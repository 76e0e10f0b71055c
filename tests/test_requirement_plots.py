"""The pictures a requirements review needs (issue 27, point 5): the pointing margin against time
shows what the motion does, with a 0.2° dip below zero in plain view; the sky map puts each
boresight where it points; the row figures draw the actuators' limits where the spacecraft has them.

Oracles: motions built by hand as rotations about the inertial z axis by a known angle θ(t), whose
boresight directions, angles and margins are written here in closed form (NumPy rotation
matrices, spherical trigonometry), never through the code under test.
"""
from __future__ import annotations

import dataclasses
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from matplotlib.collections import PolyCollection
from PIL import Image

from ocp import Magnetorquers, ReactionWheels, Spacecraft, Torquers
from ocp.dynamics.layout import control_layout
from ocp.geometry import PointingConstraint
from scenarios.output.plot_data import (
    MARGINS_FILE,
    SKY_FILE,
    margin_series,
    plot_jobs,
    row_series,
    sky_path,
    sky_series,
)
from scenarios.output.plots import RowFigure, margin_figure, sky_figure

REPO = Path(__file__).resolve().parents[1]
T = 100.0
"""Length of the hand-built motions [s]."""


def about_z(theta: np.ndarray) -> np.ndarray:
    """Quaternions (scalar first, body to inertial) of rotations by ``theta`` [rad] about z."""
    return np.stack([np.cos(theta / 2), 0 * theta, 0 * theta, np.sin(theta / 2)], axis=1)


def rz(theta: np.ndarray) -> np.ndarray:
    """Rotation matrices about z, written out (N, 3, 3)."""
    c, s, zero, one = np.cos(theta), np.sin(theta), 0 * theta, 0 * theta + 1
    return np.stack([np.stack([c, -s, zero], -1), np.stack([s, c, zero], -1), np.stack([zero, zero, one], -1)], -2)


class Reference:
    """A reference turning about z by ``peak · sin(π t / T)``."""

    ok = True
    duration = T

    def __init__(self, peak: float):
        self.peak = peak
        self.stats: dict = {}

    def theta(self, t):
        return self.peak * np.sin(np.pi * np.asarray(t) / T)

    def q(self, t):
        return about_z(self.theta(t))


def hand_row(label: str, reference_peak: float, closed_loop_peak: float, samples: int = 501):
    """A row whose reference and closed loop turn about z (peaks [rad]), the closed loop sampled."""
    t = np.linspace(0.0, T, samples)
    reference = Reference(reference_peak)
    simulation = SimpleNamespace(t=t, q=about_z(closed_loop_peak * np.sin(np.pi * t / T)))
    return SimpleNamespace(label=label, reference=reference, simulation=simulation,
                           closed_loop_theta=closed_loop_peak * np.sin(np.pi * t / T))


def hand_results(rows, pointing):
    problem = SimpleNamespace(pointing=tuple(pointing), duration=T, qf=None, spacecraft=None)
    return SimpleNamespace(scenario=SimpleNamespace(name="hand-built", problem=problem), rows=rows)


# A star tracker on body x kept 30° out of the inertial y axis; the closed loop turns to
# 60.2° (0.2° into the cone), the reference to 59.99° (0.01° clear).
KEEP_OUT = PointingConstraint("tracker_sun", [1, 0, 0], True, np.deg2rad(30.0), directions=[[0, 1, 0]],
                              description="star_tracker keep-out 30 deg about sun")
DIP_DEG = -0.2


def expected_margin_deg(theta: np.ndarray, direction: np.ndarray, boresight: np.ndarray, limit_deg: float,
                        keep_out: bool) -> np.ndarray:
    """The margin from first principles: rotate the boresight by the written-out matrix, take the
    angle to the direction."""
    pointing = rz(theta) @ (boresight / np.linalg.norm(boresight))
    d = direction / np.linalg.norm(direction)
    angle = np.rad2deg(np.arccos(np.clip(pointing @ d, -1.0, 1.0)))
    return angle - limit_deg if keep_out else limit_deg - angle


def margin_lines(axis):
    """The panel's curves by legend name (``"<row>, closed loop: ..."``)."""
    return {line.get_label().split(":")[0]: line for line in axis.get_lines() if ", " in line.get_label()}


def dip_row():
    return hand_row("dip", np.deg2rad(60.0 - 0.01), np.deg2rad(60.0 - DIP_DEG))


def test_the_margin_panel_plots_the_margins_of_the_motion():
    row = dip_row()
    keep_in = PointingConstraint("camera_keep_in", [0.0, 0.6, 0.8], False, np.deg2rad(50.0),
                                 directions=[[0.0, 0.0, 1.0]], description="zenith")
    figure = margin_figure(margin_series(hand_results([row], [KEEP_OUT, keep_in])))
    axes = [a for a in figure.axes if a.get_title(loc="left")]
    assert len(axes) == 2
    for axis, constraint, boresight, direction, limit in (
            (axes[0], KEEP_OUT, np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), 30.0),
            (axes[1], keep_in, np.array([0, 0.6, 0.8]), np.array([0, 0, 1.0]), 50.0)):
        lines = margin_lines(axis)
        assert set(lines) == {"dip, reference", "dip, closed loop"}
        for name, theta in (("dip, closed loop", lambda t: np.deg2rad(60.2) * np.sin(np.pi * t / T)),
                            ("dip, reference", row.reference.theta)):
            t, plotted = lines[name].get_data()
            assert t[0] == 0.0 and t[-1] == T
            np.testing.assert_allclose(plotted, expected_margin_deg(theta(t), direction, boresight, limit,
                                                                    constraint.keep_out), atol=1e-9)
        assert axis.get_ylabel() == "margin (deg)"
    # the keep-out's closed loop reaches -0.2°, its reference +0.01°; both dashed/solid as stated
    lines = margin_lines(axes[0])
    assert np.min(lines["dip, closed loop"].get_ydata()) == pytest.approx(DIP_DEG, abs=1e-3)
    assert np.min(lines["dip, reference"].get_ydata()) == pytest.approx(0.01, abs=1e-3)
    assert lines["dip, closed loop"].get_linestyle() == "-" and lines["dip, reference"].get_linestyle() == "--"
    assert "min -0.2°" in lines["dip, closed loop"].get_label()
    assert figure.axes[-1].get_xlabel() == "time (s)"


def test_the_title_names_the_requirement_the_sensor_and_the_direction():
    plain = PointingConstraint("cone", [0, 0, 1], False, np.deg2rad(12.5), directions=[[0, 1, 0]])
    figure = margin_figure(margin_series(hand_results([dip_row()], [KEEP_OUT, plain])))
    titles = [axis.get_title(loc="left") for axis in figure.axes]
    assert titles[0] == "tracker_sun: star_tracker keep-out 30 deg about sun; boresight [1, 0, 0] (body)"
    assert titles[1] == "cone: keep-in 12.5 deg about inertial [0, 1, 0]; boresight [0, 0, 1] (body)"


def zero_line(axis):
    return [line for line in axis.get_lines() if np.all(np.asarray(line.get_ydata()) == 0.0)
            and tuple(line.get_xdata()) == (0, 1) and line.get_color() == "k"]


@pytest.mark.parametrize("start_deg", [0.0, 55.0, 120.0])
def test_a_small_dip_below_zero_is_in_plain_view_whatever_the_other_margins(start_deg):
    """The closed loop starts ``start_deg`` from the cone's edge and dips 0.2° inside it. The
    zero line is drawn, the dip lies inside the y range with room below it, and it takes a
    visible share of the panel height between it and the zero line (on a linear 0-to-60° axis
    it would take 0.3 %, under a pixel)."""
    offset = np.deg2rad(90.0 - 30.0 - start_deg)  # the row starts at θ = offset: margin start_deg
    peak = np.deg2rad(60.2) - offset
    t = np.linspace(0.0, T, 1001)
    theta = offset + peak * np.sin(np.pi * t / T)  # 60.2° at t = T/2
    row = SimpleNamespace(label="r", reference=None, simulation=SimpleNamespace(t=t, q=about_z(theta)))
    figure = margin_figure(margin_series(hand_results([row], [KEEP_OUT])))
    axis = figure.axes[0]
    assert zero_line(axis), "no zero line"
    bottom, top = axis.get_ylim()
    assert bottom < DIP_DEG < 0.0 < top
    to_pixels = axis.transData.transform
    (_, y_bottom), (_, y_dip), (_, y_zero), (_, y_top) = to_pixels([[0, bottom], [0, DIP_DEG], [0, 0.0], [0, top]])
    height = y_top - y_bottom
    assert (y_dip - y_bottom) / height > 0.04, "no room below the dip"
    assert (y_zero - y_dip) / height > 0.15, "the dip is squeezed against the zero line"
    # and the largest margin (start_deg at the ends) is still inside the panel
    assert top > max(start_deg, 0.0)


def test_violations_are_shaded_over_their_interval():
    """The filled area below zero spans the closed form's violation interval: θ(t) > 60° ⇔
    sin(π t / T) > 60 / 60.2."""
    figure = margin_figure(margin_series(hand_results([dip_row()], [KEEP_OUT])))
    fills = [c for c in figure.axes[0].collections if isinstance(c, PolyCollection)
             and len(c.get_paths()) and c.get_paths()[0].vertices[:, 1].min() < 0]
    assert len(fills) == 1  # the closed loop's; the reference never violates
    vertices = np.concatenate([p.vertices for p in fills[0].get_paths()])
    start = T / np.pi * np.arcsin(60.0 / 60.2)
    assert vertices[:, 0].min() == pytest.approx(start, abs=0.2)
    assert vertices[:, 0].max() == pytest.approx(T - start, abs=0.2)
    assert vertices[:, 1].min() == pytest.approx(DIP_DEG, abs=1e-3)


def test_a_window_greys_the_time_outside_it_and_the_margins_there_are_gaps():
    windowed = dataclasses.replace(KEEP_OUT, window=(20.0, 70.0))
    figure = margin_figure(margin_series(hand_results([dip_row()], [windowed])))
    t, margin = margin_lines(figure.axes[0])["dip, closed loop"].get_data()
    assert np.all(np.isnan(margin[(t < 20.0) | (t > 70.0)])) and np.all(np.isfinite(margin[(t >= 20) & (t <= 70)]))
    assert "20-70 s" in figure.axes[0].get_title(loc="left")


# ---------------------------------------------------------------------------------- the sky map

def radec(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    v = v / np.linalg.norm(v, axis=-1, keepdims=True)
    return np.rad2deg(np.arctan2(v[..., 1], v[..., 0])) % 360, np.rad2deg(np.arcsin(v[..., 2]))


@pytest.mark.parametrize("ra,dec", [(0.0, 0.0), (90.0, 0.0), (200.0, 45.0), (359.0, -60.0), (30.0, 89.9)])
def test_known_directions_have_their_right_ascension_and_declination(ra, dec):
    a, d = np.deg2rad(ra), np.deg2rad(dec)
    got_ra, got_dec = sky_path(np.array([[np.cos(d) * np.cos(a), np.cos(d) * np.sin(a), np.sin(d)]]))
    assert got_ra[0] == pytest.approx(ra, abs=1e-9) and got_dec[0] == pytest.approx(dec, abs=1e-9)


def test_the_track_is_where_the_boresight_points_and_breaks_where_the_map_wraps():
    """Boresight 20° above body x; the body turns 300° about z: the boresight runs along Dec 20°
    with RA = θ, crossing RA 180° (the map's edge) once."""
    t = np.linspace(0.0, T, 601)
    theta = np.deg2rad(300.0) * t / T
    row = SimpleNamespace(label="turn", reference=None, simulation=SimpleNamespace(t=t, q=about_z(theta)))
    boresight = np.array([np.cos(np.deg2rad(20)), 0.0, np.sin(np.deg2rad(20))])
    constraint = PointingConstraint("star_keep_out", boresight, True, np.deg2rad(15.0), directions=[[-1.0, 0.0, 0.0]])
    series = sky_series(hand_results([row], [constraint]))
    ra, dec = series.panels[0].closed_loop[0]
    gaps = np.isnan(ra)
    assert gaps.sum() == 1 and np.all(np.isnan(dec[gaps]))
    expected_ra, expected_dec = radec(rz(theta) @ boresight)
    np.testing.assert_allclose(ra[~gaps], expected_ra, atol=1e-9)
    np.testing.assert_allclose(dec[~gaps], expected_dec, atol=1e-9)
    # the oracle agrees with the spherical picture: RA = θ, Dec = 20°
    np.testing.assert_allclose(expected_ra, np.rad2deg(theta) % 360, atol=1e-9)
    np.testing.assert_allclose(expected_dec, 20.0, atol=1e-9)
    figure = sky_figure(series)
    axis = figure.axes[0]
    assert axis.name == "mollweide"
    track = next(line for line in axis.get_lines() if line.get_label() == "turn, closed loop")
    x, y = (np.asarray(v, dtype=float) for v in track.get_data())
    finite = np.isfinite(x)
    # the map: RA grows to the left from the centre RA 0, declination up, radians
    np.testing.assert_allclose(x[finite], -np.deg2rad(((expected_ra + 180) % 360) - 180), atol=1e-9)
    np.testing.assert_allclose(y[finite], np.deg2rad(20.0), atol=1e-9)
    steps = np.diff(x)
    assert np.all(np.abs(steps[np.isfinite(steps)]) < np.pi)  # no segment crosses the map
    assert "declination (deg)" == axis.get_ylabel() and "right ascension (deg)" == axis.get_xlabel()


def test_every_cone_is_drawn_at_its_limit_with_its_centre_path_and_the_earth_disc():
    """A fixed keep-out, and an Earth-limb keep-out whose direction turns 90° about z over the run
    and whose cone grows by a 60° Earth radius."""
    t = np.linspace(0.0, T, 11)
    nadir = np.stack([np.cos(np.pi / 2 * t / T), np.sin(np.pi / 2 * t / T), -0.5 + 0 * t], axis=1)
    limb = PointingConstraint("earth_limb", [1, 0, 0], True, np.deg2rad(10.0), times=t, directions=nadir,
                              growth=np.full(t.size, np.deg2rad(60.0)), description="earth limb")
    fixed = PointingConstraint("sun", [1, 0, 0], True, np.deg2rad(30.0), directions=[[0, 1, 0]])
    series = sky_series(hand_results([dip_row()], [fixed, limb]))
    panel = series.panels[0]
    assert len(series.panels) == 1 and [c.label for c in panel.cones] == ["sun", "earth_limb"]
    sun, earth = panel.cones
    starts = (np.array([0, 1.0, 0]), nadir[0]), (nadir[0], nadir[-1])
    for cone, centres, radius_deg in ((sun, starts[0][:1], 30.0), (earth, starts[1], 70.0)):
        assert len(cone.boundaries) == len(centres)
        for (ra, dec), centre in zip(cone.boundaries, centres):
            keep = np.isfinite(ra)
            a, d = np.deg2rad(ra[keep]), np.deg2rad(dec[keep])
            points = np.stack([np.cos(d) * np.cos(a), np.cos(d) * np.sin(a), np.sin(d)], axis=1)
            angles = np.rad2deg(np.arccos(np.clip(points @ (centre / np.linalg.norm(centre)), -1, 1)))
            np.testing.assert_allclose(angles, radius_deg, atol=1e-6)
    assert len(earth.discs) == 2 and not sun.discs
    for (ra, dec), centre in zip(earth.discs, starts[1]):
        keep = np.isfinite(ra)
        a, d = np.deg2rad(ra[keep]), np.deg2rad(dec[keep])
        points = np.stack([np.cos(d) * np.cos(a), np.cos(d) * np.sin(a), np.sin(d)], axis=1)
        np.testing.assert_allclose(np.rad2deg(np.arccos(points @ (centre / np.linalg.norm(centre)))), 60.0, atol=1e-6)
    # the centre runs through the table's directions, interpolated linearly (then normalised) between rows
    ra, dec = earth.centre
    times = np.linspace(0.0, T, ra.size)
    between = np.stack([np.interp(times, t, nadir[:, i]) for i in range(3)], axis=1)
    expected_ra, expected_dec = radec(between)
    np.testing.assert_allclose(ra, expected_ra, atol=1e-9)
    np.testing.assert_allclose(dec, expected_dec, atol=1e-9)
    assert ra[-1] == pytest.approx(90.0) and dec[-1] == pytest.approx(np.rad2deg(np.arctan(-0.5)))
    figure = sky_figure(series)
    labels = [text.get_text() for text in figure.axes[0].get_legend().get_texts()]
    for label in ("dip, reference", "dip, closed loop", "sun (keep-out)", "earth_limb (keep-out)",
                  "earth_limb (keep-out) at the end", "Earth disc"):
        assert label in labels
    assert {text.get_text().strip() for text in figure.axes[0].texts} >= {"sun", "earth_limb"}


def test_one_sky_panel_per_sensor():
    a = PointingConstraint("a", [1, 0, 0], True, 0.5, directions=[[0, 1, 0]])
    b = PointingConstraint("b", [2, 0, 0], False, 1.0, directions=[[0, 0, 1]])  # the same sensor as a
    c = PointingConstraint("c", [0, 0, 1], True, 0.3, directions=[[1, 0, 0]])
    series = sky_series(hand_results([dip_row()], [a, b, c]))
    assert [[cone.label for cone in p.cones] for p in series.panels] == [["a", "b"], ["c"]]
    assert "[1, 0, 0]" in series.panels[0].title and "[0, 0, 1]" in series.panels[1].title


# ------------------------------------------------------------------------- actuator limit lines

def simulated(spacecraft: Spacecraft, scale: float, samples: int = 200):
    """A made-up simulation of ``spacecraft`` whose actuator commands reach ``scale`` times their
    limit (only drawing is tested)."""
    rng = np.random.default_rng(3)
    t = np.linspace(0.0, 50.0, samples + 1)
    slices, nu = control_layout(spacecraft)
    u = np.zeros((samples, nu))
    wheels, magnetorquers = spacecraft.wheels, spacecraft.magnetorquers
    if wheels is not None:
        u[:, slices["wheels"]] = scale * wheels.max_torque * np.sin(np.linspace(0, 6, samples))[:, None]
        u[:, slices["wheels"]][:, list(wheels.failed)] = 0.0
    if magnetorquers is not None:
        u[:, slices["dipole"]] = scale * magnetorquers.max_dipole * np.cos(np.linspace(0, 6, samples))[:, None]
    n = spacecraft.n_wheels
    momentum = scale * (wheels.max_momentum if wheels is not None else np.zeros(0)) * np.sin(t / 10)[:, None]
    q = about_z(0.01 * t)
    x = np.hstack([q, rng.normal(0, 1e-3, (t.size, 3)), momentum.reshape(t.size, n)])
    simulation = SimpleNamespace(t=t, x=x, q=x[:, :4], omega=x[:, 4:7], wheel_momentum=x[:, 7:], applied_u=u,
                                 applied_torque=rng.normal(0, 0.05 * scale, (samples, 3)))
    return SimpleNamespace(label="row", planner=None, controller="law", reference=None, simulation=simulation)


def limit_values(figure: RowFigure, panel: str) -> list[float]:
    """The y values of the panel's limit lines (each line is horizontal; NaN ones are not drawn)."""
    values = []
    for name, _, _, line in figure.limit_lines:
        y = np.asarray(line.get_ydata(), dtype=float)
        if name == panel and not np.all(np.isnan(y)):
            assert y.size == 2 and y[0] == y[1]
            values.append(float(y[0]))
    return sorted(values)


def drawn(spacecraft, tmp_path, scale=0.8):
    series = row_series(simulated(spacecraft, scale), None, spacecraft)
    figure = RowFigure(*series.shape)
    figure.draw(series, tmp_path / "row.png")
    return figure, series


def panel_label(figure: RowFigure, panel: str) -> str:
    (label,) = [text.get_text() for text in figure.panels[panel].texts if text.get_rotation() == 90]
    return label


def test_wheel_panels_carry_the_wheels_limits_and_mark_the_dead_one(tmp_path):
    wheels = ReactionWheels(np.eye(3), max_torque=0.05, max_momentum=[2.0, 3.0, 4.0], spin_inertia=0.02, failed=[2])
    figure, _ = drawn(Spacecraft([10.0, 12.0, 14.0], wheels=wheels), tmp_path)
    assert limit_values(figure, "wheel_torque") == [-0.05, 0.05]  # one pair: the working wheels share it
    assert limit_values(figure, "wheel_momentum") == [-3.0, -2.0, 2.0, 3.0]  # the dead wheel's 4 N m s is no limit
    rpm = np.array([2.0, 3.0]) / 0.02 * 60 / (2 * np.pi)
    np.testing.assert_allclose(limit_values(figure, "wheel_speed"), sorted([*rpm, *-rpm]))
    # body box of three aligned wheels, z dead: 0.05 N m on x and y, nothing on z
    np.testing.assert_allclose(limit_values(figure, "torque"), [-0.05, -0.05, -0.0, 0.0, 0.05, 0.05], atol=1e-12)
    for panel, unit in (("wheel_torque", "(N m)"), ("wheel_momentum", "(N m s)"), ("wheel_speed", "(rpm)"),
                        ("torque", "(N m)")):
        assert panel_label(figure, panel).endswith(unit)
        low, high = figure.panels[panel].get_ylim()
        assert low <= min(limit_values(figure, panel)) and high >= max(limit_values(figure, panel))  # in view
    dead = [line for line in figure.panels["wheel_momentum"].get_lines() if line.get_label() == "h_w2 failed"]
    assert len(dead) == 1 and dead[0].get_linestyle() == ":"
    legend = [text.get_text() for text in figure.panels["wheel_torque"].get_legend().get_texts()]
    assert "g_w2 failed" in legend and "±limit" in legend
    # the wheel speed is the momentum over the spin inertia
    speed = next(line for line in figure.panels["wheel_speed"].get_lines() if line.get_label() == "Ω_w1")
    momentum = next(line for line in figure.panels["wheel_momentum"].get_lines() if line.get_label() == "h_w1")
    np.testing.assert_allclose(speed.get_ydata(), np.asarray(momentum.get_ydata()) / 0.02 * 60 / (2 * np.pi))


def test_torquer_and_magnetorquer_limits(tmp_path):
    figure, _ = drawn(Spacecraft([10.0, 12.0, 14.0], torquers=Torquers(max_torque=[0.3, 0.5, 0.5])), tmp_path)
    assert limit_values(figure, "torque") == [-0.5, -0.5, -0.3, 0.3, 0.5, 0.5]
    figure, _ = drawn(Spacecraft([10.0, 12.0, 14.0], magnetorquers=Magnetorquers(max_dipole=0.2)), tmp_path)
    assert limit_values(figure, "dipole") == [-0.2, 0.2]
    assert limit_values(figure, "torque") == []  # a magnetorquer's torque depends on the field: no box
    assert panel_label(figure, "dipole") == "dipole (A m²)"


def test_limits_far_beyond_the_curves_leave_the_view_to_the_curves_and_say_so(tmp_path):
    wheels = ReactionWheels(np.eye(3), max_torque=0.05, max_momentum=2.0)
    figure, _ = drawn(Spacecraft([10.0, 12.0, 14.0], wheels=wheels), tmp_path, scale=1e-3)
    _, high = figure.panels["wheel_torque"].get_ylim()
    assert high < 0.05 / 3
    assert figure.off_scale["wheel_torque"].get_text() == "limit ±0.05 beyond the view"


# -------------------------------------------------------------------------------- a normal run

def test_a_run_with_pointing_requirements_writes_the_margin_and_sky_figures(tmp_path):
    import scenarios

    scenario = scenarios.load(REPO / "scenarios" / "collocation_keep_out.yaml")
    scenario.planners = [spec for spec in scenario.planners if spec.name == "eigenaxis"]
    scenario = dataclasses.replace(scenario, problem=dataclasses.replace(scenario.problem, pointing=(KEEP_OUT,)))
    results = scenarios.run(scenario)
    names = [name for name, _ in plot_jobs(results)]
    assert MARGINS_FILE in names and SKY_FILE in names
    results.write(tmp_path / "out")
    for name in (MARGINS_FILE, SKY_FILE):
        with Image.open(tmp_path / "out" / name) as image:
            assert image.format == "PNG" and min(image.size) > 300
    # the eigenaxis slew about z sweeps the tracker through the Sun: its margin reaches -30°
    series = margin_series(results)
    assert series.panels[0].worst_closed_loop[0] == pytest.approx(-30.0, abs=0.5)


def test_a_cone_that_barely_moves_is_drawn_once():
    """The Sun moves 0.04° an hour: over a slew its cone is one circle and its centre one point."""
    t = np.array([0.0, T])
    drift = np.deg2rad(0.01)
    sun = PointingConstraint("sun", [1, 0, 0], True, np.deg2rad(30.0), times=t,
                             directions=[[0, 1, 0], [-np.sin(drift), np.cos(drift), 0]])
    cone = sky_series(hand_results([dip_row()], [sun])).panels[0].cones[0]
    assert len(cone.boundaries) == 1 and len(cone.centre[0]) == 1
    assert cone.centre[0][0] == pytest.approx(90.0) and cone.centre[1][0] == pytest.approx(0.0)
