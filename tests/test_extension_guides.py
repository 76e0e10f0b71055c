"""The extension guides' examples run as written (docs/extending/*.rst).

Each guide's ``.. code-block:: python`` blocks are executed in order in one namespace, as a reader
would paste them. Each test then checks, with its own oracle and not the guide's printout, that
the extension was registered, produced an ok row in a real scenario run, and meets its contract:
the planner conformance check on every standard problem the new planner or transcription accepts,
the agreement of the new controller's NumPy and symbolic laws, and the convergence of its closed
loop to the target. The registries are module-level dicts: every test restores them, so that the
guides' registrations do not leak into other tests.
"""
from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.integrate import trapezoid

from controllers import CONTROLLERS
from ocp import Measurement, ReactionWheels, Spacecraft, Torquers, quat
from ocp.dynamics.layout import measurement_vector
from ocp.transcription import TRANSCRIPTIONS
from planners import PLANNERS
from planners.conformance import check_reference, standard_problems

GUIDES = Path(__file__).resolve().parents[1] / "docs" / "extending"
CONFORMANCE_IMPORT = "controllers.conformance"
"""The controller guide's conformance block imports this module (written alongside the guide)."""


def python_blocks(text: str) -> list[str]:
    """The ``.. code-block:: python`` blocks of an RST text, dedented, in order."""
    lines = text.splitlines()
    blocks, index = [], 0
    while index < len(lines):
        match = re.match(r"^(\s*)\.\. code-block:: python\s*$", lines[index])
        index += 1
        if not match:
            continue
        indent = len(match.group(1))
        while index < len(lines) and re.match(r"^\s+:\w[\w-]*:", lines[index]):  # directive options
            index += 1
        body = []
        while index < len(lines) and (not lines[index].strip()
                                      or len(lines[index]) - len(lines[index].lstrip()) > indent):
            body.append(lines[index])
            index += 1
        while body and not body[0].strip():
            body.pop(0)
        while body and not body[-1].strip():
            body.pop()
        width = min(len(line) - len(line.lstrip()) for line in body if line.strip())
        blocks.append("\n".join(line[width:] for line in body) + "\n")
    return blocks


def code_blocks(name: str) -> list[str]:
    """The python blocks of a guide (it must have some)."""
    blocks = python_blocks((GUIDES / name).read_text())
    assert blocks, f"{name} has no python code blocks"
    return blocks


def run_guide(name: str, skip: str | None = None) -> dict[str, Any]:
    """Execute a guide's python blocks in order (leaving out those that contain ``skip``)."""
    namespace: dict[str, Any] = {"__name__": f"guide_{Path(name).stem}"}
    for number, block in enumerate(code_blocks(name), start=1):
        if skip is not None and skip in block:
            continue
        exec(compile(block, f"{name}, python block {number}", "exec", dont_inherit=True), namespace)
    return namespace


@pytest.fixture
def registries():
    """The planner, controller and transcription registries, restored after the test."""
    saved = [(registry, dict(registry)) for registry in (PLANNERS, CONTROLLERS, TRANSCRIPTIONS)]
    yield
    for registry, contents in saved:
        registry.clear()
        registry.update(contents)


def ok_rows(results: Any, column: str, name: str) -> list[Any]:
    """The rows of a run whose ``planner`` or ``controller`` is ``name`` and whose status is ok."""
    return [row for row in results.rows if getattr(row, column) == name and row.status == "ok"]


def test_python_blocks_are_the_python_directives_only():
    text = ("Intro.\n\n.. code-block:: python\n   :caption: x\n\n   a = 1\n\n       b = a\n\nText.\n\n"
            ".. code-block:: yaml\n\n   c: 1\n\n- item\n\n  .. code-block:: python\n\n     d = 2\n  after\n")
    assert python_blocks(text) == ["a = 1\n\n    b = a\n", "d = 2\n"]


