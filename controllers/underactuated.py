"""Shared math of the two-wheel laws of Horri & Palmer (paper 004): the control frame, the singular
desired rates (eq. 7-8) and their time derivative, the min-norm projection (eq. 25, sign
corrected) and the base class of the four laws.

Control frame
-------------
The paper writes its laws with the failed wheel on z: actuated axes 1, 2 and the unactuated axis 3.
The unactuated axis here is the normal of the plane the working wheels span (for the body-axis
triad: the failed wheel's axis). It must be a principal axis of the inertia. The control frame's
rows ``C = [e1; e2; e3]`` are principal axes with ``e3`` the unactuated axis; for a diagonal
inertia with the failed wheel on body axis ``a`` they are the **cyclic** relabelling
``(a+1, a+2, a)`` (x failed: paper's 1, 2, 3 = y, z, x). The frame must be right-handed: the
kinematics ``q̇_v = ½ q0 ω − ½ ω × q_v`` keep their form only under a proper rotation. Under an
odd permutation the cross product changes sign, eq. 9 becomes ``q̇3 = +g/2 q3`` and the law
diverges (tests/test_two_wheel.py shows both).

Desired rates (eq. 7, 8; ``q = [q0, q1, q2, q3]`` the error quaternion in the control frame, the
paper's scalar-last ``[q1, q2, q3, q4]`` with ``q4 = q0``, no sign change)::

    ωd1 = −k q1 + g sat(q2 q3 / D, a1),   ωd2 = −k q2 − g sat(q1 q3 / D, a2),   D = q1² + q2² + ε_D

``a = None`` is the unsaturated eq. 7; ``ε_D`` the regularisation the paper used in orbit (end of
section IV.B). With ``ε_D = 0`` and no saturation, ``ω = ωd`` gives ``q̇3 = −g/2 q3`` (eq. 9) and
``q̇0 = k/2 (q1² + q2²)`` (eq. 10), both checked against integration.
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

import casadi as ca
import numpy as np

from controllers.base import Array, Controller
from ocp import Command, Measurement, Spacecraft
from ocp.layout import split_measurement

PRINCIPAL_TOLERANCE = 1e-9
"""Relative tolerance on ``‖I n − (nᵀ I n) n‖ / ‖I‖`` for the unactuated axis ``n`` to count as principal."""

Scalar = TypeVar("Scalar", float, ca.SX)
"""A number or a CasADi expression: the laws' arithmetic runs on both (Python loop, symbolic form)."""


@dataclass(frozen=True)
class SingularGains:
    """Gains of one desired-rate law (eq. 7/8, or eq. 27 for the Lyapunov function's rates).

    Parameters
    ----------
    k : float
        Gain on the actuated components ``q1``, ``q2`` of the error quaternion [rad/s].
    g : float
        Gain of the singular term ``q2 q3 / D``, ``q1 q3 / D`` [rad/s]; the laws need ``g > 2 k``.
    a1, a2 : float or None
        Saturation limits of the singular ratios ``q2 q3 / D`` and ``q1 q3 / D`` (dimensionless,
        eq. 8); ``None``: unsaturated (eq. 7).
    epsilon_d : float, optional
        Regularisation ``ε_D`` added to ``D = q1² + q2²`` (dimensionless); 0: the paper's eq. 7/8.
    """

    k: float
    g: float
    a1: float | None
    a2: float | None
    epsilon_d: float = 0.0


def _sat(value: float, limit: float | None) -> tuple[float, float]:
    """``(sat(value, limit), d sat / d value)``."""
    if limit is None or -limit < value < limit:
        return value, 1.0
    return (limit if value > 0 else -limit), 0.0


def _ratio(numerator: float, denominator: float) -> float:
    """``numerator / denominator`` with the singular point ``0/0`` taken as 0 (the limit along the
    closed loop, where the numerator vanishes faster) and ``x/0`` as ±inf (saturated, or a
    non-finite command that the simulator reports)."""
    if denominator > 0.0:
        return numerator / denominator
    if numerator == 0.0:
        return 0.0
    return math.copysign(math.inf, numerator)


