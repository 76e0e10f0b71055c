"""Plausibility warnings: values the schema accepts that look like a unit slip, each named by its
YAML path, its value and the physical reason, printed by ``validate`` (a finding under
``--strict``) and ``run``; none on any shipped scenario or study case."""
from __future__ import annotations

import copy
import re
from pathlib import Path

import numpy as np
import pytest
import yaml

from scenarios.cli.commands import main
from scenarios.schema.loader import OTHER_FILES, load, parse_scenario
from scenarios.schema.plausibility import plausibility_warnings
from scenarios.schema.read import read_yaml
from scenarios.study.spec import load_study

ROOT = Path(__file__).resolve().parents[1]
CUBESAT = read_yaml(ROOT / "scenarios" / "cubesat_12u_sun_keep_out.yaml")  # 500 km, I_min 0.12 kg m², 3 mN m wheels


def shipped() -> list[Path]:
    return sorted([*(ROOT / "scenarios").glob("*.yaml"), *(ROOT / "scenarios" / "bench").rglob("*.yaml")])


@pytest.mark.parametrize("path", shipped(), ids=lambda path: str(path.relative_to(ROOT)))
def test_no_shipped_scenario_or_study_case_warns(path):
    data = read_yaml(path)
    if "study" in data:
        scenarios = [parse_scenario(case.scenario) for case in load_study(path).cases]
    elif any(key in data for key in OTHER_FILES) or "maneuver" not in data:
        pytest.skip("not a scenario or a study (the bench suite)")
    else:
        scenarios = [load(path)]
    assert scenarios
    for scenario in scenarios:
        assert plausibility_warnings(scenario) == []


def warnings_of(change) -> list[str]:
    data = copy.deepcopy(CUBESAT)
    change(data)
    return [str(warning) for warning in plausibility_warnings(parse_scenario(data))]


def test_an_altitude_beyond_the_moon_names_path_value_reason_and_the_value_meant():
    said = warnings_of(lambda d: d["orbit"].update(altitude_km=500000))
    assert len(said) == 1, said
    assert said[0].startswith("orbit.altitude_km: 500000 km ")
    assert "beyond the Moon's distance (384,400 km)" in said[0] and "did you mean 500 " in said[0], said


def test_an_elliptic_orbits_apogee_counts_and_a_perigee_under_100_km_warns():
    def elliptic(apogee_beyond: bool):
        def change(d):
            d["orbit"] = {"type": "keplerian", "semi_major_axis_km": 250000.0 if apogee_beyond else 200000.0,
                          "eccentricity": 0.6 if apogee_beyond else 0.5}
        return change
    beyond = warnings_of(elliptic(True))  # apogee 250,000 x 1.6 - 6,378 = 393,622 km: beyond the Moon
    assert len(beyond) == 1 and "apogee altitude" in beyond[0] and "Moon" in beyond[0], beyond
    assert warnings_of(elliptic(False)) == []  # apogee 293,622 km, perigee 93,622 km
    low = warnings_of(lambda d: d["orbit"].update(altitude_km=80))
    assert len(low) == 1 and low[0].startswith("orbit.altitude_km: 80 km") and "Kármán" in low[0], low
    assert warnings_of(lambda d: d["orbit"].update(altitude_km=120)) == []


@pytest.mark.parametrize("path", ["maneuver.max_rate", "requirements.rate.max"])
def test_a_rate_bound_in_degrees_per_second_warns(path):
    def change(d):
        section, *inner, key = path.split(".")
        node = d.setdefault(section, {})
        for name in inner:
            node = node.setdefault(name, {})
        node[key] = 3.0
    said = warnings_of(change)
    assert len(said) == 1 and said[0].startswith(f"{path}: 3 rad/s is 172 deg/s"), said
    assert "did you mean 0.05236 rad/s" in said[0], said
    loose = 0.9  # just under 1 rad/s: no warning
    assert warnings_of(lambda d: d["maneuver"].update(max_rate=loose)) == []


