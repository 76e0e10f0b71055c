"""The model's fingerprint (the key of built solvers) describes the spacecraft and environment only.

A frozen ``Spacecraft`` memoises derived values (``body_torque_limit``, a controller's description)
in a private cache; the fingerprint must not depend on whether those were computed before, or two
identical models key their solvers differently (a needless rebuild per run).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from ocp import AttitudeModel, CircularOrbit, Environment, ReactionWheels, Spacecraft


def _spacecraft(moments: list[float]) -> Spacecraft:
    return Spacecraft(moments, wheels=ReactionWheels.from_body_axes(max_torque=0.1))


def test_fingerprint_does_not_depend_on_the_spacecraft_memo() -> None:
    fresh = AttitudeModel(_spacecraft([1.0, 2.0, 2.5])).fingerprint
    used = _spacecraft([1.0, 2.0, 2.5])
    used.body_torque_limit()          # fills the spacecraft's private cache
    assert AttitudeModel(used).fingerprint == fresh


def test_fingerprint_still_tells_different_spacecraft_apart() -> None:
    assert AttitudeModel(_spacecraft([1.0, 2.0, 2.5])).fingerprint != AttitudeModel(_spacecraft([1.0, 2.0, 2.6])).fingerprint


# --- every number exactly, however deep; an object it cannot state is equal to no other ----------

@dataclass(frozen=True)
class _TableField:
    """A field model holding its numbers in a dict: a nested value the fingerprint must read exactly."""

    coefficients: dict[str, np.ndarray]

    def field_inertial(self, position: Any, t: Any) -> Any:
        return ca.DM(self.coefficients["b"])


class _OpaqueField:
    """A field model that is no dataclass, with a repr that drops its number."""

    def __init__(self, strength: float) -> None:
        self.strength = strength

    def field_inertial(self, position: Any, t: Any) -> Any:
        return ca.DM([self.strength, 0.0, 0.0])

    def __repr__(self) -> str:
        return "_OpaqueField()"


def _model(field: Any) -> AttitudeModel:
    environment = Environment(orbit=CircularOrbit(altitude=500e3), magnetic_field=field)
    return AttitudeModel(_spacecraft([1.0, 2.0, 2.5]), environment)


def test_fingerprint_tells_apart_models_that_differ_only_deep_in_a_nested_value() -> None:
    b = np.array([2e-5, -1e-5, 3e-5])
    nudged = b.copy()
    nudged[1] = np.nextafter(nudged[1], 0.0)  # one bit of one number inside a dict inside the field
    assert _model(_TableField({"b": b})).fingerprint != _model(_TableField({"b": nudged})).fingerprint
    assert _model(_TableField({"b": b})).fingerprint == _model(_TableField({"b": b.copy()})).fingerprint


def test_an_object_the_fingerprint_cannot_state_makes_the_model_equal_to_no_other() -> None:
    """As documented (AttitudeModel.fingerprint): its own fingerprint, never another model's."""
    assert _model(_OpaqueField(2e-5)).fingerprint != _model(_OpaqueField(3e-5)).fingerprint
    same = _OpaqueField(2e-5)
    assert _model(same).fingerprint != _model(same).fingerprint
    model = _model(same)
    assert model.fingerprint == model.fingerprint  # a model agrees with itself


def test_an_object_the_fingerprint_cannot_state_keys_the_same_while_it_lives() -> None:
    """The same environment object in two models: equal fingerprints (they build the same
    functions); and a controller whose options hold a callable keys its law the same on every call,
    so its closed loop is built once, not per run (a token drawn per call rebuilt it; found by a
    review, 2026-12-03)."""
    import dataclasses

    from controllers import CONTROLLERS
    from ocp import ReactionWheels, Spacecraft

    environment = Environment(orbit=CircularOrbit(altitude=500e3), magnetic_field=_OpaqueField(2e-5))
    spacecraft = _spacecraft([1.0, 2.0, 2.5])
    assert AttitudeModel(spacecraft, environment).fingerprint == AttitudeModel(spacecraft, environment).fingerprint
    assert _model(_OpaqueField(2e-5)).fingerprint != _model(_OpaqueField(2e-5)).fingerprint

    @dataclasses.dataclass(frozen=True)
    class Scheduled:
        kp: float = 0.2
        kd: float = 0.6
        schedule: Any = _OpaqueField(1.0)  # a plugin law's gain schedule, say

    law = CONTROLLERS["augmented_quaternion_feedback"]({"kp": 0.2, "kd": 0.6})
    law.reset(Spacecraft(np.diag([3.0, 3.5, 4.0]), wheels=ReactionWheels(np.eye(3), max_torque=0.05)), 1.0)
    object.__setattr__(law, "options", Scheduled())
    assert law.symbolic_key() == law.symbolic_key()
    other = Scheduled(schedule=_OpaqueField(1.0))
    first = law.symbolic_key()
    object.__setattr__(law, "options", other)
    assert law.symbolic_key() != first
