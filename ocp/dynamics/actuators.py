"""Actuator commands and the actuator model that turns a command into what is applied.

A controller returns a :class:`Command`; the simulator's :class:`ActuatorModel` enforces the
hardware through each actuator's own saturation (:meth:`~ocp.dynamics.actuator_kinds.Actuator.saturate`):
failed wheels give nothing, each wheel's torque and momentum stay within their limits over the
coming zero-order-hold interval, and dipoles and torquer torques are clipped per axis (or, for
magnetorquers with ``saturation="scale"``, the dipole vector is scaled down as a whole).
"""
from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, fields
from operator import attrgetter
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp.dynamics.layout import actuator_blocks
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
    other : dict of str to array_like, the commands of actuator kinds without a field here, by
        their kind's :attr:`~ocp.dynamics.actuator_kinds.Actuator.command` name.
    Any may be ``None`` (nothing asked of that actuator).
    """

    wheel_torque: Array | None = None
    dipole: Array | None = None
    torque: Array | None = None
    other: dict[str, ArrayLike] | None = None

    def value(self, name: str) -> ArrayLike | None:
        """What is asked of the actuator kind whose command is ``name``.

        Parameters
        ----------
        name : str
            The kind's :attr:`~ocp.dynamics.actuator_kinds.Actuator.command`.

        Returns
        -------
        array_like or None
            The field ``name``, or the entry of :attr:`other`; ``None``: nothing asked.
        """
        return command_getter(name)(self)

    def set(self, name: str, value: ArrayLike) -> None:
        """Ask ``value`` of the actuator kind whose command is ``name``.

        Parameters
        ----------
        name : str
            The kind's :attr:`~ocp.dynamics.actuator_kinds.Actuator.command`.
        value : array_like
            Its command, in the unit of its block.
        """
        if name in _FIELDS:
            setattr(self, name, value)
        else:
            self.other = {**(self.other or {}), name: value}


_FIELDS = frozenset(f.name for f in fields(Command)) - {"other"}
"""The fields of :class:`Command` that hold an actuator's command."""


def command_getter(name: str) -> Callable[[Command], Any]:
    """A function reading one actuator kind's command (per-sample code: chosen once).

    Parameters
    ----------
    name : str
        The kind's :attr:`~ocp.dynamics.actuator_kinds.Actuator.command`.

    Returns
    -------
    callable
        ``command -> value or None``: the field ``name`` of a :class:`Command`, or its entry in
        :attr:`Command.other`.
    """
    if name in _FIELDS:
        return attrgetter(name)
    return lambda command: None if command.other is None else command.other.get(name)


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


class ActuatorModel:
    """Saturation and failures of a spacecraft's actuators, for a zero-order hold of ``dt``.

    Parameters
    ----------
    spacecraft : Spacecraft
        Its actuators give the limits, the failures and how each saturates.
    slices : dict of str to slice
        Where each actuator's block sits in the control vector ``u``
        (``AttitudeModel.control_slices``; the actuators of ``spacecraft`` without a block here
        are left out).
    nu : int
        Length of ``u``.
    """

    def __init__(self, spacecraft: Spacecraft, slices: dict[str, slice], nu: int):
        self.spacecraft = spacecraft
        self.slices = slices
        self.nu = nu
        self._blocks = [(block.actuator, slices[block.actuator.block], block.state)
                        for block in actuator_blocks(spacecraft) if block.actuator.block in slices]
        self._n_states = sum(actuator.state_size for actuator, _, _ in self._blocks)
        # Per sample: the command's reader, the actuator's saturation, where its block sits (plain
        # ints), and its states: None when they are all the states (handed over as they are),
        # else a slice (empty for a kind without states).
        self._parts = [(command_getter(actuator.command), actuator.saturate, where.start, where.stop,
                        None if 0 < state.stop - state.start == self._n_states else state)
                       for actuator, where, state in self._blocks]
        self._check_states = any(state is not None and state.stop > state.start for *_, state in self._parts)
        """Whether the states are split among several kinds (then their total length is checked here)."""

    def command_vector(self, command: Command, out: Array | None = None) -> Array:
        """A command as the vector ``u`` (before saturation).

        Parameters
        ----------
        command : Command
            What the controller asks.
        out : (nu,) ndarray, optional
            A zero row to write into; a new one if ``None``.

        Returns
        -------
        (nu,) ndarray
            The command in the model's layout (wheel torques [N m], dipole [A m^2], torquer
            torque [N m], ...); zeros where nothing is asked. ``out`` when given.
        """
        if out is None:
            out = np.zeros(self.nu)
        for read, _, start, stop, _ in self._parts:
            value = read(command)
            if value is not None:
                out[start:stop] = value
        return out

    def apply(self, command: Command, wheel_momentum: ArrayLike, dt: float,
              out: Array | None = None) -> tuple[Array, bool]:
        """The applied control for a command held over ``dt``.

        The wheel torque is clipped to ``[−g_max, g_max]`` and further so that ``h_w + g dt``
        stays within ``±h_max`` (``ḣ_w = g`` is constant over the hold, so this is exact); failed
        wheels give nothing. Dipoles and torquer torques are clipped per axis, or (magnetorquers
        with ``saturation="scale"``) the dipole vector is scaled down as a whole. Each actuator
        saturates its own block (:meth:`~ocp.dynamics.actuator_kinds.Actuator.saturate`).

        Parameters
        ----------
        command : Command
            What the controller asks (``None`` fields: nothing asked of that actuator).
        wheel_momentum : (nx - 7,) array_like
            The actuators' states at the start of the hold: wheel momenta [N m s].
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
        wheel_momentum : sequence of float
            The actuators' states at the start of the hold: wheel momenta [N m s].
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
        if self._check_states and len(wheel_momentum) != self._n_states:
            raise ValueError(f"wheel_momentum needs {self._n_states} values (the actuators' states), "
                             f"got {len(wheel_momentum)}")
        for read, saturate, start, stop, state in self._parts:
            value = read(command)
            if value is None:
                continue
            applied, at_limit = saturate(as_floats(value), wheel_momentum if state is None else wheel_momentum[state], dt)
            values[start:stop] = applied
            if at_limit:
                saturated = True
        return values, saturated

    def apply_symbolic(self, u: Any, wheel_momentum: Any, dt: Any) -> tuple[Any, Any]:
        """:meth:`apply` on CasADi expressions.

        Parameters
        ----------
        u : (nu, 1) casadi.SX or casadi.MX
            Command vector in the model's control layout (zeros where nothing is asked).
        wheel_momentum : (nx - 7, 1) casadi.SX or casadi.MX
            The actuators' states at the start of the hold: wheel momenta [N m s].
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
        for actuator, where, state in self._blocks:
            applied, at_limit = actuator.saturate_symbolic(u[where], wheel_momentum[state], dt)
            parts.append((where, applied))
            flags += at_limit
        applied_u = ca.SX.zeros(self.nu) if not isinstance(u, ca.MX) else ca.MX.zeros(self.nu)
        for where, value in parts:
            applied_u[where] = value
        saturated = ca.mmax(ca.vertcat(*flags)) if flags else ca.SX(0)
        return applied_u, saturated
