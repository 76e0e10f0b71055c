"""The ``closed_form`` check of the planner conformance (:func:`planners.conformance.check_closed_form`).

``slewbench codegen`` exports ``reference.symbolic_evaluator()`` as C for a planner that declares
``closed_form``; the check compares it with the reference's own ``sample`` on a grid with the ends,
the breakpoints' neighbourhoods and times after T. The oracle is ``sample`` itself (the reference
the tables, the scoring and the simulation use); the defects are planted in a plugin planner's
evaluator written here, not produced by the code under test.
"""
from __future__ import annotations

import copy
import re
import typing
from dataclasses import dataclass

import casadi as ca
import numpy as np
import pytest

from ocp import quat, quat_casadi
from planners import (
    PLANNERS,
    ManeuverProblem,
    Planner,
    Reference,
    ReferenceSample,
    inverse_dynamics_torque,
)
from planners.conformance import (
    CHECKS,
    check_closed_form,
    check_reference,
    standard_problems,
)
from planners.eigenaxis import BangCoastBangProfile, EigenaxisReference
from planners.errors import ConformanceError

PROBLEMS = standard_problems()


class CubicReference(Reference):
    """The extension guide's cubic eigenaxis slew, with a symbolic evaluator written independently
    (``rate_sign = -1``: the sign slip in ω; ``clamp = False``: t not clamped to [0, T])."""

    def __init__(self, problem: ManeuverProblem, rate_sign: float = 1.0, clamp: bool = True) -> None:
        assert problem.qf is not None
        rotation = quat.to_rotation_vector(quat.error(problem.qf, problem.q0))
        self.angle = float(np.linalg.norm(rotation))
        self.axis = rotation / self.angle
        self.q0, self.rate_sign, self.clamp = problem.q0, rate_sign, clamp
        super().__init__("cubic_closed_form", problem.duration, problem.spacecraft.inertia)

    def _evaluate(self, t: np.ndarray) -> ReferenceSample:
        s = t / self.duration
        theta = self.angle * (3 * s**2 - 2 * s**3)
        rate = self.angle * (6 * s - 6 * s**2) / self.duration
        acceleration = self.angle * (6 - 12 * s) / self.duration**2
        q = quat.product(self.q0, quat.from_axis_angle(self.axis, theta))
        omega, omega_dot = rate[:, None] * self.axis, acceleration[:, None] * self.axis
        return ReferenceSample(q, omega, omega_dot, inverse_dynamics_torque(self.inertia, omega, omega_dot))

    def symbolic_evaluator(self) -> ca.Function:
        t = ca.SX.sym("t")
        s = (ca.fmin(ca.fmax(t, 0.0), self.duration) if self.clamp else t) / self.duration
        theta = self.angle * (3 * s**2 - 2 * s**3)
        rate = self.angle * (6 * s - 6 * s**2) / self.duration
        acceleration = self.angle * (6 - 12 * s) / self.duration**2
        axis, inertia = ca.DM(self.axis), ca.DM(self.inertia)
        q = quat_casadi.product(ca.DM(self.q0), quat_casadi.from_axis_angle(axis, theta))
        omega, omega_dot = self.rate_sign * rate * axis, acceleration * axis
        torque = ca.mtimes(inertia, omega_dot) + ca.cross(omega, ca.mtimes(inertia, omega))
        return ca.Function("reference", [t], [ca.vertcat(q, omega, omega_dot, torque)], ["t"], ["row"])


class CubicClosedForm(Planner):
    """A plugin planner that declares ``closed_form`` (not registered unless a test does)."""

    name = "cubic_closed_form"
    closed_form = True
    rate_sign, clamp = 1.0, True

    @dataclass(frozen=True)
    class Options:
        pass

    def problem_error(self, problem: ManeuverProblem) -> str | None:
        if np.any(problem.omega0) or (problem.omegaf is not None and np.any(problem.omegaf)):
            return "rest to rest only"
        return super().problem_error(problem)

    def _plan(self, problem: ManeuverProblem) -> Reference:
        return CubicReference(problem, self.rate_sign, self.clamp)


