"""The nano-spacecraft detumbling scenarios end to end, and the paper's qualitative claims.

Full runs (60,000-300,000 s) are ``slow``; the default run takes snapshots of the same runs at
5,000-20,000 s. The asserted numbers are our measurements with a margin (the paper's own times are
not reproducible without its gains, sample time and criterion: see scenarios/REPRODUCTION.md).
"""
from pathlib import Path

import numpy as np
import pytest

import scenarios
from controllers import TDFC, BDot
from ocp import (
    AttitudeModel,
    CircularOrbit,
    Environment,
    Magnetorquers,
    SensorNoise,
    Simulator,
    Spacecraft,
    TiltedDipole,
    quat,
)

HERE = Path(__file__).resolve().parent.parent / "scenarios"
INERTIA = np.diag([0.0109, 0.05, 0.05])


def energy(omega):
    return 0.5 * np.einsum("ni,ij,nj->n", omega, INERTIA, omega)


def run_scenario(name, duration=None):
    scenario = scenarios.load(HERE / name)
    if duration is not None:
        scenario.simulation.duration = duration
    results = scenarios.run(scenario)
    assert [(row.label, row.controller, row.status) for row in results.rows] == [("B-dot", "bdot", "ok"),
                                                                               ("TDFC", "tdfc", "ok")]
    return {row.label: row for row in results.rows}


def noisy_pair(duration):
    """B-dot (K_b = 2e4 A m² s/T) and TDFC (K_t = 1e4 A m²/T, τ = 2 s) at a 0.2 s sample with 1e-5 T
    magnetometer noise, same seed, from the paper's tip-off rate."""
    model = AttitudeModel(Spacecraft(INERTIA, magnetorquers=Magnetorquers(0.1)),
                          Environment(CircularOrbit(600e3, np.deg2rad(97.79)), magnetic_field=TiltedDipole()))
    simulator = Simulator(model, 0.2, max_step=0.1, max_samples=600_000)
    x0 = np.r_[quat.IDENTITY, 0.52, 0.52, 0.52]
    noise = SensorNoise(field_std=1e-5, seed=1)
    return (simulator.run(BDot({"gain": 2.0e4}), x0, duration, noise=noise),
            simulator.run(TDFC({"gain": 1.0e4, "delay": 2.0}), x0, duration, noise=noise))


def test_ideal_scenario_snapshot_at_20000_s():
    """Both laws have removed >99 % of the energy by 20,000 s; B-dot is ahead (the paper's ideal
    ordering). Measured: energy ratios ~2e-4 (B-dot) and ~2e-3 (TDFC)."""
    rows = run_scenario("nano_detumble.yaml", duration=20000.0)
    bdot, tdfc = rows["B-dot"].closed_loop_metrics, rows["TDFC"].closed_loop_metrics
    assert bdot["energy_ratio"] < 1e-2 and tdfc["energy_ratio"] < 1e-2
    assert bdot["final_rate"] < tdfc["final_rate"]
    assert 0 < bdot["int_dipole"] < 0.1 * np.sqrt(3) * 20000.0  # bounded by the saturated dipole


def test_noise_snapshot_tdfc_ahead_of_bdot_at_5000_s():
    """With 1e-5 T noise at 0.2 s, B-dot's backward difference is dominated by the noise
    (σ√2/T_s ≈ 7e-5 T/s against |Ḃ| ≈ |ω||B| ≈ 3e-5 T/s) and its dipole saturates at random;
    TDFC's delayed difference over 2 s is not. After 5,000 s TDFC has removed more energy."""
    bdot, tdfc = noisy_pair(5000.0)
    e_bdot, e_tdfc = energy(bdot.omega)[-1], energy(tdfc.omega)[-1]
    assert np.mean(bdot.saturated) > 0.99  # the noise drives B-dot's dipole to its limit
    assert e_tdfc < 0.7 * e_bdot < 0.7 * energy(bdot.omega)[0]


@pytest.mark.slow
def test_noise_tdfc_detumbles_faster_than_bdot_over_100000_s():
    """The paper's qualitative claim with noise: TDFC detumbles, B-dot (same seed) does not within
    100,000 s, so the ratio of detumbling times is at least 100,000 / t_TDFC (measured ~3)."""
    from ocp.metrics import detumble_time
    bdot, tdfc = noisy_pair(100000.0)
    t_tdfc, t_bdot = detumble_time(tdfc.t, tdfc.omega), detumble_time(bdot.t, bdot.omega)
    assert t_tdfc is not None and t_tdfc < 50000.0
    assert t_bdot is None or t_bdot > 2.0 * t_tdfc
    assert np.linalg.norm(bdot.omega[-1]) > 3 * np.linalg.norm(tdfc.omega[-1])


