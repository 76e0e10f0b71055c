"""A star tracker blinded by a bright body: no update while the TRUE attitude puts its boresight
within an exclusion angle of the body (``simulation.sensors.star_tracker.exclusion_deg``).

Oracles independent of the code under test: the boresight turned to inertial by SciPy's rotation
of the simulated true attitude, the Sun's direction from the JPL ephemeris (``sun_position``, not
the direction tables the tracker uses), nadir of a circular orbit and the Earth's apparent radius
by hand, and for a uniform slew past a fixed direction the window in closed form.
"""
from __future__ import annotations

import copy
import csv
import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import yaml
from scipy.spatial.transform import Rotation

from controllers import CONTROLLERS
from ocp import Simulator
from ocp.dynamics.ephemeris import moon_position, sun_position
from ocp.estimation import (
    BLINDED,
    Exclusion,
    Gyro,
    Mekf,
    SensorSuite,
    StarTracker,
    draw_sensor_noise,
    initial_sensor_state,
    sensor_step,
)
from ocp.estimation.mekf import unpack
from ocp.metrics import metrics_from_simulation
from planners import PLANNERS
from scenarios.errors import ScenarioError
from scenarios.output.writer import write_timeseries
from scenarios.schema.loader import parse_scenario

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "scenarios" / "spin_repoint_estimator.yaml"
EPOCH = "2025-06-21T00:00:00Z"  # the Sun near the inertial y-z plane the boresight sweeps as body x spins
HALF_ANGLE_DEG = 30.0


def scenario_data(exclusion: dict | None = None, epoch: str | None = EPOCH) -> dict:
    data = yaml.safe_load(EXAMPLE.read_text())
    if epoch is not None:
        data["epoch"] = epoch
    if exclusion is not None:
        data["simulation"]["sensors"]["star_tracker"]["exclusion_deg"] = exclusion
    return data


@pytest.fixture(scope="module")
def blinded_example():
    scenario = parse_scenario(scenario_data({"sun": HALF_ANGLE_DEG}))
    spec = scenario.planners[0]
    return scenario, PLANNERS[spec.name](spec.options).plan(scenario.problem)


def simulate(scenario, reference, sensors=None, duration=120.0, **options):
    spec, problem = scenario.simulation, scenario.problem
    simulator = Simulator(problem.model, spec.sample_time, spec.integrator, max_step=spec.max_step, **options)
    controller = CONTROLLERS[scenario.controller.name](scenario.controller.options)
    return simulator.run(controller, scenario.true_initial_state, duration, reference=reference,
                         target=(problem.qf, problem.omegaf), noise=spec.noise,
                         sensors=spec.sensors if sensors is None else sensors)


def sun_angle_deg(result) -> np.ndarray:
    """Angle between the boresight (body z) and the Sun at each sample t_0 .. t_(N-1), by hand."""
    t = result.t[:-1]
    sun = sun_position(EPOCH, t)
    sun = sun / np.linalg.norm(sun, axis=1, keepdims=True)
    q = result.q[:-1]
    boresight = Rotation.from_quat(q[:, [1, 2, 3, 0]]).apply([0.0, 0.0, 1.0])  # SciPy: scalar last
    return np.degrees(np.arccos(np.clip(np.sum(boresight * sun, axis=1), -1.0, 1.0)))


def attitude_variance(result) -> np.ndarray:
    """Trace of the MEKF covariance's attitude block after each sample [rad²]."""
    return np.array([np.trace(unpack(row[10:31])[0:3, 0:3]) for row in result.sensor_state[1:]])


def test_blinded_samples_are_those_with_the_sun_inside_the_cone(blinded_example):
    scenario, reference = blinded_example
    result = simulate(scenario, reference, python_loop=True)
    angle = sun_angle_deg(result)
    inside = angle < HALF_ANGLE_DEG
    assert np.min(np.abs(angle - HALF_ANGLE_DEG)) > 1e-3  # no sample on the edge: the match is exact
    assert 5 <= np.count_nonzero(inside) <= inside.size - 20  # the spin sweeps the boresight past the Sun
    np.testing.assert_array_equal(result.blinded != 0, inside)
    # the MEKF only propagates there: its attitude variance grows at every blinded sample and falls
    # at the first update after one (the tracker is due every sample but in its 50-60 s outage)
    variance = attitude_variance(result)
    due = scenario.simulation.sensors.star_tracker.available(result.t[:-1])
    for k in np.flatnonzero(inside):
        assert variance[k] > variance[k - 1], k
        after = k + 1
        if after < inside.size and not inside[after] and due[after]:
            assert variance[after] < variance[k], after
    metrics = metrics_from_simulation(result, scenario.problem.qf, reference=reference)
    assert metrics["star_tracker_blinded_s"] == pytest.approx(float(np.count_nonzero(inside)) * 1.0)
    assert metrics["star_tracker_blinded_updates"] == np.count_nonzero(inside & due)


