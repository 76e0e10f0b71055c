"""Min-norm two-wheel law (Horri & Palmer eq. 22-29): the smallest torque that decreases the
control Lyapunov function at least as fast as the snlc benchmark does.

``V = k(qᵀq + (1 − q4)²) + ½ (ω − ω_γσ)ᵀ(ω − ω_γσ)`` (eq. 26) with ``ω_γσ`` the desired rates of
eq. 27 (gains γ, σ and the same saturation). ``ω̇ = I⁻¹ u`` on the actuated axes, so
``L_gV = [(ω1 − ω_γσ1)/I1, (ω2 − ω_γσ2)/I2]``. The benchmark is the snlc torque
``k(x) = −K (ω − ωd) + I ω̇d`` (eq. 24) and

    u = (L_gV k) L_gVᵀ / (L_gV L_gVᵀ)  if L_gV k < 0,   else 0.

Eq. 25 prints a minus in front: that u gives ``L_gV u = −L_gV k > 0`` and drives V up (the test
suite shows the printed sign diverging).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Any

from controllers.singular_zero_momentum import check_singular_gains
from controllers.underactuated import (
    SingularGains,
    TwoWheelLaw,
    desired_rates,
    desired_rates_symbolic,
    min_norm,
    min_norm_symbolic,
    rate_tracking_torque,
)
from ocp import Command, Measurement
from ocp.options import Range


class MinNorm(TwoWheelLaw):
    """Min-norm projection of the snlc law (see the module docstring)."""

    name = "min_norm"

    @dataclass(frozen=True)
    class Options:
        k: Annotated[float, Range(gt=0.0)] = 0.02            # rad/s, benchmark snlc
        g: Annotated[float, Range(gt=0.0)] = 0.08            # rad/s; g > 2k
        K: Annotated[float, Range(gt=0.0)] = 10.0            # N m s/rad
        gamma: Annotated[float, Range(gt=0.0)] = 0.01        # rad/s, V's desired rates (eq. 27)
        sigma: Annotated[float, Range(gt=0.0)] = 0.04        # rad/s
        a1: Annotated[float | None, Range(gt=0.0)] = 0.025   # saturation of both desired rates; null: none
        a2: Annotated[float | None, Range(gt=0.0)] = 0.025
        epsilon_D: Annotated[float, Range(ge=0.0)] = 0.0

        def __post_init__(self) -> None:
            check_singular_gains("g", self.k, self.g)

    def reset(self, spacecraft, sample_time, target=None) -> None:
        super().reset(spacecraft, sample_time, target)
        o = self.options
        self.gains = SingularGains(o.k, o.g, o.a1, o.a2, o.epsilon_D)
        self.lyapunov_gains = SingularGains(o.gamma, o.sigma, o.a1, o.a2, o.epsilon_D)

    def lgv(self, state: tuple[float, ...]) -> tuple[float, float]:
        """``L_gV`` (s/(kg m²)) at the control-frame ``state`` of :meth:`error`."""
        q0, q1, q2, q3, w1, w2, w3 = state
        v1, v2, _, _ = desired_rates(q0, q1, q2, q3, w1, w2, w3, self.lyapunov_gains)
        return (w1 - v1) / self.moments[0], (w2 - v2) / self.moments[1]

    def benchmark(self, state: tuple[float, ...]) -> tuple[float, float]:
        """The snlc benchmark torque ``k(x)`` (N m, control frame)."""
        q0, q1, q2, q3, w1, w2, w3 = state
        rates = desired_rates(q0, q1, q2, q3, w1, w2, w3, self.gains)
        return rate_tracking_torque(w1, w2, rates, self.options.K, self.moments[:2])

    def project(self, benchmark: tuple[float, float], lgv: tuple[float, float]) -> tuple[float, float]:
        """The min-norm torque for ``benchmark`` (sign-corrected eq. 25)."""
        return min_norm(benchmark, lgv)

    def torques(self, measurement: Measurement) -> tuple[tuple[float, float], tuple[float, float], tuple[float, float]]:
        """``(u, benchmark, L_gV)`` on the actuated axes (control frame)."""
        state = self.error(measurement)
        benchmark, lgv = self.benchmark(state), self.lgv(state)
        return self.project(benchmark, lgv), benchmark, lgv

    def __call__(self, t: float, measurement: Measurement, reference: Any) -> Command:
        u, _, _ = self.torques(measurement)
        return self.command_torque(u[0], u[1], measurement)

    def benchmark_symbolic(self, q: list, w: list) -> tuple:
        """:meth:`benchmark` on expressions."""
        rates = desired_rates_symbolic(q, w, self.gains)
        return rate_tracking_torque(w[0], w[1], rates, self.options.K, self.moments[:2])

    def _law(self, t, y, z, r):
        q, w = self.error_symbolic(y)
        v1, v2, _, _ = desired_rates_symbolic(q, w, self.lyapunov_gains)
        lgv = ((w[0] - v1) / self.moments[0], (w[1] - v2) / self.moments[1])
        u1, u2 = min_norm_symbolic(self.benchmark_symbolic(q, w), lgv)
        return self.command_symbolic(u1, u2, y), z
