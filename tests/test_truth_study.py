"""The ``truth:`` section (issue 28): bad input names its YAML path, every dispersible truth path
reaches the plant it names and nothing else, and a Monte Carlo of the plant's inertia spreads the
closed loop while the design model stays what it was."""
from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest

from ocp.dynamics.model import _plain
from scenarios.errors import ScenarioError
from scenarios.schema.keys import Section
from scenarios.schema.loader import load, parse_scenario
from scenarios.schema.read import read_yaml
from scenarios.schema.truth import TRUTH
from scenarios.study.spec import parse_study
from scenarios.study.worker import run_case

ROOT = Path(__file__).resolve().parents[1] / "scenarios"

BASE = {
    "name": "truth-paths",
    "spacecraft": {"inertia": [2.0, 1.8, 1.2],
                   "wheels": {"max_torque": 0.005, "max_momentum": 0.05, "spin_inertia": 2e-4},
                   "magnetorquers": {"max_dipole": 0.5}},
    "orbit": {"altitude_km": 500.0, "inclination_deg": 97.0},
    "environment": {"magnetic_field": "tilted_dipole", "disturbance_torque": [1e-7, 0, 0]},
    "maneuver": {"duration": 60.0, "initial": {"q": [1, 0, 0, 0]},
                 "final": {"q": [0.9848078, 0.1736482, 0, 0], "omega": [0, 0, 0]}},
    "planners": [{"name": "eigenaxis"}],
    "controller": {"name": "augmented_quaternion_feedback", "options": {"kp": 0.02, "kd": 0.1}},
    "simulation": {"sample_time": 1.0},
    "truth": {
        "spacecraft": {"inertia": [2.0, 1.8, 1.2]},
        "wheels": {"misalignment_deg": [[0, 1, 0], [0, 0, 1], [1, 0, 0]], "max_torque": 0.004,
                   "max_momentum": 0.04, "friction": {"coulomb": 1e-5, "viscous": 1e-6},
                   "max_speed_rpm": 3000.0, "torque_noise": 1e-5},
        "magnetorquers": {"scale_error": 0.05},
        "residual_dipole": [0.01, 0.0, 0.0],
        "disturbance": {"constant": [0.0, 1e-7, 0.0],
                        "orbit_periodic": [{"harmonic": 1, "amplitude": [1e-7, 0, 0], "phase_deg": [0, 0, 0]}]},
    },
}

# Every leaf of the truth section: the Truth field it sets and a value other than the base's.
CHANGES = {
    "truth.spacecraft.inertia": ("inertia", [2.2, 1.7, 1.3]),
    "truth.wheels.misalignment_deg": ("wheel_misalignment", [[0, 2, 0], [0, 0, 1], [1, 0, 0]]),
    "truth.wheels.max_torque": ("wheel_max_torque", 0.003),
    "truth.wheels.max_momentum": ("wheel_max_momentum", [0.04, 0.03, 0.04]),
    "truth.wheels.friction.coulomb": ("wheel_coulomb", 2e-5),
    "truth.wheels.friction.viscous": ("wheel_viscous", 3e-6),
    "truth.wheels.max_speed_rpm": ("wheel_max_speed", 2000.0),
    "truth.wheels.torque_noise": ("wheel_torque_noise", 2e-5),
    "truth.magnetorquers.scale_error": ("dipole_scale_error", -0.05),
    "truth.residual_dipole": ("residual_dipole", [0.0, 0.02, 0.0]),
    "truth.disturbance.constant": ("constant_disturbance", [0.0, 0.0, 2e-7]),
    "truth.disturbance.orbit_periodic[0].harmonic": ("periodic_disturbance", 2),
    "truth.disturbance.orbit_periodic[0].amplitude": ("periodic_disturbance", [0, 2e-7, 0]),
    "truth.disturbance.orbit_periodic[0].phase_deg": ("periodic_disturbance", [10, 0, 0]),
}


def leaves(section: Section, prefix: str) -> list[str]:
    found = []
    for key in section.keys:
        path = f"{prefix}.{key.name}"
        if key.section is not None and key.entries:
            found += leaves(key.section, f"{path}[0]")
        elif key.section is not None:
            found += leaves(key.section, path)
        else:
            found.append(path)
    return found


def design_of(scenario):
    """Everything the planners and the controller are given, as plain values."""
    problem = scenario.problem
    return (problem.model.fingerprint, _plain(problem.spacecraft), problem.q0.tolist(), problem.qf.tolist(),
            problem.duration, [(p.name, repr(p.options)) for p in scenario.planners],
            [(c.name, repr(c.options)) for c in scenario.controllers], repr(scenario.simulation))


