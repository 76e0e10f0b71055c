"""Singular zero-momentum law (Horri & Palmer eq. 12-13): the wheels are given the momentum that
makes the body turn at the desired rates, ``h_i = −I_i ωd_i(q)``.

Under zero total angular momentum ``I ω + A h_w = 0``, so ``ω_i = −h_i / I_i`` on the actuated axes
and ``ω3 = 0``: setting the wheel momenta sets the body rate. The law feeds back the attitude and
the wheel momenta (the wheel-speed loop), never the body rate. Each sample the wheel torque that
brings the momentum to its demand over the hold is commanded, ``g = (h_demand − h_w) / Δt``; the
actuator model clips it to the wheel's torque limit (the paper's 20 mN m).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Any

import casadi as ca

from controllers.two_wheel.singular_rates import (
    SingularGains,
    desired_rates,
    desired_rates_symbolic,
)
from controllers.two_wheel.underactuated import TwoWheelLaw
from ocp import Command, Measurement, Spacecraft
from ocp.dynamics.layout import split_measurement
from ocp.errors import InvalidOption
from ocp.options import Range


class SingularZeroMomentum(TwoWheelLaw):
    """Attitude-only two-wheel law through the wheel momenta (see the module docstring)."""

    name = "singular_zero_momentum"

    @dataclass(frozen=True)
    class Options:
        """Options of ``singular_zero_momentum`` (the YAML keys under the controller's ``options``; defaults: the
        paper's gains, Horri & Palmer section VI).

        Parameters
        ----------
        k : float, > 0
            k [rad/s], gain on the actuated components ``q1``, ``q2`` of the error quaternion in the
            desired rates (eq. 7/8). Default 0.02 rad/s (paper, section VI).
        g : float, > 0
            g [rad/s], gain of the singular term ``q2 q3 / D``, ``q1 q3 / D``; must exceed ``2 k``
            (section III.C: ``q3`` must vanish faster than ``q1² + q2²``). Default 0.08 rad/s.
        a1, a2 : float > 0 or None
            Saturation limits of the singular ratios ``q2 q3 / D`` and ``q1 q3 / D`` (dimensionless,
            eq. 8); ``null``: the unsaturated eq. 7. Default 0.025.
        epsilon_D : float, >= 0
            ε_D, added to ``D = q1² + q2²`` (dimensionless): the regularisation the paper used in
            orbit (end of section IV.B). Default 0: eq. 7/8 as printed.
        """

        k: Annotated[float, Range(gt=0.0)] = 0.02
        g: Annotated[float, Range(gt=0.0)] = 0.08
        a1: Annotated[float | None, Range(gt=0.0)] = 0.025
        a2: Annotated[float | None, Range(gt=0.0)] = 0.025
        epsilon_D: Annotated[float, Range(ge=0.0)] = 0.0

        def __post_init__(self) -> None:
            check_singular_gains("g", self.k, self.g)

    def reset(self, spacecraft: Spacecraft, sample_time: float, target: Any = None) -> None:
        super().reset(spacecraft, sample_time, target)
        o = self.options
        self.gains = SingularGains(o.k, o.g, o.a1, o.a2, o.epsilon_D)
        # h_demand = −A⁺ I Cᵀ [ωd1, ωd2, 0]: wheel momenta whose body momentum cancels I ω_d.
        self._momentum_map = -self._wheel_pinv @ spacecraft.inertia @ self.frame.T[:, :2]

    def __call__(self, t: float, measurement: Measurement, reference: Any) -> Command:
        q0, q1, q2, q3, _, _, _ = self.error(measurement)
        wd1, wd2, _, _ = desired_rates(q0, q1, q2, q3, 0.0, 0.0, 0.0, self.gains)
        m = self._momentum_map
        demand = m[:, 0] * wd1 + m[:, 1] * wd2
        return Command(wheel_torque=(demand - measurement.wheel_momentum) / self.sample_time)

    def _law(self, t: ca.SX, y: ca.SX, z: ca.SX, r: ca.SX) -> tuple[ca.SX, ca.SX]:
        q, _ = self.error_symbolic(y)
        wd1, wd2, _, _ = desired_rates_symbolic(q, [0.0, 0.0, 0.0], self.gains)
        m = self._momentum_map
        demand = ca.DM(m[:, 0]) * wd1 + ca.DM(m[:, 1]) * wd2
        u = ca.SX.zeros(self._nu)
        u[self._slices["wheels"]] = (demand - split_measurement(y, self._spacecraft().n_wheels)[2]) / self.sample_time
        return u, z


def check_singular_gains(option: str, k: float, g: float, suffix: str = "") -> None:
    """Raise :class:`InvalidOption` on ``option`` unless ``g > 2 k`` (section III.C: the singular
    term's numerator ``q3 ~ e^(−g t/2)`` must vanish faster than ``q1² + q2² ~ e^(−k t)``).

    Parameters
    ----------
    option : str
        The option reported (``"g"``, ``"g1"``, ``"g2"``).
    k, g : float
        The desired rates' gains [rad/s].
    suffix : str, optional
        Suffix of the option names in the message (``"1"`` for ``k1``, ``g1``).
    """
    if not g > 2.0 * k:
        raise InvalidOption(option, f"expected g{suffix} > 2 k{suffix} (the singular term must vanish: "
                            f"q3 ~ exp(-g t/2) faster than q1² + q2² ~ exp(-k t)), got g{suffix} = {g!r}, "
                            f"k{suffix} = {k!r}")
