"""The model's fingerprint (the key of built solvers) describes the spacecraft and environment only.

A frozen ``Spacecraft`` memoises derived values (``body_torque_limit``, a controller's description)
in a private cache; the fingerprint must not depend on whether those were computed before, or two
identical models key their solvers differently (a needless rebuild per run).
"""
from __future__ import annotations

from ocp import AttitudeModel, ReactionWheels, Spacecraft


def _spacecraft(moments: list[float]) -> Spacecraft:
    return Spacecraft(moments, wheels=ReactionWheels.from_body_axes(max_torque=0.1))


def test_fingerprint_does_not_depend_on_the_spacecraft_memo() -> None:
    fresh = AttitudeModel(_spacecraft([1.0, 2.0, 2.5])).fingerprint
    used = _spacecraft([1.0, 2.0, 2.5])
    used.body_torque_limit()          # fills the spacecraft's private cache
    assert AttitudeModel(used).fingerprint == fresh


def test_fingerprint_still_tells_different_spacecraft_apart() -> None:
    assert AttitudeModel(_spacecraft([1.0, 2.0, 2.5])).fingerprint != AttitudeModel(_spacecraft([1.0, 2.0, 2.6])).fingerprint