def test_every_truth_key_has_a_dispersion_case():
    assert sorted(leaves(TRUTH, "truth")) == sorted(CHANGES)


@pytest.mark.parametrize("path", sorted(CHANGES))
def test_a_dispersed_truth_path_changes_the_plant_it_names_and_nothing_else(path):
    field, other = CHANGES[path]
    study = parse_study({"study": "arrival", "scenario": copy.deepcopy(BASE),
                         "zip": {path: [_base_value(path), other]}})
    first, second = (parse_scenario(case.scenario) for case in study.cases)
    assert design_of(first) == design_of(second)
    truth_a, truth_b = first.truth.truth, second.truth.truth
    for name in ("inertia", "wheel_misalignment", "wheel_max_torque", "wheel_max_momentum", "wheel_coulomb",
                 "wheel_viscous", "wheel_max_speed", "wheel_torque_noise", "dipole_scale_error", "residual_dipole",
                 "constant_disturbance", "periodic_disturbance"):
        same = _plain(getattr(truth_a, name)) == _plain(getattr(truth_b, name))
        assert same == (name != field), name
    assert first.truth.fingerprint != second.truth.fingerprint
    assert first.truth.design.fingerprint == second.truth.design.fingerprint


def _base_value(path):
    node = BASE
    for part in path.split("."):
        if part.endswith("[0]"):
            node = node[part[:-3]][0]
        else:
            node = node[part]
    return copy.deepcopy(node)


@pytest.mark.parametrize(("path", "value", "words"), [
    ("wheels.misalignment_deg", [[0, 10.5, 0], [0, 0, 1], [1, 0, 0]], "exceeds 10 deg"),
    ("wheels.torque_noise", -1e-5, "expected numbers >= 0"),
    ("wheels.friction.viscous", [1e-6, -1e-6, 0], "expected numbers >= 0"),
    ("spacecraft.inertia", [[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 1.0]], "positive definite"),
    ("magnetorquers.scale_error", -1.0, "> -1"),
    ("wheels.max_torque", [0.1, 0.1], "one per wheel"),
])
def test_bad_truth_input_names_its_yaml_path(path, value, words):
    data = copy.deepcopy(BASE)
    node = data["truth"]
    *parents, last = path.split(".")
    for part in parents:
        node = node[part]
    node[last] = value
    with pytest.raises(ScenarioError) as caught:
        parse_scenario(data)
    where = f"truth.{path}" + ("[0]" if last == "misalignment_deg" else "")
    assert caught.value.path == where
    assert words in str(caught.value)


def test_residual_dipole_without_a_field_names_its_path():
    data = copy.deepcopy(BASE)
    del data["environment"]["magnetic_field"]
    with pytest.raises(ScenarioError, match="magnetic field") as caught:
        parse_scenario(data)
    assert caught.value.path == "truth.residual_dipole"


def test_without_truth_the_scenario_has_none():
    data = copy.deepcopy(BASE)
    del data["truth"]
    assert parse_scenario(data).truth is None
    data["truth"] = None
    assert parse_scenario(data).truth is None


def test_inertia_monte_carlo_spreads_settling_and_momentum_and_keeps_the_design():
    """The shipped study, 10 samples run as a sweep's worker runs them: each case's plant inertia is
    scaled within ±10 %, the design (model, planners, controller) is the base scenario's in every
    case, and the closed loop's settling time and peak wheel momentum spread."""
    source = ROOT / "study_truth_inertia_monte_carlo.yaml"
    data = read_yaml(source)
    data["monte_carlo"]["samples"] = 10
    study = parse_study(data, source=source)
    base = load(ROOT / "eigenaxis_truth.yaml")
    base_inertia = np.diag(base.truth.truth.inertia)
    rows = []
    for case in study.cases:
        scenario = parse_scenario(case.scenario)
        assert design_of(scenario) == design_of(base)
        ratio = np.diag(scenario.truth.truth.inertia) / base_inertia
        assert np.all((ratio >= 0.9) & (ratio <= 1.1)) and np.all(ratio != 1.0)
        outcome = run_case({"key": case.key, "scenario": case.scenario, "timeout_s": 60.0})
        assert outcome["status"] == "ok"
        rows += outcome["rows"]
    for label in ("smooth", "bang-coast-bang"):
        mine = [row for row in rows if row["label"] == label]
        assert len(mine) == 10 and all(row["status"] == "ok" for row in mine)
        for metric in ("settling_time_s", "peak_wheel_momentum"):
            values = [row["closed_loop"][metric] for row in mine]
            assert np.std(values) > 0, (label, metric)
