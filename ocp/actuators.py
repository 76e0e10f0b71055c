"""Actuator commands and the actuator model that turns a command into what is applied.

A controller returns a :class:`Command`; the simulator's :class:`ActuatorModel` enforces the
hardware: failed wheels give nothing, each wheel's torque and momentum stay within their limits
over the coming zero-order-hold interval, and dipoles and torquer torques are clipped per axis (or,
for magnetorquers with ``saturation="scale"``, the dipole vector is scaled down as a whole).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ocp.spacecraft import Spacecraft

Array = NDArray[np.float64]


@dataclass
class Command:
    """What a controller asks of the actuators.

    Attributes
    ----------
    wheel_torque : (n_w,) N m, motor torques ``g`` (``ḣ_w = g``, the body feels ``−A g``).
    dipole : (3,) A m², magnetorquer dipole in body axes.
    torque : (3,) N m, ideal torquer torque in body axes.
    Any may be ``None`` (nothing asked of that actuator).
    """

    wheel_torque: Array | None = None
    dipole: Array | None = None
    torque: Array | None = None


@dataclass
class Measurement:
    """What the controller sees at a sample: time (s), attitude, body rate (rad/s), wheel momenta
    (N m s) and the magnetometer reading in body axes (T; ``None`` without a field model).
    ``field_rate_inertial`` (T/s, inertial axes) is the rate of the inertial field along the orbit,
    given only to laws that declare ``needs_field_rate`` (the ideal B-dot)."""

    t: float
    q: Array
    omega: Array
    wheel_momentum: Array
    field_body: Array | None = None
    field_rate_inertial: Array | None = None


class ActuatorModel:
    """Saturation and failures of a spacecraft's actuators, for a zero-order hold of ``dt``."""

    def __init__(self, spacecraft: Spacecraft, slices: dict[str, slice], nu: int):
        self.spacecraft = spacecraft
        self.slices = slices
        self.nu = nu
        wheels = spacecraft.wheels
        if wheels is not None:
            self._wheel_mask = wheels.working.astype(float)
            self._wheel_limit = wheels.max_torque
            self._momentum_limit = wheels.max_momentum
        self._dipole_limit = None if spacecraft.magnetorquers is None else spacecraft.magnetorquers.max_dipole
        self._dipole_scaled = spacecraft.magnetorquers is not None and spacecraft.magnetorquers.saturation == "scale"
        self._torquer_limit = None if spacecraft.torquers is None else spacecraft.torquers.max_torque

    def apply(self, command: Command, wheel_momentum: Array, dt: float) -> tuple[Array, bool]:
        """Applied control vector ``u`` for the model, and whether any actuator is at its limit.

        The wheel torque is clipped to ``[−g_max, g_max]`` and further so that ``h_w + g dt``
        stays within ``±h_max`` (``ḣ_w = g`` is constant over the hold, so this is exact).
        """
        u = np.zeros(self.nu)
        saturated = False
        if "wheels" in self.slices and command.wheel_torque is not None:
            g = np.asarray(command.wheel_torque, dtype=float) * self._wheel_mask
            low = np.maximum(-self._wheel_limit, (-self._momentum_limit - wheel_momentum) / dt)
            high = np.maximum(np.minimum(self._wheel_limit, (self._momentum_limit - wheel_momentum) / dt), low)
            applied = np.minimum(np.maximum(g, low), high)  # np.clip, without its per-call overhead
            saturated = bool((np.abs(applied - g) > 1e-12 * np.maximum(1.0, np.abs(g))).any()
                             or (np.abs(applied) >= self._wheel_limit * (1 - 1e-12)).any())
            u[self.slices["wheels"]] = applied
        for name, value, limit in (
            ("dipole", command.dipole, self._dipole_limit),
            ("torquers", command.torque, self._torquer_limit),
        ):
            if name in self.slices and value is not None:
                value = np.asarray(value, dtype=float)
                if name == "dipole" and self._dipole_scaled:
                    # the whole vector is scaled down until every axis is within its limit: direction kept
                    ratio = float(np.max(np.abs(value) / limit))
                    u[self.slices[name]] = value / ratio if ratio > 1.0 else value
                else:
                    u[self.slices[name]] = np.minimum(np.maximum(value, -limit), limit)
                saturated = saturated or bool((np.abs(value) >= limit * (1 - 1e-12)).any())
        return u, saturated

    def apply_symbolic(self, u: Any, wheel_momentum: Any, dt: Any) -> tuple[Any, Any]:
        """:meth:`apply` on CasADi expressions of a command vector ``u`` (layout of the model's
        controls; zeros where nothing is asked): the applied ``u`` and the saturation flag (0/1)."""
        parts = []
        flags = []
        if "wheels" in self.slices:
            g = u[self.slices["wheels"]] * ca.DM(self._wheel_mask)
            g_max, h_max = ca.DM(self._wheel_limit), ca.DM(self._momentum_limit)
            low = ca.fmax(-g_max, (-h_max - wheel_momentum) / dt)
            high = ca.fmax(ca.fmin(g_max, (h_max - wheel_momentum) / dt), low)
            applied = ca.fmin(ca.fmax(g, low), high)
            flags += [ca.fabs(applied - g) > 1e-12 * ca.fmax(1.0, ca.fabs(g)), ca.fabs(applied) >= g_max * (1 - 1e-12)]
            parts.append((self.slices["wheels"], applied))
        for name, limit in (("dipole", self._dipole_limit), ("torquers", self._torquer_limit)):
            if name in self.slices:
                value = u[self.slices[name]]
                bound = ca.DM(limit)
                if name == "dipole" and self._dipole_scaled:  # as apply(): the vector scaled as a whole
                    ratio = ca.mmax(ca.fabs(value) / bound)
                    parts.append((self.slices[name], ca.if_else(ratio > 1.0, value / ratio, value)))
                else:
                    parts.append((self.slices[name], ca.fmin(ca.fmax(value, -bound), bound)))
                flags.append(ca.fabs(value) >= bound * (1 - 1e-12))
        applied_u = ca.SX.zeros(self.nu) if not isinstance(u, ca.MX) else ca.MX.zeros(self.nu)
        for where, value in parts:
            applied_u[where] = value
        saturated = ca.mmax(ca.vertcat(*flags)) if flags else ca.SX(0)
        return applied_u, saturated