def test_a_rate_noise_in_degrees_per_second_warns():
    """``simulation.sensor_noise.rate`` is rad/s (1 sigma): 2 (deg/s meant) fed the controller 115 deg/s
    of noise with no word; a gyro-class noise (1e-4 rad/s) and one just under 0.1 rad/s pass."""
    def noise(value):
        return lambda d: d.setdefault("simulation", {}).update(sensor_noise={"rate": value, "seed": 1})
    said = warnings_of(noise(2.0))
    assert len(said) == 1 and said[0].startswith("simulation.sensor_noise.rate: 2 rad/s is 115 deg/s"), said
    assert "at or above 0.1 rad/s" in said[0] and "did you mean 0.03491 rad/s (2 deg/s)?" in said[0], said
    assert warnings_of(noise(1e-4)) == [] and warnings_of(noise(0.099)) == []


def _rate_error(error, max_torque=None):
    def change(d):
        d.setdefault("simulation", {})["initial_rate_error"] = error
        if max_torque is not None:
            d["spacecraft"]["wheels"]["max_torque"] = max_torque
    return change


def test_an_initial_rate_error_in_degrees_per_second_warns():
    """``simulation.initial_rate_error`` is rad/s: 5 (deg/s meant) started every closed loop at
    286 deg/s with no word, while a rate noise of 2 warned. The oracle: 5 deg/s = 0.0872665 rad/s."""
    said = warnings_of(_rate_error([0, 5, 0]))
    assert len(said) == 1, said
    assert said[0].startswith("simulation.initial_rate_error: [0.0, 5.0, 0.0] rad/s has ‖δω‖ = 5 rad/s "
                              "(286.5 deg/s), at or above 0.1 rad/s"), said
    assert "did you mean [0.0, 0.087266, 0.0] rad/s (deg/s written as rad/s)?" in said[0], said
    # the CubeSat's wheels take out 3.03 rad/s in the 70 s window: just under the bar, and the
    # shipped scenarios' 0.002 rad/s, pass
    assert warnings_of(_rate_error([0.099, 0, 0])) == [] and warnings_of(_rate_error([0.0, 0.002, -0.002])) == []


def test_an_initial_rate_error_the_actuators_cannot_remove_in_the_window_warns():
    """Below the 0.1 rad/s bar, an error larger than the actuators can take out within the
    closed-loop window. The oracle, by hand: 10 µN m per body axis on the least moment 0.12 kg m²
    give at most ‖(1, 1, 1)‖ 1e-5 / 0.12 = 1.443e-4 rad/s², 0.0101 rad/s over simulation.duration (70 s)."""
    reach = np.sqrt(3) * 1e-5 / 0.12 * 70.0
    said = warnings_of(_rate_error([0.05, 0, 0], max_torque=1e-5))
    assert len(said) == 1 and said[0].startswith("simulation.initial_rate_error: [0.05, 0.0, 0.0] rad/s"), said
    assert f"within the closed-loop window (0.000144 rad/s² at most about the least principal axis for 70 s: " \
           f"{reach:.3g} rad/s), so no row's closed loop removes it" in said[0], said
    assert "did you mean" not in said[0], said  # no unit slip below the bar
    assert warnings_of(_rate_error([0.0, 0.95 * reach, 0.0], max_torque=1e-5)) == []
    assert len(warnings_of(_rate_error([0.0, 1.05 * reach, 0.0], max_torque=1e-5))) == 1


def test_an_initial_rate_error_with_magnetorquers_alone_is_judged_by_the_bar_only():
    data = read_yaml(ROOT / "scenarios" / "nano_detumble.yaml")  # no stated torque bound: the field decides
    data.setdefault("simulation", {})["initial_rate_error"] = [0.05, 0.0, 0.0]
    assert plausibility_warnings(parse_scenario(data)) == []
    data["simulation"]["initial_rate_error"] = [0.0, 0.0, -0.2]
    said = [str(w) for w in plausibility_warnings(parse_scenario(data))]
    assert len(said) == 1 and "at or above 0.1 rad/s" in said[0] and "closed-loop window" not in said[0], said


