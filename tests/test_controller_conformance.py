"""Every registered controller against the controller contract (as tests/test_planner_conformance.py
does for planners), and laws broken on purpose that each check must catch.

For each entry of ``CONTROLLERS`` and each option set of :func:`controllers.conformance.option_variants`
(the defaults, each option changed alone, all changed at once), every check of
:data:`controllers.conformance.CHECKS` runs: declared option ranges and refusals that name the
option, numeric = symbolic law, purity, the double cover, allocation (actuators present, pure wheel
mode, the same body motion whatever the actuators), no command at rest at the target, and a
converging closed loop. ``options`` checks a class, so it runs on the defaults only; the closed
loop of a single changed option runs with ``pytest -m slow``.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Any

import numpy as np
import pytest

from controllers import (
    CONTROLLERS,
    TDFC,
    BDot,
    Controller,
    EigenaxisPD,
    SingularRateTracking,
)
from controllers.conformance import (
    CHECKS,
    INERTIA,
    check_controller,
    describe_options,
    option_variants,
    standard_plants,
)
from controllers.errors import ConformanceError
from controllers.tracking.augmented_quaternion_feedback import (
    AugmentedQuaternionFeedback,
)
from ocp import Command, Measurement, SlewbenchError, quat
from ocp.options import Range

KNOWN_FAILURES = {
    ("costate_feedback", "closed_loop"): (
        "co-state feedback has almost no attitude feedback: P is fitted to a window of nearly equal states, so "
        "P (x − x_ref) vanishes for an attitude error (normal to q); 2 deg off the reference it ends 1.2 to 7.6 "
        "deg off (no torque after t_f). Reported to the lead; Vepa's law is shown on rate acquisition only."),
}


def _cases() -> list[Any]:
    cases = []
    for name in sorted(CONTROLLERS):
        variants = option_variants(CONTROLLERS[name])
        for index, options in enumerate(variants):
            for check in CHECKS:
                if check == "options" and index > 0:
                    continue  # a check of the class
                marks = []
                single = 0 < index < len(variants) - 1 or (index == 1 and len(variants) == 2)
                if check == "closed_loop" and single:
                    marks.append(pytest.mark.slow)
                if name == "costate_feedback" and index > 0:
                    marks.append(pytest.mark.slow)  # 9 ms a sample (a constrained fit at each)
                if (name, check) in KNOWN_FAILURES:
                    marks.append(pytest.mark.xfail(strict=True, raises=ConformanceError,
                                                   reason=KNOWN_FAILURES[name, check]))
                cases.append(pytest.param(name, options, check, marks=marks,
                                          id=f"{name}[{describe_options(options)}]-{check}"))
    return cases


@pytest.mark.parametrize("name,options,check", _cases())
def test_conformance(name, options, check):
    CHECKS[check](CONTROLLERS[name](options, path="controller.options"))


def test_conformance_error_is_a_slewbench_error_and_an_assertion():
    assert issubclass(ConformanceError, SlewbenchError) and issubclass(ConformanceError, AssertionError)


def test_every_law_runs_on_a_standard_plant_and_gets_non_default_options():
    plants = standard_plants()
    for name, cls in CONTROLLERS.items():
        law = cls()
        assert any(law.environment_error(p.problem.spacecraft, p.problem.environment) is None
                   for p in plants.values()), name
        if [f for f in cls.Options.__dataclass_fields__]:
            assert len(option_variants(cls)) > 1, f"{name}: no option set beyond the defaults"


def test_a_scalar_gain_becomes_a_non_symmetric_matrix():
    variants = option_variants(AugmentedQuaternionFeedback)
    matrix = np.array(next(v["kp"] for v in variants if isinstance(v.get("kp"), list)))
    assert np.max(np.abs(matrix - matrix.T)) > 0.1 * np.max(np.abs(matrix))
    assert np.linalg.eigvalsh(0.5 * (matrix + matrix.T)).min() > 0
    np.testing.assert_allclose(np.trace(matrix), 0.06 * np.trace(INERTIA @ np.diag([1.2, 0.9, 1.05])))


# --- a law written by a user, and laws broken on purpose -------------------------------------------

class UserPD(Controller):
    """A quaternion PD regulator written the way a user would, on the contract alone."""

    name = "user_pd"

    @dataclass(frozen=True)
    class Options:
        kp: Annotated[float, Range(ge=0.0)] = 0.06
        kd: Annotated[float, Range(ge=0.0)] = 0.48
        bias: Annotated[float, Range(ge=-1.0, le=1.0)] = 0.0

    hemisphere = True

    def torque(self, measurement: Measurement) -> np.ndarray:
        error = quat.product(quat.conjugate(self.target[0]), measurement.q)
        if self.hemisphere and error[0] < 0:
            error = -error
        inertia = self.spacecraft.inertia
        omega = measurement.omega
        return (-self.options.kp * inertia @ error[1:] - self.options.kd * inertia @ omega
                + np.cross(omega, inertia @ omega) + self.options.bias)

    def __call__(self, t, measurement, reference):
        return self.allocate(self.torque(measurement), measurement)


def test_a_correct_user_law_passes_every_check():
    check_controller(UserPD())
    check_controller(UserPD({"kp": 0.1, "kd": 0.3}))


class NoHemisphere(UserPD):
    """The error quaternion taken as it comes: −q commands the long way round."""

    hemisphere = False


class OwnWheelMap(UserPD):
    """Maps the torque to the wheels itself, forgetting the wheels' momentum ω × A h_w."""

    def __call__(self, t, measurement, reference):
        u = self.torque(measurement)
        spacecraft = self.spacecraft
        if spacecraft.torquers is not None:
            return Command(torque=u)
        return Command(wheel_torque=-np.linalg.pinv(spacecraft.wheel_axes) @ u)


