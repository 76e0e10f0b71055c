"""Fresh-eyes report of 2026-12-02 on a 4-wheel pyramid with wheel 0 failed (``slewbench codegen``):
the C table at a reference's rate jump, the default table, and ``example.c``'s checksum."""
import ctypes
import re
import shutil
import subprocess
from types import SimpleNamespace

import numpy as np
import pytest
import yaml

from scenarios.codegen.export import _default_row
from scenarios.schema.loader import load
from tests.test_codegen_flight import Built, Table

needs_cc = pytest.mark.skipif(shutil.which("make") is None or shutil.which("cc") is None,
                              reason="needs make and a C compiler")

PYRAMID = {
    "name": "pyr54-fail0",
    "spacecraft": {"inertia": [2.0, 2.5, 3.0],
                   "wheels": {"axes": [[0.8165, 0.0, 0.57735], [0.0, 0.8165, 0.57735],
                                       [-0.8165, 0.0, 0.57735], [0.0, -0.8165, 0.57735]],
                              "max_torque": 0.01, "max_momentum": 0.05, "failed": [0]}},
    "maneuver": {"duration": 150.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": {"axis_angle": {"axis": [1, 2, 3], "angle_deg": 100}}, "omega": [0, 0, 0]}},
    "planners": [{"name": "natural_motion"}],
    "controller": {"name": "augmented_quaternion_feedback"},
    "simulation": {"sample_time": 0.5, "duration": 160.0},
}


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    if shutil.which("make") is None or shutil.which("cc") is None:
        pytest.skip("needs make and a C compiler")
    root = tmp_path_factory.mktemp("pyr54")
    path = root / "pyr54.yaml"
    path.write_text(yaml.safe_dump(PYRAMID))
    return Built(str(path), root / "c"), load(path)


@needs_cc
def test_the_c_table_gives_the_references_side_of_a_rate_jump(built):
    # natural_motion's step stop: the rate reference drops to zero at T - 10 s = 140 s, a multiple of
    # the sample time. At 140 s the reference gives the arc's rate (its own convention, the oracle
    # here); the C read the value after the jump there (a 0.01 N m command difference one sample early).
    built, scenario = built
    reference = scenario.planners[0].planner.plan(scenario.problem)
    assert reference.ok and reference.breakpoints.size, reference.message
    c_table, _ = built.table(scenario.planners[0].label)
    for b in reference.breakpoints:
        for t in (b - 0.5, b - 1e-6, b, b + 1e-6, b + 0.5):
            expected = reference.sample(np.array([t]))
            got = built.row(c_table, t)
            np.testing.assert_allclose(got[4:7], expected.omega[0], rtol=0, atol=1e-9, err_msg=f"omega at {t} s")
            np.testing.assert_allclose(got[7:13], np.r_[expected.omega_dot[0], expected.torque[0]], rtol=0,
                                       atol=1e-6, err_msg=f"omega_dot, torque at {t} s")
    jump = reference.breakpoints[-1]
    assert np.linalg.norm(reference.sample(np.array([jump])).omega) > 1e-3  # the left side: still turning
    # the stated error covers the nodes (the breakpoints' included)
    error = built.interface["tables"][scenario.planners[0].label]["error"]
    assert error["rate_rad_s"] < 1e-9


@needs_cc
def test_the_examples_checksum_sums_every_applied_command(built):
    # wheel 0 failed: its command is always 0, and the checksum summed it alone (it printed 0). The
    # oracle: the same calls made through ctypes, summing |u_applied| over every actuator.
    built, _ = built
    text = subprocess.run([str(built.out / "example")], check=True, capture_output=True, text=True).stdout
    checksum = float(re.search(r"checksum ([^)]+)\)", text).group(1))
    params = built.params()
    params.reference = ctypes.pointer(Table.in_dll(built.lib, built.interface["step"]["default_reference"]))
    state = built.init()
    m = SimpleNamespace(q=[1.0, 0.0, 0.0, 0.0], omega=[0.01, -0.02, 0.005], wheel_momentum=[0.0] * built.n_w,
                        field_body=[2e-5, -1e-5, 3e-5])
    for k in range(5):
        assert built.step(k * built.sample_time, m, params, state)[0] == 0
    total, applied = 0.0, []
    for k in range(200000):
        _, _, u_applied, _ = built.step(0.5 * built.sample_time + 1e-7 * k, m, params, state)
        total += float(np.sum(np.abs(u_applied)))
        applied.append(u_applied[0])
    assert max(abs(a) for a in applied) == 0.0  # the failed wheel
    assert checksum > 0 and checksum == pytest.approx(total, rel=1e-5)


def test_the_default_table_meets_its_tolerances_where_a_row_has_one():
    # the user's pyr54: colloc-min-energy meets the requirements but its table misses omega_dot and
    # torque; spin_extremal (then exported) met both. Rows and verdicts as the user's export gave them.
    labels = ["smooth", "trapezoidal", "colloc-min-energy", "colloc-min-time", "spin_extremal"]
    broken = {"smooth": ["wheels_momentum"], "trapezoidal": ["wheels_torque"]}
    missed = {"colloc-min-energy": ("omega_dot", "torque"), "colloc-min-time": ("attitude", "rate")}
    row, reason = _default_row(labels, broken, True, True, missed)
    assert row == "spin_extremal", reason
    assert "whose table meets its tolerances" in reason and "'colloc-min-energy' misses" in reason
    # none meets both: the first that meets the requirements, and the header says its table misses
    row, reason = _default_row(labels[:4], broken, True, True, missed)
    assert row == "colloc-min-energy"
    assert "WARNING: its table misses its tolerances (omega_dot, torque)" in reason
    # every row breaks the requirements: a table that meets its tolerances first
    row, reason = _default_row(labels[:4], {label: ["x"] for label in labels}, True, True, missed)
    assert row == "smooth" and "WARNING: every exported row breaks" in reason
    # all meet everything: the first row, no warning
    row, reason = _default_row(labels, {}, True, True, {})
    assert row == "smooth" and "WARNING" not in reason