def test_a_boundary_rate_the_actuators_cannot_reach_warns_and_a_reachable_spin_does_not():
    said = warnings_of(lambda d: d["maneuver"]["initial"].update(omega=[0.0, 0.0, 3.0]))
    assert len(said) == 1 and said[0].startswith("maneuver.initial.omega: [0.0, 0.0, 3.0] rad/s"), said
    assert "0.05236" in said[0], said

    def strong(d):  # 0.3 N m per axis on 0.12 kg m²: 4.3 rad/s² peak, 3 rad/s reached in 60 s
        d["spacecraft"]["wheels"] = None
        d["spacecraft"]["torquers"] = {"max_torque": 0.3}
        d["maneuver"]["initial"]["omega"] = [0.0, 0.0, 3.0]
    assert warnings_of(strong) == []


def test_a_torque_in_millinewton_metres_written_as_newton_metres_warns():
    said = warnings_of(lambda d: d["spacecraft"]["wheels"].update(max_torque=3))  # 25 rad/s² on 0.12 kg m²
    assert len(said) == 1 and said[0].startswith("spacecraft.wheels.max_torque: 3 N m"), said
    assert "25 rad/s²" in said[0] and "did you mean 0.003 N m" in said[0], said
    assert warnings_of(lambda d: d["spacecraft"]["wheels"].update(max_torque=0.5)) == []  # 4.2 rad/s²


BILIMORIA_WIE = read_yaml(ROOT / "scenarios" / "bench" / "problems" / "bilimoria_wie_180.yaml")
# unit inertia, 1 N m per body axis (torquers alone), 180 deg about x, rest to rest; windows 10 s and 4 s


def slew_warnings(scale: float, change=None) -> list[str]:
    """The warnings of the Bilimoria-Wie slew with its inertia ``scale`` times as large."""
    data = copy.deepcopy(BILIMORIA_WIE)
    data["spacecraft"]["inertia"] = [scale] * 3
    if change is not None:
        change(data)
    return [str(warning) for warning in plausibility_warnings(parse_scenario(data))]


def test_an_inertia_far_too_large_for_its_torque_warns_at_ten_times_the_window():
    """By hand: the torque box (1, 1, 1) N m has the norm √3, so the unit inertia scaled by ``k``
    turns at √3 / k rad/s² at most, and the 180 deg slew takes at least 2 √(π k / √3) s; the window
    is maneuver.duration, 10 s (longer than simulation.duration, 4 s), and ten times it is 100 s:
    k = 1400 gives 100.78 s (warns), k = 1350 gives 98.97 s (does not)."""
    said = slew_warnings(1400.0)
    assert len(said) == 1, said
    assert said[0].startswith("spacecraft.inertia: [1400.0, 1400.0, 1400.0] kg m² (least principal moment 1400 "), said
    assert "‖τ‖ = 1.73 N m" in said[0] and "180 deg rest-to-rest slew takes at least 101 s" in said[0], said
    assert "10 times maneuver.duration (10 s, the manoeuvre's time budget)" in said[0] and "is the inertia in kg m²" in said[0], said
    assert slew_warnings(1350.0) == []


def test_the_slews_window_is_the_budget_not_the_simulation():
    """maneuver.duration is every planner's time budget: a longer simulation.duration changes
    nothing (it did: 20 s moved the bar to 200 s, k = 5513)."""
    def longer(d):
        d["simulation"]["duration"] = 20.0
    said = slew_warnings(1400.0, longer)
    assert len(said) == 1 and "10 times maneuver.duration (10 s, the manoeuvre's time budget)" in said[0], said
    assert "simulation.duration" not in said[0]
    assert slew_warnings(1350.0, longer) == []


