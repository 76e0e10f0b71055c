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

import casadi as ca

from controllers.two_wheel.singular_rates import (
    SingularGains,
    desired_rates,
    desired_rates_symbolic,
    min_norm,
    min_norm_symbolic,
    rate_tracking_torque,
)
from controllers.two_wheel.singular_zero_momentum import check_singular_gains
from controllers.two_wheel.underactuated import TwoWheelLaw
from ocp import Command, Measurement, Spacecraft
from ocp.options import Range


class MinNorm(TwoWheelLaw):
    """Min-norm projection of the snlc law (see the module docstring)."""

    name = "min_norm"

    @dataclass(frozen=True)
    class Options:
        """Options of ``min_norm`` (the YAML keys under the controller's ``options``; defaults: the
        paper's gains, Horri & Palmer section VI).

        ``k``, ``g``, ``K`` are the snlc benchmark's; ``a1``, ``a2``, ``epsilon_D`` apply to both
        the benchmark's and V's desired rates.

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
        gamma : float, > 0
            γ [rad/s], the ``k`` of the desired rates ``ω_γσ`` in the Lyapunov function V (eq. 26-27).
            Default 0.01 rad/s (paper, section VI).
        sigma : float, > 0
            σ [rad/s], the ``g`` of ``ω_γσ`` (eq. 27). Default 0.04 rad/s.
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
        gamma: Annotated[float, Range(gt=0.0)] = 0.01
        sigma: Annotated[float, Range(gt=0.0)] = 0.04
        a1: Annotated[float | None, Range(gt=0.0)] = 0.025
        a2: Annotated[float | None, Range(gt=0.0)] = 0.025
        epsilon_D: Annotated[float, Range(ge=0.0)] = 0.0

        def __post_init__(self) -> None:
            check_singular_gains("g", self.k, self.g)

    def reset(self, spacecraft: Spacecraft, sample_time: float, target: Any = None) -> None:
        super().reset(spacecraft, sample_time, target)
        o = self.options
        self.gains = SingularGains(o.k, o.g, o.a1, o.a2, o.epsilon_D)
        self.lyapunov_gains = SingularGains(o.gamma, o.sigma, o.a1, o.a2, o.epsilon_D)

    def lgv(self, state: tuple[float, ...]) -> tuple[float, float]:
        """``L_gV = [(ω1 − ω_γσ1)/I1, (ω2 − ω_γσ2)/I2]``: V's gradient along the control.

        Parameters
        ----------
        state : tuple of 7 float
            ``(q0, q1, q2, q3, ω1, ω2, ω3)`` as :meth:`~controllers.two_wheel.underactuated.TwoWheelLaw.error`
            returns it: error quaternion and body rate [rad/s], control frame.

        Returns
        -------
        tuple of 2 float
            ``L_gV`` [s/(kg m²)] on the actuated axes.
        """
        q0, q1, q2, q3, w1, w2, w3 = state
        v1, v2, _, _ = desired_rates(q0, q1, q2, q3, w1, w2, w3, self.lyapunov_gains)
        return (w1 - v1) / self.moments[0], (w2 - v2) / self.moments[1]

    def benchmark(self, state: tuple[float, ...]) -> tuple[float, float]:
        """The snlc benchmark torque ``k(x) = −K (ω − ωd) + I ω̇d`` (eq. 24).

        Parameters
        ----------
        state : tuple of 7 float
            ``(q0, q1, q2, q3, ω1, ω2, ω3)`` as :meth:`~controllers.two_wheel.underactuated.TwoWheelLaw.error`
            returns it: error quaternion and body rate [rad/s], control frame.

        Returns
        -------
        tuple of 2 float
            ``k(x)`` [N m] on the actuated axes, control frame.
        """
        q0, q1, q2, q3, w1, w2, w3 = state
        rates = desired_rates(q0, q1, q2, q3, w1, w2, w3, self.gains)
        return rate_tracking_torque(w1, w2, rates, self.options.K, self.moments[:2])

    def project(self, benchmark: tuple[float, float], lgv: tuple[float, float]) -> tuple[float, float]:
        """The min-norm torque for ``benchmark`` (sign-corrected eq. 25, :func:`~controllers.two_wheel.singular_rates.min_norm`).

        Parameters
        ----------
        benchmark : tuple of 2 float
            Benchmark torque [N m], control frame.
        lgv : tuple of 2 float
            ``L_gV`` [s/(kg m²)].

        Returns
        -------
        tuple of 2 float
            The applied torque ``(u1, u2)`` [N m], control frame.
        """
        return min_norm(benchmark, lgv)

    def torques(self, measurement: Measurement) -> tuple[tuple[float, float], tuple[float, float], tuple[float, float]]:
        """The applied torque with what it is made of.

        Parameters
        ----------
        measurement : Measurement
            The sample's measured attitude and body rate.

        Returns
        -------
        tuple of 3 (float, float) pairs
            ``(u, benchmark, L_gV)`` on the actuated axes, control frame: the applied torque [N m],
            the benchmark torque [N m] and ``L_gV`` [s/(kg m²)].
        """
        state = self.error(measurement)
        benchmark, lgv = self.benchmark(state), self.lgv(state)
        return self.project(benchmark, lgv), benchmark, lgv

    def __call__(self, t: float, measurement: Measurement, reference: Any) -> Command:
        u, _, _ = self.torques(measurement)
        return self.command_torque(u[0], u[1], measurement)

    def benchmark_symbolic(self, q: list[ca.SX], w: list[ca.SX]) -> tuple[ca.SX, ca.SX]:
        """:meth:`benchmark` on expressions.

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
        rates = desired_rates_symbolic(q, w, self.gains)
        return rate_tracking_torque(w[0], w[1], rates, self.options.K, self.moments[:2])

    def _law(self, t: ca.SX, y: ca.SX, z: ca.SX, r: ca.SX) -> tuple[ca.SX, ca.SX]:
        q, w = self.error_symbolic(y)
        v1, v2, _, _ = desired_rates_symbolic(q, w, self.lyapunov_gains)
        lgv = ((w[0] - v1) / self.moments[0], (w[1] - v2) / self.moments[1])
        u1, u2 = min_norm_symbolic(self.benchmark_symbolic(q, w), lgv)
        return self.command_symbolic(u1, u2, y), z
