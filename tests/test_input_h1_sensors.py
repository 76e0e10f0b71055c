"""Absurd sensor and estimator settings: a star tracker noise of degrees, an update rate of kHz or
above the controller's sample rate, a gyro noise hiding any slew's rate warn, naming the YAML path,
the value and what is plausible; values that break the simulation (a covariance or an update count
that overflows, an estimator's process noise that raised OverflowError) are errors of the schema."""
from __future__ import annotations

import copy
import math
from pathlib import Path

import pytest

from scenarios.errors import ScenarioError
from scenarios.schema.loader import parse_scenario
from scenarios.schema.plausibility import plausibility_warnings
from scenarios.schema.read import read_yaml

ROOT = Path(__file__).resolve().parents[1]
pytestmark = pytest.mark.filterwarnings("ignore::scenarios.errors.PlausibilityWarning")
ESTIMATOR = read_yaml(ROOT / "scenarios" / "spin_repoint_estimator.yaml")  # sample_time 1 s, tracker 1 Hz


def scenario(path: str, value):
    data = copy.deepcopy(ESTIMATOR)
    node = data
    *parents, key = path.split(".")
    for name in parents:
        node = node[name]
    node[key] = value
    return data


def said(path: str, value) -> list[str]:
    return [str(warning) for warning in plausibility_warnings(parse_scenario(scenario(path, value)))]


TRACKER = "simulation.sensors.star_tracker"
GYRO = "simulation.sensors.gyro"


def test_a_star_tracker_noise_of_degrees_warns_and_one_beyond_half_a_turn_is_an_error():
    """1 deg is 3,600 arcsec (no tracker that coarse); 180 deg is 648,000 arcsec (no attitude at all;
    1e83 arcsec made the filter's knowledge NaN)."""
    warned = said(f"{TRACKER}.noise_arcsec", [5000, 5, 40])
    assert len(warned) == 1, warned
    assert warned[0].startswith(f"{TRACKER}.noise_arcsec: [5000, 5, 40] arcsec "), warned
    assert "3,600 arcsec (1 deg)" in warned[0] and "plausible" in warned[0], warned
    assert said(f"{TRACKER}.noise_arcsec", [3600, 3600, 3600]) == []  # the bar itself: a degree
    for noise in ([1e9, 1e9, 1e9], [648_001, 5, 5], [1e83, 1e83, 1e83]):
        with pytest.raises(ScenarioError) as raised:
            parse_scenario(scenario(f"{TRACKER}.noise_arcsec", noise))
        assert f"{TRACKER}.noise_arcsec" in str(raised.value) and "648,000 arcsec" in str(raised.value)
    assert said(f"{TRACKER}.noise_arcsec", [648_000, 5, 5])  # at the limit: accepted, warned


def test_a_star_tracker_rate_above_the_sample_rate_or_a_khz_warns_and_an_overflowing_one_is_an_error():
    """sample_time 1 s: 2 Hz asks two updates a sample (one is given); 5 kHz is no tracker. 1e308 Hz
    overflows t * rate at t = 2 s, after which the tracker silently stopped updating."""
    sampled = said(f"{TRACKER}.rate_hz", 2.0)
    assert len(sampled) == 1 and sampled[0].startswith(f"{TRACKER}.rate_hz: 2 Hz "), sampled
    assert "sample rate (1 Hz" in sampled[0] and "khz" not in sampled[0].lower(), sampled
    fast = said(f"{TRACKER}.rate_hz", 5000.0)
    assert len(fast) == 1 and fast[0].startswith(f"{TRACKER}.rate_hz: 5,000 Hz ") and "1,000 Hz" in fast[0], fast
    assert said(f"{TRACKER}.rate_hz", 1.0) == [] and said(f"{TRACKER}.rate_hz", 0.2) == []
    for rate in (1e9, 1e308):
        with pytest.raises(ScenarioError) as raised:
            parse_scenario(scenario(f"{TRACKER}.rate_hz", rate))
        assert f"{TRACKER}.rate_hz" in str(raised.value) and "1e+07" in str(raised.value), str(raised.value)


