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

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Annotated, Any

import casadi as ca
import numpy as np

from controllers.allocation import float_rows
from controllers.base import Array, Controller, check_gain, gain_matrix
from ocp import Command, Measurement, Spacecraft
from ocp.dynamics.layout import REFERENCE_FIELDS, split_measurement
from ocp.fast_call import as_floats
from ocp.options import Range
from ocp.simulation.simulator import GridSampledReference


class AugmentedQuaternionFeedback(Controller):
    """Quaternion PD tracking with gyroscopic compensation and reference acceleration feed-forward.

    Parameters
    ----------
    options : mapping or Options, optional
        The law's options (:class:`Options`); ``None``: the defaults.
    path : str, optional
        YAML path of the options, for error messages.
    """

    name = "augmented_quaternion_feedback"
    tracks_reference = True
    """Follow the reference when there is one (``eigenaxis_pd`` always regulates to the target)."""

    @dataclass(frozen=True)
    class Options:
        """Options of the augmented quaternion feedback (YAML keys under ``controller.options``).

        Parameters
        ----------
        kp : float or (3, 3) nested list
            Attitude gain ``K``: a scalar [1/s²] times the inertia (default 0.06, the spin
            paper's "medium" gains), or a full matrix [N m] whose symmetric part is positive
            semi-definite.
        kd : float or (3, 3) nested list
            Rate gain ``C``: a scalar [1/s] times the inertia (default 0.48), or a full matrix
            [N m s] whose symmetric part is positive semi-definite.
        feedforward : bool
            Add the reference acceleration term ``I ω̇*`` of eq. 38 (default on).
        hold_compensation : bool
            Make the held torque right to ``O(T²)`` over the coming sample (module docstring;
            default on); off: the continuous law sampled at ``t_k``.
        """

        kp: Annotated[float | list[list[float]], Range(shape=(3, 3))] = 0.06       # 1/s² times inertia (spin paper "medium" gains)
        kd: Annotated[float | list[list[float]], Range(shape=(3, 3))] = 0.48       # 1/s times inertia
        feedforward: bool = True                    # the I ω̇* term of eq. 38
        hold_compensation: bool = True              # held torque right to O(T²) (module docstring)

        def __post_init__(self) -> None:
            check_gain("kp", self.kp)
            check_gain("kd", self.kd)

    def reset(self, spacecraft: Spacecraft, sample_time: float, target: Any = None) -> None:
        super().reset(spacecraft, sample_time, target)
        self.stiffness = gain_matrix(self.options.kp, spacecraft.inertia)
        self.damping = gain_matrix(self.options.kd, spacecraft.inertia)
        self._inverse_inertia = np.linalg.inv(spacecraft.inertia)
        self._regulation_rows = None if target is None else self.reference_rows(None, np.zeros(2))
        # Per-sample arithmetic is on Python floats (NumPy costs ~1 µs per call on 3-vectors).
        self._rows_k = float_rows(self.stiffness)
        self._rows_c = float_rows(self.damping)
        self._rows_i = float_rows(spacecraft.inertia)
        self._rows_i_inv = float_rows(self._inverse_inertia)
        self._regulation_pair = None if self._regulation_rows is None else float_rows(self._regulation_rows)

    def setpoints(self, t: float, reference: Any) -> Array:
        """Reference rows at the sample and at the next one.

        Parameters
        ----------
        t : float
            Sample instant [s].
        reference : planners.Reference or None
            The reference; ``None`` (or a law that always regulates): the target of ``reset``.

        Returns
        -------
        (2, 13) ndarray
            Rows ``[q*, ω*, ω̇*, τ*]`` at ``t`` and ``t + T`` (``Controller.reference_rows``).
        """
        if reference is None or not self.tracks_reference:
            if self._regulation_rows is None:
                raise ValueError(f"controller {self.name} regulates to a target: reset it with one")
            return self._regulation_rows
        return self.reference_rows(reference, np.array([t, t + self.sample_time]))

    def _setpoint_pair(self, t: float, reference: Any) -> Sequence[Sequence[float]]:
        """:meth:`setpoints` as two rows of Python floats; from the simulator's grid table when
        both instants are on it."""
        if reference is None or not self.tracks_reference:
            if self._regulation_pair is None:
                raise ValueError(f"controller {self.name} regulates to a target: reset it with one")
            return self._regulation_pair
        if isinstance(reference, GridSampledReference):
            now, then = reference.row(t), reference.row(t + self.sample_time)
            if now is not None and then is not None:
                return now, then
        return self.setpoints(t, reference).tolist()

    def __call__(self, t: float, measurement: Measurement, reference: Any) -> Command:
        # Python floats throughout, 3x3 products written out (NumPy costs ~1 µs per call on
        # 3-vectors); tests/test_symbolic_laws.py holds it to the symbolic law below.
        row, row_next = self._setpoint_pair(t, reference)
        q0, q1, q2, q3 = as_floats(measurement.q)
        w0, w1, w2 = as_floats(measurement.omega)
        r0, r1, r2, r3, v0, v1, v2 = row[0:7]
        # q_e = q_ref* ⊗ q, vector part, with the sign that makes its scalar part non-negative.
        e0 = r0 * q1 - q0 * r1 - (r2 * q3 - r3 * q2)
        e1 = r0 * q2 - q0 * r2 - (r3 * q1 - r1 * q3)
        e2 = r0 * q3 - q0 * r3 - (r1 * q2 - r2 * q1)
        if r0 * q0 + r1 * q1 + r2 * q2 + r3 * q3 < 0.0:
            e0, e1, e2 = -e0, -e1, -e2
        d0, d1, d2 = w0 - v0, w1 - v1, w2 - v2
        (k00, k01, k02), (k10, k11, k12), (k20, k21, k22) = self._rows_k
        (c00, c01, c02), (c10, c11, c12), (c20, c21, c22) = self._rows_c
        f0 = -(k00 * e0 + k01 * e1 + k02 * e2) - (c00 * d0 + c01 * d1 + c02 * d2)  # −K q_e − C ω_e
        f1 = -(k10 * e0 + k11 * e1 + k12 * e2) - (c10 * d0 + c11 * d1 + c12 * d2)
        f2 = -(k20 * e0 + k21 * e1 + k22 * e2) - (c20 * d0 + c21 * d1 + c22 * d2)
        options, T = self.options, self.sample_time
        if not options.feedforward:
            a0 = a1 = a2 = 0.0
        elif options.hold_compensation:
            a0, a1, a2 = (row_next[4] - v0) / T, (row_next[5] - v1) / T, (row_next[6] - v2) / T
        else:
            a0, a1, a2 = row[7:10]
        m0, m1, m2 = w0, w1, w2
        if options.hold_compensation:  # ω_m = ω + (T/2)(I⁻¹ feedback + ᾱ*)
            (n00, n01, n02), (n10, n11, n12), (n20, n21, n22) = self._rows_i_inv
            half = 0.5 * T
            m0 = w0 + half * (n00 * f0 + n01 * f1 + n02 * f2 + a0)
            m1 = w1 + half * (n10 * f0 + n11 * f1 + n12 * f2 + a1)
            m2 = w2 + half * (n20 * f0 + n21 * f1 + n22 * f2 + a2)
        (i00, i01, i02), (i10, i11, i12), (i20, i21, i22) = self._rows_i
        j0 = i00 * m0 + i01 * m1 + i02 * m2  # I ω_m
        j1 = i10 * m0 + i11 * m1 + i12 * m2
        j2 = i20 * m0 + i21 * m1 + i22 * m2
        t0 = f0 + (i00 * a0 + i01 * a1 + i02 * a2) + (m1 * j2 - m2 * j1)  # feedback + I ᾱ + ω_m × I ω_m
        t1 = f1 + (i10 * a0 + i11 * a1 + i12 * a2) + (m2 * j0 - m0 * j2)
        t2 = f2 + (i20 * a0 + i21 * a1 + i22 * a2) + (m0 * j1 - m1 * j0)
        h_mid = None
        if options.hold_compensation and self._pinv_rows is not None:  # h_m = h_w + (T/2) g₀
            h = as_floats(measurement.wheel_momentum)
            k0 = k1 = k2 = 0.0
            for (x0, x1, x2), h_i in zip(self._axes_cols, h):  # A h_w
                k0 += x0 * h_i
                k1 += x1 * h_i
                k2 += x2 * h_i
            s0, s1, s2 = t0 + (m1 * k2 - m2 * k1), t1 + (m2 * k0 - m0 * k2), t2 + (m0 * k1 - m1 * k0)
            half = 0.5 * T
            h_mid = [h_i - half * (x0 * s0 + x1 * s1 + x2 * s2) for h_i, (x0, x1, x2) in zip(h, self._pinv_rows)]
        return self._allocate((t0, t1, t2), measurement, (m0, m1, m2), h_mid)

    def _law(self, t: ca.SX, y: ca.SX, z: ca.SX, r: ca.SX) -> tuple[ca.SX, ca.SX]:
        spacecraft = self._spacecraft()
        n_w = spacecraft.n_wheels
        q, w, h, _ = split_measurement(y, n_w)
        # A regulator reads its target from r when it is built for code generation (the generated
        # step fills r with the target then); otherwise the target is compiled in.
        rows = r if self.tracks_reference or self._constants is not None else ca.DM(self.setpoints(0.0, None).ravel())
        q_ref, w_ref = rows[0:4], rows[4:7]
        w_ref_next, accel_ref = rows[REFERENCE_FIELDS + 4:REFERENCE_FIELDS + 7], rows[7:10]
        scalar = ca.dot(q_ref, q)
        vector = q_ref[0] * q[1:4] - q[0] * q_ref[1:4] - ca.cross(q_ref[1:4], q[1:4])
        vector = ca.if_else(scalar < 0, -vector, vector)
        K, C = self.constant("stiffness", self.stiffness), self.constant("damping", self.damping)
        feedback = -ca.mtimes(K, vector) - ca.mtimes(C, w - w_ref)
        options, T = self.options, self.constant("sample_time", float(self.sample_time))
        inertia = self.constant("inertia", spacecraft.inertia)
        accel: ca.SX | ca.DM
        if not options.feedforward:
            accel = ca.DM.zeros(3)
        elif options.hold_compensation:
            accel = (w_ref_next - w_ref) / T
        else:
            accel = accel_ref
        if options.hold_compensation:
            inverse = ca.inv_minor(inertia) if self._constants is not None else ca.DM(self._inverse_inertia)
            w_mid = w + 0.5 * T * (ca.mtimes(inverse, feedback) + accel)
        else:
            w_mid = w
        torque = feedback + ca.mtimes(inertia, accel) + ca.cross(w_mid, ca.mtimes(inertia, w_mid))
        h_mid = None
        if options.hold_compensation and self._working_axes is not None:
            axes, _, wheel_pinv = self._wheel_matrices_symbolic()
            h_mid = h - 0.5 * T * ca.mtimes(wheel_pinv, torque + ca.cross(w_mid, ca.mtimes(axes, h)))
        return self.allocate_symbolic(torque, y, rate=w_mid, wheel_momentum=h_mid), z
