"""Actuator commands and the actuator model that turns a command into what is applied.

A controller returns a :class:`Command`; the simulator's :class:`ActuatorModel` enforces the
hardware: failed wheels give nothing, each wheel's torque and momentum stay within their limits
over the coming zero-order-hold interval, and dipoles and torquer torques are clipped per axis (or,
for magnetorquers with ``saturation="scale"``, the dipole vector is scaled down as a whole).
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp.dynamics.spacecraft import Spacecraft
from ocp.fast_call import as_floats

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
    """What the controller sees at a sample.

    Parameters
    ----------
    t : float
        Sample instant [s].
    q : (4,) ndarray
        Measured attitude, scalar-first unit quaternion rotating body vectors to inertial.
    omega : (3,) ndarray
        Measured body rate [rad/s], body axes.
    wheel_momentum : (n_w,) ndarray
        Wheel momenta about their axes [N m s] (empty without wheels).
    field_body : (3,) ndarray or None, optional
        Magnetometer reading [T], body axes; ``None`` without a field model.
    field_rate_inertial : (3,) ndarray or None, optional
        Rate of the inertial field along the orbit [T/s], inertial axes; given only to laws that
        declare ``needs_field_rate`` (the ideal B-dot), else ``None``.
    """

    t: float
    q: Array
    omega: Array
    wheel_momentum: Array
    field_body: Array | None = None
    field_rate_inertial: Array | None = None


def _limits(values: Array, size: int) -> tuple[float, ...]:
    """Per-element limits as Python floats (the spacecraft stores them broadcast, inf = none)."""
    return tuple(np.broadcast_to(np.asarray(values, dtype=float), (size,)).tolist())


class ActuatorModel:
    """Saturation and failures of a spacecraft's actuators, for a zero-order hold of ``dt``.

    Parameters
    ----------
    spacecraft : Spacecraft
        Its wheels, magnetorquers and torquers give the limits and failures.
    slices : dict of str to slice
        Where ``"wheels"``, ``"dipole"`` and ``"torquers"`` sit in the control vector ``u``
        (``AttitudeModel.control_slices``).
    nu : int
        Length of ``u``.
    """

    def __init__(self, spacecraft: Spacecraft, slices: dict[str, slice], nu: int):
        self.spacecraft = spacecraft
        self.slices = slices
        self.nu = nu
        wheels = spacecraft.wheels
        self._wheel_mask = np.zeros(0)
        self._wheel_limit = np.zeros(0)
        self._momentum_limit = np.zeros(0)
        # Per-sample code works on Python floats: NumPy costs microseconds per call on 3-vectors.
        self._wheels: tuple[int, tuple[float, ...], tuple[float, ...], tuple[float, ...]] | None = None
        if wheels is not None and "wheels" in slices:
            n = wheels.count
            self._wheel_mask = wheels.working.astype(float)
            self._wheel_limit = np.broadcast_to(np.asarray(wheels.max_torque, dtype=float), (n,)).copy()
            self._momentum_limit = np.broadcast_to(np.asarray(wheels.max_momentum, dtype=float), (n,)).copy()
            self._wheels = (slices["wheels"].start, tuple(self._wheel_mask.tolist()), _limits(self._wheel_limit, n),
                            _limits(self._momentum_limit, n))
        magnetorquers, torquers = spacecraft.magnetorquers, spacecraft.torquers
        self._dipole_limit = None if magnetorquers is None else np.asarray(magnetorquers.max_dipole, dtype=float)
        self._dipole_scaled = magnetorquers is not None and magnetorquers.saturation == "scale"
        self._torquer_limit = None if torquers is None else np.asarray(torquers.max_torque, dtype=float)
        self._vectors: list[tuple[str, int, tuple[float, ...], bool]] = []
        """(Command attribute, offset in u, per-axis limits, scaled as a whole) of dipole and torquers."""
        for name, attribute, limit in (("dipole", "dipole", self._dipole_limit),
                                       ("torquers", "torque", self._torquer_limit)):
            if name in slices and limit is not None:
                self._vectors.append((attribute, slices[name].start, _limits(limit, 3),
                                      name == "dipole" and self._dipole_scaled))

    def apply(self, command: Command, wheel_momentum: ArrayLike, dt: float,
              out: Array | None = None) -> tuple[Array, bool]:
        """The applied control for a command held over ``dt``.

        The wheel torque is clipped to ``[−g_max, g_max]`` and further so that ``h_w + g dt``
        stays within ``±h_max`` (``ḣ_w = g`` is constant over the hold, so this is exact); failed
        wheels give nothing. Dipoles and torquer torques are clipped per axis, or (magnetorquers
        with ``saturation="scale"``) the dipole vector is scaled down as a whole.

        Parameters
        ----------
        command : Command
            What the controller asks (``None`` fields: nothing asked of that actuator).
        wheel_momentum : (n_w,) array_like
            Wheel momenta at the start of the hold [N m s].
        dt : float
            Length of the hold [s], positive.
        out : (nu,) ndarray, optional
            Where to write the applied control (overwritten whole); a new array if ``None``.

        Returns
        -------
        u : (nu,) ndarray
            Applied control in the model's layout (wheel torques [N m], dipole [A m^2] and
            torquer torque [N m], body axes), ``out`` when given.
        saturated : bool
            Whether any actuator is at its limit.

        Raises
        ------
        ValueError
            A wheel command or momentum with other than one value per wheel, or a dipole or
            torquer torque with other than 3 values.
        """
        values, saturated = self.apply_floats(command, as_floats(wheel_momentum), dt)
        if out is None:
            return np.array(values), saturated
        out[:] = values
        return out, saturated

    def apply_floats(self, command: Command, wheel_momentum: Sequence[float], dt: float) -> tuple[list[float], bool]:
        """:meth:`apply` on Python floats, for per-sample code.

        Parameters
        ----------
        command : Command
            What the controller asks.
        wheel_momentum : sequence of n_w float
            Wheel momenta at the start of the hold [N m s].
        dt : float
            Length of the hold [s], positive.

        Returns
        -------
        u : list of nu float
            Applied control, as :meth:`apply` returns it.
        saturated : bool
            Whether any actuator is at its limit.
        """
        values = [0.0] * self.nu
        saturated = False
        wheels = self._wheels
        if wheels is not None and command.wheel_torque is not None:
            start, mask, g_max, h_max = wheels
            asked_torques = as_floats(command.wheel_torque)
            if len(asked_torques) != len(mask) or len(wheel_momentum) != len(mask):
                raise ValueError(f"wheel_torque and wheel_momentum need {len(mask)} values (one per wheel), "
                                 f"got {len(asked_torques)} and {len(wheel_momentum)}")
            applied_wheels = []
            for asked, working, limit, h_limit, h in zip(asked_torques, mask, g_max, h_max, wheel_momentum):
                # Written as comparisons (no min/max calls); each line is the NumPy/CasADi
                # max/min of apply_symbolic, with the command first so that a NaN stays NaN.
                g = asked * working
                low = (-h_limit - h) / dt
                if not low > -limit:
                    low = -limit
                high = (h_limit - h) / dt
                if not high < limit:
                    high = limit
                if low > high:  # noqa: PLR1730 (comparisons: no call per wheel and sample)
                    high = low
                applied = low if low > g else g  # noqa: FURB136 (max(g, low), g kept when NaN)
                if high < applied:  # noqa: PLR1730
                    applied = high
                size = abs(g)
                scale = size if size > 1.0 else 1.0  # noqa: FURB136 (max(1.0, |g|))
                if abs(applied - g) > 1e-12 * scale or abs(applied) >= limit * (1 - 1e-12):
                    saturated = True
                applied_wheels.append(applied)
            values[start:start + len(applied_wheels)] = applied_wheels
        for attribute, start, limits, scaled in self._vectors:
            value = getattr(command, attribute)
            if value is None:
                continue
            vector = as_floats(value)
            if len(vector) != 3:
                raise ValueError(f"{attribute} needs 3 values (body axes), got {len(vector)}")
            if scaled:  # the whole vector is scaled down until every axis is within its limit: direction kept
                ratio = max(abs(a) / limit for a, limit in zip(vector, limits))
                values[start:start + 3] = [a / ratio for a in vector] if ratio > 1.0 else vector
            else:
                values[start:start + 3] = [min(max(a, -limit), limit) for a, limit in zip(vector, limits)]
            if any(abs(a) >= limit * (1 - 1e-12) for a, limit in zip(vector, limits)):
                saturated = True
        return values, saturated

    def apply_symbolic(self, u: Any, wheel_momentum: Any, dt: Any) -> tuple[Any, Any]:
        """:meth:`apply` on CasADi expressions.

        Parameters
        ----------
        u : (nu, 1) casadi.SX or casadi.MX
            Command vector in the model's control layout (zeros where nothing is asked).
        wheel_momentum : (n_w, 1) casadi.SX or casadi.MX
            Wheel momenta at the start of the hold [N m s].
        dt : casadi.SX, casadi.MX or float
            Length of the hold [s].

        Returns
        -------
        applied_u : (nu, 1) casadi.SX or casadi.MX
            Applied control, as :meth:`apply` computes it.
        saturated : casadi.SX or casadi.MX
            1 when any actuator is at its limit, else 0.
        """
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
            if name in self.slices and limit is not None:
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

