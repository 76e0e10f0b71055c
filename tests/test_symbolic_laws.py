"""Every registered controller's NumPy law (``__call__``) and its symbolic law agree (issue 13).

A controller that declares itself non-symbolic must say why. The check runs several successive
samples so that a law's state update (delay buffers, modes) is compared too, on spacecraft with
every kind of actuator, in tracking and in regulation, with each boolean option flipped.
"""
import dataclasses

import numpy as np
import pytest

from controllers import CONTROLLERS
from ocp import Magnetorquers, Measurement, ReactionWheels, Spacecraft, Torquers, quat
from ocp.dynamics.layout import measurement_vector
from planners.reference import ReferenceSample

SPACECRAFT = {
    "three_wheels": lambda: Spacecraft([[19.5, 0.3, -0.2], [0.3, 19.0, 0.1], [-0.2, 0.1, 12.6]],
                                       wheels=ReactionWheels.from_body_axes(max_torque=0.1)),
    "failed_wheel_and_torquers": lambda: Spacecraft(
        [2.0, 3.0, 4.0], wheels=ReactionWheels.from_body_axes(max_torque=0.1, failed=(1,)), torquers=Torquers(0.05)),
    "skewed_wheels": lambda: Spacecraft([2.0, 3.0, 4.0], wheels=ReactionWheels(
        np.array([[1, 0, 0, 0.577], [0, 1, 0, 0.577], [0, 0, 1, 0.577]]))),
    "two_wheels_and_magnetorquers": lambda: Spacecraft(
        [0.0109, 0.05, 0.05], wheels=ReactionWheels.from_body_axes(2), magnetorquers=Magnetorquers(0.2)),
    "torquers": lambda: Spacecraft([19.5, 19.0, 12.6], torquers=Torquers(0.1)),
    "magnetorquers": lambda: Spacecraft([0.0109, 0.05, 0.05], magnetorquers=Magnetorquers(0.2)),
}


class RandomReference:
    """A smooth made-up reference (its values need not be consistent: only agreement is tested)."""

    def __init__(self, rng):
        self.a, self.b, self.c = rng.standard_normal((3, 13))

    def sample(self, t):
        t = np.atleast_1d(np.asarray(t, dtype=float))[:, None]
        values = self.a + self.b * np.sin(0.3 * t + self.c)
        q = values[:, 0:4] / np.linalg.norm(values[:, 0:4], axis=1, keepdims=True)
        return ReferenceSample(q, 0.1 * values[:, 4:7], 0.01 * values[:, 7:10], 0.01 * values[:, 10:13])


def option_variants(cls):
    """The defaults, and each boolean option flipped on its own."""
    variants = [{}]
    for field in dataclasses.fields(cls.Options):
        if isinstance(field.default, bool):
            variants.append({field.name: not field.default})
    return variants


def random_measurement(rng, spacecraft, t):
    field = rng.normal(0.0, 3e-5, 3) if spacecraft.magnetorquers is not None else None
    return Measurement(t, quat.random_unit(rng), rng.normal(0, 0.3, 3), rng.normal(0, 1.0, spacecraft.n_wheels), field)


@pytest.mark.parametrize("name", sorted(CONTROLLERS))
def test_numpy_and_symbolic_laws_agree(name, rng):
    cls = CONTROLLERS[name]
    reason = cls().symbolic_error()
    if reason is not None:  # a law that cannot be symbolic says why, and refuses to build one
        assert isinstance(reason, str) and len(reason) > 40
        with pytest.raises(NotImplementedError, match="."):
            cls().symbolic_law()
        return
    checked = 0
    for kind, build in SPACECRAFT.items():
        for options in option_variants(cls):
            for tracking in (True, False):
                controller = cls(options)
                spacecraft = build()
                if getattr(controller, "wheels_only", False) and controller.environment_error(spacecraft, None):
                    continue  # a two-wheel law takes only spacecraft whose working wheels span a plane
                sample_time = float(rng.uniform(0.05, 2.0))
                if controller.sample_time_error(sample_time):  # e.g. tdfc: τ (2 s) a multiple of T_s
                    sample_time = 2.0 / int(rng.integers(1, 4))
                    assert controller.sample_time_error(sample_time) is None
                target = (quat.random_unit(rng), rng.normal(0, 0.05, 3) if rng.uniform() < 0.5 else None)
                reference = RandomReference(rng) if tracking else None
                if controller.needs_reference and reference is None:
                    continue
                controller.reset(spacecraft, sample_time, target=target)
                law = controller.symbolic_law()
                z = law.state0
                np.testing.assert_array_equal(z, controller.state_vector())
                for k in range(4):
                    t = k * sample_time
                    measurement = random_measurement(rng, spacecraft, t)
                    r = controller.reference_rows(reference, np.array([t, t + sample_time])).ravel()
                    u, z_next = (v.full().ravel() for v in law.function(t, measurement_vector(measurement), z, r))
                    command = controller(t, measurement, reference)
                    expected = controller.command_vector(command)
                    scale = max(1.0, float(np.max(np.abs(expected))))
                    np.testing.assert_allclose(u, expected, rtol=0, atol=1e-12 * scale,
                                               err_msg=f"{name} on {kind} with {options}, tracking={tracking}, k={k}")
                    np.testing.assert_allclose(z_next, controller.state_vector(), rtol=0, atol=1e-12)
                    z = z_next
                checked += 1
    assert checked > 0
