"""Vector layouts shared by the symbolic controller laws, the simulator and the generated C code.

* control ``u = [g (n_w), m (3), τ_t (3)]``: blocks of the actuators present (:func:`control_layout`);
* measurement ``y = [q (4), ω (3), h_w (n_w), b (3)]``: attitude, body rate (rad/s), wheel
  momenta (N m s), magnetometer reading (T, body axes; zeros without a field model);
* reference row ``[q* (4), ω* (3), ω̇* (3), τ* (3)]`` (:data:`REFERENCE_FIELDS` numbers), and a
  law's reference input ``r`` = the rows at ``t`` and ``t + T_s`` stacked (26 numbers).
"""
from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

Array = NDArray[np.float64]
REFERENCE_FIELDS = 13
"""Numbers in one reference row ``[q*, ω*, ω̇*, τ*]``."""


def control_layout(spacecraft: Any) -> tuple[dict[str, slice], int]:
    """Slices of ``"wheels"``, ``"dipole"``, ``"torquers"`` in ``u`` and its size ``nu``.

    Parameters
    ----------
    spacecraft : ``ocp.Spacecraft``.

    Returns
    -------
    (dict of slices, int)
    """
    slices: dict[str, slice] = {}
    offset = 0
    for name, present, size in (
        ("wheels", spacecraft.wheels is not None, spacecraft.n_wheels),
        ("dipole", spacecraft.magnetorquers is not None, 3),
        ("torquers", spacecraft.torquers is not None, 3),
    ):
        if present:
            slices[name] = slice(offset, offset + size)
            offset += size
    return slices, offset


def measurement_size(spacecraft: Any) -> int:
    """Length of the measurement vector ``y``: ``7 + n_w + 3``."""
    return 10 + spacecraft.n_wheels


def split_measurement(y: Any, n_wheels: int) -> tuple[Any, Any, Any, Any]:
    """``(q, ω, h_w, b)`` parts of a measurement vector (symbolic column or NumPy array)."""
    return y[0:4], y[4:7], y[7:7 + n_wheels], y[7 + n_wheels:10 + n_wheels]


def measurement_vector(measurement: Any) -> Array:
    """A :class:`~ocp.actuators.Measurement` as the vector ``y`` (a missing field is zeros)."""
    field = np.zeros(3) if measurement.field_body is None else measurement.field_body
    return np.concatenate([measurement.q, measurement.omega, measurement.wheel_momentum, field])


def reference_rows(reference: Any, times: ArrayLike, target: Any = None) -> Array:
    """(len(times), 13) rows ``[q*, ω*, ω̇*, τ*]`` of ``reference`` (anything with a vectorised
    ``sample(t)``) at ``times`` (s); with ``reference=None`` the rows hold the target
    ``(q_f, ω_f or None)`` at rest or at ``ω_f`` with no acceleration or torque."""
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