def test_planner_guide(registries):
    namespace = run_guide("planner.rst")
    planner = namespace["CubicSlewPlanner"]
    assert PLANNERS["cubic_slew"] is planner
    rows = ok_rows(namespace["results"], "planner", "cubic_slew")
    assert len(rows) == 1 and rows[0].closed_loop_metrics["final_error_deg"] < 0.01
    accepted = 0
    for problem in standard_problems().values():
        if planner().problem_error(problem) is None:
            check_reference(problem, planner().plan(problem))
            accepted += 1
    assert accepted >= 3
    # the method, by a hand-worked value: 90 deg about z (I_z = 12.6 kg m^2) in 96 s, cubic profile
    reference = rows[0].reference
    t = np.linspace(0.0, reference.duration, 20001)
    u2 = trapezoid(np.sum(reference.torque(t) ** 2, axis=1), t)
    assert reference.duration == 96.0
    assert u2 == pytest.approx(12 * 12.6**2 * (np.pi / 2) ** 2 / 96.0**3, rel=1e-6)


def symbolic_and_numeric_agree(cls: type, rng: np.random.Generator) -> None:
    """The controller's ``__call__`` and its symbolic law give the same command (to 1e-12), with and
    without a reference, on wheels and on torquers."""
    planned = PLANNERS["eigenaxis"]().plan(standard_problems()["rest_to_rest"])  # any smooth reference
    for spacecraft in (Spacecraft([[19.5, 0.3, -0.2], [0.3, 19.0, 0.1], [-0.2, 0.1, 12.6]],
                                  wheels=ReactionWheels.from_body_axes(max_torque=0.1)),
                       Spacecraft([2.0, 3.0, 4.0], torquers=Torquers(0.05))):
        for options in ({}, {"feedforward": False}):
            controller = cls(options)
            controller.reset(spacecraft, 0.5, target=(quat.random_unit(rng), np.zeros(3)))
            law = controller.symbolic_law()
            for tracked in (planned, None):
                for t in (3.0, 40.0, 90.0):
                    measurement = Measurement(t, quat.random_unit(rng), rng.normal(0, 0.05, 3),
                                              rng.normal(0, 1.0, spacecraft.n_wheels), None)
                    rows = controller.reference_rows(tracked, np.array([t, t + 0.5])).ravel()
                    u, _ = (v.full().ravel() for v in law.function(t, measurement_vector(measurement), law.state0, rows))
                    expected = controller.command_vector(controller(t, measurement, tracked))
                    np.testing.assert_allclose(u, expected, rtol=0, atol=1e-12 * max(1.0, np.abs(expected).max()))


def test_controller_guide(registries, rng):
    namespace = run_guide("controller.rst", skip=CONFORMANCE_IMPORT)
    law = namespace["QuaternionPD"]
    assert CONTROLLERS["quaternion_pd"] is law
    rows = ok_rows(namespace["results"], "controller", "quaternion_pd")
    assert len(rows) == 2
    scenario = namespace["results"].scenario
    for row in rows:  # the closed loop converges to the target (independent of the metrics code)
        error = np.degrees(quat.error_angle(row.simulation.q[-1], scenario.problem.qf))
        assert error < 0.01, (row.label, error)
        assert np.linalg.norm(row.simulation.omega[-1]) < 1e-5
        assert row.simulation.path != "python"  # the symbolic law ran the closed loop
    symbolic_and_numeric_agree(law, rng)


def test_controller_guide_conformance(registries):
    blocks = [block for block in code_blocks("controller.rst") if CONFORMANCE_IMPORT in block]
    assert len(blocks) == 1, "the guide's conformance block is kept apart"
    run_guide("controller.rst")  # every block, the conformance call included: it raises on failure


def test_transcription_guide(registries):
    namespace = run_guide("transcription.rst")
    transcription = namespace["TrapezoidalCollocation"]
    assert TRANSCRIPTIONS["trapezoidal"] is transcription
    rows = ok_rows(namespace["results"], "planner", "collocation")
    assert any(row.reference.stats["transcription"] == "trapezoidal" for row in rows)
    planner = PLANNERS["collocation"]
    for problem in standard_problems().values():
        check_reference(problem, planner({"transcription": "trapezoidal", "intervals": 30}).plan(problem))
    # second order: the error of the optimum against Radau collocation (a second method) falls by 4
    problem = standard_problems()["non_principal"]
    exact = planner({"intervals": 80}).plan(problem).stats["objective"]
    errors = [planner({"transcription": "trapezoidal", "intervals": n}).plan(problem).stats["objective"] - exact
              for n in (20, 40)]
    assert errors[0] > 0 and errors[1] > 0
    assert errors[0] / errors[1] == pytest.approx(4.0, rel=0.1)
