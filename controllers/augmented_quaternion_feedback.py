"""Augmented quaternion feedback tracking law (spin paper eq. 38-39; nano paper eq. 40).

``u = −K q_e − C ω_e + ω × I ω + I ω̇*``, with ``q_e`` the vector part of ``q* ⊗ q`` (sign chosen
so that its scalar part is non-negative), ``ω_e = ω − ω*`` (eq. 39), ``K = k_p I``, ``C = k_d I``
for scalar gains (or full matrices). The wheel-momentum term of nano eq. 40, ``ω × h``, enters
through the allocation ``τ_w = u + ω × A h_w`` (see ``Controller.allocate``, which also
corrects the held gyroscopic term to mid-sample). With it the closed loop obeys
``ω̇_e = −I⁻¹(K q_e + C ω_e)`` and the Lyapunov function of the spin paper's appendix
(eq. 42-43), ``V = 2 k_p (1 − q_e0) + ½ ω_eᵀ ω_e``, has ``V̇ = −k_d ω_eᵀ ω_e`` for scalar gains.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Any

import numpy as np

from controllers.base import Array, Controller, check_gain, gain_matrix
from ocp import Command, Measurement, quat
from ocp.options import Range


class AugmentedQuaternionFeedback(Controller):
    """Quaternion PD tracking with gyroscopic compensation and reference acceleration feed-forward."""

    name = "augmented_quaternion_feedback"

    @dataclass(frozen=True)
    class Options:
        kp: Annotated[float | list[list[float]], Range(shape=(3, 3))] = 0.06       # 1/s² times inertia (spin paper "medium" gains)
        kd: Annotated[float | list[list[float]], Range(shape=(3, 3))] = 0.48       # 1/s times inertia
        feedforward: bool = True                    # the I ω̇* term of eq. 38
        hold_compensation: bool = True              # gyroscopic term at mid-sample (Controller.allocate)

        def __post_init__(self) -> None:
            check_gain("kp", self.kp)
            check_gain("kd", self.kd)

    def reset(self, spacecraft, sample_time, target=None) -> None:
        super().reset(spacecraft, sample_time, target)
        self.hold_compensation = self.options.hold_compensation
        self.stiffness = gain_matrix(self.options.kp, spacecraft.inertia)
        self.damping = gain_matrix(self.options.kd, spacecraft.inertia)

    def setpoint(self, t: float, reference: Any) -> tuple[Array, Array, Array]:
        """Reference attitude, rate and acceleration at ``t`` (the target when there is no reference)."""
        if reference is None:
            q_target, omega_target = self.target
            omega = np.zeros(3) if omega_target is None else np.asarray(omega_target, dtype=float)
            return np.asarray(q_target, dtype=float), omega, np.zeros(3)
        sample = reference.sample(t)
        return sample.q, sample.omega, sample.omega_dot

    def body_torque(self, t: float, measurement: Measurement, reference: Any) -> Array:
        """The law's rigid-body torque ``u`` (N m, body axes)."""
        q_ref, omega_ref, omega_dot_ref = self.setpoint(t, reference)
        q_error = quat.error(measurement.q, q_ref)[1:]
        omega = measurement.omega
        inertia = self.spacecraft.inertia
        torque = -self.stiffness @ q_error - self.damping @ (omega - omega_ref) + np.cross(omega, inertia @ omega)
        if self.options.feedforward:
            torque += inertia @ omega_dot_ref
        return torque

    def __call__(self, t: float, measurement: Measurement, reference: Any) -> Command:
        return self.allocate(self.body_torque(t, measurement, reference), measurement)