class AsksMissingTorquers(UserPD):
    def __call__(self, t, measurement, reference):
        return Command(torque=self.torque(measurement))


class Flipped(UserPD):
    """The attitude feedback with the wrong sign."""

    def torque(self, measurement):
        error = quat.product(quat.conjugate(self.target[0]), measurement.q)
        error = -error if error[0] < 0 else error
        inertia, omega = self.spacecraft.inertia, measurement.omega
        return (self.options.kp * inertia @ error[1:] - self.options.kd * inertia @ omega
                + np.cross(omega, inertia @ omega))


class TransposedSymbolic(AugmentedQuaternionFeedback):
    """The symbolic form uses the transposed gain: the same law for the (symmetric) defaults."""

    def _law(self, t, y, z, r):
        stiffness = self.stiffness
        self.stiffness = stiffness.T
        try:
            return super()._law(t, y, z, r)
        finally:
            self.stiffness = stiffness


class SharedIntegral(UserPD):
    """An integral term kept on the class: reset clears it, but two instances share it."""

    shared = np.zeros(3)

    def reset(self, spacecraft, sample_time, target=None):
        super().reset(spacecraft, sample_time, target)
        self.shared[:] = 0.0

    def torque(self, measurement):
        self.shared += 1e-3 * measurement.omega
        return super().torque(measurement) - self.shared


class ForgetsReset(TDFC):
    """Keeps the delay buffer of the previous run."""

    def reset(self, spacecraft, sample_time, target=None):
        buffer = getattr(self, "_buffer", None)
        super().reset(spacecraft, sample_time, target)
        if buffer is not None:
            self._buffer = buffer


class ModifiesMeasurement(UserPD):
    def __call__(self, t, measurement, reference):
        measurement.omega *= 0.5
        return super().__call__(t, measurement, reference)


class BiasedBDot(BDot):
    def __call__(self, t, measurement, reference):
        command = super().__call__(t, measurement, reference)
        command.dipole = np.zeros(3) + 1e-3 if command.dipole is None else command.dipole + 1e-3
        return command


class PumpingBDot(BDot):
    """B-dot with the sign of the dipole flipped: it feeds the tumble."""

    def __call__(self, t, measurement, reference):
        command = super().__call__(t, measurement, reference)
        if command.dipole is not None:
            command.dipole = -command.dipole
        return command


class LeakyTwoWheel(SingularRateTracking):
    """A two-wheel law that also asks the torquers for what the wheels cannot give."""

    def __call__(self, t, measurement, reference):
        command = super().__call__(t, measurement, reference)
        if self.spacecraft.torquers is not None:
            command.torque = np.array([0.0, 0.0, 1e-4])
        return command


@dataclass(frozen=True)
class _UnrangedOptions(EigenaxisPD.Options):
    bias: float = 0.0


class UnrangedOption(EigenaxisPD):
    Options = _UnrangedOptions


@dataclass(frozen=True)
class _BareValueErrorOptions(EigenaxisPD.Options):
    def __post_init__(self) -> None:
        super().__post_init__()
        if isinstance(self.kd, float) and self.kd > 0.5:
            raise ValueError("kd is too large")


class BareValueError(EigenaxisPD):
    Options = _BareValueErrorOptions


@dataclass
class _MutableOptions:
    kp: Annotated[float, Range(ge=0.0)] = 0.06
    kd: Annotated[float, Range(ge=0.0)] = 0.48
    bias: Annotated[float, Range(ge=-1.0, le=1.0)] = 0.0


class MutableOptions(UserPD):
    Options = _MutableOptions


MATRIX = next(v for v in option_variants(AugmentedQuaternionFeedback) if isinstance(v.get("kp"), list))


@pytest.mark.parametrize("law,check,message", [
    (UnrangedOption(), "options", "declares no range"),
    (BareValueError(), "options", "without naming an option"),
    (MutableOptions(), "options", "frozen"),
    (TransposedSymbolic(MATRIX), "symbolic", "symbolic law gives"),
    (SharedIntegral(), "pure", "beside another instance"),
    (ForgetsReset(), "pure", "reset must clear"),
    (ModifiesMeasurement(), "pure", "changed measurement.omega"),
    (NoHemisphere(), "double_cover", "negating the measured quaternion"),
    (OwnWheelMap(), "allocation", "ω × A h_w"),
    (AsksMissingTorquers(), "allocation", "asks torque of a spacecraft that has none"),
    (LeakyTwoWheel(), "allocation", "wheels_only"),
    (UserPD({"bias": 1e-4}), "at_rest", "at the target at rest"),
    (BiasedBDot(), "at_rest", "at the target at rest"),
    (Flipped(), "closed_loop", "must converge"),
    (PumpingBDot(), "closed_loop", "remove energy"),
], ids=lambda v: type(v).__name__ if isinstance(v, Controller) else (v if v in CHECKS else ""))
def test_a_broken_law_fails_its_check(law, check, message):
    with pytest.raises(ConformanceError, match=message):
        CHECKS[check](law)


def test_defaults_hide_a_transposed_gain():
    CHECKS["symbolic"](TransposedSymbolic())  # symmetric default gains: nothing to see


@pytest.mark.parametrize("law,failing", [
    (NoHemisphere(), "double_cover"),
    (UserPD({"bias": 1e-4}), "at_rest"),
    (OwnWheelMap(), "allocation"),
], ids=["NoHemisphere", "Biased", "OwnWheelMap"])
def test_each_broken_law_fails_only_where_it_is_broken(law, failing):
    for name, check in CHECKS.items():
        if name == failing:
            with pytest.raises(ConformanceError):
                check(law)
        else:
            check(law)
