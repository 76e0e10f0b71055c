"""Augmented quaternion feedback tracking law (spin paper eq. 38-39; nano paper eq. 40).

``u = −K q_e − C ω_e + ω × I ω + I ω̇*``, with ``q_e`` the vector part of ``q* ⊗ q`` (sign chosen
so that its scalar part is non-negative), ``ω_e = ω − ω*`` (eq. 39), ``K = k_p I``, ``C = k_d I``
for scalar gains (or full matrices). The wheel-momentum term of nano eq. 40, ``ω × h``, enters
through the allocation ``τ_w = u + ω × A h_w`` (see ``Controller.allocate``). With it the closed
loop obeys ``ω̇_e = −I⁻¹(K q_e + C ω_e)`` and the Lyapunov function of the spin paper's appendix
(eq. 42-43), ``V = 2 k_p (1 − q_e0) + ½ ω_eᵀ ω_e``, has ``V̇ = −k_d ω_eᵀ ω_e`` for scalar gains.

Zero-order hold (``hold_compensation``, default on). The command is held over ``[t_k, t_k + T]``;
sampling the continuous law there leaves a tracking error of first order in ``T``. The held torque
that is right to second order is the law's torque averaged over the hold, which the midpoint rule
gives to ``O(T²)``:

* feed-forward ``I ᾱ*`` with ``ᾱ* = (ω*(t_k + T) − ω*(t_k)) / T``, the reference acceleration
  averaged over the hold (exactly);
* the intended acceleration ``α = I⁻¹(−K q_e − C ω_e) + ᾱ*`` predicts the mid-sample rate
  ``ω_m = ω + (T/2) α`` (to ``O(T²)``), and the gyroscopic term is ``ω_m × I ω_m``;
* with wheels, ``ω × A h_w`` is taken at ``ω_m`` and ``h_m = h_w + (T/2) g₀``, where
  ``g₀ = −A⁺(u + ω_m × A h_w)`` is the wheel torque without that correction (``ḣ_w = g``).

So ``u = −K q_e − C ω_e + I ᾱ* + ω_m × I ω_m``. As ``T → 0`` this is the continuous law above, and
with zero error and an exact reference the local error of a hold is ``O(T³)``, so the tracking
error falls as ``T²`` (``tests/test_tracking.py``). Without the option the continuous law is
sampled at ``t_k`` (``ω̇*(t_k)``, ``ω × I ω``).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Any

import casadi as ca
import numpy as np

from controllers.base import Array, Controller, check_gain, cross3, gain_matrix
from ocp import Command, Measurement
from ocp.layout import REFERENCE_FIELDS, split_measurement
from ocp.options import Range


class AugmentedQuaternionFeedback(Controller):
    """Quaternion PD tracking with gyroscopic compensation and reference acceleration feed-forward."""

    name = "augmented_quaternion_feedback"
    tracks_reference = True
    """Follow the reference when there is one (``eigenaxis_pd`` always regulates to the target)."""

    @dataclass(frozen=True)
    class Options:
        kp: Annotated[float | list[list[float]], Range(shape=(3, 3))] = 0.06       # 1/s² times inertia (spin paper "medium" gains)
        kd: Annotated[float | list[list[float]], Range(shape=(3, 3))] = 0.48       # 1/s times inertia
        feedforward: bool = True                    # the I ω̇* term of eq. 38
        hold_compensation: bool = True              # held torque right to O(T²) (module docstring)

        def __post_init__(self) -> None:
            check_gain("kp", self.kp)
            check_gain("kd", self.kd)

    def reset(self, spacecraft, sample_time, target=None) -> None:
        super().reset(spacecraft, sample_time, target)
        self.stiffness = gain_matrix(self.options.kp, spacecraft.inertia)
        self.damping = gain_matrix(self.options.kd, spacecraft.inertia)
        self._inverse_inertia = np.linalg.inv(spacecraft.inertia)
        self._regulation_rows = None if target is None else self.reference_rows(None, np.zeros(2))

    def setpoints(self, t: float, reference: Any) -> Array:
        """(2, 13) reference rows ``[q*, ω*, ω̇*, τ*]`` at ``t`` and ``t + T`` (the target's when
        there is no reference or the law regulates)."""
        if reference is None or not self.tracks_reference:
            if self._regulation_rows is None:
                raise ValueError(f"controller {self.name} regulates to a target: reset it with one")
            return self._regulation_rows
        return self.reference_rows(reference, np.array([t, t + self.sample_time]))

    def __call__(self, t: float, measurement: Measurement, reference: Any) -> Command:
        rows = self.setpoints(t, reference)
        q, w = measurement.q, measurement.omega
        q_ref, w_ref = rows[0, 0:4], rows[0, 4:7]
        # q_e = q_ref* ⊗ q, vector part, with the sign that makes its scalar part non-negative.
        scalar = q_ref[0] * q[0] + q_ref[1] * q[1] + q_ref[2] * q[2] + q_ref[3] * q[3]
        vector = q_ref[0] * q[1:4] - q[0] * q_ref[1:4] - cross3(q_ref[1:4], q[1:4])
        if scalar < 0.0:
            vector = -vector
        feedback = -(self.stiffness @ vector) - self.damping @ (w - w_ref)
        options, inertia, T = self.options, self.spacecraft.inertia, self.sample_time
        if not options.feedforward:
            accel = np.zeros(3)
        elif options.hold_compensation:
            accel = (rows[1, 4:7] - w_ref) / T
        else:
            accel = rows[0, 7:10]
        w_mid = w + 0.5 * T * (self._inverse_inertia @ feedback + accel) if options.hold_compensation else w
        torque = feedback + inertia @ accel + cross3(w_mid, inertia @ w_mid)
        h_mid = None
        if options.hold_compensation and self._working_axes is not None:
            axes = self.spacecraft.wheel_axes
            h = measurement.wheel_momentum
            h_mid = h - 0.5 * T * (self._wheel_pinv @ (torque + cross3(w_mid, axes @ h)))
        return self.allocate(torque, measurement, rate=w_mid, wheel_momentum=h_mid)

    def _law(self, t, y, z, r):
        n_w = self.spacecraft.n_wheels
        q, w, h, _ = split_measurement(y, n_w)
        rows = r if self.tracks_reference else ca.DM(self.setpoints(0.0, None).ravel())
        q_ref, w_ref = rows[0:4], rows[4:7]
        w_ref_next, accel_ref = rows[REFERENCE_FIELDS + 4:REFERENCE_FIELDS + 7], rows[7:10]
        scalar = ca.dot(q_ref, q)
        vector = q_ref[0] * q[1:4] - q[0] * q_ref[1:4] - ca.cross(q_ref[1:4], q[1:4])
        vector = ca.if_else(scalar < 0, -vector, vector)
        K, C = ca.DM(self.stiffness), ca.DM(self.damping)
        feedback = -ca.mtimes(K, vector) - ca.mtimes(C, w - w_ref)
        options, T = self.options, self.sample_time
        inertia = ca.DM(self.spacecraft.inertia)
        if not options.feedforward:
            accel = ca.DM.zeros(3)
        elif options.hold_compensation:
            accel = (w_ref_next - w_ref) / T
        else:
            accel = accel_ref
        if options.hold_compensation:
            w_mid = w + 0.5 * T * (ca.mtimes(ca.DM(self._inverse_inertia), feedback) + accel)
        else:
            w_mid = w
        torque = feedback + ca.mtimes(inertia, accel) + ca.cross(w_mid, ca.mtimes(inertia, w_mid))
        h_mid = None
        if options.hold_compensation and self._working_axes is not None:
            axes = ca.DM(self.spacecraft.wheel_axes)
            h_mid = h - 0.5 * T * ca.mtimes(ca.DM(self._wheel_pinv), torque + ca.cross(w_mid, ca.mtimes(axes, h)))
        return self.allocate_symbolic(torque, y, rate=w_mid, wheel_momentum=h_mid), z