def test_the_slow_slew_warning_says_what_the_rows_become_not_that_they_fail():
    said = slew_warnings(1400.0)
    assert "fails" not in said[0], said
    assert ("no slew within it stays within the actuators' torque bound: a planner that takes its own time ends "
            "after the budget (its row infeasible)") in said[0], said


DEMO = read_yaml(ROOT / "scenarios" / "eigenaxis_demo.yaml")


def demo_warnings(scale: float) -> list[str]:
    data = copy.deepcopy(DEMO)
    data["spacecraft"]["inertia"] = [v * scale for v in data["spacecraft"]["inertia"]]
    return [str(warning) for warning in plausibility_warnings(parse_scenario(data))]


def test_eigenaxis_demo_warns_from_the_factor_the_guide_states():
    """By hand: least moment 12.6 kg m², wheels 0.1 N m on the body axes (‖τ‖ = 0.1 √3), 90 deg:
    2 √(π/2 x 12.6 / 0.1732) = 21.379 s, 0.178 of the 120 s budget; k x the inertia warns when
    21.379 √k > 1200 s, k > 3150.45. A hundred times (213.8 s) does not."""
    assert demo_warnings(100.0) == []
    assert demo_warnings(3150.0) == []
    said = demo_warnings(3151.0)
    assert len(said) == 1 and said[0].startswith("spacecraft.inertia: ") and "10 times maneuver.duration (120 s" in said[0]
    text = re.sub(r"\s+", " ", (ROOT / "docs" / "guide" / "scenarios.rst").read_text())
    assert "``eigenaxis_demo`` (21.4 s of 120 s) warns from ``k`` = 3,151" in text
    assert "none warns below ``k`` = 625" in text


def test_a_cubesat_inertia_in_gram_square_millimetres_warns_and_one_ten_times_off_does_not():
    def scaled(factor):
        return lambda d: d["spacecraft"].update(inertia=[v * factor for v in d["spacecraft"]["inertia"]])
    said = warnings_of(scaled(1e7))
    assert len(said) == 1 and said[0].startswith("spacecraft.inertia: ") and "its row infeasible" in said[0]
    assert warnings_of(scaled(10.0)) == []


def test_a_slew_not_from_rest_to_rest_and_an_unbounded_torque_are_not_judged():
    def tumbling(d):
        d["maneuver"]["initial"]["omega"] = [0.0, 0.0, 0.01]
    assert slew_warnings(1e6, tumbling) == []

    def unbounded(d):
        d["spacecraft"]["torquers"] = {}  # no max_torque: unbounded (a min-energy plan needs no bound)
        d["planners"] = [{"name": "collocation", "options": {"objective": "min_energy"}}]
    assert slew_warnings(1e6, unbounded) == []


def write(tmp_path: Path, data: dict) -> str:
    path = tmp_path / "slip.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return str(path)


def test_validate_prints_them_and_strict_counts_them(tmp_path, capsys):
    data = copy.deepcopy(CUBESAT)
    data["orbit"]["altitude_km"] = 500000
    path = write(tmp_path, data)
    assert main(["validate", path]) == 0
    assert "  warning: orbit.altitude_km: 500000 km" in capsys.readouterr().out
    assert main(["validate", path, "--strict"]) == 1
    captured = capsys.readouterr()
    assert "warning: orbit.altitude_km" in captured.out and "--strict: 1 plausibility warning(s)" in captured.err
    assert main(["validate", write(tmp_path, CUBESAT), "--strict"]) == 0
    assert "warning" not in capsys.readouterr().out


def test_run_prints_them_on_stderr_and_runs(tmp_path, capsys):
    data = read_yaml(ROOT / "scenarios" / "eigenaxis_demo.yaml")
    data["planners"] = data["planners"][:1]
    data["maneuver"]["max_rate"] = 2.0
    assert main(["run", write(tmp_path, data), "--out", str(tmp_path / "out"), "--no-plots"]) == 0
    err = capsys.readouterr().err
    assert "slewbench: warning: maneuver.max_rate: 2 rad/s is 115 deg/s" in err, err
    assert (tmp_path / "out" / "results.json").exists()