def desired_rates(q0: float, q1: float, q2: float, q3: float, w1: float, w2: float, w3: float,
                  gains: SingularGains) -> tuple[float, float, float, float]:
    """Desired rates of eq. 7/8 and their time derivative along ``q̇ = ½ q ⊗ [0, ω]``.

    Parameters
    ----------
    q0, q1, q2, q3 : float
        Error quaternion in the control frame (scalar first, dimensionless).
    w1, w2, w3 : float
        Body rate in the control frame [rad/s]; it enters the derivative only.
    gains : SingularGains
        The law's gains.

    Returns
    -------
    tuple of 4 float
        ``(ωd1, ωd2, ω̇d1, ω̇d2)`` [rad/s, rad/s²]; the derivative is zero where a ratio saturates.
    """
    k, g = gains.k, gains.g
    dq1 = 0.5 * (q0 * w1 - q3 * w2 + q2 * w3)
    dq2 = 0.5 * (q0 * w2 - q1 * w3 + q3 * w1)
    dq3 = 0.5 * (q0 * w3 - q2 * w1 + q1 * w2)
    d = q1 * q1 + q2 * q2 + gains.epsilon_d
    dd = 2.0 * (q1 * dq1 + q2 * dq2)
    r1, slope1 = _sat(_ratio(q2 * q3, d), gains.a1)
    r2, slope2 = _sat(_ratio(q1 * q3, d), gains.a2)
    wd1 = -k * q1 + g * r1
    wd2 = -k * q2 - g * r2
    if d > 0.0:
        dr1 = ((dq2 * q3 + q2 * dq3) - q2 * q3 * dd / d) / d if slope1 else 0.0
        dr2 = ((dq1 * q3 + q1 * dq3) - q1 * q3 * dd / d) / d if slope2 else 0.0
    else:
        dr1 = dr2 = 0.0
    return wd1, wd2, -k * dq1 + g * dr1, -k * dq2 - g * dr2


def rate_tracking_torque(w1: Scalar, w2: Scalar, rates: tuple[Scalar, Scalar, Scalar, Scalar], gain: float,
                         inertia: tuple[float, float]) -> tuple[Scalar, Scalar]:
    """snlc law (eq. 14/24 with eq. 31's units): ``u_i = −K (ω_i − ωd_i) + I_i ω̇d_i``.

    Works on floats and on CasADi expressions alike.

    Parameters
    ----------
    w1, w2 : float or casadi.SX
        Body rate on the actuated axes [rad/s], control frame.
    rates : tuple of 4 float or casadi.SX
        ``(ωd1, ωd2, ω̇d1, ω̇d2)`` [rad/s, rad/s²] as :func:`desired_rates` returns them.
    gain : float
        K [N m s/rad] (eq. 31's units; not 1/s times the inertia as eq. 14's ``I_i K_i`` reads).
    inertia : tuple of 2 float
        Principal moments ``I1``, ``I2`` of the actuated axes [kg m²].

    Returns
    -------
    tuple of 2 float or casadi.SX
        Torque ``(u1, u2)`` on the actuated axes [N m], control frame.
    """
    wd1, wd2, dwd1, dwd2 = rates
    return -gain * (w1 - wd1) + inertia[0] * dwd1, -gain * (w2 - wd2) + inertia[1] * dwd2


