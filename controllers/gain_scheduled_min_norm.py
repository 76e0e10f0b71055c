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
from typing import Annotated

import casadi as ca

from controllers.min_norm import MinNorm
from controllers.singular_zero_momentum import check_singular_gains
from controllers.underactuated import (
    SingularGains,
    desired_rates,
    desired_rates_symbolic,
    rate_tracking_torque,
)
from ocp.options import Range


class GainScheduledMinNorm(MinNorm):
    """Min-norm projection of a low- or high-gain snlc law, switched on the torque bound ε."""

    name = "gain_scheduled_min_norm"

    @dataclass(frozen=True)
    class Options:
        k1: Annotated[float, Range(gt=0.0)] = 0.02           # rad/s, low-gain mode
        g1: Annotated[float, Range(gt=0.0)] = 0.08           # rad/s; g1 > 2 k1
        K1: Annotated[float, Range(gt=0.0)] = 10.0           # N m s/rad
        k2: Annotated[float, Range(gt=0.0)] = 0.2            # rad/s, high-gain mode
        g2: Annotated[float, Range(gt=0.0)] = 1.2            # rad/s; g2 > 2 k2
        K2: Annotated[float, Range(gt=0.0)] = 10.0           # N m s/rad
        epsilon: Annotated[float, Range(gt=0.0)] = 0.02      # N m, high gain while ‖u_hg‖∞ < ε
        gamma: Annotated[float, Range(gt=0.0)] = 0.01        # rad/s, V's desired rates (eq. 27)
        sigma: Annotated[float, Range(gt=0.0)] = 0.04        # rad/s
        a1: Annotated[float | None, Range(gt=0.0)] = 0.025   # saturation of every desired rate; null: none
        a2: Annotated[float | None, Range(gt=0.0)] = 0.025
        epsilon_D: Annotated[float, Range(ge=0.0)] = 0.0

        def __post_init__(self) -> None:
            check_singular_gains("g1", self.k1, self.g1, "1")
            check_singular_gains("g2", self.k2, self.g2, "2")

    def reset(self, spacecraft, sample_time, target=None) -> None:
        super(MinNorm, self).reset(spacecraft, sample_time, target)
        o = self.options
        self.low = SingularGains(o.k1, o.g1, o.a1, o.a2, o.epsilon_D)
        self.high = SingularGains(o.k2, o.g2, o.a1, o.a2, o.epsilon_D)
        self.lyapunov_gains = SingularGains(o.gamma, o.sigma, o.a1, o.a2, o.epsilon_D)

    def benchmark(self, state: tuple[float, ...]) -> tuple[float, float]:
        """The mode's snlc torque: high gain if ``‖u_hg‖∞ < ε``, else low gain (N m, control frame)."""
        q0, q1, q2, q3, w1, w2, w3 = state
        o, inertia = self.options, self.moments[:2]
        high = rate_tracking_torque(w1, w2, desired_rates(q0, q1, q2, q3, w1, w2, w3, self.high), o.K2, inertia)
        if max(abs(high[0]), abs(high[1])) < o.epsilon:
            return high
        return rate_tracking_torque(w1, w2, desired_rates(q0, q1, q2, q3, w1, w2, w3, self.low), o.K1, inertia)

    def benchmark_symbolic(self, q: list, w: list) -> tuple:
        """:meth:`benchmark` on expressions (the mode switch as ``if_else``)."""
        o, inertia = self.options, self.moments[:2]
        high = rate_tracking_torque(w[0], w[1], desired_rates_symbolic(q, w, self.high), o.K2, inertia)
        low = rate_tracking_torque(w[0], w[1], desired_rates_symbolic(q, w, self.low), o.K1, inertia)
        use_high = ca.fmax(ca.fabs(high[0]), ca.fabs(high[1])) < o.epsilon
        return ca.if_else(use_high, high[0], low[0]), ca.if_else(use_high, high[1], low[1])