@pytest.mark.slow
def test_ideal_scenario_full_run():
    """60,000 s: both detumble (max|ω_i| < 0.01 rad/s) and settle near twice the orbital rate
    (B-dot's known floor); B-dot first, as in the paper (measured 19,689 s and 26,638 s)."""
    rows = run_scenario("nano_detumble.yaml")
    bdot, tdfc = rows["B-dot"].closed_loop_metrics, rows["TDFC"].closed_loop_metrics
    assert bdot["detumble_time_s"] is not None and tdfc["detumble_time_s"] is not None
    assert bdot["detumble_time_s"] < 0.9 * tdfc["detumble_time_s"] < 0.9 * 60000.0
    orbital_rate = np.sqrt(3.986004418e14 / (6378.137e3 + 600e3) ** 3)
    for metrics in (bdot, tdfc):
        assert 0.5 * orbital_rate < metrics["final_rate"] < 4 * orbital_rate
        assert metrics["energy_ratio"] < 1e-4


def edited_scenario(tmp_path, old, new):
    text = (HERE / "nano_detumble.yaml").read_text()
    assert old in text
    path = tmp_path / "edited.yaml"
    path.write_text(text.replace(old, new))
    return path


@pytest.mark.parametrize("old, new, path, fragment", [
    ("delay: 2.0}", "delay: 2.5}", "controllers[1].options.delay", "whole multiple"),
    ("delay: 2.0}", "delay: 0.0}", "controllers[1].options.delay", "> 0"),
    ("{gain: 2.0e4}", "{gain: -1.0}", "controllers[0].options.gain", ">= 0"),
    ("{gain: 2.0e4}", "{gain: 2.0e4, derivative: spline}", "controllers[0].options.derivative", "one of"),
    ("magnetorquers: {max_dipole: 0.1}", "torquers: {max_torque: 0.1}", "controllers[0].name", "magnetorquers"),
    ("{magnetic_field: tilted_dipole}", "{magnetic_field: none}", "controllers[0].name", "magnetic field"),
    ("{max_dipole: 0.1}", "{max_dipole: 0.1, saturation: clip}", "spacecraft.magnetorquers.saturation", "scale"),
    ("detumble_tolerance: 0.01", "detumble_tolerance: -1", "simulation.detumble_tolerance", "positive"),
])
def test_detumbling_input_errors_name_the_yaml_path(tmp_path, old, new, path, fragment):
    with pytest.raises(scenarios.ScenarioError) as error:
        scenarios.load(edited_scenario(tmp_path, old, new))
    assert error.value.path == path and fragment in str(error.value), str(error.value)


def test_free_attitude_needs_a_law_that_declares_it(tmp_path):
    """Regulation with q: null is accepted for bdot/tdfc (capability), refused for an attitude law."""
    path = edited_scenario(tmp_path, "  - {name: tdfc, label: TDFC, options: {gain: 1.0e4, delay: 2.0}}",
                           "  - {name: eigenaxis_pd, label: PD}")
    with pytest.raises(scenarios.ScenarioError) as error:
        scenarios.load(path)
    assert error.value.path == "maneuver.final.q" and "eigenaxis_pd" in str(error.value)
    scenario = scenarios.load(HERE / "nano_detumble.yaml")
    assert scenario.problem.qf is None and [c.name for c in scenario.controllers] == ["bdot", "tdfc"]


@pytest.mark.slow
def test_noisy_scenario_full_run():
    """300,000 s with 1e-5 T noise at 1 s: TDFC detumbles, B-dot takes far longer or never (its
    noise-driven rate floor sits near the 0.01 rad/s tolerance). Measured, seed 1: 38,447 s and
    277,907 s (at a 0.02 rad/s tolerance B-dot's time drops to 48,303 s: the criterion matters)."""
    rows = run_scenario("nano_detumble_noisy.yaml")
    t_bdot = rows["B-dot"].closed_loop_metrics["detumble_time_s"]
    t_tdfc = rows["TDFC"].closed_loop_metrics["detumble_time_s"]
    assert t_tdfc is not None and t_tdfc < 80000.0
    assert t_bdot is None or t_bdot > 2.0 * t_tdfc
