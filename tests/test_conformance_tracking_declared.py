"""A law's ``tracks_reference`` declaration is checked, not trusted.

The checks run a law along a reference only if it declares ``tracks_reference``; the default
``False`` says it regulates to the target whatever the reference. A user's law written as the
controller guide showed (a PD with the reference's feed-forward, the flag unset) was therefore
checked in regulation alone, where ``τ* = 0``: its symbolic form could leave the feed-forward out
and pass, while the simulator (which gives every law the reference) ran that symbolic form along
the reference. Each law below is the guide's PD or a registered law with one such defect.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Any, ClassVar

import casadi as ca
import numpy as np
import pytest

from controllers import Controller, EigenaxisPD
from controllers.conformance import CHECKS, check_controller
from controllers.errors import ConformanceError
from ocp import Command, Measurement, Spacecraft, quat, quat_casadi
from ocp.dynamics.layout import split_measurement
from ocp.options import Range


class QuaternionPD(Controller):
    """The controller guide's law, without its ``tracks_reference = True``: it reads ``q*``, ``ω*``
    and ``τ*``, ``u = τ* − k_p I vec(q_e) − k_d I (ω − ω*)``."""

    name = "quaternion_pd"

    @dataclass(frozen=True)
    class Options:
        kp: Annotated[float, Range(ge=0.0)] = 0.06
        kd: Annotated[float, Range(ge=0.0)] = 0.48

    def reset(self, spacecraft: Spacecraft, sample_time: float, target: Any = None) -> None:
        super().reset(spacecraft, sample_time, target)
        self.stiffness = self.options.kp * spacecraft.inertia
        self.damping = self.options.kd * spacecraft.inertia

    def __call__(self, t: float, measurement: Measurement, reference: Any) -> Command:
        row = self.reference_rows(reference, np.array([t]))[0]
        q_e = quat.error(measurement.q, row[0:4])
        torque = -self.stiffness @ q_e[1:4] - self.damping @ (measurement.omega - row[4:7]) + row[10:13]
        return self.allocate(torque, measurement)

    def _law(self, t: ca.SX, y: ca.SX, z: ca.SX, r: ca.SX) -> tuple[ca.SX, ca.SX]:
        q, omega, _, _ = split_measurement(y, self.spacecraft.n_wheels)
        q_e = quat_casadi.error(q, r[0:4])
        torque = -ca.mtimes(ca.DM(self.stiffness), q_e[1:4]) - ca.mtimes(ca.DM(self.damping), omega - r[4:7])
        return self.allocate_symbolic(torque + self.feedforward(r), y), z

    def feedforward(self, r: ca.SX) -> ca.SX:
        return r[10:13]


class BadPD(QuaternionPD):
    """The user's case: the symbolic form leaves the feed-forward out (``__call__`` keeps it)."""

    name = "bad_pd"

    def feedforward(self, r: ca.SX) -> ca.SX:
        return ca.SX.zeros(3)


class BadPDTracks(BadPD):
    """The same defect in a law that declares it tracks."""

    name = "bad_pd_tracks"
    tracks_reference = True


class TracksSymbolically(EigenaxisPD):
    """A regulator (``__call__`` ignores the reference) whose symbolic form reads its setpoint
    from ``r``, as it does when built for code generation: in the simulator it would track."""

    def _law(self, t: ca.SX, y: ca.SX, z: ca.SX, r: ca.SX) -> tuple[ca.SX, ca.SX]:
        self.tracks_reference = True   # the parent's _law then takes its rows from r
        try:
            return super()._law(t, y, z, r)
        finally:
            del self.tracks_reference


class Regulator(Controller):
    """A quaternion PD regulator to the target that never looks at the reference; it records the
    references it is given."""

    name = "regulator"
    given: ClassVar[list[Any]] = []

    @dataclass(frozen=True)
    class Options:
        kp: Annotated[float, Range(ge=0.0)] = 0.06
        kd: Annotated[float, Range(ge=0.0)] = 0.48

    def __call__(self, t: float, measurement: Measurement, reference: Any) -> Command:
        Regulator.given.append(reference)
        q_e = quat.error(measurement.q, self.target[0])
        inertia, omega = self.spacecraft.inertia, measurement.omega
        torque = -self.options.kp * inertia @ q_e[1:4] - self.options.kd * inertia @ omega
        return self.allocate(torque, measurement)


UNDECLARED = r"set tracks_reference = True"


@pytest.mark.parametrize("law,message", [
    (BadPD(), (r"bad_pd \(defaults\) on three_wheels, sample 0 \(t = [0-9.]+ s\): __call__ gives u = .* along a "
               r"planned reference \(eigenaxis\) but .* regulating to the same target")),
    (QuaternionPD(), r"quaternion_pd \(defaults\) on three_wheels, .*__call__ gives u = .* along a planned reference"),
    (TracksSymbolically(), (r"eigenaxis_pd \(defaults\) on three_wheels, sample 0 .*: the symbolic law gives u = "
                            r".* with a planned reference's rows r \(eigenaxis\) but .* with the target's")),
], ids=["BadPD", "QuaternionPD", "TracksSymbolically"])
def test_a_law_that_reads_the_reference_without_declaring_it_fails(law, message):
    with pytest.raises(ConformanceError, match=message) as error:
        check_controller(law)
    assert UNDECLARED in str(error.value)


def test_a_law_that_declares_it_tracks_is_checked_along_the_reference():
    CHECKS["ignores_reference"](BadPDTracks())   # declared: not this check's business
    with pytest.raises(ConformanceError, match=r"bad_pd_tracks \(defaults\) on three_wheels, tracking, sample 0: "
                                               r"the symbolic law gives u ="):
        check_controller(BadPDTracks())


def test_a_law_that_ignores_the_reference_passes_once_given_one():
    Regulator.given.clear()
    check_controller(Regulator())
    assert any(reference is not None for reference in Regulator.given), "the checks never gave it a reference"
