"""Vector layouts shared by the symbolic controller laws, the simulator and the generated C code.

* control ``u = [g (n_w), m (3), τ_t (3)]``: blocks of the actuators present, in the order of
  their kinds' registration (:func:`actuator_blocks`, :func:`control_layout`); the actuators'
  states (the wheel momenta ``h_w``) follow ``q`` and ``ω`` in the state ``x`` in the same order;
* measurement ``y = [q (4), ω (3), h_w (n_w), b (3)]``: attitude, body rate (rad/s), wheel
  momenta (N m s), magnetometer reading (T, body axes; zeros without a field model);
* reference row ``[q* (4), ω* (3), ω̇* (3), τ* (3)]`` (:data:`REFERENCE_FIELDS` numbers), and a
  law's reference input ``r`` = the rows at ``t`` and ``t + T_s`` stacked (26 numbers).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp.dynamics.actuator_kinds import Actuator
from ocp.dynamics.spacecraft import Spacecraft

Array = NDArray[np.float64]
REFERENCE_FIELDS = 13
"""Numbers in one reference row ``[q*, ω*, ω̇*, τ*]``."""


@dataclass(frozen=True)
class ActuatorBlock:
    """Where one actuator sits in the control and the state.

    Parameters
    ----------
    actuator : Actuator
        The actuator.
    control : slice
        Its block of the control ``u``.
    state : slice
        Its block of the actuator states ``x[7:]`` (empty for a kind without states).
    """

    actuator: Actuator
    control: slice
    state: slice


def actuator_blocks(spacecraft: Spacecraft) -> tuple[ActuatorBlock, ...]:
    """The blocks of the spacecraft's actuators, in the order of :attr:`Spacecraft.actuators`.

    Parameters
    ----------
    spacecraft : Spacecraft
        Its actuators fix the blocks (sizes :attr:`Actuator.control_size` and
        :attr:`Actuator.state_size`).

    Returns
    -------
    tuple of ActuatorBlock
        One per actuator present.
    """
    blocks = []
    control = state = 0
    for actuator in spacecraft.actuators:
        nu, ns = actuator.control_size, actuator.state_size
        blocks.append(ActuatorBlock(actuator, slice(control, control + nu), slice(state, state + ns)))
        control, state = control + nu, state + ns
    return tuple(blocks)


def control_layout(spacecraft: Spacecraft) -> tuple[dict[str, slice], int]:
    """Slices of the actuators' blocks in ``u`` (``"wheels"``, ``"dipole"``, ``"torquers"``, ...)
    and its size ``nu``.

    Parameters
    ----------
    spacecraft : Spacecraft
        The actuators present fix the blocks, keyed by their kind's :attr:`Actuator.block`:
        ``n_w`` wheel torques [N m], then the dipole [A m^2] (3, with magnetorquers), then
        torquer torques [N m] (3, with torquers), then the blocks of other registered kinds.

    Returns
    -------
    slices : dict of str to slice
        Slice of ``u`` for each block present.
    nu : int
        Size of ``u``.
    """
    blocks = actuator_blocks(spacecraft)
    return {block.actuator.block: block.control for block in blocks}, sum(b.actuator.control_size for b in blocks)


def measurement_size(spacecraft: Any) -> int:
    """Length of the measurement vector ``y = [q, ω, h_w, b]``.

    Parameters
    ----------
    spacecraft : Spacecraft
        Gives the number of wheels ``n_w`` (failed ones included).

    Returns
    -------
    int
        ``10 + n_w``.
    """
    return 10 + spacecraft.n_wheels


def split_measurement(y: Any, n_wheels: int) -> tuple[Any, Any, Any, Any]:
    """The parts of a measurement vector.

    Parameters
    ----------
    y : (10 + n_w,) ndarray or (10 + n_w, 1) casadi.SX / MX
        Measurement ``[q, ω, h_w, b]``.
    n_wheels : int
        Number of wheels ``n_w``.

    Returns
    -------
    q : (4,) slice of ``y``
        Measured attitude, scalar-first quaternion, body to inertial.
    omega : (3,) slice of ``y``
        Measured body rate [rad/s], body axes.
    h_w : (n_w,) slice of ``y``
        Wheel spin momenta [N m s].
    b : (3,) slice of ``y``
        Magnetometer reading [T], body axes (zeros without a field model).
    """
    return y[0:4], y[4:7], y[7:7 + n_wheels], y[7 + n_wheels:10 + n_wheels]


def measurement_vector(measurement: Any) -> Array:
    """A measurement as the vector ``y``.

    Parameters
    ----------
    measurement : ocp.dynamics.actuators.Measurement
        What the controller sees at one sample.

    Returns
    -------
    (10 + n_w,) ndarray
        ``[q, ω, h_w, b]`` (units as in the module docstring); ``b`` is zeros when the
        measurement has no field.
    """
    field = np.zeros(3) if measurement.field_body is None else measurement.field_body
    return np.concatenate([measurement.q, measurement.omega, measurement.wheel_momentum, field])


def reference_rows(reference: Any, times: ArrayLike, target: Any = None) -> Array:
    """Reference rows ``[q*, ω*, ω̇*, τ*]`` at given times, as the symbolic laws read them.

    Parameters
    ----------
    reference : planners.base.Reference or None
        Anything with a vectorised ``sample(t)`` returning ``q``, ``omega``, ``omega_dot`` and
        ``torque``; ``None``: regulation to ``target``.
    times : float or (N,) array_like
        Times [s].
    target : (q_f, omega_f) or None, optional
        Used only when ``reference`` is None (then required): final attitude (scalar first,
        body to inertial; ``None``: free, its four columns stay zero) and final body rate
        [rad/s] (``None``: zero).

    Returns
    -------
    (N, 13) ndarray
        Rows: quaternion (scalar first, body to inertial), body rate [rad/s], body angular
        acceleration [rad/s^2] and feed-forward torque [N m], body axes. Without a reference:
        the target, no acceleration, no torque.

    Raises
    ------
    ValueError
        If both ``reference`` and ``target`` are None.
    """
    times = np.atleast_1d(np.asarray(times, dtype=float))
    rows = np.zeros((times.size, REFERENCE_FIELDS))
    if reference is None:
        if target is None:
            raise ValueError("regulation needs a target (q_f, ω_f) when there is no reference")
        if target[0] is not None:  # a free final attitude (rate regulation, detumbling) leaves q* zero
            rows[:, 0:4] = np.asarray(target[0], dtype=float)
        if target[1] is not None:
            rows[:, 4:7] = np.asarray(target[1], dtype=float)
        return rows
    sample = reference.sample(times)
    rows[:, 0:4], rows[:, 4:7], rows[:, 7:10], rows[:, 10:13] = sample.q, sample.omega, sample.omega_dot, sample.torque
    return rows
