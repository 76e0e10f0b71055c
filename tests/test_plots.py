"""Figures drawn cheaply must be the figures drawn plainly (issue 13): a row drawn on a reused
figure equals the same row drawn on a new one, pixel for pixel, and decimation keeps every peak.

What a review reads off them (issue 31): Euler angles (checked against SciPy's rotations and
against rotations composed by hand), quaternions without sign jumps and on the closed loop's side,
rates in deg/s, one colour per body axis in every panel, and a comparison figure per axis whose
legend lies outside the data and tells near-identical rows apart."""
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from matplotlib.colors import to_hex
from PIL import Image
from scipy.spatial.transform import Rotation

from ocp import ReactionWheels, Spacecraft, quat
from planners.reference import ReferenceSample
from scenarios.errors import ScenarioError
from scenarios.output.plot_data import (
    EULER_SEQUENCE,
    RowSeries,
    continuous_quaternions,
    decimate,
    euler_angles,
    overlay_series,
    plot_jobs,
    row_series,
)
from scenarios.output.plots import LogTicks, RowFigure, overlay_figure
from scenarios.runner import run
from scenarios.schema.loader import parse_scenario
from scenarios.schema.read import read_yaml

ROOT = Path(__file__).resolve().parents[1]


class Reference:
    """A made-up reference (only drawing is tested): attitude about z, its rate and torque."""

    duration = 1e9  # s: longer than any run drawn here (the target is q_f throughout)

    def __init__(self, scale):
        self.scale = scale

    def sample(self, t):
        angle = self.scale * np.sin(0.05 * t)
        q = np.stack([np.cos(angle / 2), 0 * t, 0 * t, np.sin(angle / 2)], axis=1)
        omega = np.stack([0 * t, 0 * t, self.scale * 0.05 * np.cos(0.05 * t)], axis=1)
        return ReferenceSample(q, omega, -0.05 * omega, 0.3 * omega)


def make_row(rng, label, scale, samples=300):
    t = np.linspace(0.0, 150.0, samples + 1)
    reference = Reference(scale)
    ref = reference.sample(t)
    q = quat.normalize(ref.q + rng.normal(0, 1e-3, ref.q.shape))
    x = np.hstack([q, ref.omega + rng.normal(0, 1e-4, (t.size, 3)), rng.normal(0, scale, (t.size, 3))])
    wheel_torque = rng.normal(0, 0.01 * scale, (samples, 3))
    simulation = SimpleNamespace(t=t, x=x, q=x[:, 0:4], omega=x[:, 4:7], wheel_momentum=x[:, 7:],
                                 applied_torque=-wheel_torque, applied_u=wheel_torque)
    return SimpleNamespace(label=label, planner="eigenaxis", controller="augmented_quaternion_feedback",
                           simulation=simulation, reference=reference)


def pixels(path):
    return np.asarray(Image.open(path).convert("RGB"))


def test_a_row_on_a_reused_figure_is_the_row_on_a_new_figure(tmp_path, rng):
    """Every row, not only the second: the static part drawn once must not depend on the row's
    values (the vertical spines' ends do, through the value limits: a corner pixel moved)."""
    target = quat.from_axis_angle([0, 0, 1], 1.0)
    spacecraft = Spacecraft([1.0, 2.0, 3.0], wheels=ReactionWheels(np.eye(3), max_torque=0.02, max_momentum=[1.0, 2.0, 3.0],
                                                                   spin_inertia=1e-3, failed=[1]))
    rows = [make_row(rng, name, scale) for name, scale in (("first", 1.0), ("second", 0.02), ("third", 3.0))]
    shape = row_series(rows[0], target, spacecraft).shape
    reused = RowFigure(*shape)
    for row in rows:  # the limit lines in view for the first and third rows, beyond it for the second
        reused.draw(row_series(row, target, spacecraft), tmp_path / f"{row.label}_reused.png")
        RowFigure(*shape).draw(row_series(row, target, spacecraft), tmp_path / f"{row.label}_new.png")
        np.testing.assert_array_equal(pixels(tmp_path / f"{row.label}_reused.png"),
                                      pixels(tmp_path / f"{row.label}_new.png"))
    assert not np.array_equal(pixels(tmp_path / "first_new.png"), pixels(tmp_path / "second_new.png"))