def min_norm(benchmark: tuple[float, float], lgv: tuple[float, float]) -> tuple[float, float]:
    """Minimum-norm ``u`` with ``L_gV u <= L_gV k`` (eq. 22), sign corrected.

    ``u = (L_gV k) L_gVᵀ / (L_gV L_gVᵀ)`` when ``L_gV k < 0``, else 0. Eq. 25 prints a leading
    minus, which gives ``L_gV u = −L_gV k > 0``: V̇ increases wherever the law acts. ``‖u‖ =
    |L_gV k| / ‖L_gV‖ <= ‖k‖`` (Cauchy-Schwarz), not ``= ‖k‖`` as the text after eq. 24 says.

    Parameters
    ----------
    benchmark : tuple of 2 float
        The benchmark torque ``k(x)`` on the actuated axes [N m], control frame.
    lgv : tuple of 2 float
        ``L_gV``, the gradient of the Lyapunov function along the control [s/(kg m²)].

    Returns
    -------
    tuple of 2 float
        The min-norm torque ``(u1, u2)`` [N m], control frame; zeros where the benchmark does not
        decrease V or ``L_gV = 0``.
    """
    s = lgv[0] * benchmark[0] + lgv[1] * benchmark[1]
    norm2 = lgv[0] * lgv[0] + lgv[1] * lgv[1]
    if s >= 0.0 or norm2 == 0.0:
        return 0.0, 0.0
    scale = s / norm2
    return scale * lgv[0], scale * lgv[1]


def _sat_symbolic(value: ca.SX, limit: float | None) -> tuple[ca.SX, ca.SX]:
    """:func:`_sat` on expressions."""
    if limit is None:
        return value, ca.SX(1.0)
    return ca.fmin(ca.fmax(value, -limit), limit), ca.if_else(ca.fabs(value) < limit, 1.0, 0.0)


def _ratio_symbolic(numerator: ca.SX, denominator: ca.SX) -> ca.SX:
    """:func:`_ratio` on expressions."""
    safe = ca.if_else(denominator > 0, denominator, 1.0)
    singular = ca.if_else(numerator == 0, 0.0, ca.sign(numerator) * ca.inf)
    return ca.if_else(denominator > 0, numerator / safe, singular)


def desired_rates_symbolic(q: Sequence[ca.SX], w: Sequence[ca.SX | float],
                           gains: SingularGains) -> tuple[ca.SX, ca.SX, ca.SX, ca.SX]:
    """:func:`desired_rates` on expressions: the same arithmetic, branches as ``if_else``.

    Parameters
    ----------
    q : sequence of 4 casadi.SX
        Error quaternion ``[q0, q1, q2, q3]`` in the control frame (scalar first).
    w : sequence of 3 casadi.SX or float
        Body rate ``[ω1, ω2, ω3]`` in the control frame [rad/s]; it enters the derivative only.
    gains : SingularGains
        The law's gains.

    Returns
    -------
    tuple of 4 casadi.SX
        ``(ωd1, ωd2, ω̇d1, ω̇d2)`` [rad/s, rad/s²].
    """
    q0, q1, q2, q3 = q
    w1, w2, w3 = w
    k, g = gains.k, gains.g
    dq1 = 0.5 * (q0 * w1 - q3 * w2 + q2 * w3)
    dq2 = 0.5 * (q0 * w2 - q1 * w3 + q3 * w1)
    dq3 = 0.5 * (q0 * w3 - q2 * w1 + q1 * w2)
    d = q1 * q1 + q2 * q2 + gains.epsilon_d
    dd = 2.0 * (q1 * dq1 + q2 * dq2)
    r1, slope1 = _sat_symbolic(_ratio_symbolic(q2 * q3, d), gains.a1)
    r2, slope2 = _sat_symbolic(_ratio_symbolic(q1 * q3, d), gains.a2)
    safe = ca.if_else(d > 0, d, 1.0)
    dr1 = ca.if_else(ca.logic_and(d > 0, slope1 != 0), ((dq2 * q3 + q2 * dq3) - q2 * q3 * dd / safe) / safe, 0.0)
    dr2 = ca.if_else(ca.logic_and(d > 0, slope2 != 0), ((dq1 * q3 + q1 * dq3) - q1 * q3 * dd / safe) / safe, 0.0)
    return -k * q1 + g * r1, -k * q2 - g * r2, -k * dq1 + g * dr1, -k * dq2 - g * dr2


