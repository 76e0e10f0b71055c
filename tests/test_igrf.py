"""IGRF field tabulated along the orbit (ocp.dynamics.igrf) against the ppigrf package it is built from.

The oracle is ppigrf itself, called here at orbit positions computed here (the orbit and the
Earth's rotation written out independently of ocp), with the spherical-to-Cartesian conversion
written out again.
"""
import datetime
import textwrap

import numpy as np
import pytest

ppigrf = pytest.importorskip("ppigrf")

import scenarios
from ocp import AttitudeModel, CircularOrbit, Environment, IGRFField, Spacecraft, quat
from ocp.dynamics.igrf import greenwich_mean_sidereal_angle

EPOCH = datetime.datetime(2025, 1, 1)
MU, R_EARTH, EARTH_RATE = 3.986004418e14, 6378.137e3, 7.2921159e-5


def package_field(times, altitude, inclination, raan, u0, gmst0):
    """ppigrf's field (T, inertial axes) along the circular orbit at ``times``."""
    radius = R_EARTH + altitude
    n = np.sqrt(MU / radius**3)
    u = u0 + n * times
    in_plane = np.stack([np.cos(u), np.sin(u), np.zeros_like(u)], axis=1) * radius
    ci, si, co, so = np.cos(inclination), np.sin(inclination), np.cos(raan), np.sin(raan)
    to_inertial = np.array([[co, -so, 0], [so, co, 0], [0, 0, 1]]) @ np.array([[1, 0, 0], [0, ci, -si], [0, si, ci]])
    inertial = in_plane @ to_inertial.T
    theta = gmst0 + EARTH_RATE * times
    c, s = np.cos(theta), np.sin(theta)
    x, y, z = c * inertial[:, 0] + s * inertial[:, 1], -s * inertial[:, 0] + c * inertial[:, 1], inertial[:, 2]
    r = np.sqrt(x * x + y * y + z * z)
    colat, lon = np.arccos(z / r), np.arctan2(y, x)
    b_r, b_t, b_p = (1e-9 * v[0] for v in ppigrf.igrf_gc(r / 1e3, np.rad2deg(colat), np.rad2deg(lon), EPOCH))
    radial = np.stack([np.sin(colat) * np.cos(lon), np.sin(colat) * np.sin(lon), np.cos(colat)], axis=1)
    south = np.stack([np.cos(colat) * np.cos(lon), np.cos(colat) * np.sin(lon), -np.sin(colat)], axis=1)
    east = np.stack([-np.sin(lon), np.cos(lon), np.zeros_like(lon)], axis=1)
    earth_fixed = b_r[:, None] * radial + b_t[:, None] * south + b_p[:, None] * east
    return np.stack([c * earth_fixed[:, 0] - s * earth_fixed[:, 1], s * earth_fixed[:, 0] + c * earth_fixed[:, 1],
                     earth_fixed[:, 2]], axis=1)


def test_gmst_of_j2000_midnight_is_the_almanac_value():
    """GMST at 2000-01-01 0h UT is 6h 39m 52.27s (Astronomical Almanac); to a second of time."""
    almanac = (6 + 39 / 60 + 52.27 / 3600) * np.pi / 12
    assert abs(greenwich_mean_sidereal_angle(datetime.datetime(2000, 1, 1)) - almanac) < np.pi / 43200


@pytest.mark.parametrize("altitude_km, inclination_deg, raan_deg", [(600, 97.79, 0.0), (420, 51.6, 123.0)])
def test_tabulated_igrf_agrees_with_the_package(altitude_km, inclination_deg, raan_deg, rng):
    """1 nT at the nodes, 0.1 % of |B| between them (mid-intervals, where a spline is worst)."""
    orbit = CircularOrbit(altitude_km * 1e3, np.deg2rad(inclination_deg), np.deg2rad(raan_deg), np.deg2rad(20.0))
    field = IGRFField(orbit, span=7000.0, epoch="2025-01-01")
    args = (orbit.altitude, orbit.inclination, orbit.raan, orbit.arg_latitude, greenwich_mean_sidereal_angle(EPOCH))
    nodes = field.nodes[rng.choice(field.nodes.size, 12, replace=False)]
    between = np.sort(rng.uniform(0.0, field.valid_until, 40))
    between[:10] = field.nodes[:10] + 0.5 * field.step  # mid-intervals
    position = orbit.function()
    # The bound between nodes is 0.1 % of |B|; a cubic spline at 30 s nodes achieves ~4e-6, and a
    # linear or shifted table would not, so the test holds the spline to 2e-5 (inside the bound).
    for times, limit in ((nodes, lambda b: 1e-9), (between, lambda b: 2e-5 * np.linalg.norm(b))):
        expected = package_field(times, *args)
        for t, b in zip(times, expected):
            got = field.interpolant(t).full().ravel()
            assert np.linalg.norm(got - b) < limit(b), (t, got, b)
            np.testing.assert_array_equal(field.field_inertial(position(t)[0], t).full().ravel(), got)
    magnitude = np.linalg.norm(expected, axis=1)
    assert 1.5e-5 < magnitude.min() and magnitude.max() < 6.5e-5  # the geomagnetic field at LEO altitudes