def test_a_gyro_noise_hiding_any_slews_rate_warns():
    """0.1 rad/s over one second is 0.1 * 180 / pi * 60 = 343.8 deg/sqrt(h)."""
    bar = math.degrees(0.1) * 60.0
    gyro = dict(ESTIMATOR["simulation"]["sensors"]["gyro"])
    warned = said(GYRO, {**gyro, "arw_deg_per_sqrt_h": 1000})
    assert len(warned) == 1 and warned[0].startswith(f"{GYRO}.arw_deg_per_sqrt_h: 1,000 deg/√h "), warned
    assert "0.2909 rad/s" in warned[0] and "344 deg/√h" in warned[0], warned  # 1000 pi / 180 / 60
    assert said(GYRO, {**gyro, "arw_deg_per_sqrt_h": bar * 0.99}) == []
    assert said(GYRO, {**gyro, "arw_deg_per_sqrt_h": 5.0}) == []  # a poor MEMS gyro


@pytest.mark.parametrize("path, value", [
    (f"{GYRO}.arw_deg_per_sqrt_h", 1e300),          # OverflowError in the MEKF's process noise
    (f"{GYRO}.rrw_deg_per_h_per_sqrt_h", 1e300),    # likewise
    (f"{GYRO}.bias_deg_per_h", [1e300, 0, 0]),       # the knowledge error came out NaN
    ("simulation.estimator.initial_bias_sigma_deg_per_h", 1e300),  # OverflowError
])
def test_gyro_and_estimator_values_that_overflow_are_errors_naming_path_and_value(path, value):
    with pytest.raises(ScenarioError) as raised:
        parse_scenario(scenario(path, value))
    message = str(raised.value)
    assert message.startswith(path) and "1e+300" in message and ("<=" in message or "at most" in message), message


NANO = read_yaml(ROOT / "scenarios" / "nano_detumble_noisy.yaml")  # a magnetic field, sensor_noise.magnetic_field 1e-5 T
DEMO = read_yaml(ROOT / "scenarios" / "eigenaxis_demo.yaml")


def said_on(base: dict, path: str, value) -> list[str]:
    data = copy.deepcopy(base)
    node = data
    *parents, key = path.split(".")
    for name in parents:
        node = node.setdefault(name, {})
    node[key] = value
    return [str(warning) for warning in plausibility_warnings(parse_scenario(data))]


def refused_on(base: dict, path: str, value) -> str:
    data = copy.deepcopy(base)
    node = data
    *parents, key = path.split(".")
    for name in parents:
        node = node.setdefault(name, {})
    node[key] = value
    with pytest.raises(ScenarioError) as raised:
        parse_scenario(data)
    assert raised.value.path == path, raised.value
    return raised.value.message


def test_a_magnetometer_noise_beyond_the_field_warns_and_one_beyond_a_tesla_is_an_error_reading_it_in_nt():
    """The Earth's field is at most 6.5e-5 T: 1e-3 T of noise warns; 5 (5 nT written as T) and 1e300
    T (accepted: a 27 s B-dot run on noise alone) are errors, 5 nT being 5e-9 T."""
    path = "simulation.sensor_noise.magnetic_field"
    warned = said_on(NANO, path, 1e-3)
    assert len(warned) == 1 and warned[0].startswith(f"{path}: 0.001 T is up to 0.001 T, above 0.0001 T"), warned
    assert said_on(NANO, path, 5e-8) == []  # 50 nT
    assert refused_on(NANO, path, 5).endswith("if it is in nT, write 5e-09"), refused_on(NANO, path, 5)
    assert refused_on(NANO, path, 1e300).startswith("1e+300 T is beyond 1 T")
    sensors = copy.deepcopy(NANO)
    sensors["simulation"]["sensor_noise"]["magnetic_field"] = 0.0
    for key, value, meant in (("noise_T", 7, "7e-09"), ("bias_T", [100, 0, 0], "[1e-07, 0.0, 0.0]")):
        data = copy.deepcopy(sensors)
        data["simulation"]["sensors"] = {"magnetometer": {key: value}}
        with pytest.raises(ScenarioError) as raised:
            parse_scenario(data)
        assert raised.value.path == f"simulation.sensors.magnetometer.{key}", raised.value
        assert raised.value.message.endswith(f"if it is in nT, write {meant}"), raised.value


def test_an_attitude_noise_coarser_than_any_sensor_warns_and_one_beyond_half_a_turn_is_an_error():
    path = "simulation.sensor_noise.attitude_deg"
    warned = said_on(DEMO, path, 20)
    assert len(warned) == 1 and warned[0].startswith(f"{path}: 20 deg is above 10 deg"), warned
    assert said_on(DEMO, path, 2.0) == []  # a Sun sensor's
    assert refused_on(DEMO, path, 1e300) == "expected a number <= 180, got 1e+300"

