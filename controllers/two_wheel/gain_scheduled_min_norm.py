"""Gain-scheduled min-norm two-wheel law (Horri & Palmer eq. 30-33).

Two snlc modes, low gain (k1, g1, K1: the benchmark's gains) and high gain (k2, g2, K2):
``u_m = −K_m (ω − ωd(k_m, g_m)) + I ω̇d(k_m, g_m)`` (eq. 31-32). The high-gain mode is the
benchmark where its torque is small, ``‖u_hg‖∞ < ε``, the low-gain mode elsewhere; the applied
torque is the min-norm projection of that benchmark on ``L_gV`` (V of eq. 26 with γ, σ), which is
the optimisation the paper states in eq. 33. Where they differ, eq. 30 as printed switches the
zero-torque mode on ``L_gV u_hg`` alone; eq. 33 (followed here) asks ``V̇ <= V̇_ulg`` in the
low-gain region, whose min-norm answer is zero when ``L_gV u_lg >= 0``, never a projection
that raises V. Eq. 32's second line prints ``q2 q3`` where eq. 8 has ``q1 q3``; ours is eq. 8's.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Any

import casadi as ca

from controllers.two_wheel.min_norm import MinNorm
from controllers.two_wheel.singular_rates import (
    SingularGains,
    desired_rates,
    desired_rates_symbolic,
    rate_tracking_torque,
)
from controllers.two_wheel.singular_zero_momentum import check_singular_gains
from ocp import Spacecraft
from ocp.options import Range


class GainScheduledMinNorm(MinNorm):
    """Min-norm projection of a low- or high-gain snlc law, switched on the torque bound ε."""

    name = "gain_scheduled_min_norm"

    @dataclass(frozen=True)
    class Options:
        """Options of ``gain_scheduled_min_norm`` (the YAML keys under the controller's ``options``;
        defaults: the paper's gains, Horri & Palmer section VI).

        Parameters
        ----------
        k1, g1 : float, > 0
            k, g [rad/s] of the low-gain mode's desired rates (eq. 7/8), the snlc benchmark's;
            ``g1 > 2 k1``. Defaults 0.02 and 0.08 rad/s.
        K1 : float, > 0
            K [N m s/rad] of the low-gain mode's rate tracking (eq. 31-32). Default 10 N m s/rad.
        k2, g2 : float, > 0
            k, g [rad/s] of the high-gain mode; ``g2 > 2 k2``. Defaults 0.2 and 1.2 rad/s.
        K2 : float, > 0
            K [N m s/rad] of the high-gain mode (eq. 31-32). Default 10 N m s/rad.
        epsilon : float, > 0
            ε [N m]: the high-gain mode is the benchmark while ``‖u_hg‖∞ < ε``, the low-gain mode
            elsewhere (typically a fraction of the wheel torque limit). Default 0.02 N m.
        gamma : float, > 0
            γ [rad/s], the ``k`` of the desired rates ``ω_γσ`` in the Lyapunov function V (eq. 26-27).
            Default 0.01 rad/s (paper, section VI).
        sigma : float, > 0
            σ [rad/s], the ``g`` of ``ω_γσ`` (eq. 27). Default 0.04 rad/s.
        a1, a2 : float > 0 or None
            Saturation limits of the singular ratios ``q2 q3 / D`` and ``q1 q3 / D`` (dimensionless,
            eq. 8) of every mode's and V's desired rates; ``null``: the unsaturated eq. 7.
            Default 0.025.
        epsilon_D : float, >= 0
            ε_D, added to ``D = q1² + q2²`` (dimensionless): the regularisation the paper used in
            orbit (end of section IV.B). Default 0: eq. 7/8 as printed.
        """

        k1: Annotated[float, Range(gt=0.0)] = 0.02
        g1: Annotated[float, Range(gt=0.0)] = 0.08
        K1: Annotated[float, Range(gt=0.0)] = 10.0
        k2: Annotated[float, Range(gt=0.0)] = 0.2
        g2: Annotated[float, Range(gt=0.0)] = 1.2
        K2: Annotated[float, Range(gt=0.0)] = 10.0
        epsilon: Annotated[float, Range(gt=0.0)] = 0.02
        gamma: Annotated[float, Range(gt=0.0)] = 0.01
        sigma: Annotated[float, Range(gt=0.0)] = 0.04
        a1: Annotated[float | None, Range(gt=0.0)] = 0.025
        a2: Annotated[float | None, Range(gt=0.0)] = 0.025
        epsilon_D: Annotated[float, Range(ge=0.0)] = 0.0

        def __post_init__(self) -> None:
            check_singular_gains("g1", self.k1, self.g1, "1")
            check_singular_gains("g2", self.k2, self.g2, "2")

    def reset(self, spacecraft: Spacecraft, sample_time: float, target: Any = None) -> None:
        super(MinNorm, self).reset(spacecraft, sample_time, target)
        o = self.options
        self.low = SingularGains(o.k1, o.g1, o.a1, o.a2, o.epsilon_D)
        self.high = SingularGains(o.k2, o.g2, o.a1, o.a2, o.epsilon_D)
        self.lyapunov_gains = SingularGains(o.gamma, o.sigma, o.a1, o.a2, o.epsilon_D)

    def benchmark(self, state: tuple[float, ...]) -> tuple[float, float]:
        """The mode's snlc torque: high gain if ``‖u_hg‖∞ < ε``, else low gain.

        Parameters
        ----------
        state : tuple of 7 float
            ``(q0, q1, q2, q3, ω1, ω2, ω3)`` as :meth:`~controllers.two_wheel.underactuated.TwoWheelLaw.error`
            returns it: error quaternion and body rate [rad/s], control frame.

        Returns
        -------
        tuple of 2 float
            The benchmark torque [N m] on the actuated axes, control frame.
        """
        q0, q1, q2, q3, w1, w2, w3 = state
        o, inertia = self.options, self.moments[:2]
        high = rate_tracking_torque(w1, w2, desired_rates(q0, q1, q2, q3, w1, w2, w3, self.high), o.K2, inertia)
        if max(abs(high[0]), abs(high[1])) < o.epsilon:
            return high
        return rate_tracking_torque(w1, w2, desired_rates(q0, q1, q2, q3, w1, w2, w3, self.low), o.K1, inertia)

    def benchmark_symbolic(self, q: list[ca.SX], w: list[ca.SX]) -> tuple[ca.SX, ca.SX]:
        """:meth:`benchmark` on expressions (the mode switch as ``if_else``).

        Parameters
        ----------
        q : list of 4 casadi.SX
            Error quaternion ``[q0, q1, q2, q3]``, control frame.
        w : list of 3 casadi.SX
            Body rate [rad/s], control frame.

        Returns
        -------
        tuple of 2 casadi.SX
            The benchmark torque [N m], control frame.
        """
        o, inertia = self.options, self.moments[:2]
        high = rate_tracking_torque(w[0], w[1], desired_rates_symbolic(q, w, self.high), o.K2, inertia)
        low = rate_tracking_torque(w[0], w[1], desired_rates_symbolic(q, w, self.low), o.K1, inertia)
        use_high = ca.fmax(ca.fabs(high[0]), ca.fabs(high[1])) < o.epsilon
        return ca.if_else(use_high, high[0], low[0]), ca.if_else(use_high, high[1], low[1])