def test_body_field_of_the_model_rotates_the_tabulated_field(rng):
    orbit = CircularOrbit(600e3, np.deg2rad(97.79))
    field = IGRFField(orbit, span=3000.0)
    model = AttitudeModel(Spacecraft([0.0109, 0.05, 0.05]), Environment(orbit, magnetic_field=field))
    for _ in range(5):
        q, t = quat.random_unit(rng), float(rng.uniform(0, 3000))
        body = model.field_body(np.r_[q, 0, 0, 0], t).full().ravel()
        np.testing.assert_allclose(quat.rotate(q, body), field.interpolant(t).full().ravel(), rtol=1e-12, atol=1e-20)


SCENARIO = """
name: igrf
spacecraft: {inertia: [0.0109, 0.05, 0.05], wheels: none, magnetorquers: {max_dipole: 0.1}}
orbit: {altitude_km: 600, inclination_deg: 97.79}
environment: {magnetic_field: {model: igrf, epoch: 2025-01-01}}
maneuver:
  duration: 300.0
  initial: {q: [1, 0, 0, 0], omega: [0.1, 0.1, 0.1]}
  final: {q: null, omega: [0, 0, 0]}
planners: []
controllers: [{name: bdot}, {name: tdfc, options: {delay: 2.0}}]
simulation: {sample_time: 0.5}
"""


def test_scenario_with_igrf_runs_and_tables_its_window(tmp_path):
    path = tmp_path / "igrf.yaml"
    path.write_text(textwrap.dedent(SCENARIO))
    scenario = scenarios.load(path)
    field = scenario.problem.environment.magnetic_field
    assert isinstance(field, IGRFField) and field.valid_until >= 300.0
    results = scenarios.run(scenario)
    assert [row.status for row in results.rows] == ["ok", "ok"]
    assert all(row.closed_loop_metrics["energy_ratio"] < 1.0 for row in results.rows)


@pytest.mark.parametrize("change, path, fragment", [
    ("epoch: 2025-01-01", "environment.magnetic_field.epoch", "IGRF-14 covers"),
    ("step_s: 30", "environment.magnetic_field.step_s", "positive"),
])
def test_igrf_errors_name_the_yaml_path(tmp_path, change, path, fragment):
    bad = {"epoch: 2025-01-01": "epoch: 1850-01-01", "step_s: 30": "step_s: -3"}[change]
    text = SCENARIO.replace("{model: igrf, epoch: 2025-01-01}", "{model: igrf, epoch: 2025-01-01, step_s: 30}")
    text = text.replace(change, bad)
    (tmp_path / "bad.yaml").write_text(textwrap.dedent(text))
    with pytest.raises(scenarios.ScenarioError) as error:
        scenarios.load(tmp_path / "bad.yaml")
    assert error.value.path == path and fragment in str(error.value)


def test_run_beyond_the_table_is_a_failed_row(tmp_path):
    text = SCENARIO.replace("{model: igrf, epoch: 2025-01-01}", "{model: igrf, span_s: 100}")
    (tmp_path / "short.yaml").write_text(textwrap.dedent(text))
    results = scenarios.run(scenarios.load(tmp_path / "short.yaml"))
    assert all(row.status == "failed" and "span_s" in row.message for row in results.rows)


def test_the_greenwich_angle_option_is_in_degrees(tmp_path):
    """``greenwich_angle_deg: 90`` puts the Earth-fixed x axis on the inertial y axis at t = 0: the field is
    ppigrf's along the orbit with the Earth turned from π/2 rad (docs: the option is in degrees)."""
    text = SCENARIO.replace("{model: igrf, epoch: 2025-01-01}",
                            "{model: igrf, epoch: 2025-01-01, greenwich_angle_deg: 90, span_s: 200}")
    (tmp_path / "turned.yaml").write_text(textwrap.dedent(text))
    field = scenarios.load(tmp_path / "turned.yaml").problem.environment.magnetic_field
    times = field.nodes[:5]
    expected = package_field(times, 600e3, np.deg2rad(97.79), 0.0, 0.0, np.pi / 2)
    got = np.array([field.interpolant(t).full().ravel() for t in times])
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-9)


@pytest.mark.parametrize("epoch, refused", [("1900-01-01", False), ("2029-12-31", False), ("1899-12-31", True),
                                            ("2030-01-01", True)])
def test_the_epoch_range_is_1900_to_the_end_of_2029(epoch, refused):
    """IGRF-14's coefficients (the 2025 model's secular variation) end at 2030.0: 2030-01-01 is refused."""
    from ocp.dynamics.igrf import parse_epoch
    from ocp.errors import ModelError
    if refused:
        with pytest.raises(ModelError, match="IGRF-14 covers"):
            parse_epoch(epoch)
    else:
        assert parse_epoch(epoch) == datetime.datetime.fromisoformat(epoch)


@pytest.mark.parametrize("span, step", [(100.0, 30.0), (300.0, 30.0), (7000.0, 7.0), (1000.0, 120.0)])
def test_the_table_covers_its_span_with_the_least_whole_steps(span, step):
    """The nodes are 0, step, 2 step, ... up to the first one at or after the span (at least four): the
    window asked for is covered and no more than a step beyond (ceil(span / step) steps, by hand)."""
    field = IGRFField(CircularOrbit(600e3, 1.0), span=span, step=step)
    steps = max(3, int(np.ceil(span / step - 1e-12)))
    np.testing.assert_allclose(field.nodes, step * np.arange(steps + 1), rtol=0, atol=1e-9)
    assert span <= field.valid_until < span + step