def test_validate_names_the_study_case_whose_value_looks_like_a_slip(tmp_path, capsys):
    path = tmp_path / "study.yaml"
    path.write_text(yaml.safe_dump({"study": "altitudes", "scenario": CUBESAT,
                                    "grid": {"orbit.altitude_km": [500, 500000]}}, sort_keys=False))
    assert main(["validate", str(path)]) == 0
    out = capsys.readouterr().out
    assert "case 1 [orbit.altitude_km=500000]: warning: orbit.altitude_km: 500000 km" in out, out
    assert "case 0" not in out
    assert main(["validate", str(path), "--strict"]) == 1


def test_the_moons_distance_is_compared_with_the_distance_from_the_earths_centre():
    """A reviewer: the apogee's altitude was compared with the Moon's distance from the centre."""
    def circular(altitude_km):
        return lambda d: d["orbit"].update(altitude_km=altitude_km)
    assert warnings_of(circular(384_400 - 6_378.137 - 100)) == []  # 100 km inside the Moon's distance
    assert len(warnings_of(circular(384_400 - 6_378.137 + 100))) == 1  # 100 km beyond it


def test_a_fast_tumble_with_magnetorquers_alone_is_not_judged():
    """A legitimate detumble of a nanosatellite spinning at 60 deg/s about each axis warned "0 rad/s²":
    a magnetorquer's torque depends on the field, so there is no bound to judge the rate against."""
    data = read_yaml(ROOT / "scenarios" / "nano_detumble.yaml")
    data["maneuver"]["initial"]["omega"] = [0.6, 0.6, 0.6]  # 1.04 rad/s in norm
    assert plausibility_warnings(parse_scenario(data)) == []


def test_a_rate_beyond_what_wheels_alone_can_store_warns():
    """A reviewer: 2 rad/s on the 12U CubeSat (2 deg/s meant) was not flagged, though its momentum
    is many times what the wheels store; the torque check alone let it through."""
    said = warnings_of(lambda d: d["maneuver"]["initial"].update(omega=[2.0, 0.0, 0.0]))
    assert len(said) == 1 and said[0].startswith("maneuver.initial.omega: [2.0, 0.0, 0.0] rad/s"), said
    assert "more than the wheels alone can take" in said[0] and "did you mean [0.034907, 0.0, 0.0]" in said[0], said
    data = copy.deepcopy(CUBESAT)
    inertia = parse_scenario(data).problem.spacecraft.inertia
    wheels = parse_scenario(data).problem.spacecraft.wheels
    storage = float(sum(wheels.max_momentum))
    assert float(inertia[0, 0]) * 2.0 > 8 * storage  # the oracle: J_xx ω = 0.5 N m s against the bounds' sum, 0.06


def test_wheels_that_span_only_a_plane_warn_naming_the_missing_direction():
    """A tester's four wheels in the body xy-plane (no control about z) validated without a word.
    The oracle: the cross product of two of the in-plane axes is the direction no wheel torques about."""
    axes = [[1.0, 0.0, 0.0], [0.6, 0.8, 0.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]]
    said = warnings_of(lambda d: d["spacecraft"].update(wheels={**d["spacecraft"]["wheels"], "axes": axes}))
    normal = np.cross(axes[0], axes[1])
    assert len(said) == 1 and said[0].startswith(f"spacecraft.wheels.axes: {axes} (4 wheels) span only a plane"), said
    assert f"the body direction {(normal / np.max(np.abs(normal))).tolist()}" in said[0], said
    # tilted out of the plane (a pyramid), or two wheels (the underactuated problem), or a failure: no warning
    pyramid = [[0.8, 0.0, 0.6], [0.0, 0.8, 0.6], [-0.8, 0.0, 0.6], [0.0, -0.8, 0.6]]
    assert warnings_of(lambda d: d["spacecraft"].update(wheels={**d["spacecraft"]["wheels"], "axes": pyramid})) == []
    assert warnings_of(lambda d: d["spacecraft"].update(wheels={**d["spacecraft"]["wheels"], "axes": axes[:2]})) == []
    assert warnings_of(lambda d: d["spacecraft"].update(
        wheels={**d["spacecraft"]["wheels"], "axes": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "failed": [2]})) == []