class SignSlip(CubicClosedForm):
    rate_sign = -1.0


class Unclamped(CubicClosedForm):
    clamp = False


class NoEvaluator(CubicClosedForm):
    """Declares ``closed_form`` but its reference keeps the default ``symbolic_evaluator`` (None)."""

    def _plan(self, problem: ManeuverProblem) -> Reference:
        reference = super()._plan(problem)
        reference.symbolic_evaluator = lambda: None  # type: ignore[method-assign]
        return reference


class Undeclared(CubicClosedForm):
    """Does not declare ``closed_form``; its reference's evaluator records being asked (and is wrong)."""

    name = "cubic_undeclared"
    closed_form = False
    rate_sign = -1.0
    asked: typing.ClassVar[list[str]] = []

    def _plan(self, problem: ManeuverProblem) -> Reference:
        reference = super()._plan(problem)
        evaluator = reference.symbolic_evaluator
        reference.planner = self.name

        def asked() -> ca.Function:
            Undeclared.asked.append(reference.planner)
            return evaluator()

        reference.symbolic_evaluator = asked  # type: ignore[method-assign]
        return reference


def accepted(planner: Planner) -> dict[str, ManeuverProblem]:
    return {key: problem for key, problem in PROBLEMS.items() if planner.problem_error(problem) is None}


@pytest.fixture
def registry():
    """``PLANNERS``, restored after the test."""
    saved = dict(PLANNERS)
    yield PLANNERS
    PLANNERS.clear()
    PLANNERS.update(saved)


def _vector(text: str) -> np.ndarray:
    return np.array([float(v) for v in text.split(",")])


def test_a_correct_plugin_evaluator_passes_on_every_problem_it_accepts():
    planner = CubicClosedForm()
    problems = accepted(planner)
    assert set(problems) == {"rest_to_rest", "non_principal", "gravity_gradient"}
    for problem in problems.values():
        check_reference(problem, planner.plan(problem), planner)


def test_a_sign_slip_in_omega_fails_naming_the_planner_time_field_and_both_values(registry):
    planner = SignSlip()
    problem = PROBLEMS["non_principal"]
    reference = planner.plan(problem)
    for check in ("finite", "boundary", "ends", "kinematics", "dynamics", "vectorised", "after_end"):
        CHECKS[check](problem, reference)  # the numeric reference is right ...
    with pytest.raises(ConformanceError) as caught:
        check_reference(problem, reference, planner)  # ... its exported C would not be
    message = str(caught.value)
    assert message.startswith("cubic_closed_form: the symbolic evaluator")
    match = re.search(r"at t = (\S+) s .* in ω: symbolic_evaluator gives \[(.*?)\] but sample gives \[(.*?)\]", message)
    assert match, message
    t = float(match.group(1))
    assert 0.0 < t < problem.duration
    # the values named are the reference's ω at that time and its negative (the slip)
    s = t / problem.duration
    axis = reference.axis
    rate = reference.angle * (6 * s - 6 * s**2) / problem.duration
    np.testing.assert_allclose(_vector(match.group(3)), rate * axis, rtol=1e-12)
    np.testing.assert_allclose(_vector(match.group(2)), -rate * axis, rtol=1e-12)
    # the same failure through the registry (the planner not passed) and undeclared-unknown (not registered)
    with pytest.raises(ConformanceError, match="in ω:"):
        check_closed_form(reference)  # not registered: the evaluator offered is checked
    registry[SignSlip.name] = SignSlip
    with pytest.raises(ConformanceError, match="in ω:"):
        CHECKS["closed_form"](problem, reference)


def test_an_evaluator_that_does_not_clamp_t_fails_after_T():
    planner = Unclamped()
    problem = PROBLEMS["rest_to_rest"]
    reference = planner.plan(problem)
    with pytest.raises(ConformanceError, match=r"after T, clamped to T\) in q:"):
        check_closed_form(reference, planner)