EARTH_RADIUS = 6378137.0  # m (WGS-84)


def circular_orbit(t: np.ndarray, altitude: float, inclination_deg: float, raan_deg: float) -> tuple[np.ndarray, float]:
    """By hand: the inertial position [m] of a circular orbit at ``t`` [s] (at its ascending node at
    t = 0), and its radius [m]: r (cos u, sin u cos i, sin u sin i) turned by the RAAN about z."""
    a = EARTH_RADIUS + altitude
    u = math.sqrt(3.986004418e14 / a**3) * t  # μ [m³/s²]
    inclination, raan = math.radians(inclination_deg), math.radians(raan_deg)
    x, y, z = np.cos(u), np.sin(u) * math.cos(inclination), np.sin(u) * math.sin(inclination)
    return a * np.stack([x * math.cos(raan) - y * math.sin(raan), x * math.sin(raan) + y * math.cos(raan), z],
                        axis=1), a


def test_the_earth_limb_cone_is_the_half_angle_plus_the_earths_apparent_radius(blinded_example):
    """A 500 km circular orbit at 51.6° (ascending node on x, at t = 0): the position by hand,
    nadir, and the cone 20° + asin(R / r) about it (the boresight within 20° of the limb)."""
    _, reference = blinded_example
    data = scenario_data({"earth_limb": 20}, epoch=None)
    data["orbit"] = {"altitude_km": 500.0, "inclination_deg": 51.6}
    scenario = parse_scenario(data)
    result = simulate(scenario, reference, python_loop=True)
    t = result.t[:-1]
    position, a = circular_orbit(t, 500e3, 51.6, 0.0)
    nadir = -position / a
    boresight = Rotation.from_quat(result.q[:-1][:, [1, 2, 3, 0]]).apply([0.0, 0.0, 1.0])
    angle = np.degrees(np.arccos(np.clip(np.sum(boresight * nadir, axis=1), -1.0, 1.0)))
    cone = 20.0 + math.degrees(math.asin(EARTH_RADIUS / a))  # 88.02°
    assert np.min(np.abs(angle - cone)) > 1e-4  # no sample on the edge
    assert 10 <= np.count_nonzero(angle < cone) <= angle.size - 10
    np.testing.assert_array_equal(result.blinded != 0, angle < cone)


def test_the_sun_blinds_the_tracker_in_eclipse_too(blinded_example):
    """The Sun's exclusion makes no shadow test (conservative: a real tracker is not blinded by an
    eclipsed Sun). A 500 km circular orbit at 51.6° with its node at RAAN 270° starts on the
    night side: the spacecraft is in the Earth's cylindrical shadow (by hand: behind the Earth from
    the Sun, nearer the Sun line than the Earth's radius) at every sample, and the tracker is
    blinded exactly where the boresight is within 30° of the Sun seen from there."""
    _, reference = blinded_example
    data = scenario_data({"sun": HALF_ANGLE_DEG})
    data["orbit"] = {"altitude_km": 500.0, "inclination_deg": 51.6, "raan_deg": 270.0}
    scenario = parse_scenario(data)
    result = simulate(scenario, reference, python_loop=True)
    t = result.t[:-1]
    position, _ = circular_orbit(t, 500e3, 51.6, 270.0)
    sun = sun_position(EPOCH, t)
    sun_unit = sun / np.linalg.norm(sun, axis=1, keepdims=True)
    along = np.sum(position * sun_unit, axis=1)
    off_axis = np.linalg.norm(position - along[:, None] * sun_unit, axis=1)
    assert np.all(along < 0) and np.all(off_axis < EARTH_RADIUS)  # in the umbra's cylinder throughout
    seen = sun - position
    seen /= np.linalg.norm(seen, axis=1, keepdims=True)
    boresight = Rotation.from_quat(result.q[:-1][:, [1, 2, 3, 0]]).apply([0.0, 0.0, 1.0])
    angle = np.degrees(np.arccos(np.clip(np.sum(boresight * seen, axis=1), -1.0, 1.0)))
    assert np.min(np.abs(angle - HALF_ANGLE_DEG)) > 1e-3  # no sample on the edge
    assert 5 <= np.count_nonzero(angle < HALF_ANGLE_DEG) <= angle.size - 20
    np.testing.assert_array_equal(result.blinded != 0, angle < HALF_ANGLE_DEG)


