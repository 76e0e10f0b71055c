"""The conformance checks name the defect a user made, not what it breaks further on.

A NaN in a reference or a command, a quaternion that is not of unit norm, a law that returns the
wrong type or shape: each was reported as another defect (a vectorisation bug, a ``reset`` that
does not clear the state, a symbolic mismatch) or as a bare Python error from deep inside the
library. Each case below is a correct reference or law with one such defect.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Annotated, Any

import numpy as np
import pytest

from controllers import Controller
from controllers.conformance import CHECKS as CONTROLLER_CHECKS
from controllers.conformance import check_controller
from controllers.errors import ConformanceError as ControllerConformanceError
from ocp import Command, Measurement, quat
from ocp.options import Range
from planners import PLANNERS, Reference, ReferenceSample
from planners.conformance import CHECKS as PLANNER_CHECKS
from planners.conformance import NORM_TOLERANCE, check_reference, standard_problems
from planners.errors import ConformanceError as PlannerConformanceError

PROBLEM = standard_problems()["rest_to_rest"]
GOOD = PLANNERS["eigenaxis"]({"profile": "smooth"}).plan(PROBLEM)


class Broken(Reference):
    """The eigenaxis reference with one quantity changed at some times."""

    def __init__(self, change: Any) -> None:
        super().__init__("broken", GOOD.duration, GOOD.inertia)
        self.change = change

    def _evaluate(self, t: np.ndarray) -> ReferenceSample:
        sample = GOOD.sample(t)
        return self.change(t, *(np.array(a) for a in sample))


def _nan_torque_mid(t, q, w, wd, u):
    u[np.abs(t - 0.5 * GOOD.duration) < 1e-9] = np.nan
    return ReferenceSample(q, w, wd, u)


def _nan_omega_window(t, q, w, wd, u):
    w[(t > 0.30 * GOOD.duration) & (t < 0.31 * GOOD.duration)] = np.nan
    return ReferenceSample(q, w, wd, u)


def _nan_q_late(t, q, w, wd, u):
    q[t > 0.7 * GOOD.duration] = np.nan
    return ReferenceSample(q, w, wd, u)


def _scaled_q(t, q, w, wd, u):
    return ReferenceSample(1.01 * q, w, wd, u)


def _nan_torque_alone(t, q, w, wd, u):  # the user's tq[len(t) // 2] = nan: NaN for one time alone
    u[len(t) // 2] = np.nan if len(t) == 1 else u[len(t) // 2]
    return ReferenceSample(q, w, wd, u)


def test_the_finiteness_check_runs_first():
    assert next(iter(PLANNER_CHECKS)) == "finite"
    assert list(CONTROLLER_CHECKS)[:2] == ["options", "commands"]


def test_the_unbroken_reference_passes():
    check_reference(PROBLEM, Broken(lambda t, *a: ReferenceSample(*a)))


@pytest.mark.parametrize("change,message", [
    (_nan_torque_mid, r"non-finite torque at t = 75 s \(0\.5 T\)"),
    # A NaN lasting T/100, between the finite-difference checks' 41 times: missed before.
    (_nan_omega_window, r"non-finite ω at t = 45\.075 s"),
    # Was "ValueError: cannot normalise a zero or non-finite quaternion" from ocp/quat.py.
    (_nan_q_late, r"non-finite q at t = 105\.075 s"),
    # Was accepted.
    (_scaled_q, r"has norm 1\.01, not 1 \(\|‖q‖ − 1\| = 0\.01 > 1e-06\)"),
], ids=["nan_torque", "nan_omega_window", "nan_q_late", "scaled_q"])
def test_a_non_finite_or_scaled_reference_is_named_as_such(change, message):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no numpy RuntimeWarning (it said "atol: nan") on the way
        with pytest.raises(PlannerConformanceError, match=message):
            check_reference(PROBLEM, Broken(change))


def test_the_norm_tolerance_is_the_stated_one():
    scale = 1.0 + 0.5 * NORM_TOLERANCE
    check_reference(PROBLEM, Broken(lambda t, q, w, wd, u: ReferenceSample(scale * q, w, wd, u)))


def test_a_wrong_shape_is_a_conformance_error():
    # Was a bare ValueError out of check_reference (Reference.sample's own words, kept).
    with pytest.raises(PlannerConformanceError, match=r"returned omega of shape \(2001,\); expected \(2001, 3\)"):
        check_reference(PROBLEM, Broken(lambda t, q, w, wd, u: ReferenceSample(q, np.linalg.norm(w, axis=1), wd, u)))


def test_a_value_non_finite_only_when_sampled_alone_is_named_so():
    with pytest.raises(PlannerConformanceError, match=r"non-finite torque at t = 0 s when sampled alone"):
        check_reference(PROBLEM, Broken(_nan_torque_alone))


# --- controllers -------------------------------------------------------------------------------------

class PD(Controller):
    """A quaternion PD regulator; ``bug`` breaks what it returns."""

    name = "diagnosis_pd"

    @dataclass(frozen=True)
    class Options:
        kp: Annotated[float, Range(ge=0.0)] = 0.06
        kd: Annotated[float, Range(ge=0.0)] = 0.48

    bug = "none"

    def symbolic_error(self) -> str:
        return "a test law written in Python only"

    def __call__(self, t: float, measurement: Measurement, reference: Any) -> Any:
        error = quat.error(measurement.q, self.target[0])
        inertia = self.spacecraft.inertia
        u = -self.options.kp * inertia @ error[1:] - self.options.kd * inertia @ measurement.omega
        if self.bug == "nan":
            u = u * np.nan
        if self.bug == "nan_at_target":  # an axis normalised by the error's size: 0/0 at the target
            size = np.linalg.norm(error[1:])
            with np.errstate(invalid="ignore"):
                u = -self.options.kp * inertia @ (error[1:] / size * np.arcsin(min(size, 1.0)))
            u = u - self.options.kd * inertia @ measurement.omega
        if self.bug == "four_vector_to_allocate":
            u = np.r_[u, 0.0]
        if self.bug == "ndarray":
            return u
        if self.bug == "four_vector_command":
            return Command(torque=np.r_[u, 0.0])
        return self.allocate(u, measurement)


def _law(bug: str) -> PD:
    law = type(f"PD_{bug}", (PD,), {"bug": bug})()
    return law


def test_the_unbroken_law_passes():
    check_controller(_law("none"))


@pytest.mark.parametrize("bug,message", [
    # Was "the symbolic law gives ..." (a symbolic law) or "reset must clear every state" (none).
    ("nan", r"non-finite command at t = [\d.]+ s: Command\.wheel_torque = \[nan, nan, nan\]"),
    # Passed: NaN only at the exact target, where the at-rest check compared NaN > limit (False).
    ("nan_at_target", r"with no error: non-finite command"),
    # Was "ValueError: too many values to unpack (expected 3)" from controllers/allocation.py.
    ("four_vector_to_allocate", (r"raised ValueError.*Controller\.allocate\(u, measurement\) failed: u must be "
                                 r"the rigid-body torque, 3 numbers")),
    # Was "AttributeError: 'numpy.ndarray' object has no attribute 'wheel_torque'" from ocp/dynamics/actuators.py.
    ("ndarray", r"__call__ returned ndarray .*it must return an ocp\.Command"),
    ("four_vector_command", r"Command\.torque at t = [\d.]+ s has shape \(4,\); expected \(3,\)"),
], ids=["nan", "nan_at_target", "four_vector_to_allocate", "ndarray", "four_vector_command"])
def test_a_broken_return_is_named_by_the_commands_check_first(bug, message):
    with pytest.raises(ControllerConformanceError, match=message):
        check_controller(_law(bug))
    with pytest.raises(ControllerConformanceError, match=message):
        CONTROLLER_CHECKS["commands"](_law(bug))


def test_every_check_calls_the_law_through_the_return_check():
    # The check that used to report the NaN law as a reset bug names the NaN now.
    with pytest.raises(ControllerConformanceError, match="non-finite command"):
        CONTROLLER_CHECKS["pure"](_law("nan"))
    with pytest.raises(ControllerConformanceError, match="non-finite command"):
        CONTROLLER_CHECKS["at_rest"](_law("nan_at_target"))