def min_norm_symbolic(benchmark: tuple[ca.SX, ca.SX], lgv: tuple[ca.SX, ca.SX]) -> tuple[ca.SX, ca.SX]:
    """:func:`min_norm` on expressions (the branch as ``if_else``).

    Parameters
    ----------
    benchmark : tuple of 2 casadi.SX
        The benchmark torque ``k(x)`` on the actuated axes [N m], control frame.
    lgv : tuple of 2 casadi.SX
        ``L_gV`` [s/(kg m²)].

    Returns
    -------
    tuple of 2 casadi.SX
        The min-norm torque ``(u1, u2)`` [N m], control frame.
    """
    s = lgv[0] * benchmark[0] + lgv[1] * benchmark[1]
    norm2 = lgv[0] * lgv[0] + lgv[1] * lgv[1]
    acting = ca.logic_and(s < 0, norm2 != 0)
    scale = ca.if_else(acting, s / ca.if_else(norm2 != 0, norm2, 1.0), 0.0)
    return scale * lgv[0], scale * lgv[1]


def control_frame(spacecraft: Spacecraft) -> Array | str:
    """Rows ``[e1; e2; e3]`` (body axes) of the right-handed principal control frame whose ``e3``
    is the unactuated axis, or the reason why the spacecraft has none.

    Parameters
    ----------
    spacecraft : Spacecraft
        The spacecraft; it needs reaction wheels whose working axes span exactly a plane whose
        normal is a principal axis of the inertia.

    Returns
    -------
    (3, 3) ndarray or str
        The rotation matrix from body to control axes (rows ``e1, e2, e3`` in body axes), or the
        reason why there is none (the caller prefixes the controller's name).
    """
    wheels = spacecraft.wheels
    if wheels is None or not np.any(wheels.working):
        return "needs reaction wheels (two working, spanning a plane)"
    axes = wheels.axes[:, wheels.working]
    u, s, _ = np.linalg.svd(axes)
    rank = int(np.sum(s > 1e-9 * s[0]))
    if rank != 2:
        return (f"is a two-wheel law: the working wheels must span exactly two axes (they span {rank}); "
                "list the broken wheel under spacecraft.wheels.failed")
    normal = u[:, 2]
    inertia = spacecraft.inertia
    scale = float(np.max(np.abs(inertia)))
    if np.linalg.norm(inertia @ normal - (normal @ inertia @ normal) * normal) > PRINCIPAL_TOLERANCE * scale:
        return (f"needs the unactuated axis {np.round(normal, 6).tolist()} (normal to the working wheels of "
                "spacecraft.wheels: the failed wheel's axis) to be a principal axis of spacecraft.inertia")
    index = int(np.argmax(np.abs(normal)))
    if spacecraft.is_principal and abs(abs(normal[index]) - 1.0) < 1e-12:
        return np.eye(3)[[(index + 1) % 3, (index + 2) % 3, index]]  # cyclic relabelling
    _, vectors = np.linalg.eigh(inertia)
    third = int(np.argmax(np.abs(vectors.T @ normal)))
    e3 = vectors[:, third] * np.sign(vectors[:, third] @ normal)
    e1 = vectors[:, next(i for i in range(3) if i != third)]
    return np.array([e1, np.cross(e3, e1), e3])


