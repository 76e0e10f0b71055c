"""The ``none`` law declares that it needs no target (``needs_target_attitude = False``), so its
closed-loop key leaves the target out: one closed loop serves every target (counted in builds),
with the numbers of a loop built for that target alone; a law that needs a target keeps it in its key."""
from __future__ import annotations

import numpy as np

from controllers import CONTROLLERS
from ocp import AttitudeModel, ReactionWheels, SensorNoise, Simulator, Spacecraft, quat

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