def test_a_disturbance_torque_the_actuators_cannot_counter_warns():
    """A constant disturbance of 4 N m written for 4 mN m validated without a word, though no
    controller can hold an attitude against it. The oracle: the CubeSat's wheels lie along the
    body axes at 3 mN m each, so along x they give 3 mN m, and along the diagonal 3 mN m per axis
    (‖·‖ = 5.2 mN m): 4 mN m about x is beyond them, [2, 2, 2] mN m (‖·‖ = 3.46 mN m) is not."""
    def disturbance(torque):
        return lambda d: d["environment"].update(disturbance_torque=torque)
    said = warnings_of(disturbance([0.004, 0.0, 0.0]))
    assert len(said) == 1 and said[0].startswith("environment.disturbance_torque: [0.004, 0.0, 0.0] N m has "
                                                 "‖τ_d‖ = 0.004 N m, more than the actuators give against it "
                                                 "(0.003 N m along −τ_d"), said
    assert "did you mean [4e-06, 0.0, 0.0] N m (mN m written as N m)?" in said[0], said
    assert warnings_of(disturbance([0.0, -4.0, 0.0]))[0].startswith("environment.disturbance_torque: [0.0, -4.0, 0.0]")
    assert warnings_of(disturbance([0.002, 0.002, 0.002])) == []  # a norm above 3 mN m the wheels still counter
    assert warnings_of(disturbance([1e-5, 0.0, 0.0])) == []
    data = read_yaml(ROOT / "scenarios" / "nano_detumble.yaml")  # magnetorquers alone: the field decides
    data["environment"]["disturbance_torque"] = [1.0, 0.0, 0.0]
    assert plausibility_warnings(parse_scenario(data)) == []


def test_the_guide_states_the_slow_slew_bar_the_code_uses():
    from scenarios.schema.plausibility import SLOW_SLEW_FACTOR
    text = re.sub(r"\s+", " ", (ROOT / "docs" / "guide" / "scenarios.rst").read_text())
    assert f"exceeds {SLOW_SLEW_FACTOR:g} times its time budget (``maneuver.duration``)" in text


@pytest.mark.parametrize("change, path", [
    (lambda d: d.setdefault("simulation", {}).setdefault("sensor_noise", {}).update(rate=1e261),
     "simulation.sensor_noise.rate"),
    (lambda d: d.setdefault("maneuver", {}).update(max_rate=1.2e261), "maneuver.max_rate"),
])
def test_a_huge_value_is_written_in_exponent_form_not_hundreds_of_digits(change, path):
    """A rate of 1e261 rad/s was written as 70,114,267,... deg/s (263 digits) in the warning; from
    1e15 the text gives exponent form. Grouped thousands stay below it (57,296 deg/s above)."""
    said = warnings_of(change)
    assert len(said) == 1 and said[0].startswith(path), said
    assert "e+" in said[0]
    assert not re.search(r"\d[\d,]{24,}", said[0]), said[0]  # no run of 20-odd digits


@pytest.mark.parametrize("orbit", [{"altitude_km": 1e300}, {"type": "keplerian", "semi_major_axis_km": 1e300},
                                   {"type": "keplerian", "altitude_km": 2e9}])
