"""The first planner a newcomer writes, following only the guide to adding a planner
(docs/extending/planner.rst): its example passes the conformance test as written, and the usual
first mistakes fail with a message that says what to do. The code is the page's own block (edited
per mistake), so the test follows the documentation."""
from __future__ import annotations

import re
import textwrap
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from planners.conformance import CHECKS, check_reference, standard_problems
from planners.errors import ConformanceError

DOCS = Path(__file__).resolve().parents[1] / "docs"
PAGE = DOCS / "extending" / "planner.rst"


@cache
def definitions() -> str:
    """The page's example planner: its python block that defines ``CubicSlewPlanner``, up to the
    lines that use it (a reStructuredText ``code-block`` or ``literalinclude``, or a Markdown fence)."""
    assert PAGE.is_file(), f"{PAGE} is missing: the guide to adding a planner holds the example this test runs"
    text = PAGE.read_text()
    blocks = [textwrap.dedent(body) for body in re.findall(
        r"^\.\. code-block:: python\n(?: {3}:.*\n)*\n((?:(?: {3}.*)?\n)+)", text, flags=re.MULTILINE)]
    blocks += re.findall(r"```python\n(.*?)```", text, flags=re.DOTALL)
    for path in re.findall(r"^\.\. literalinclude:: (\S+)", text, flags=re.MULTILINE):  # "/x": from docs/
        blocks.append((DOCS / path[1:] if path.startswith("/") else PAGE.parent / path).read_text())
    (example,) = [block for block in blocks if "class CubicSlewPlanner" in block]
    return example.split("problem = standard_problems()")[0]


def newcomer_module(*edits: tuple[str, str]) -> dict[str, Any]:
    """The page's planner, with each ``(old, new)`` edit applied (``old`` must be in the page)."""
    source = definitions()
    for old, new in edits:
        assert old in source, f"the example of {PAGE.name} no longer contains {old!r}"
        source = source.replace(old, new)
    namespace: dict[str, Any] = {"__name__": "newcomer"}
    exec(compile(source, f"{PAGE.name} example planner", "exec", dont_inherit=True), namespace)
    return namespace


def test_the_documented_planner_passes_every_check_on_every_problem_it_accepts():
    planner = newcomer_module()["CubicSlewPlanner"]()
    accepted = 0
    for problem in standard_problems().values():
        if planner.problem_error(problem) is None:
            check_reference(problem, planner.plan(problem))
            accepted += 1
    assert accepted >= 3


def test_forgetting_the_dataclass_decorator_says_so():
    module = newcomer_module(("    @dataclass(frozen=True)\n    class Options:", "    class Options:"))
    with pytest.raises(TypeError, match=r"must be a dataclass: decorate it with @dataclass\(frozen=True\)"):
        module["CubicSlewPlanner"]()


def test_forgetting_the_inertia_names_it():
    module = newcomer_module(('super().__init__("cubic_slew", duration, problem.spacecraft.inertia)',
                              'super().__init__("cubic_slew", duration)'))
    with pytest.raises(TypeError, match="inertia"):
        module["CubicSlewPlanner"]().plan(standard_problems()["rest_to_rest"])


def test_arrays_of_the_wrong_shape_say_which_and_what_shape():
    module = newcomer_module(("return ReferenceSample(q, omega, omega_dot, torque)",
                              "return ReferenceSample(q.T, omega, omega_dot, torque)"))
    reference = module["CubicSlewPlanner"]().plan(standard_problems()["rest_to_rest"])
    with pytest.raises(ValueError, match=r"returned q of shape \(4, 5\); expected \(5, 4\)"):
        reference.sample(np.linspace(0.0, 10.0, 5))


def test_a_constant_rate_slew_misses_the_boundary_rates_and_is_told_to_declare_them():
    module = newcomer_module(("rate = self.angle * (6 * s - 6 * s**2) / self.duration",
                              "rate = np.full_like(s, self.angle / self.duration)"),
                             ("theta = self.angle * (3 * s**2 - 2 * s**3)", "theta = self.angle * s"),
                             ("acceleration = self.angle * (6 - 12 * s) / self.duration**2",
                              "acceleration = np.zeros_like(s)"))
    problem = standard_problems()["rest_to_rest"]
    reference = module["CubicSlewPlanner"]().plan(problem)
    for check in ("kinematics", "dynamics", "vectorised", "after_end"):
        CHECKS[check](problem, reference)  # a consistent motion ...
    with pytest.raises(ConformanceError, match=r"ω\(0\).*free_boundary=\{'omega0'\}"):
        check_reference(problem, reference)  # ... that does not start at rest


def test_a_gyroscopic_term_with_the_wrong_sign_is_caught_and_the_helper_named():
    module = newcomer_module(("torque = inverse_dynamics_torque(self.inertia, omega, omega_dot)",
                              "torque = omega_dot @ self.inertia.T - np.cross(omega, omega @ self.inertia.T)"))
    problem = standard_problems()["non_principal"]  # the gyroscopic term vanishes about a principal axis
    reference = module["CubicSlewPlanner"]().plan(problem)
    with pytest.raises(ConformanceError, match="inverse_dynamics_torque"):
        CHECKS["dynamics"](problem, reference)


def test_a_three_vector_option_may_be_written_as_a_tuple():
    module = newcomer_module(("        time_fraction: Annotated[float, Range(gt=0.0, le=1.0)] = 1.0",
                              ("        time_fraction: Annotated[float, Range(gt=0.0, le=1.0)] = 1.0\n"
                               "        axis_hint: tuple[float, float, float] = (0.0, 0.0, 1.0)")))
    planner = module["CubicSlewPlanner"]({"axis_hint": [1, 0, 0]})
    assert planner.options.axis_hint == (1.0, 0.0, 0.0)
    with pytest.raises(ValueError, match="axis_hint: expected a list of 3 numbers"):
        module["CubicSlewPlanner"]({"axis_hint": [1, 0]})
