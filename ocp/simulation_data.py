"""What a simulation takes and gives: the sensor noise, the reference served on the sample grid,
the result, and the error raised when the integration diverges (used by :mod:`ocp.simulator`)."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp.actuators import Command, Measurement
from ocp.layout import reference_rows
from ocp.model import AttitudeModel

Array = NDArray[np.float64]


class GridSampledReference:
    """A reference with its samples on a time grid computed once (vectorised).

    It is the reference as far as a controller can tell: :meth:`sample` answers the grid times
    from the table and any other time from the reference itself, and every other attribute is the
    reference's. :meth:`row` serves per-sample code one grid time as Python floats.

    Parameters
    ----------
    reference : planners.Reference
        Anything with a vectorised ``sample(t)`` returning a named tuple of arrays whose first
        axis is time (for :meth:`row`: the fields ``q``, ``omega``, ``omega_dot``, ``torque``).
    times : (N,) array_like
        Times to precompute [s] (duplicates are merged).
    """

    def __init__(self, reference: Any, times: ArrayLike):
        self.reference = reference
        grid = np.unique(np.asarray(times, dtype=float))
        self._times = grid
        table = reference.sample(grid)
        # Our own copy, read only: its rows are handed out as views and kept across runs, so a law
        # writing into a sample would otherwise change every later run.
        self._table = type(table)(*(np.array(a) for a in table))
        for array in self._table:
            array.setflags(write=False)
        self._index = {value: i for i, value in enumerate(grid.tolist())}
        self._scalar: dict[int, Any] = {}
        self._rows: list[tuple[float, ...]] | None = None

    def sample(self, t: ArrayLike) -> Any:
        """The reference at ``t``, as ``reference.sample`` returns it.

        Parameters
        ----------
        t : float or (M,) array_like
            Time(s) [s]; grid times come from the table, others from the reference.

        Returns
        -------
        named tuple
            The reference's sample (arrays with a leading axis of ``M`` for an array ``t``). The
            arrays of a grid time are read-only views of the table (kept across runs).
        """
        index = self._index
        if np.ndim(t) == 0:
            i = index.get(float(t))  # type: ignore[arg-type]  # a 0-d array_like is a number
            if i is None:
                return self.reference.sample(t)
            scalar = self._scalar.get(i)
            if scalar is None:
                scalar = self._scalar[i] = type(self._table)(*(a[i] for a in self._table))
            return scalar
        rows = [index.get(value) for value in np.ravel(t).astype(float).tolist()]
        if None in rows:
            return self.reference.sample(t)
        return type(self._table)(*(a[rows] for a in self._table))

    def row(self, t: float) -> tuple[float, ...] | None:
        """The reference row ``[q*, ω*, ω̇*, τ*]`` at a grid time, as Python floats.

        Parameters
        ----------
        t : float
            Time [s].

        Returns
        -------
        tuple of 13 float or None
            Attitude quaternion, body rate [rad/s], body acceleration [rad/s^2], feed-forward
            torque [N m] (layout of :func:`ocp.layout.reference_rows`); ``None`` when ``t`` is not
            on the grid.
        """
        i = self._index.get(t)
        if i is None:
            return None
        if self._rows is None:
            self._rows = [tuple(row) for row in reference_rows(self, self._times).tolist()]
        return self._rows[i]

    def __getattr__(self, name: str) -> Any:
        return getattr(self.reference, name)


class SimulationError(RuntimeError):
    """The integration diverged (non-finite state), e.g. a step far too long for the rates."""


@dataclass(frozen=True)
class SensorNoise:
    """Gaussian sensor noise, white per sample.

    Each sample draws attitude, then rate (only the non-zero ones) from the stream seeded by
    ``seed``, and the magnetometer from its own stream (seeded by ``[seed, 1]``), so that adding
    magnetometer noise leaves the attitude and rate noise of a scenario unchanged.

    Parameters
    ----------
    attitude_std : float, optional
        Per-axis standard deviation of the attitude error, a rotation vector [rad] applied in
        body axes (``q ⊗ exp(v/2)``); 0: none.
    rate_std : float, optional
        Per-axis standard deviation of the body-rate error [rad/s], body axes; 0: none.
    seed : int, optional
        Non-negative seed of the generators (same seed, same noise).
    field_std : float, optional
        Per-axis standard deviation of the magnetometer error [T], body axes; 0: none.
    """

    attitude_std: float = 0.0
    rate_std: float = 0.0
    seed: int = 0
    field_std: float = 0.0

    def __post_init__(self) -> None:
        for name in ("attitude_std", "rate_std", "field_std"):
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or not math.isfinite(value) or value < 0:
                raise ValueError(f"{name} must be a finite non-negative standard deviation, got {value!r}")
        if not isinstance(self.seed, (int, np.integer)) or isinstance(self.seed, bool) or self.seed < 0:
            raise ValueError(f"seed must be a non-negative integer, got {self.seed!r}")


@dataclass
class SimulationResult:
    """Time series of a simulation with ``N`` samples.

    Attributes
    ----------
    model : AttitudeModel
        The simulated model.
    sample_time : float
        Controller period [s].
    t : (N+1,) ndarray
        Sample instants and the final time [s].
    x : (N+1, nx) ndarray
        States ``[q, ω, h_w]`` at ``t``: attitude (scalar-first, body to inertial), body rate
        [rad/s], wheel momenta [N m s].
    commanded_u : (N, nu) ndarray
        Control asked for (before saturation), layout of ``model.control_slices``.
    applied_u : (N, nu) ndarray
        Control applied over ``[t_k, t_k+1]``.
    applied_torque : (N, 3) ndarray
        Actuator torque on the body at ``t_k`` [N m], body axes.
    saturated : (N,) bool ndarray
        Whether any actuator was at its limit during sample k.
    path : str
        How it was computed: ``"python"`` (loop), ``"interpreted"`` or ``"compiled"`` (one
        CasADi function).
    """

    model: AttitudeModel
    sample_time: float
    t: Array
    x: Array
    commanded_u: Array
    applied_u: Array
    applied_torque: Array
    saturated: NDArray[np.bool_]
    path: str = "python"

    @property
    def q(self) -> Array:
        """(N+1, 4) attitude quaternions, scalar first, body to inertial."""
        return self.x[:, 0:4]

    @property
    def omega(self) -> Array:
        """(N+1, 3) body rates [rad/s], body axes."""
        return self.x[:, 4:7]

    @property
    def wheel_momentum(self) -> Array:
        """(N+1, n_w) wheel momenta [N m s]."""
        return self.x[:, 7:]


class ControllerLike(Protocol):
    """What the simulator needs of a controller (``controllers.base.Controller`` has it)."""

    def reset(self, spacecraft: Any, sample_time: float, target: Any = None) -> None:
        """Prepare for a run.

        Parameters
        ----------
        spacecraft : Spacecraft
            The controlled spacecraft.
        sample_time : float
            Controller period and zero-order-hold length [s].
        target : (q_f, ω_f or None), optional
            Final attitude (scalar-first quaternion) and body rate [rad/s] for regulation.
        """

    def __call__(self, t: float, measurement: Measurement, reference: Any) -> Command:
        """The command for the sample starting at ``t`` [s] (see ``Controller.__call__``)."""


def measure(x: Array, t: float, noise: SensorNoise, rng: np.random.Generator, field: Array | None = None,
            field_rng: np.random.Generator | None = None) -> Measurement:
    """What the controller sees at one sample: the state with the sensor noise of ``noise``.

    The simulator's Python loop calls it once per sample; the compiled closed loop
    (:mod:`ocp.closed_loop`) performs the same operations symbolically, on noise drawn in advance
    in the same order.

    Parameters
    ----------
    x : (nx,) ndarray
        State ``[q (scalar first, body to inertial), ω [rad/s] (body), h_w [N m s]]``.
    t : float
        Time [s].
    noise : SensorNoise
        Standard deviations (attitude [rad] as a rotation vector, rate [rad/s], field [T]).
    rng : numpy.random.Generator
        The attitude and rate noise stream.
    field : (3,) ndarray, optional
        The geomagnetic field at ``x`` and ``t`` [T] (body frame; a copy the function may modify),
        ``None`` without magnetometer.
    field_rng : numpy.random.Generator, optional
        The magnetometer's own stream (``None``: ``rng``).

    Returns
    -------
    Measurement
        Noisy attitude, rate, field and the wheel momenta.
    """
    q, omega = x[0:4], x[4:7]
    if noise.attitude_std > 0:  # q ⊗ exp(v/2), written out (no general quaternion helper per sample)
        v = rng.normal(0.0, noise.attitude_std, 3)
        angle = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
        s = math.sin(0.5 * angle) / angle if angle > 0 else 0.5
        p0, p1, p2, p3 = math.cos(0.5 * angle), s * v[0], s * v[1], s * v[2]
        q0, q1, q2, q3 = q
        q = np.array([q0 * p0 - q1 * p1 - q2 * p2 - q3 * p3,
                      q0 * p1 + p0 * q1 + q2 * p3 - q3 * p2,
                      q0 * p2 + p0 * q2 + q3 * p1 - q1 * p3,
                      q0 * p3 + p0 * q3 + q1 * p2 - q2 * p1])
    if noise.rate_std > 0:
        omega = omega + rng.normal(0.0, noise.rate_std, 3)
    if noise.field_std > 0 and field is not None:  # its own stream: attitude and rate noise unchanged
        field += (rng if field_rng is None else field_rng).normal(0.0, noise.field_std, 3)
    return Measurement(t=t, q=q.copy(), omega=omega.copy(), wheel_momentum=x[7:].copy(), field_body=field)
