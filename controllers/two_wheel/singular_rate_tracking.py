"""Singular nonlinear rate-tracking law, the paper's snlc (Horri & Palmer eq. 14/24):
``u_i = −K (ω_i − ωd_i) + I_i ω̇d_i`` on the two actuated axes, with ωd of eq. 7/8.

``K`` is in N m s/rad, as the units printed with eq. 31 say (eq. 14 writes ``I_i K_i``, i.e. K in
1/s; with the paper's K = 10 that reading gives 400 N m s/rad, and with the 1 s hold the rate
error is multiplied by 1 − 10 = −9 per sample: the loop diverges). Under zero momentum ``I ω̇ = u``
(eq. 4): the law's torque is applied by the wheels as it is, ``N = −ḣ``.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Any

import casadi as ca

from controllers.two_wheel.singular_rates import (
    SingularGains,
    desired_rates,
    desired_rates_symbolic,
    rate_tracking_torque,
)
from controllers.two_wheel.singular_zero_momentum import check_singular_gains
from controllers.two_wheel.underactuated import TwoWheelLaw
from ocp import Command, Measurement, Spacecraft
from ocp.options import Range


class SingularRateTracking(TwoWheelLaw):
    """Full-state two-wheel law tracking the singular desired rates (see the module docstring)."""

    name = "singular_rate_tracking"

    @dataclass(frozen=True)
    class Options:
        """Options of ``singular_rate_tracking`` (the YAML keys under the controller's ``options``; defaults: the
        paper's gains, Horri & Palmer section VI).

        Parameters
        ----------
        k : float, > 0
            k [rad/s], gain on the actuated components ``q1``, ``q2`` of the error quaternion in the
            desired rates (eq. 7/8). Default 0.02 rad/s (paper, section VI).
        g : float, > 0
            g [rad/s], gain of the singular term ``q2 q3 / D``, ``q1 q3 / D``; must exceed ``2 k``
            (section III.C: ``q3`` must vanish faster than ``q1² + q2²``). Default 0.08 rad/s.
        K : float, > 0
            K [N m s/rad], rate-tracking gain ``u_i = −K (ω_i − ωd_i) + I_i ω̇d_i`` (eq. 14/24 with
            eq. 31's units; reading eq. 14's ``I_i K_i`` as K in 1/s makes the paper's K = 10
            diverge under a 1 s hold). Default 10 N m s/rad.
        a1, a2 : float > 0 or None
            Saturation limits of the singular ratios ``q2 q3 / D`` and ``q1 q3 / D`` (dimensionless,
            eq. 8); ``null``: the unsaturated eq. 7. Default 0.025.
        epsilon_D : float, >= 0
            ε_D, added to ``D = q1² + q2²`` (dimensionless): the regularisation the paper used in
            orbit (end of section IV.B). Default 0: eq. 7/8 as printed.
        """

        k: Annotated[float, Range(gt=0.0)] = 0.02
        g: Annotated[float, Range(gt=0.0)] = 0.08
        K: Annotated[float, Range(gt=0.0)] = 10.0
        a1: Annotated[float | None, Range(gt=0.0)] = 0.025
        a2: Annotated[float | None, Range(gt=0.0)] = 0.025
        epsilon_D: Annotated[float, Range(ge=0.0)] = 0.0

        def __post_init__(self) -> None:
            check_singular_gains("g", self.k, self.g)

    def reset(self, spacecraft: Spacecraft, sample_time: float, target: Any = None) -> None:
        super().reset(spacecraft, sample_time, target)
        o = self.options
        self.gains = SingularGains(o.k, o.g, o.a1, o.a2, o.epsilon_D)

    def torque(self, measurement: Measurement) -> tuple[float, float]:
        """The law's torque on the actuated axes.

        Parameters
        ----------
        measurement : Measurement
            The sample's measured attitude and body rate.

        Returns
        -------
        tuple of 2 float
            ``(u1, u2)`` [N m], control frame.
        """
        q0, q1, q2, q3, w1, w2, w3 = self.error(measurement)
        rates = desired_rates(q0, q1, q2, q3, w1, w2, w3, self.gains)
        return rate_tracking_torque(w1, w2, rates, self.options.K, self.moments[:2])

    def __call__(self, t: float, measurement: Measurement, reference: Any) -> Command:
        return self.command_torque(*self.torque(measurement), measurement)

    def _law(self, t: ca.SX, y: ca.SX, z: ca.SX, r: ca.SX) -> tuple[ca.SX, ca.SX]:
        q, w = self.error_symbolic(y)
        rates = desired_rates_symbolic(q, w, self.gains)
        u1, u2 = rate_tracking_torque(w[0], w[1], rates, self.options.K, self.moments[:2])
        return self.command_symbolic(u1, u2, y), z
