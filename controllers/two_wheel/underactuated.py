"""The control frame and the base class of the two-wheel laws of Horri & Palmer (paper 004).

The desired-rate math (eq. 7-8, 14/24, 25) is in :mod:`controllers.two_wheel.singular_rates`.

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
"""
from __future__ import annotations

from typing import Any

import casadi as ca
import numpy as np

from controllers.base import Array, Controller
from ocp import Command, Measurement, Spacecraft, quat
from ocp.dynamics.layout import split_measurement

PRINCIPAL_TOLERANCE = 1e-9
"""Relative tolerance on ``‖I n − (nᵀ I n) n‖ / ‖I‖`` for the unactuated axis ``n`` to count as principal."""


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
        """Refuse momentum in a failed wheel, a non-zero total angular momentum or a final rate: the
        laws need ``I ω0 + A h_w0 = 0`` (the unactuated rate stays zero only then), no momentum in a
        failed wheel (none can take it out: the body would keep ``I ω = −a h`` to hold the total
        at zero, a spin that never ends) and end at rest.

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
            ``(key, message)`` with the key under ``maneuver`` (``"initial.wheel_momentum"``,
            ``"initial.omega"`` or ``"final.omega"``), or ``None`` when the state is accepted.
        """
        scale = max(float(np.abs(spacecraft.inertia).max()) * 1e-9, 1e-12)
        wheels = spacecraft.wheels
        if wheels is not None:
            failed = [i for i in range(wheels.count) if not wheels.working[i] and abs(wheel_momentum0[i]) > scale]
            if failed:
                held = [float(wheel_momentum0[i]) for i in failed]
                return ("initial.wheel_momentum", (
                    f"controller {self.name} needs zero momentum in a failed wheel (spacecraft.wheels.failed): "
                    f"wheel(s) {failed} hold {held} N m s, which no torque removes, so the body would spin on "
                    f"forever to keep the total momentum"))
        momentum = spacecraft.inertia @ omega0 + spacecraft.wheel_axes @ wheel_momentum0
        if float(np.linalg.norm(momentum)) > scale:
            return ("initial.omega", (f"controller {self.name} needs zero total angular momentum I ω + A h_w, got "
                                      f"{np.round(momentum, 9).tolist()} N m s (initial.omega, initial.wheel_momentum)"))
        if omegaf is not None and float(np.linalg.norm(omegaf)) > 0.0:
            return ("final.omega", f"controller {self.name} regulates to rest; final.omega must be zero or null")
        return None

    def initial_attitude_error(self, spacecraft: Spacecraft, q0: Array, omega0: Array,
                               qf: Array | None) -> tuple[str, str] | None:
        """Refuse an initial attitude outside the laws' domain ``Ω = {q1² + q2² ≠ 0}`` (paper section
        III.C: "the initial condition must be chosen in the manifold Ω").

        With the attitude error purely about the unactuated axis (``q1 = q2 = 0``, ``q3 ≠ 0``; e.g.
        180° about it) the singular ratios are ``0/0``, taken as their limit 0: the desired rates
        are zero, and from rest the laws give no torque at all, for ever. A start turning about an
        actuated axis leaves that set at once, and is accepted.

        Parameters
        ----------
        spacecraft : Spacecraft
            The spacecraft (its control frame).
        q0 : (4,) ndarray
            The simulated initial attitude, scalar first, body to inertial.
        omega0 : (3,) ndarray
            The simulated initial body rate [rad/s], body axes.
        qf : (4,) ndarray or None
            The target attitude; ``None``: the identity.

        Returns
        -------
        tuple of 2 str or None
            ``("initial.q", message)``, or ``None`` when the attitude is in ``Ω`` (or at the target).
        """
        frame = self.control_frame(spacecraft)
        if isinstance(frame, str):
            return None  # environment_error refuses the spacecraft
        error = quat.product(quat.conjugate(quat.IDENTITY if qf is None else qf), q0)
        q1, q2, q3 = frame @ error[1:]
        if q1 * q1 + q2 * q2 > 1e-24 or abs(q3) <= 1e-12:  # in Ω (to rounding), or at the target
            return None
        if float(np.linalg.norm((frame @ omega0)[:2])) > 1e-12:  # turning about an actuated axis: leaves it
            return None
        angle = float(np.rad2deg(quat.error_angle(q0, quat.IDENTITY if qf is None else qf)))
        return ("initial.q", (
            f"controller {self.name} is defined for attitude errors with q1² + q2² ≠ 0 (Horri & Palmer, section "
            f"III.C): the initial error is a {angle:.6g} deg rotation about the unactuated axis "
            f"{np.round(frame[2], 6).tolist()}, where the desired rates are 0/0 and the law gives no torque from "
            f"rest; start off that axis (e.g. simulation.initial_attitude_error_deg)"))

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
            Measurement vector ``[q, ω, h_w, b]`` (layout in :mod:`ocp.dynamics.layout`).

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