@pytest.mark.parametrize("n", [10, 1000, 100_003])
def test_decimation_keeps_the_envelope_and_the_ends(n, rng):
    t = np.linspace(0.0, 1.0, n)
    values = np.cumsum(rng.standard_normal((n, 2)), axis=0)
    t_kept, kept = decimate(t, values, 400)
    assert t_kept[0] == t[0] and t_kept[-1] == t[-1] and np.all(np.diff(t_kept) > 0)
    assert kept.shape[1] == 2 and np.all(np.isin(t_kept, t))
    assert kept[:, 0].max() == values[:, 0].max() and kept[:, 0].min() == values[:, 0].min()
    if n > 800:
        assert t_kept.size <= 2 * 400 + 2
        np.testing.assert_array_equal(kept, values[np.searchsorted(t, t_kept)])  # samples, not averages
        size = -(-n // 400)
        for start in range(0, n, size):  # each pixel column keeps its own extremes of the first series
            column = values[start:start + size, 0]
            assert column.max() in kept[:, 0] and column.min() in kept[:, 0]
    else:
        assert t_kept.size == n


SEQUENCES = ["321", "123", "312", "213", "132", "231", "313", "121", "131", "212", "232", "323"]


@pytest.mark.parametrize("sequence", SEQUENCES)
def test_euler_angles_are_scipys_intrinsic_angles(sequence, rng):
    """SciPy's ``as_euler`` with upper-case (intrinsic) axes is the independent oracle: ``R = R_a R_b R_c``."""
    q = quat.normalize(rng.standard_normal((500, 4)))
    expected = Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_euler("".join("XYZ"[int(c) - 1] for c in sequence),
                                                                 degrees=True)
    middle = expected[:, 1]
    away = (middle > 1.0) & (middle < 179.0) if sequence[0] == sequence[2] else np.abs(middle) < 89.0  # no gimbal lock
    for k in np.flatnonzero(away):  # one sample at a time: the series is unwrapped in time
        got = euler_angles(q[k:k + 1], sequence)[0]
        np.testing.assert_allclose((got - expected[k] + 180.0) % 360.0 - 180.0, 0.0, atol=1e-9)


def test_321_angles_of_a_rotation_composed_by_hand_are_unwrapped_and_ignore_the_sign():
    """q = q_z(ψ) ⊗ q_y(θ) ⊗ q_x(φ) with ψ turning twice round: yaw, pitch and roll come back,
    yaw without a 360° jump, whatever the sign of each sample."""
    t = np.linspace(0.0, 1.0, 2001)
    psi, theta, phi = np.deg2rad(720.0 * t - 170.0), np.deg2rad(40.0 * np.sin(3 * t)), np.deg2rad(-25.0 * np.cos(5 * t))
    q = quat.product(quat.product(quat.from_axis_angle([0, 0, 1], psi), quat.from_axis_angle([0, 1, 0], theta)),
                     quat.from_axis_angle([1, 0, 0], phi))
    signs = np.where(np.random.default_rng(3).random(t.size) < 0.5, -1.0, 1.0)[:, None]
    angles = euler_angles(q * signs, "321")
    assert EULER_SEQUENCE == "321"
    np.testing.assert_allclose(angles, np.rad2deg(np.stack([psi, theta, phi], axis=1)), atol=1e-9)


def slew_about_y(samples=301, flip_after=200):
    """A 180° slew about y (the issue's case: q2 goes to 1), the closed loop a little behind and stored
    with its sign flipped from sample ``flip_after`` on; the reference on the other sign throughout."""
    t = np.linspace(0.0, 100.0, samples)
    angle = np.pi * np.clip(t / 80.0, 0, 1)
    reference_q = -np.stack([np.cos(angle / 2), 0 * t, np.sin(angle / 2), 0 * t], axis=1)
    lag = np.pi * np.clip((t - 2.0) / 80.0, 0, 1)
    closed = np.stack([np.cos(lag / 2), 0 * t, np.sin(lag / 2), 0 * t], axis=1)
    closed[flip_after:] *= -1.0
    rate = np.gradient(lag, t)
    omega = np.stack([0 * t, rate, 0 * t], axis=1)

    class Reference:
        duration = 1e9  # s: longer than the run (the target is q_f throughout)

        def sample(self, times):
            return ReferenceSample(reference_q, np.stack([0 * t, np.gradient(angle, t), 0 * t], axis=1), 0 * omega,
                                   0 * omega)

    simulation = SimpleNamespace(t=t, q=closed, omega=omega, wheel_momentum=np.zeros((t.size, 0)),
                                 applied_torque=np.zeros((t.size - 1, 3)), applied_u=np.zeros((t.size - 1, 3)))
    row = SimpleNamespace(label="slew", planner="eigenaxis", controller="pd", simulation=simulation, reference=Reference())
    return row, t, omega


def test_the_quaternions_keep_their_sign_and_the_reference_takes_the_closed_loops_side():
    row, _, omega = slew_about_y()
    series = row_series(row, np.array([0.0, 0.0, 1.0, 0.0]), Spacecraft([1.0, 2.0, 3.0]))
    closed = np.stack([series.quaternion[i][1] for i in range(4)], axis=1)
    reference = np.stack([series.reference[2][i][1] for i in range(4)], axis=1)
    for q in (closed, reference):
        assert np.all(np.einsum("ij,ij->i", q[1:], q[:-1]) > 0.99)  # no jump to -q
    assert closed[0, 0] > 0.99  # starts with its scalar part positive
    assert closed[-1, 2] == pytest.approx(1.0) and reference[-1, 2] == pytest.approx(1.0)  # both end at q2 = +1
    np.testing.assert_allclose(np.abs(closed), np.abs(row.simulation.q), atol=1e-15)  # the same attitudes
    for i in range(3):  # rates in degrees per second
        np.testing.assert_allclose(series.rate[i][1], np.rad2deg(omega[:, i]), rtol=1e-15)


def test_continuous_quaternions_pick_the_side_of_a_given_series(rng):
    q = quat.normalize(np.cumsum(rng.normal(0, 0.05, (400, 4)), axis=0) + [1, 0, 0, 0])
    flipped = q * np.where(rng.random(400) < 0.3, -1.0, 1.0)[:, None]
    np.testing.assert_allclose(continuous_quaternions(flipped), q if q[0, 0] > 0 else -q, atol=1e-15)
    np.testing.assert_allclose(continuous_quaternions(flipped, like=-q), -q, atol=1e-15)


def figure_colors(figure, panel):
    return {line.get_label(): to_hex(line.get_color()) for line in figure.panels[panel].get_lines()}


def test_each_body_axis_has_one_colour_in_every_panel(rng):
    wheels = ReactionWheels(np.eye(3)[:, [2, 0, 1]], max_torque=0.1, max_momentum=1.0, spin_inertia=1e-3)
    row = make_row(rng, "row", 1.0)
    row.simulation.applied_u = row.simulation.applied_u[:, :3]
    figure = RowFigure(*row_series(row, quat.from_axis_angle([0, 0, 1], 1.0), Spacecraft([1.0, 2.0, 3.0], wheels=wheels)).shape)
    torque, rate, quaternion = (figure_colors(figure, p) for p in ("torque", "rate", "quaternion"))
    euler, speed = figure_colors(figure, "euler"), figure_colors(figure, "wheel_speed")
    by_axis = {axis: {torque[f"u_{axis}"], rate[f"ω_{axis}"], quaternion[f"q{k + 1}"]} for k, axis in enumerate("xyz")}
    by_axis["x"] |= {euler["φ roll (x)"], speed["Ω_w1"]}  # wheel 1 spins about x, wheel 2 about y, wheel 0 about z
    by_axis["y"] |= {euler["θ pitch (y)"], speed["Ω_w2"]}
    by_axis["z"] |= {euler["ψ yaw (z)"], speed["Ω_w0"]}
    assert all(len(colors) == 1 for colors in by_axis.values()), by_axis
    assert len(set.union(*by_axis.values()) | {quaternion["q0"]}) == 4
    dipole = RowFigure(0, False, False, dipole=True)  # magnetorquers: the dipole per axis, same colours
    assert [to_hex(line.get_color()) for line in dipole.dipole] == [next(iter(by_axis[a])) for a in "xyz"]


def comparison_results(rng):
    """Three rows on four wheels at skewed axes: two identical, one different."""
    axes = np.array([[1, 0, 0, 1], [0, 1, 0, 1], [0, 0, 1, 1]]) / np.array([1, 1, 1, np.sqrt(3)])
    wheels = ReactionWheels(axes, max_torque=0.1, max_momentum=1.0)
    target = quat.from_axis_angle([0, 0, 1], 1.0)
    same, other = make_row(rng, "A", 1.0), make_row(rng, "C", 0.5)
    rows = [same, SimpleNamespace(**{**vars(same), "label": "B"}), other]
    for row in rows:
        row.simulation.x = np.hstack([row.simulation.x[:, :7], rng.normal(0, 0.1, (row.simulation.t.size, 4))])
        row.simulation.wheel_momentum = row.simulation.x[:, 7:]
    problem = SimpleNamespace(qf=target, omegaf=np.zeros(3), spacecraft=Spacecraft([1.0, 2.0, 3.0], wheels=wheels))
    return SimpleNamespace(scenario=SimpleNamespace(name="three rows", problem=problem), rows=rows), axes, target


def test_the_comparison_overlays_every_row_per_axis_with_its_final_values_beside_the_panels(rng):
    results, axes, target = comparison_results(rng)
    figure = overlay_figure(overlay_series(results))
    figure.canvas.draw()
    rows = {}  # the panels by row of panels (top to bottom), left to right
    for axis in figure.axes:
        rows.setdefault(-round(axis.get_position().y0, 3), []).append(axis)
    rows = [sorted(row, key=lambda a: a.get_position().x0) for _, row in sorted(rows.items())]

    def label(axis):
        return next((t.get_text() for t in axis.texts if t.get_rotation() == 90), "")

    assert [[label(a) for a in row] for row in rows] == [
        ["body rate (deg/s)", "", ""], ["wheel momentum (N m s)", "", ""], ["‖u‖ (N m)", "error to target (deg)"]]
    assert [a.get_title() for a in rows[0]] == ["body x axis", "body y axis", "body z axis"]
    for row in rows[:2]:  # one value scale per quantity, its ticks on the x panel only
        assert len({a.get_ylim() for a in row}) == 1
        assert [len(a.get_yticks()) > 0 for a in row] == [True, False, False]
    # one time span everywhere, its ticks below the per-axis panels and below the norm and the error
    assert len({a.get_xlim() for row in rows for a in row}) == 1
    assert [[a.get_xlabel() for a in row] for row in rows] == [["", "", ""], ["time (s)"] * 3, ["time (s)"] * 2]
    assert all(len(a.get_xticks()) == 0 for a in rows[0])
    for k, row in enumerate(results.rows):
        sim = row.simulation
        body = sim.wheel_momentum @ axes.T  # the wheels' momentum in body axes, by hand
        for i in range(3):
            np.testing.assert_allclose(rows[0][i].get_lines()[k].get_ydata(), np.rad2deg(sim.omega[:, i]))
            np.testing.assert_allclose(rows[1][i].get_lines()[k].get_ydata(), body[:, i])
        torque = np.linalg.norm(sim.applied_torque, axis=1)  # held over each sample
        np.testing.assert_allclose(rows[2][0].get_lines()[k].get_ydata(), np.append(torque, torque[-1]))
    error = rows[2][1]
    legend = figure.legends[0]
    texts = [t.get_text() for t in legend.get_texts()]
    final = np.rad2deg(quat.error_angle(results.rows[2].simulation.q[-1], target))
    assert texts[2].startswith("C\n") and f"final {final:.3g} deg" in texts[2]
    assert texts[0].split("\n", 1)[1] == texts[1].split("\n", 1)[1]  # identical rows: the same final values
    styles = [(to_hex(line.get_color()), line.get_linestyle()) for line in error.get_lines()]
    assert len(set(styles)) == 3  # ... drawn apart
    box = legend.get_window_extent()
    assert all(not box.overlaps(axis.get_window_extent()) for axis in figure.axes)  # beside the data


def test_another_euler_sequence_is_named_in_its_panel(rng):
    row = make_row(rng, "row", 1.0)
    wheels = ReactionWheels(np.eye(3), max_torque=0.1, max_momentum=1.0)
    series = row_series(row, None, Spacecraft([1.0, 2.0, 3.0], wheels=wheels), euler_sequence="313")
    figure = RowFigure(*series.shape)
    (label,) = [t.get_text() for t in figure.panels["euler"].texts if t.get_rotation() == 90]
    assert label == "Euler 3-1-3 (deg)"
    assert [line.get_label() for line in figure.euler] == ["α₁ (z)", "β₂ (x)", "γ₃ (z)"]
    assert to_hex(figure.euler[0].get_color()) != to_hex(figure.euler[2].get_color())  # two angles about z
    with pytest.raises(ValueError, match="Euler sequence"):
        row_series(row, None, Spacecraft([1.0, 2.0, 3.0], wheels=wheels), euler_sequence="331")


@pytest.mark.parametrize("low,high,expected", [
    (1e-9, 100.0, [1e-8, 1e-6, 1e-4, 1e-2, 1.0, 100.0]),  # many decades: at most seven powers of ten
    (1e-3, 100.0, [1e-3, 1e-2, 0.1, 1.0, 10.0, 100.0]),
    (0.15, 0.6, [0.2, 0.5]),  # less than a decade: 1, 2, 5 times a power of ten
    (17.0, 40.0, [18.0, 24.0, 30.0, 36.0]),  # fewer than two of those: evenly spaced
])
def test_a_logarithmic_axis_has_ticks_however_narrow_its_view(low, high, expected):
    ticks = np.asarray(LogTicks().tick_values(low, high))
    np.testing.assert_allclose(ticks[(ticks >= low) & (ticks <= high)], expected)


@pytest.mark.parametrize("written,drawn", [("313", "313"), (321, "321"), (None, "321")])
def test_the_scenarios_euler_sequence_reaches_the_row_figures(written, drawn):
    """``plots.euler_sequence`` (absent: 3-2-1) is the sequence of every row figure's Euler panel,
    whose angles, composed by SciPy as intrinsic rotations, give back the closed loop's attitude
    (valid at gimbal lock too, where the angles themselves are not unique)."""
    data = read_yaml(ROOT / "scenarios" / "eigenaxis_demo.yaml")
    data["planners"] = data["planners"][:1]
    if written is not None:
        data["plots"] = {"euler_sequence": written}
    results = run(parse_scenario(data))
    (row_job,) = [series for _, series in plot_jobs(results) if isinstance(series, RowSeries)]
    assert row_job.euler_sequence == drawn
    assert RowFigure(*row_job.shape).panels["euler"] is not None
    q = results.rows[0].simulation.q
    composed = Rotation.from_euler("".join("XYZ"[int(c) - 1] for c in drawn), euler_angles(q, drawn), degrees=True)
    mismatch = (composed.inv() * Rotation.from_quat(q[:, [1, 2, 3, 0]])).magnitude()
    assert mismatch.max() < 1e-9


@pytest.mark.parametrize("value", ["zyx", "331", 312.5, True, None])
def test_a_bad_euler_sequence_names_its_yaml_path(value):
    data = read_yaml(ROOT / "scenarios" / "eigenaxis_demo.yaml")
    data["plots"] = {"euler_sequence": value}
    with pytest.raises(ScenarioError, match=r"plots\.euler_sequence: expected an Euler sequence, one of \['321'"):
        parse_scenario(data)


def test_png_bytes_is_a_png_of_the_canvas_pixels_with_its_resolution(rng):
    """The PNG writer (unfiltered lines, one deflate) reads back, through Pillow's own decoder, as the
    drawn RGB pixels of a figure and a random image (every byte value, no flat areas), with the dpi."""
    import io

    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from scenarios.output.plot_data import DPI
    from scenarios.output.plots import png_bytes

    figure = Figure(figsize=(3.1, 1.7), dpi=DPI)
    canvas = FigureCanvasAgg(figure)
    figure.subplots().plot([0, 1, 2], [2, 0, 1], label="a")
    canvas.draw()
    drawn = np.asarray(canvas.buffer_rgba())
    noise = rng.integers(0, 256, size=(7, 11, 4), dtype=np.uint8)
    for rgba in (drawn, noise):
        data = png_bytes(rgba)
        assert data[:8] == b"\x89PNG\r\n\x1a\n"
        with Image.open(io.BytesIO(data)) as image:
            image.load()  # decodes every line and checks the chunks' CRCs
            assert image.mode == "RGB" and image.size == (rgba.shape[1], rgba.shape[0])
            assert np.array_equal(np.asarray(image), rgba[..., :3])
            assert image.info["dpi"] == pytest.approx((DPI, DPI), abs=0.01)