def test_an_orbit_beyond_any_earth_orbit_is_refused_at_its_path(orbit):
    """An altitude of 1e300 km overflowed the orbit's rate (radius³) and ended ``validate`` in an
    internal error; above MAX_ORBIT_KM the loader names the path and the bound."""
    from ocp.dynamics.orbits import MAX_ORBIT_KM
    from scenarios.errors import ScenarioError

    data = copy.deepcopy(CUBESAT)
    data["orbit"] = orbit
    with pytest.raises(ScenarioError) as raised:
        parse_scenario(data)
    key = "altitude_km" if "altitude_km" in orbit else "semi_major_axis_km"
    assert f"orbit.{key}" in str(raised.value) and f"{MAX_ORBIT_KM:g}" in str(raised.value), str(raised.value)


def test_a_star_tracker_noise_in_radians_written_as_arcsec_warns_with_the_arcsec_meant():
    """5, 5 and 41 arcsec written in radians (2.4e-5, 2.4e-5, 2e-4): 206,264.8 arcsec to the radian
    by hand gives 4.95, 4.95 and 41.25 arcsec."""
    def tracker(noise):
        def change(d):
            d.setdefault("simulation", {})["sensors"] = {
                "gyro": {"arw_deg_per_sqrt_h": 0.15},
                "star_tracker": {"noise_arcsec": noise, "rate_hz": 1.0}}
        return change
    said = warnings_of(tracker([2.4e-5, 2.4e-5, 2e-4]))
    assert len(said) == 1, said
    assert said[0].startswith("simulation.sensors.star_tracker.noise_arcsec: [2.4e-05, 2.4e-05, 0.0002] arcsec ")
    assert "did you mean [4.95, 4.95, 41.25] arcsec" in said[0], said
    assert warnings_of(tracker([5, 5, 40])) == []       # a small satellite's tracker
    assert warnings_of(tracker([0.1, 0.1, 0.5])) == []  # the most precise
    assert warnings_of(tracker([0, 0, 0])) == []        # a perfect sensor, meant


def test_a_sun_or_moon_cone_in_radians_written_as_degrees_warns_with_the_degrees_meant():
    """35 deg written in radians is 0.6109 (35 pi / 180 by hand), and 0.6109 rad is 35.0 deg back:
    a cone about the Sun that small (the disc is 0.27 deg in radius) protects nothing; so for the
    Moon, and a star tracker's exclusion about either. 1 deg and more, 0 (no cone) and a small
    cone about the Earth's limb are not judged."""
    def cone(body, angle):
        def change(d):
            d.setdefault("requirements", {})["pointing"] = {
                "st": {"sensor": "star_tracker", "keep_out": body, "angle_deg": angle}}
        return change
    said = warnings_of(cone("sun", 0.6109))
    assert len(said) == 1, said
    assert said[0].startswith("requirements.pointing.st.angle_deg: 0.6109 deg "), said
    assert "about the Sun" in said[0] and "did you mean 35 deg (radians written as degrees)" in said[0], said
    moon = warnings_of(cone("moon", 0.17453))  # 10 pi / 180
    assert len(moon) == 1 and "about the Moon" in moon[0] and "did you mean 10 deg" in moon[0], moon
    for body, angle in (("sun", 30), ("sun", 1.0), ("moon", 5), ("earth_limb", 0.5)):
        assert warnings_of(cone(body, angle)) == [], (body, angle)

    def exclusion(angles):
        def change(d):
            d.setdefault("simulation", {})["sensors"] = {
                "gyro": {"arw_deg_per_sqrt_h": 0.15},
                "star_tracker": {"noise_arcsec": [6, 6, 40], "rate_hz": 1.0, "exclusion_deg": angles}}
        return change
    tracker = warnings_of(exclusion({"sun": 0.5236, "moon": 10}))
    assert len(tracker) == 1 and tracker[0].startswith("simulation.sensors.star_tracker.exclusion_deg.sun: 0.5236 deg"), \
        tracker
    assert "did you mean 30 deg" in tracker[0], tracker
    assert warnings_of(exclusion({"sun": 30, "moon": 10, "earth_limb": 0.5})) == []
