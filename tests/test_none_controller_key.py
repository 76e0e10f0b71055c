"""The ``none`` law declares that it needs no target (``needs_target_attitude = False``), so its
closed-loop key leaves the target out: one closed loop serves every target (counted in builds),
with the numbers of a loop built for that target alone; a law that needs a target keeps it in its key."""
from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from controllers import CONTROLLERS
from controllers.conformance import check_symbolic
from controllers.errors import ConformanceError
from controllers.none import NoControl
from ocp import (
    AttitudeModel,
    Command,
    ReactionWheels,
    SensorNoise,
    Simulator,
    Spacecraft,
    quat,
)

X0 = np.r_[quat.IDENTITY, 0.02, -0.01, 0.005, 0, 0, 0]
NOISE = SensorNoise(1e-3, 1e-4, seed=3)
TARGETS = [(quat.normalize(np.array(q, dtype=float)), omega) for q, omega in (
    ([0.6, 0.2, -0.5, 0.3], None), ([0.0, 1.0, 0.0, 0.0], None), ([0.5, 0.5, 0.5, 0.5], np.zeros(3)))]


def _model() -> AttitudeModel:
    spacecraft = Spacecraft([2.0, 3.0, 4.0], wheels=ReactionWheels.from_body_axes(max_torque=0.05, max_momentum=0.3))
    return AttitudeModel(spacecraft)


def _run(model: AttitudeModel, name: str, target, options=None):
    simulator = Simulator(model, 1.0)
    return simulator, simulator.run(CONTROLLERS[name](options), X0, 20.0, target=target, noise=NOISE)


def test_the_none_law_builds_one_closed_loop_for_every_target():
    model = _model()
    simulator, first = _run(model, "none", TARGETS[0])
    builds = simulator.loop_cache.builds
    assert builds > 0 and first.path == "interpreted"
    for target in TARGETS[1:]:
        simulator, result = _run(model, "none", target)
        assert simulator.loop_cache.builds == builds, target  # nothing built for another target
        fresh = _run(_model(), "none", target)[1]  # a loop built for this target alone
        np.testing.assert_array_equal(result.x, fresh.x)
        np.testing.assert_array_equal(result.commanded_u, fresh.commanded_u)


def test_the_key_holds_the_target_only_for_a_law_that_needs_one():
    spacecraft = _model().spacecraft
    keys: dict[str, set[str]] = {}
    for name, options in (("none", None), ("augmented_quaternion_feedback", {"kp": 0.2, "kd": 0.8})):
        law = CONTROLLERS[name](options)
        for target in TARGETS:
            law.reset(spacecraft, 1.0, target=target)
            keys.setdefault(name, set()).add(law.symbolic_key())
    assert not CONTROLLERS["none"].needs_target_attitude
    assert len(keys["none"]) == 1
    assert len(keys["augmented_quaternion_feedback"]) == len(TARGETS)


class _BakesTheTarget(NoControl):
    """A law that says it needs no target but bakes the target's second quaternion component into
    its wheel torques: its build for one target is wrong for the next."""

    name = "bakes_the_target"

    def _torque(self) -> float:
        q_f = None if self.target is None else self.target[0]
        return 0.0 if q_f is None else 1e-3 * float(q_f[1])

    def __call__(self, t, measurement, reference):
        wheels = self._slices.get("wheels")
        return Command() if wheels is None else Command(wheel_torque=np.full(wheels.stop - wheels.start, self._torque()))

    def _law(self, t, y, z, r):
        u = ca.SX.zeros(self._nu)
        if "wheels" in self._slices:
            u[self._slices["wheels"]] = self._torque()
        return u, z


def test_conformance_refuses_a_law_that_needs_no_target_but_bakes_one_in():
    check_symbolic(CONTROLLERS["none"]())  # the none law bakes none in
    with pytest.raises(ConformanceError, match="the symbolic law gives u"):
        check_symbolic(_BakesTheTarget())