def test_without_the_exclusion_nothing_is_blinded(blinded_example):
    scenario, reference = blinded_example
    plain = parse_scenario(scenario_data()).simulation.sensors
    assert plain.star_tracker.exclusions == () and plain.noise_size == 10
    result = simulate(scenario, reference, sensors=plain, python_loop=True)
    assert not np.any(result.blinded)
    metrics = metrics_from_simulation(result, scenario.problem.qf, reference=reference)
    assert metrics["star_tracker_blinded_s"] is None and metrics["star_tracker_blinded_updates"] is None


def test_python_interpreted_and_compiled_loops_blind_the_same_samples(blinded_example, tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    scenario, reference = blinded_example
    python = simulate(scenario, reference, duration=200.0, python_loop=True)
    interpreted = simulate(scenario, reference, duration=200.0)
    compiled = simulate(scenario, reference, duration=200.0, compile=True)
    assert (python.path, interpreted.path) == ("python", "interpreted") and compiled.path in ("compiled", "interpreted")
    assert np.count_nonzero(python.blinded) >= 10
    for other in (interpreted, compiled):
        np.testing.assert_array_equal(other.blinded, python.blinded)
        np.testing.assert_allclose(other.sensor_state, python.sensor_state, rtol=0, atol=1e-9)
        np.testing.assert_allclose(other.x, python.x, rtol=0, atol=1e-9)


OBLIQUE = [0.6, 0.64, -0.48]  # a unit vector off every body axis


def to_inertial(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Body vectors ``v`` turned to inertial by scalar-first Hamilton quaternions ``q`` (body to
    inertial), ``q ⊗ (0, v) ⊗ q*`` written out: ``v + 2 w (r × v) + 2 r × (r × v)``."""
    w, r = q[:, :1], q[:, 1:]
    c = np.cross(r, v)
    return v + 2.0 * w * c + 2.0 * np.cross(r, c)


def body_angle_deg(result, boresight, position) -> np.ndarray:
    """Angle between ``boresight`` (body axes) and a body (``position(EPOCH, t)``, geocentric) at
    each sample t_0 .. t_(N-1), by hand."""
    t = result.t[:-1]
    body = position(EPOCH, t)
    body = body / np.linalg.norm(body, axis=1, keepdims=True)
    b = np.tile(np.asarray(boresight, dtype=float) / np.linalg.norm(boresight), (t.size, 1))
    return np.degrees(np.arccos(np.clip(np.sum(to_inertial(result.q[:-1], b) * body, axis=1), -1.0, 1.0)))


def with_boresight(exclusion: dict, boresight: list) -> dict:
    data = scenario_data(exclusion)
    data["simulation"]["sensors"]["star_tracker"]["boresight"] = boresight
    return data


@pytest.mark.parametrize("boresight", [[0.0, 1.0, 0.0], OBLIQUE], ids=["body y", "oblique"])
def test_a_boresight_off_body_z_is_blinded_where_it_is_near_the_sun(blinded_example, boresight, tmp_path,
                                                                    monkeypatch):
    """The Python loop and the compiled closed loop blind the samples where the boresight, turned
    by the true attitude, is within 30° of the Sun, and not those of body z."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    _, reference = blinded_example
    scenario = parse_scenario(with_boresight({"sun": HALF_ANGLE_DEG}, boresight))
    python = simulate(scenario, reference, python_loop=True)
    compiled = simulate(scenario, reference, compile=True)
    assert compiled.path in ("compiled", "interpreted")
    angle = body_angle_deg(python, boresight, sun_position)
    inside = angle < HALF_ANGLE_DEG
    assert np.min(np.abs(angle - HALF_ANGLE_DEG)) > 1e-3  # no sample on the edge
    assert 5 <= np.count_nonzero(inside) <= inside.size - 20
    body_z = body_angle_deg(python, [0.0, 0.0, 1.0], sun_position) < HALF_ANGLE_DEG
    assert np.count_nonzero(body_z != inside) >= 5  # the boresight matters
    np.testing.assert_array_equal(python.blinded, inside.astype(np.int64))
    np.testing.assert_array_equal(compiled.blinded, inside.astype(np.int64))
    np.testing.assert_allclose(compiled.x, python.x, rtol=0, atol=1e-9)


def test_the_timeseries_has_the_blinded_bits_in_the_order_written(blinded_example, tmp_path):
    """``exclusion_deg: {moon: 25, sun: 30}``: bit 0 is the Moon's, bit 1 the Sun's, in
    ``SimulationResult.blinded`` and in the ``blinded`` column of the time series (integers, blank
    at the final time)."""
    _, reference = blinded_example
    scenario = parse_scenario(with_boresight({"moon": 25.0, "sun": HALF_ANGLE_DEG}, OBLIQUE))
    result = simulate(scenario, reference, python_loop=True)
    moon, sun = body_angle_deg(result, OBLIQUE, moon_position), body_angle_deg(result, OBLIQUE, sun_position)
    assert np.min(np.abs(moon - 25.0)) > 1e-3 and np.min(np.abs(sun - HALF_ANGLE_DEG)) > 1e-3
    moon_bit, sun_bit = moon < 25.0, sun < HALF_ANGLE_DEG
    assert np.any(moon_bit & ~sun_bit) and np.any(sun_bit & ~moon_bit)  # the bits tell them apart
    expected = 1 * moon_bit + 2 * sun_bit
    np.testing.assert_array_equal(result.blinded, expected)
    path = tmp_path / "row.csv"
    write_timeseries(SimpleNamespace(label="row", simulation=result, reference=reference), path)  # type: ignore[arg-type]
    with path.open(newline="") as handle:
        lines = list(csv.reader(handle))
    assert lines[0][-6:] == ["known_q0", "known_q1", "known_q2", "known_q3", "knowledge_error_deg", "blinded"]
    assert [line[-1] for line in lines[1:]] == [str(bit) for bit in expected] + [""]
    assert all(len(line) == len(lines[0]) for line in lines)
    assert float(lines[1 + np.argmax(sun_bit)][0]) == result.t[np.argmax(sun_bit)]  # the bits at their times


SLEW_RATE = 0.01  # rad/s about body x = inertial x: body z goes to (0, -sin θ, cos θ), θ = SLEW_RATE t
DIRECTION = np.array([0.0, -1.0, 0.0])  # the boresight meets it at θ = 90°


def slew_attitude(t: float) -> np.ndarray:
    return np.array([math.cos(0.5 * SLEW_RATE * t), math.sin(0.5 * SLEW_RATE * t), 0.0, 0.0])


def run_slew(exclusions: tuple) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The NumPy sensor step over a uniform slew (300 samples of 1 s): the exclusion bits, the
    MEKF's attitude variance and its attitude error [deg] after each sample."""
    gyro = Gyro(arw=math.radians(1.0) / 60.0, rrw=math.radians(1.0) / 3600.0 / 60.0,
                bias=np.radians([0.1, -0.05, 0.08]) / 3600.0)
    tracker = StarTracker(noise=np.radians([5.0, 5.0, 40.0]) / 3600.0, exclusions=exclusions)
    suite = SensorSuite(gyro, tracker, None, Mekf(math.radians(0.1), math.radians(5.0) / 3600.0))
    times = np.arange(301.0)
    noise = draw_sensor_noise(suite, 11, times)
    s = initial_sensor_state(suite, slew_attitude(0.0), 11)
    bits, variance, error = [], [], []
    for k in range(300):
        q = slew_attitude(times[k])
        q_hat, _, _, s = sensor_step(suite, s, q, np.array([SLEW_RATE, 0.0, 0.0]), None, noise[k], 1.0)
        bits.append(s[BLINDED])
        variance.append(np.trace(unpack(s[10:31])[0:3, 0:3]))
        error.append(np.degrees((Rotation.from_quat(q[[1, 2, 3, 0]]).inv()
                                 * Rotation.from_quat(q_hat[[1, 2, 3, 0]])).magnitude()))
    return np.array(bits), np.array(variance), np.array(error)


def test_a_slew_past_a_body_blinds_the_closed_form_window_and_the_estimate_drifts():
    """Blinded while θ = 0.01 t is within 30° of 90°: 60° < θ < 120°, t in (104.7, 209.4) s. The
    MEKF then propagates on a 1 deg/√h gyro: its variance grows at every blinded sample and its
    error, tens of arcsec while updated, grows past five times the unblinded run's."""
    bits, variance, error = run_slew((Exclusion("sun", math.radians(30.0), DIRECTION),))
    t = np.arange(300.0)
    window = (t > math.radians(60.0) / SLEW_RATE) & (t < math.radians(120.0) / SLEW_RATE)
    np.testing.assert_array_equal(bits != 0, window)
    inside = np.flatnonzero(window)
    assert np.all(np.diff(variance[inside]) > 0) and variance[inside[0]] > variance[inside[0] - 1]
    assert variance[inside[-1] + 1] < 0.01 * variance[inside[-1]]  # the first update after it
    clear_bits, clear_variance, clear_error = run_slew(())
    assert not np.any(clear_bits)
    assert np.max(clear_variance[inside]) < 0.01 * variance[inside[-1]]
    # gyro-only over the 104 s window: σ ≈ ARW √t = 1/60 deg/√s × √104 s ≈ 0.17 deg per axis
    assert error[inside[-1]] > 5.0 * np.max(clear_error[inside])
    assert error[inside[-1]] < 4.0 * np.degrees(math.sqrt(variance[inside[-1]]))  # and as the filter says
    # updated every sample, the error stays within 4 σ of the tracker's noise (5, 5, 40 arcsec)
    assert np.max(clear_error[50:]) < 4.0 * math.sqrt(5.0**2 + 5.0**2 + 40.0**2) / 3600.0


def test_an_exclusion_adds_the_bodys_growth_to_its_half_angle():
    """A table with growth (the Earth's apparent radius for ``earth_limb``): the cone's cosine is
    cos(half-angle + growth), capped at π."""
    exclusion = Exclusion("earth_limb", math.radians(20.0),
                          lambda times: (np.tile([0.0, 0.0, 2.0], (len(times), 1)), np.radians([60.0, 170.0])))
    directions, cosines = exclusion.table(np.array([0.0, 1.0]))
    np.testing.assert_allclose(directions, [[0, 0, 1], [0, 0, 1]])
    np.testing.assert_allclose(cosines, [math.cos(math.radians(80.0)), -1.0], atol=1e-15)


BAD = {
    "a negative angle": ({"sun": -5}, EPOCH, "simulation.sensors.star_tracker.exclusion_deg.sun", "non-negative"),
    "over 180 deg": ({"moon": 190}, EPOCH, "simulation.sensors.star_tracker.exclusion_deg.moon", "<= 180"),
    "not a number": ({"sun": "wide"}, EPOCH, "simulation.sensors.star_tracker.exclusion_deg.sun", "number"),
    "an unknown body": ({"jupiter": 5}, EPOCH, "simulation.sensors.star_tracker.exclusion_deg.jupiter",
                        "unknown key; expected one of ['earth_limb', 'moon', 'sun']"),
    "a cone about nadir": ({"earth": 30}, EPOCH, "simulation.sensors.star_tracker.exclusion_deg.earth",
                           "expected one of ['earth_limb', 'moon', 'sun']"),  # 30 deg of nadir: on the disc, unblinded
    "not a mapping": ([30], EPOCH, "simulation.sensors.star_tracker.exclusion_deg", "mapping"),
    "the Sun without an epoch": ({"sun": 30}, None, "simulation.sensors.star_tracker.exclusion_deg.sun", "epoch"),
    "the Earth's limb without an orbit": ({"earth_limb": 20}, EPOCH,
                                          "simulation.sensors.star_tracker.exclusion_deg.earth_limb", "orbit"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_exclusions_name_the_yaml_path(case):
    exclusion, epoch, path, words = BAD[case]
    with pytest.raises(ScenarioError) as raised:
        parse_scenario(copy.deepcopy(scenario_data(exclusion, epoch)))
    assert path in str(raised.value) and words in str(raised.value)


def test_the_tracker_refuses_bad_exclusions_in_python():
    with pytest.raises(ValueError, match="half-angle"):
        Exclusion("sun", 4.0, DIRECTION)
    with pytest.raises(ValueError, match="distinct"):
        StarTracker(noise=[1e-5] * 3, exclusions=(Exclusion("sun", 0.5, DIRECTION),) * 2)