class LateSwitch(BangCoastBangProfile):
    """The bang-coast-bang profile whose symbolic form switches at ``t <= ramp`` instead of ``t < ramp``:
    wrong at the breakpoint's instant only."""

    def symbolic(self, t: ca.SX) -> tuple[ca.SX, ca.SX, ca.SX]:
        a, w, ramp = self.alpha, self.rate_max, self.ramp
        late = ca.fmax(self.duration - t, 0.0)
        accelerating, decelerating = t <= ramp, t > ramp + self.coast
        position = ca.if_else(accelerating, 0.5 * a * t**2, ca.if_else(
            decelerating, self.angle - 0.5 * a * late**2, 0.5 * a * ramp**2 + w * (t - ramp)))
        rate = ca.if_else(accelerating, a * t, ca.if_else(decelerating, a * late, w))
        acceleration = ca.if_else(accelerating, a, ca.if_else(decelerating, -a, 0.0))
        return position, rate, acceleration


def test_a_switch_on_the_wrong_side_of_a_breakpoint_fails_there():
    planner = PLANNERS["eigenaxis"]({"profile": "trapezoidal"})
    problem = PROBLEMS["rest_to_rest"]
    good = planner.plan(problem)
    assert isinstance(good, EigenaxisReference) and good.breakpoints.size == 2
    profile = copy.copy(good.profile)
    profile.__class__ = LateSwitch
    slipped = EigenaxisReference(good.q0, good.axis, profile, good.duration, good.inertia, good.message, problem)
    np.testing.assert_array_equal(slipped.breakpoints, good.breakpoints)
    with pytest.raises(ConformanceError, match="in ω̇:") as caught:
        check_closed_form(slipped, planner)
    t = float(re.search(r"at t = (\S+) s", str(caught.value)).group(1))
    assert t == pytest.approx(good.profile.ramp, rel=1e-12)


def test_eigenaxis_passes_with_every_profile_on_every_standard_problem():
    cls = PLANNERS["eigenaxis"]
    assert cls.closed_form
    profiles = {options["profile"] for options in cls.example_options}
    assert profiles == set(typing.get_args(typing.get_type_hints(cls.Options, include_extras=False)["profile"]))
    checked = 0
    for options in cls.example_options:
        planner = cls(options)
        for problem in accepted(planner).values():
            reference = planner.plan(problem)
            assert reference.ok, reference.message
            check_closed_form(reference, planner)
            CHECKS["closed_form"](problem, reference)  # through the registry
            checked += 1
    assert checked >= 12


def test_a_planner_declaring_closed_form_without_an_evaluator_fails():
    planner = NoEvaluator()
    with pytest.raises(ConformanceError, match="declares closed_form but .* returns None"):
        check_closed_form(planner.plan(PROBLEMS["rest_to_rest"]), planner)


def test_an_evaluator_of_the_wrong_shape_fails():
    planner = CubicClosedForm()
    reference = planner.plan(PROBLEMS["rest_to_rest"])
    full = reference.symbolic_evaluator()
    t = ca.SX.sym("t")
    reference.symbolic_evaluator = lambda: ca.Function("reference", [t], [full(t)[:7]])  # type: ignore[method-assign]
    with pytest.raises(ConformanceError, match=r"outputs of shapes \[\(7, 1\)\]"):
        check_closed_form(reference, planner)


def test_a_planner_without_closed_form_is_not_asked(registry):
    planner = Undeclared()
    problem = PROBLEMS["rest_to_rest"]
    reference = planner.plan(problem)
    Undeclared.asked.clear()
    check_reference(problem, reference, planner)  # its evaluator is wrong (the slip), but never exported
    registry[Undeclared.name] = Undeclared
    check_reference(problem, reference)  # the registered planner's declaration
    assert Undeclared.asked == []
    del registry[Undeclared.name]
    with pytest.raises(ConformanceError, match="in ω:"):
        check_reference(problem, reference)  # the declaration unknown: the evaluator offered is checked
    assert Undeclared.asked == ["cubic_undeclared"]
