"""``slewbench codegen``: the generated C, built with its Makefile and loaded with
``casadi.external``, equals the Python law (at its default parameters, the scenario's numbers) and
the Python reference at random inputs (issue 13)."""
import json
import shutil
import subprocess
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from controllers import CONTROLLERS
from ocp import Measurement, quat
from planners import PLANNERS
from scenarios.cli.commands import main
from scenarios.schema.loader import load

SCENARIOS = Path(__file__).resolve().parents[1] / "scenarios"
pytestmark = pytest.mark.skipif(shutil.which("make") is None or shutil.which("cc") is None,
                                reason="needs make and a C compiler")


def _default_parameters(parameters):
    """The parameter vector ``p`` of the defaults (column-major blocks, as interface.json says)."""
    return np.concatenate([np.asarray(p["default"], dtype=float).ravel(order="F") for p in parameters]
                          or [np.zeros(0)])


@pytest.mark.parametrize("name", ["eigenaxis_demo.yaml", "nano_eigenaxis_pd.yaml"])
def test_generated_c_equals_the_python_law_and_references(name, tmp_path, rng):
    out = tmp_path / "c"
    assert main(["codegen", str(SCENARIOS / name), "--out", str(out)]) == 0
    subprocess.run(["make", "-C", str(out)], check=True, capture_output=True)
    interface = json.loads((out / "interface.json").read_text())
    library = str(out / interface["library"])
    scenario = load(SCENARIOS / name)
    problem, spec = scenario.problem, scenario.simulation
    controller = CONTROLLERS[scenario.controller.name](scenario.controller.options)
    controller.reset(problem.spacecraft, spec.sample_time, target=(problem.qf, problem.omegaf))
    law = ca.external("slewbench_law", library)
    references = [PLANNERS[p.name](p.options).plan(problem) for p in scenario.planners]
    n_w = problem.spacecraft.n_wheels
    z = np.array(interface["slewbench_law"]["z0"])
    defaults = _default_parameters(interface["slewbench_law"]["parameters"])
    for _ in range(50):
        t = float(rng.uniform(0, 150))
        measurement = Measurement(t, quat.random_unit(rng), rng.normal(0, 0.05, 3), rng.normal(0, 0.5, n_w), None)
        reference = references[rng.integers(len(references))] if references else None
        r = controller.reference_rows(reference, np.array([t, t + spec.sample_time])).ravel()
        y = np.r_[measurement.q, measurement.omega, measurement.wheel_momentum, np.zeros(3)]
        u, z_next = (v.full().ravel() for v in law(t, y, z, r, defaults))
        expected = controller.command_vector(controller(t, measurement, reference))
        np.testing.assert_allclose(u, expected, rtol=0, atol=1e-12 * max(1.0, np.abs(expected).max()))
        np.testing.assert_allclose(z_next, controller.state_vector(), rtol=0, atol=1e-12)
    exported = interface["references"]
    assert len(exported) == len(scenario.planners)  # eigenaxis references are all closed-form
    for spec_row, reference in zip(scenario.planners, references):
        evaluate = ca.external(exported[spec_row.label]["function"], library)
        for t in rng.uniform(0, reference.duration, 50):
            sample = reference.sample(t)
            row = evaluate(t).full().ravel()
            np.testing.assert_allclose(row, np.concatenate(sample), rtol=0, atol=1e-12)


def test_codegen_never_writes_into_a_directory_it_did_not_make(tmp_path, capsys):
    users = tmp_path / "mine"
    users.mkdir()
    (users / "notes.txt").write_text("keep me")
    assert main(["codegen", str(SCENARIOS / "eigenaxis_demo.yaml"), "--out", str(users)]) == 2
    assert sorted(p.name for p in users.iterdir()) == ["notes.txt"]
    assert (users / "notes.txt").read_text() == "keep me"
    # Its own directory it may write again; a file a user added there stays.
    own = tmp_path / "own"
    assert main(["codegen", str(SCENARIOS / "eigenaxis_demo.yaml"), "--out", str(own)]) == 0
    (own / "mine.c").write_text("int x;")
    assert main(["codegen", str(SCENARIOS / "eigenaxis_demo.yaml"), "--out", str(own)]) == 0
    assert (own / "mine.c").read_text() == "int x;"


def test_a_non_symbolic_law_is_refused_with_its_reason(tmp_path, capsys):
    assert main(["codegen", str(SCENARIOS / "vepa_spin_up.yaml"), "--out", str(tmp_path / "c")]) == 2
    error = capsys.readouterr().err
    assert "controller.name" in error and "least squares" in error
    assert not (tmp_path / "c").exists()


def test_every_controller_of_a_list_is_exported(tmp_path, rng):
    """nano_detumble.yaml lists B-dot and TDFC: each gets its own C function, and each equals its
    Python law, its state included, over successive samples."""
    out = tmp_path / "c"
    assert main(["codegen", str(SCENARIOS / "nano_detumble.yaml"), "--out", str(out)]) == 0
    subprocess.run(["make", "-C", str(out)], check=True, capture_output=True)
    interface = json.loads((out / "interface.json").read_text())
    scenario = load(SCENARIOS / "nano_detumble.yaml")
    problem, spec = scenario.problem, scenario.simulation
    assert [law["label"] for law in interface["laws"].values()] == [c.label for c in scenario.controllers]
    for name, description in interface["laws"].items():
        controller_spec = next(c for c in scenario.controllers if c.label == description["label"])
        controller = CONTROLLERS[controller_spec.name](controller_spec.options)
        controller.reset(problem.spacecraft, spec.sample_time, target=(problem.qf, problem.omegaf))
        law = ca.external(name, str(out / interface["library"]))
        z = np.array(description["z0"])
        r = controller.reference_rows(None, np.array([0.0, spec.sample_time])).ravel()
        for k in range(8):
            t = k * spec.sample_time
            field = rng.normal(0.0, 3e-5, 3)
            measurement = Measurement(t, quat.random_unit(rng), rng.normal(0, 0.3, 3), np.zeros(0), field)
            y = np.r_[measurement.q, measurement.omega, field]
            u, z = (v.full().ravel() for v in law(t, y, z, r, _default_parameters(description["parameters"])))
            expected = controller.command_vector(controller(t, measurement, None))
            np.testing.assert_allclose(u, expected, rtol=0, atol=1e-12 * max(1.0, np.abs(expected).max()))
            np.testing.assert_allclose(z, controller.state_vector(), rtol=0, atol=1e-12)


def test_the_estimator_the_c_does_not_hold_is_said_on_the_command_line_readme_and_interface(tmp_path, capsys):
    """spin_repoint_estimator.yaml flies a gyro, a star tracker and an MEKF between the plant and
    the law; the C holds the law and the saturation only, so codegen says the estimator is not
    generated (a flight engineer must supply the attitude and rate); eigenaxis_demo.yaml, whose law
    read the noisy state itself, has no such note."""
    out = tmp_path / "c"
    assert main(["codegen", str(SCENARIOS / "spin_repoint_estimator.yaml"), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "note: simulation.estimator (an MEKF, with the gyro, star tracker) is not generated" in printed
    assert "Not generated: simulation.estimator" in (out / "README.md").read_text()
    assert json.loads((out / "interface.json").read_text())["not_generated"][0].startswith("simulation.estimator")
    plain = tmp_path / "plain"
    assert main(["codegen", str(SCENARIOS / "eigenaxis_demo.yaml"), "--out", str(plain)]) == 0
    assert "not generated" not in capsys.readouterr().out
    assert json.loads((plain / "interface.json").read_text())["not_generated"] == []