class TwoWheelLaw(Controller):
    """Base of the two-wheel laws: regulation to the target (rest) in the principal control frame.

    The laws assume zero total angular momentum and ignore any reference (they are regulators,
    like ``eigenaxis_pd``). Two-wheel mode is pure: :attr:`wheels_only` keeps :meth:`allocate`
    from sending what the wheels cannot give to torquers or magnetorquers, and the body torque is
    the paper's ``N = −ḣ`` on the actuated axes (``I ω̇ = u`` under zero momentum, eq. 4), without
    the gyroscopic compensation of rigid-body laws.
    """

    wheels_only = True
    gyroscopic_compensation = False

    def _spacecraft(self) -> Spacecraft:
        """The spacecraft of the last :meth:`reset` (an error before it)."""
        if self.spacecraft is None:
            raise RuntimeError(f"controller {self.name}: call reset(spacecraft, sample_time, target) first")
        return self.spacecraft

    def environment_error(self, spacecraft: Spacecraft, environment: Any) -> str | None:
        frame = self.control_frame(spacecraft)
        return f"controller {self.name} {frame}" if isinstance(frame, str) else None

    def initial_state_error(self, spacecraft: Spacecraft, omega0: Array, wheel_momentum0: Array,
                            omegaf: Array | None) -> tuple[str, str] | None:
        """Refuse a non-zero total angular momentum or a final rate: the laws need ``I ω0 + A h_w0 = 0``
        (the unactuated rate stays zero only then) and end at rest.

        Parameters
        ----------
        spacecraft : Spacecraft
            The spacecraft (inertia, wheel axes).
        omega0 : (3,) ndarray
            Initial body rate [rad/s], body frame.
        wheel_momentum0 : (n_w,) ndarray
            Initial wheel momenta [N m s] along the wheel axes.
        omegaf : (3,) ndarray or None
            Final body rate [rad/s], body frame; ``None``: free.

        Returns
        -------
        tuple of 2 str or None
            ``("initial.omega" or "final.omega", message)``, or ``None`` when the state is accepted.
        """
        momentum = spacecraft.inertia @ omega0 + spacecraft.wheel_axes @ wheel_momentum0
        scale = max(float(np.abs(spacecraft.inertia).max()) * 1e-9, 1e-12)
        if float(np.linalg.norm(momentum)) > scale:
            return ("initial.omega", f"controller {self.name} needs zero total angular momentum I ω + A h_w, got "
                                     f"{np.round(momentum, 9).tolist()} N m s (initial.omega, initial.wheel_momentum)")
        if omegaf is not None and float(np.linalg.norm(omegaf)) > 0.0:
            return ("final.omega", f"controller {self.name} regulates to rest; final.omega must be zero or null")
        return None

    def control_frame(self, spacecraft: Spacecraft) -> Array | str:
        """The control frame (see :func:`control_frame`); a test may override it.

        Parameters
        ----------
        spacecraft : Spacecraft
            The spacecraft.

        Returns
        -------
        (3, 3) ndarray or str
            Rows ``e1, e2, e3`` in body axes (``e3`` unactuated), or why there is none.
        """
        return control_frame(spacecraft)

    def reset(self, spacecraft: Spacecraft, sample_time: float, target: Any = None) -> None:
        super().reset(spacecraft, sample_time, target)
        frame = self.control_frame(spacecraft)
        if isinstance(frame, str):
            raise ValueError(f"controller {self.name} {frame}")  # noqa: TRY004 (a value of the model)
        self.frame = frame
        self._rows = [tuple(float(v) for v in row) for row in frame]
        moments = frame @ spacecraft.inertia @ frame.T
        self.moments = (float(moments[0, 0]), float(moments[1, 1]), float(moments[2, 2]))
        q_target = (1.0, 0.0, 0.0, 0.0) if target is None else tuple(float(v) for v in target[0])
        self._target_conjugate = (q_target[0], -q_target[1], -q_target[2], -q_target[3])

    def error(self, measurement: Measurement) -> tuple[float, float, float, float, float, float, float]:
        """Error quaternion and body rate in the control frame.

        Parameters
        ----------
        measurement : Measurement
            Measured attitude ``q`` (body to inertial, scalar first) and body rate [rad/s].

        Returns
        -------
        tuple of 7 float
            ``(q0, q1, q2, q3, ω1, ω2, ω3)``: the error quaternion ``q_f* ⊗ q`` (sign chosen so
            that ``q0 >= 0``; ``q_f`` the target, identity without one) with its vector part in
            the control frame, and the body rate in the control frame [rad/s].
        """
        p0, p1, p2, p3 = self._target_conjugate
        q0, q1, q2, q3 = measurement.q.tolist()
        e0 = p0 * q0 - p1 * q1 - p2 * q2 - p3 * q3
        ex = p0 * q1 + p1 * q0 + p2 * q3 - p3 * q2
        ey = p0 * q2 - p1 * q3 + p2 * q0 + p3 * q1
        ez = p0 * q3 + p1 * q2 - p2 * q1 + p3 * q0
        if e0 < 0.0:
            e0, ex, ey, ez = -e0, -ex, -ey, -ez
        wx, wy, wz = measurement.omega.tolist()
        (a, b, c), (d, e, f), (g, h, i) = self._rows
        return (e0, a * ex + b * ey + c * ez, d * ex + e * ey + f * ez, g * ex + h * ey + i * ez,
                a * wx + b * wy + c * wz, d * wx + e * wy + f * wz, g * wx + h * wy + i * wz)

    def error_symbolic(self, y: ca.SX) -> tuple[list[ca.SX], list[ca.SX]]:
        """:meth:`error` on the measurement vector ``y``.

        Parameters
        ----------
        y : casadi.SX
            Measurement vector ``[q, ω, h_w, b]`` (layout in :mod:`ocp.layout`).

        Returns
        -------
        tuple of 2 lists of casadi.SX
            ``([q0, q1, q2, q3], [ω1, ω2, ω3])``: error quaternion (``q0 >= 0``) and body rate
            [rad/s], control frame.
        """
        q, w, _, _ = split_measurement(y, self._spacecraft().n_wheels)
        p0, p1, p2, p3 = self._target_conjugate
        e0 = p0 * q[0] - p1 * q[1] - p2 * q[2] - p3 * q[3]
        ex = p0 * q[1] + p1 * q[0] + p2 * q[3] - p3 * q[2]
        ey = p0 * q[2] - p1 * q[3] + p2 * q[0] + p3 * q[1]
        ez = p0 * q[3] + p1 * q[2] - p2 * q[1] + p3 * q[0]
        sign = ca.if_else(e0 < 0, -1.0, 1.0)
        e0, ex, ey, ez = sign * e0, sign * ex, sign * ey, sign * ez
        rows = self._rows
        vector = [a * ex + b * ey + c * ez for a, b, c in rows]
        rates = [a * w[0] + b * w[1] + c * w[2] for a, b, c in rows]
        return [e0, *vector], rates

    def command_symbolic(self, u1: ca.SX, u2: ca.SX, y: ca.SX) -> ca.SX:
        """:meth:`command_torque` on expressions.

        Parameters
        ----------
        u1, u2 : casadi.SX
            Torque on the actuated axes [N m], control frame.
        y : casadi.SX
            Measurement vector ``[q, ω, h_w, b]``.

        Returns
        -------
        casadi.SX
            The control vector ``u`` in the model's control layout (wheel torques [N m]).
        """
        (a, b, c), (d, e, f), _ = self._rows
        torque = ca.vertcat(a * u1 + d * u2, b * u1 + e * u2, c * u1 + f * u2)
        return self.allocate_symbolic(torque, y)

    def to_body(self, u1: float, u2: float) -> Array:
        """A torque on the actuated axes expressed in body axes.

        Parameters
        ----------
        u1, u2 : float
            Torque on the actuated axes ``e1``, ``e2`` [N m], control frame.

        Returns
        -------
        (3,) ndarray
            The torque [N m], body frame.
        """
        (a, b, c), (d, e, f), _ = self._rows
        return np.array([a * u1 + d * u2, b * u1 + e * u2, c * u1 + f * u2])

    def command_torque(self, u1: float, u2: float, measurement: Measurement) -> Command:
        """Wheel command for a body torque on the actuated axes (pure wheel mode, no gyroscopic term).

        Parameters
        ----------
        u1, u2 : float
            Torque on the actuated axes [N m], control frame.
        measurement : Measurement
            The sample's measurement.

        Returns
        -------
        Command
            Wheel torques [N m] (``ḣ_w``) that give the body torque ``−A g``.
        """
        return self.allocate(self.to_body(u1, u2), measurement)
