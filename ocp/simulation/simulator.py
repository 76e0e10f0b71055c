"""Closed-loop simulation with zero-order hold, actuator saturation and sensor noise.

Each sample: the controller sees a (noisy) :class:`~ocp.dynamics.actuators.Measurement` and returns a
:class:`~ocp.dynamics.actuators.Command`; the :class:`~ocp.dynamics.actuators.ActuatorModel` turns it into the
applied control, held constant while the full model is integrated to the next sample (a CasADi
RK4 map with sub-steps, or CVODES); the quaternion is then re-normalised.

Controllers are duck-typed (see ``controllers.base.Controller``): ``reset(spacecraft,
sample_time, target=None)`` and ``__call__(t, measurement, reference) -> Command``.
A reference, if given, is passed to the controller as a :class:`GridSampledReference`: the same
object as far as the controller can tell (every attribute is the reference's), whose ``sample``
answers the sample instants ``t_k`` and ``t_k + T_s`` from one vectorised evaluation made before
the loop, and any other time from the reference itself.

Two paths compute the same numbers (to rounding; ``tests/test_closed_loop.py``):

* the Python loop above, for any controller;
* when the controller has a symbolic law (``symbolic_error()`` is ``None``) and the integrator is
  RK4, the whole run is one CasADi function (:mod:`ocp.simulation.closed_loop`): the reference is sampled on
  the sample grid in advance, the sensor noise drawn in advance from the same generator in the
  same order. It is interpreted by CasADi's virtual machine, or with ``compile=True`` compiled to
  C (:mod:`ocp.simulation.compiled`; without a compiler: interpreted, with a one-line notice).
"""
from __future__ import annotations

import html
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp import quat
from ocp.cache import RecentCache
from ocp.dynamics.actuators import ActuatorModel, Command, Measurement
from ocp.dynamics.integration import rk4_step
from ocp.dynamics.layout import actuator_blocks, reference_rows
from ocp.dynamics.model import AttitudeModel
from ocp.dynamics.truth import TruthPlant
from ocp.errors import CompilerUnavailable, SimulationArgumentError, SimulationError
from ocp.estimation import (
    BLINDED,
    SENSOR_STATE_SIZE,
    SensorSuite,
    draw_sensor_noise,
    initial_sensor_state,
    sensor_step,
)
from ocp.fast_call import BufferedFunction
from ocp.options import is_real
from ocp.simulation.closed_loop import ClosedLoop, draw_noise
from ocp.simulation.compiled import compile_function, notice

if TYPE_CHECKING:
    import pandas

Array = NDArray[np.float64]

_CONTROL_COLUMNS = {"wheels": ("wheel{}_torque", "N_m", False), "dipole": ("dipole_{}", "A_m2", True),
                    "torquers": ("torquer_{}", "N_m", True)}
"""Column stem, unit and per-body-axis naming of the built-in actuator blocks' controls in
:meth:`SimulationResult.to_dataframe` (another kind's block: ``<block><i>``, no unit)."""
_STATE_COLUMNS = {"wheels": ("wheel{}_momentum_N_m_s", "wheel{}_speed_rpm")}
"""Column of each state and of its speed (state over the spin inertia) of the built-in actuator
blocks with states (another kind's: ``<block>_state<i>``)."""
RPM_PER_RAD_S = 60.0 / (2.0 * math.pi)
"""Revolutions per minute in one rad/s."""


def _number(value: float) -> str:
    """A number for a repr: four significant digits."""
    return f"{value:.4g}"


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
            torque [N m] (layout of :func:`ocp.dynamics.layout.reference_rows`); ``None`` when ``t`` is not
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
            if not is_real(value) or not math.isfinite(value) or value < 0:
                raise ValueError(f"{name} must be a finite non-negative standard deviation, got {value!r}")
        if not isinstance(self.seed, (int, np.integer)) or isinstance(self.seed, bool) or self.seed < 0:
            raise ValueError(f"seed must be a non-negative integer, got {self.seed!r}")


@dataclass
class SimulationResult:
    """Time series of a simulation with ``N`` samples.

    Attributes
    ----------
    model : AttitudeModel
        The simulated model (with a truth plant, its truth model: the axes, inertia and limits
        the run had).
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
    sensor_state : (N+1, 36) ndarray or None
        With a :class:`~ocp.estimation.SensorSuite`, its state (:mod:`ocp.estimation.loop`): the
        initial one, then the one after each sample ``k``, which holds what the controller was
        given at ``t_k``: the attitude estimate ``q̂`` (the MEKF's; without it the last star
        tracker reading), the bias estimate [rad/s] and the MEKF covariance's upper triangle,
        the gyro's true bias [rad/s] and last reading, and which star tracker exclusions held
        its boresight at ``t_k`` (:attr:`blinded`); ``None`` without sensors.
    sensors : SensorSuite or None
        The sensors of the run (``None``: none).
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
    sensor_state: Array | None = None
    sensors: SensorSuite | None = None

    @property
    def blinded(self) -> NDArray[np.int64] | None:
        """(N,) bits per sample ``t_k``: bit i set when the true attitude put the star tracker's
        boresight inside its exclusion i (``sensors.star_tracker.exclusions[i]``), so that an update
        due then was dropped; ``None`` without a star tracker."""
        if self.sensors is None or self.sensors.star_tracker is None or self.sensor_state is None:
            return None
        return np.rint(self.sensor_state[1:, BLINDED]).astype(np.int64)

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

    def __repr__(self) -> str:
        return "<SimulationResult: " + ", ".join(f"{name} {value}" for name, value in self._summary()) + ">"

    def _summary(self) -> list[tuple[str, str]]:
        """(what, value) lines of the repr and of the HTML table."""
        final_rate = float(np.linalg.norm(self.omega[-1])) if self.t.size else math.nan
        blocks = [block.actuator.name for block in actuator_blocks(self.model.spacecraft)]
        return [("samples", str(self.t.size)),
                ("window", f"{_number(self.t[0])} to {_number(self.t[-1])} s"),
                ("sample time", f"{_number(self.sample_time)} s ({self.path})"),
                ("actuators", ", ".join(blocks) or "none"),
                ("final |ω|", f"{_number(final_rate)} rad/s"),
                ("saturated", f"{int(np.count_nonzero(self.saturated))} of {self.saturated.size} intervals")]

    def _repr_html_(self) -> str:
        rows = "".join(f"<tr><th style='text-align:left'>{html.escape(name)}</th><td>{html.escape(value)}</td></tr>"
                       for name, value in self._summary())
        return f"<table><caption>SimulationResult</caption>{rows}</table>"

    def to_dataframe(self, sequence: str = "321") -> pandas.DataFrame:
        """The time series as a pandas DataFrame, one line per sample, units in the column names.

        Columns, in order (``_rad_s`` is rad/s, ``_N_m`` N m, ``_N_m_s`` N m s, ``_A_m2`` A m²):

        * ``t_s``: the time [s];
        * ``q0``, ``q1``, ``q2``, ``q3``: the attitude (scalar first, body to inertial), each sample's
          sign chosen so that none jumps to ``-q`` (:func:`ocp.quat.continuous`);
        * the Euler angles of ``sequence`` [deg] (:func:`ocp.quat.to_euler`): ``yaw_deg``,
          ``pitch_deg``, ``roll_deg`` for ``"321"``, else ``euler_<sequence>_1_deg`` ... ``_3_deg``;
        * ``omega_x_rad_s``, ``omega_y_rad_s``, ``omega_z_rad_s``: the body rate, body axes;
        * ``actuator_torque_x_N_m`` ... ``_z_N_m``: the actuators' applied torque on the body, body axes;
        * per actuator, the command asked for (``_cmd``) and the one applied after saturation: the
          wheels' motor torques ``wheel<i>_torque_cmd_N_m`` and ``wheel<i>_torque_N_m``, the
          magnetorquers' dipole ``dipole_<axis>_cmd_A_m2`` and ``dipole_<axis>_A_m2``, the torquers'
          ``torquer_<axis>_cmd_N_m`` and ``torquer_<axis>_N_m`` (another kind's block:
          ``<block><i>_cmd`` and ``<block><i>``, in its own unit);
        * ``wheel<i>_momentum_N_m_s``: each wheel's spin momentum ``h_w``, and, when the wheels' spin
          inertia ``J_s`` is known, ``wheel<i>_speed_rpm``: ``h_w / J_s`` in revolutions per minute;
        * ``saturated``: whether any actuator was at its limit in the interval from this sample.

        A command is held from its sample to the next, so the commands, the applied torque and
        ``saturated`` are missing (NaN, ``<NA>``) on the last line, the final time.

        Parameters
        ----------
        sequence : str, optional
            The Euler sequence of the angle columns (:func:`ocp.quat.to_euler`); default ``"321"``
            (yaw, pitch, roll).

        Returns
        -------
        pandas.DataFrame
            ``N + 1`` lines, the columns above.

        Raises
        ------
        ImportError
            pandas is not installed.
        ValueError
            A sequence :func:`ocp.quat.to_euler` does not take.
        """
        try:
            import pandas
        except ImportError:
            raise ImportError("to_dataframe needs pandas: pip install pandas") from None
        euler = np.rad2deg(quat.to_euler(self.q, sequence))
        names = (("yaw_deg", "pitch_deg", "roll_deg") if sequence == "321"
                 else tuple(f"euler_{sequence}_{i}_deg" for i in (1, 2, 3)))
        columns: dict[str, Any] = {"t_s": self.t}
        columns.update(zip(("q0", "q1", "q2", "q3"), quat.continuous(self.q).T))
        columns.update(zip(names, euler.T))
        columns.update(zip(("omega_x_rad_s", "omega_y_rad_s", "omega_z_rad_s"), self.omega.T))

        def held(values: Array) -> Array:  # a value per interval, NaN at the final time
            return np.concatenate([values, np.full((1,) + values.shape[1:], np.nan)])

        columns.update(zip((f"actuator_torque_{axis}_N_m" for axis in "xyz"), held(self.applied_torque).T))
        momentum: dict[str, Array] = {}
        for block in actuator_blocks(self.model.spacecraft):
            actuator = block.actuator
            label, unit, per_axis = _CONTROL_COLUMNS.get(actuator.block, (f"{actuator.block}{{}}", "", False))
            suffix = f"_{unit}" if unit else ""
            for i in range(actuator.control_size):
                name = label.format("xyz"[i] if per_axis else i)
                columns[f"{name}_cmd{suffix}"] = held(self.commanded_u[:, block.control][:, i])
                columns[f"{name}{suffix}"] = held(self.applied_u[:, block.control][:, i])
            states = self.x[:, 7:][:, block.state]
            state_name, speed_name = _STATE_COLUMNS.get(actuator.block, (f"{actuator.block}_state{{}}", ""))
            spin_inertia = getattr(actuator, "spin_inertia", None)  # known for wheels that give it
            for i in range(actuator.state_size):
                momentum[state_name.format(i)] = states[:, i]
                if speed_name and spin_inertia is not None:
                    momentum[speed_name.format(i)] = states[:, i] / spin_inertia[i] * RPM_PER_RAD_S
        columns.update(momentum)
        frame = pandas.DataFrame(columns)
        frame["saturated"] = pandas.array([*map(bool, self.saturated), None], dtype="boolean")
        return frame


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


def _with_sensors(noise: SensorNoise, sensors: SensorSuite) -> SensorNoise:
    """``noise`` with the magnetometer's white noise of ``sensors``; a sensor given twice is refused."""
    for declared, name, std in ((sensors.star_tracker, "attitude_std", noise.attitude_std),
                                (sensors.gyro, "rate_std", noise.rate_std),
                                (sensors.magnetometer, "field_std", noise.field_std)):
        if declared is not None and std > 0:
            raise ValueError(f"{type(declared).__name__} is declared in sensors and SensorNoise.{name} is "
                             f"{std:g}: give that sensor's noise once")
    if sensors.magnetometer is not None:
        noise = SensorNoise(noise.attitude_std, noise.rate_std, noise.seed, sensors.magnetometer.noise)
    return noise


def measure(x: Array, t: float, noise: SensorNoise, rng: np.random.Generator, field: Array | None = None,
            field_rng: np.random.Generator | None = None) -> Measurement:
    """What the controller sees at one sample: the state with the sensor noise of ``noise``.

    The simulator's Python loop calls it once per sample; the compiled closed loop
    (:mod:`ocp.simulation.closed_loop`) performs the same operations symbolically, on noise drawn in advance
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


INTEGRATORS = ("rk4", "cvodes")
MAX_SAMPLES = 1_000_000
"""Default bound on the samples of one run (a 100,000 s run at 0.1 s): more is refused, not attempted."""
SUBSTEPS_PER_SAMPLE = 20
"""A run may integrate at most this many RK4 sub-steps per allowed sample (``max_samples``)."""
MAX_SUBSTEPS = 1000
"""Bound on RK4 sub-steps per sample (the step is one unrolled CasADi graph)."""


class Simulator:
    """Zero-order-hold simulator of an :class:`~ocp.dynamics.model.AttitudeModel`.

    Parameters
    ----------
    model : AttitudeModel
        The spacecraft in its environment.
    sample_time : float
        Controller period and zero-order-hold length [s].
    integrator : {"rk4", "cvodes"}, optional
        ``"rk4"``: fixed step, at most ``max_step`` per sub-step; ``"cvodes"``: adaptive
        (``rtol``/``atol``). RK4's local error grows as ``(h ‖ω‖)⁵``: the default 0.05 s keeps
        closed-loop attitudes within ~1e-8 deg of CVODES at rates below ~0.5 rad/s; lower it for
        fast spins or conservation studies.
    max_step : float, optional
        Longest RK4 sub-step [s] (at most :data:`MAX_SUBSTEPS` sub-steps per sample).
    rtol, atol : float, optional
        CVODES relative and absolute tolerances.
    compile : bool, optional
        Build the closed loop of symbolic laws as C (cached; see :mod:`ocp.simulation.compiled`).
    python_loop : bool, optional
        Always use the Python loop (the reference implementation), even for symbolic laws.
    max_samples : int, optional
        Most samples one run may take, and most RK4 sub-steps in all: ``SUBSTEPS_PER_SAMPLE`` times
        this (:data:`SUBSTEPS_PER_SAMPLE`); longer runs are refused with
        :class:`~ocp.errors.SimulationArgumentError` (a ``ValueError`` and a :class:`SimulationError`),
        not attempted.
    plant : TruthPlant or None, optional
        The truth model to integrate (:mod:`ocp.dynamics.truth`), built on ``model``: the loop
        saturates with its limits, delivers with its effects and integrates its dynamics, while
        the controller is reset with ``model``'s spacecraft (the design). ``None`` (default):
        ``model`` is the plant.
    """

    MAX_BUILDS = 16
    """Closed loops kept per simulator (one per law and noise shape)."""
    MODEL_BUILDS = 64
    """Closed-loop builds kept per model and thread, the most recently used (:attr:`loop_cache`): two
    to four per law (its loop, the loop's compiled twin, a run function per chunk size)."""
    CHUNK = 1000
    """Samples per accumulated call of the closed-loop function (its build unrolls them)."""

    def __init__(
        self,
        model: AttitudeModel,
        sample_time: float,
        integrator: str = "rk4",
        max_step: float = 0.05,
        rtol: float = 1e-10,
        atol: float = 1e-12,
        compile: bool = False,
        python_loop: bool = False,
        max_samples: int = MAX_SAMPLES,
        plant: TruthPlant | None = None,
    ):
        if not isinstance(model, AttitudeModel):
            raise TypeError(f"model must be an ocp.AttitudeModel, got {type(model).__name__}")
        for name, value in (("sample_time", sample_time), ("max_step", max_step), ("rtol", rtol), ("atol", atol)):
            if not is_real(value) or not math.isfinite(value) or not value > 0:
                raise ValueError(f"{name} must be a finite positive number of seconds, got {value!r}")
        sample_time, max_step, rtol, atol = float(sample_time), float(max_step), float(rtol), float(atol)
        if integrator not in INTEGRATORS:
            raise ValueError(f"integrator must be one of {INTEGRATORS}, got {integrator!r}")
        substeps = max(1, math.ceil(sample_time / max_step - 1e-9))
        if integrator == "rk4" and substeps > MAX_SUBSTEPS:
            raise ValueError(f"max_step = {max_step:g} s gives {substeps} RK4 sub-steps per {sample_time:g} s sample; "
                             f"at most {MAX_SUBSTEPS} are allowed (raise max_step or lower sample_time)")
        if not isinstance(max_samples, int) or max_samples < 1:
            raise ValueError(f"max_samples must be a positive integer, got {max_samples!r}")
        if plant is not None and (not isinstance(plant, TruthPlant) or plant.design is not model):
            raise TypeError("plant must be an ocp.dynamics.truth.TruthPlant built on this simulator's model")
        self.model = model
        self.plant = plant
        self.simulated = model if plant is None else plant.model
        """The model integrated: ``model``, or the plant's truth model."""
        self.sample_time = float(sample_time)
        self.max_samples = max_samples
        self.substeps = substeps if integrator == "rk4" else 1
        simulated = self.simulated
        self.actuators = ActuatorModel(simulated.spacecraft, simulated.control_slices, simulated.nu)
        self._step = self._build_step(integrator, substeps, rtol, atol)
        self._step_numeric = BufferedFunction(self._normalised(self._step))
        self._field_numeric = None if model.field_body is None else BufferedFunction(model.field_body)
        self._field_rate_numeric = (None if model.field_rate_inertial is None
                                    else BufferedFunction(model.field_rate_inertial))
        self.integrator = integrator
        self._tolerances = (rtol, atol) if integrator == "cvodes" else None  # what the step bakes in besides substeps
        self.compile = compile
        self.python_loop = python_loop
        self._loops: dict[Any, tuple[ClosedLoop, ca.Function, str]] = {}
        self._last_grid: tuple[Any, Array, GridSampledReference] | None = None
        self._torque_map: tuple[int, ca.Function] | None = None

    @staticmethod
    def _normalised(step: ca.Function) -> ca.Function:
        """``step`` followed by the re-normalisation of the quaternion (the Python loop's step)."""
        symbols = [step.sx_in(i) for i in range(step.n_in())] if step.is_a("SXFunction") else step.mx_in()
        x_next = step(*symbols)
        x_next = ca.vertcat(x_next[0:4] / ca.norm_2(x_next[0:4]), x_next[4:])
        return ca.Function("zoh_step_normalised", symbols, [x_next], step.name_in(), ["x_next"])

    def _build_step(self, integrator: str, substeps: int, rtol: float, atol: float) -> ca.Function:
        """``step(x, u, t, dt, p) -> x_next``: one hold interval of length ``dt`` starting at ``t``
        (of the plant's dynamics when there is one)."""
        model = self.model
        rhs = model.rhs if self.plant is None else self.plant.rhs
        x = ca.SX.sym("x", model.nx)
        u = ca.SX.sym("u", model.nu)
        t = ca.SX.sym("t")
        dt = ca.SX.sym("dt")
        p = ca.SX.sym("p", 3)
        if integrator == "rk4":
            h = dt / substeps
            x_next = x
            for k in range(substeps):
                x_next = rk4_step(lambda state, time: rhs(state, u, time, p), x_next, t + k * h, h)
            return ca.Function("zoh_step", [x, u, t, dt, p], [x_next], ["x", "u", "t", "dt", "p"], ["x_next"])
        # CVODES on normalised time s in [0, 1]: dx/ds = dt f(x, u, t + s dt, p).
        s = ca.SX.sym("s")
        params = ca.vertcat(u, t, dt, p)
        dae = {"x": x, "p": params, "t": s, "ode": dt * rhs(x, u, t + s * dt, p)}
        solver = ca.integrator("zoh_cvodes", "cvodes", dae, 0.0, 1.0, {"reltol": rtol, "abstol": atol})
        x_next = solver(x0=x, p=params)["xf"]
        return ca.Function("zoh_step", [x, u, t, dt, p], [x_next], ["x", "u", "t", "dt", "p"], ["x_next"])

    def run(
        self,
        controller: ControllerLike,
        x0: ArrayLike,
        duration: float,
        reference: Any = None,
        target: Any = None,
        noise: SensorNoise | None = None,
        parameters: ArrayLike | None = None,
        sensors: SensorSuite | None = None,
    ) -> SimulationResult:
        """Simulate in closed loop.

        Parameters
        ----------
        controller : controllers.base.Controller (anything with its reset and __call__)
            The feedback law (reset here; a symbolic law runs as one CasADi function unless
            ``python_loop``).
        x0 : (nx,) array_like
            Initial state ``[q, ω, h_w]`` (the quaternion is normalised).
        duration : float
            Simulated time [s]; the last sample is shortened to end there.
        reference : planners.Reference, optional
            Reference to track; ``None``: regulation to ``target``. It is sampled once per run on
            the sample grid (and kept for the next run with the same reference and grid).
        target : (q_f, ω_f or None), optional
            Handed to ``controller.reset``: final attitude and body rate [rad/s] for regulation.
        noise : SensorNoise, optional
            Sensor noise; ``None``: none.
        parameters : (3,) array_like, optional
            Disturbance torque ``p`` [N m], body axes; ``None``: the plant's default (the truth's
            constant disturbance, else the model's).
        sensors : SensorSuite, optional
            Gyro, star tracker, magnetometer and MEKF (:mod:`ocp.estimation`), seeded by
            ``noise.seed``; they replace ``noise``'s rate, attitude and magnetometer parts (which
            must then be zero; the magnetometer's white noise becomes ``noise.field_std``).
            ``None``: the measurement is ``noise``'s alone.

        Returns
        -------
        SimulationResult

        Raises
        ------
        SimulationError
            When the state becomes non-finite (a non-finite command named as the controller's).
        SimulationArgumentError
            A ``duration`` over the work limits (``max_samples``) or past a tabulated magnetic
            field: a ``ValueError`` and a :class:`SimulationError` both, refused before any step.
        Exception
            Whatever the controller's law raises, unchanged; :func:`law_raised` tells it apart
            and says which controller raised it and when.
        ValueError
            A sensor declared twice (in ``sensors`` and with a non-zero deviation in ``noise``), or
            a ``target`` of the wrong shape.
        TypeError
            A controller class instead of an instance, or a ``reference`` without ``sample(t)``
            (a planner's name instead of its reference).
        """
        _check_run_arguments(controller, reference, target)
        model = self.model
        x = np.asarray(x0, dtype=float).copy()
        if x.shape != (model.nx,) or not np.all(np.isfinite(x)):
            raise ValueError(f"x0 must be {model.nx} finite numbers [q, omega, h_w], got shape {x.shape}")
        if not np.linalg.norm(x[0:4]) > 1e-6:
            raise ValueError(f"x0 must start with a non-zero quaternion, got {x[0:4]}")
        x[0:4] = quat.normalize(x[0:4])
        plant = self.plant
        default = model.default_parameters if plant is None else plant.default_parameters
        p = default if parameters is None else np.asarray(parameters, dtype=float)
        if p.shape != (3,) or not np.all(np.isfinite(p)):
            raise ValueError(f"parameters must be a finite 3-vector disturbance torque (N m), got {p}")
        if not is_real(duration) or not math.isfinite(duration) or not duration > 0:
            raise ValueError(f"duration must be a finite positive number of seconds, got {duration!r}")
        duration = float(duration)
        n_samples = max(1, math.ceil(duration / self.sample_time - 1e-9))
        if n_samples > self.max_samples or n_samples * self.substeps > SUBSTEPS_PER_SAMPLE * self.max_samples:
            raise SimulationArgumentError(f"{duration:g} s at {self.sample_time:g} s samples is {n_samples} samples, over the "
                                  f"limit of {self.max_samples} samples or {SUBSTEPS_PER_SAMPLE * self.max_samples} sub-steps in all "
                                  "(simulation.max_samples raises it)")
        times = np.minimum(np.arange(n_samples + 1) * self.sample_time, duration)
        noise = noise or SensorNoise()
        if sensors is not None:
            noise = _with_sensors(noise, sensors)
        rng = np.random.default_rng(noise.seed)
        field_rng = np.random.default_rng([noise.seed, 1])
        valid_until = getattr(model.environment.magnetic_field, "valid_until", None)
        if valid_until is not None and duration > valid_until + 1e-9:
            raise SimulationArgumentError(f"the magnetic field is tabulated up to t = {valid_until:g} s, the run lasts "
                                  f"{duration:g} s; lengthen environment.magnetic_field.span_s")
        field_rate = self._field_rate_numeric if getattr(controller, "needs_field_rate", False) else None
        try:
            controller.reset(model.spacecraft, self.sample_time, target=target)  # the design, also with a plant
        except Exception as error:  # the law's own code, as below: marked (no sample time), re-raised
            setattr(error, _LAW_RAISED, (_controller_name(controller), None))
            raise
        plant_noise = None if plant is None else plant.draw_noise(noise.seed, n_samples)
        if self._symbolic(controller):
            return self._run_symbolic(controller, x, times, p, noise, rng, reference, field_rng, sensors, plant_noise)
        if reference is not None and hasattr(reference, "sample"):
            reference = self._grid_reference(reference, np.concatenate([times, times[:-1] + self.sample_time]))

        commanded = np.zeros((n_samples, model.nu))
        # Per sample: Python floats and lists, the step's own buffers (no NumPy calls on short
        # vectors beyond the copies the measurement hands out); arrays are made at the end.
        states: list[list[float]] = [x.tolist()]
        applied: list[list[float]] = []
        saturated: list[bool] = []
        step = self._step_numeric
        x_in, u_in, t_in, dt_in, p_in = step.inputs
        x_out = step.outputs[0]
        x_in[:] = x
        p_in[:] = p
        evaluate, apply, fill_command = step.evaluate, self.actuators.apply_floats, self.actuators.command_vector
        deliver = None if plant is None else plant.deliver
        times_list = times.tolist()
        sensor_states: list[Array] = []
        if sensors is not None:
            drawn = draw_sensor_noise(sensors, noise.seed, times)
            sensor_states.append(initial_sensor_state(sensors, x[0:4], noise.seed))
        for k in range(n_samples):
            t_k = times_list[k]
            measurement = self._measure(x_in, t_k, noise, rng, field_rng)
            if sensors is not None:
                measurement = self._sensed(sensors, measurement, x_in, sensor_states, drawn[k],
                                           times_list[k + 1] - t_k)
            if field_rate is not None:
                measurement.field_rate_inertial = field_rate(t_k).copy()
            try:
                command = controller(t_k, measurement, reference)
                if not isinstance(command, Command):
                    raise TypeError(f"the law returned {type(command).__name__}, not an ocp.Command "
                                    f"(Controller.allocate(torque, measurement) makes one from a body torque)")
            except Exception as error:  # the law's own code: marked for law_raised, re-raised unchanged
                setattr(error, _LAW_RAISED, (_controller_name(controller), t_k))
                raise
            fill_command(command, commanded[k])
            dt = times_list[k + 1] - t_k
            u, at_limit = apply(command, states[k][7:], dt)
            if deliver is not None:  # the truth's noise and scale errors
                u = deliver(u, None if plant_noise is None else plant_noise[k].tolist())
            applied.append(u)
            saturated.append(at_limit)
            u_in[:] = u
            t_in[0], dt_in[0] = t_k, dt
            evaluate()
            x_next = x_out.tolist()  # the quaternion re-normalised by the step function
            if not math.isfinite(sum(x_next)) and not np.isfinite(x_out).all():  # the sum can overflow
                raise SimulationError(self._divergence(times, k, commanded, controller))
            x_in[:] = x_out
            states.append(x_next)
        result = self._result(times, np.array(states), commanded, np.array(applied).reshape(n_samples, model.nu),
                              np.array(saturated, dtype=bool), "python")
        result.sensor_state = np.array(sensor_states) if sensors is not None else None
        result.sensors = sensors
        return result

    @staticmethod
    def _sensed(sensors: SensorSuite, measurement: Measurement, x: Array, sensor_states: list[Array],
                noise: Array, dt: float) -> Measurement:
        """The measurement once the sensors of ``sensors`` (and the MEKF) have read the true state
        ``x``; appends the next sensor state to ``sensor_states``."""
        q = x[0:4].copy() if sensors.star_tracker is not None else measurement.q
        omega = x[4:7].copy() if sensors.gyro is not None else measurement.omega
        q, omega, field, s_next = sensor_step(sensors, sensor_states[-1], q, omega, measurement.field_body, noise, dt)
        sensor_states.append(s_next)
        measurement.q, measurement.omega, measurement.field_body = q.copy(), omega.copy(), field
        return measurement

    def _result(self, times: Array, states: Array, commanded: Array, applied: Array, saturated: NDArray[np.bool_],
                path: str) -> SimulationResult:
        if self._torque_map is None or self._torque_map[0] != times.size - 1:
            body_torque = self.model.body_torque if self.plant is None else self.plant.body_torque
            self._torque_map = (times.size - 1, body_torque.map(times.size - 1))
        torque_map = self._torque_map[1]
        applied_torque = torque_map(states[:-1].T, applied.T, times[:-1]).full().T
        return SimulationResult(self.simulated, self.sample_time, times, states, commanded, applied, applied_torque,
                                saturated, path)

    @staticmethod
    def _divergence(times: Array, k: int, commanded: Array, controller: Any) -> str:
        """Why the state is not finite after sample ``k``: the law's command when it was not
        finite (named as ``controllers.conformance.checked_command`` names it), else the step."""
        bad = ~np.all(np.isfinite(commanded[:k + 1]), axis=1)
        if np.any(bad):
            j = int(np.argmax(bad))
            return (f"{_controller_name(controller)} returned a non-finite command at t = {times[j]:g} s: "
                    f"u = {commanded[j].tolist()}; a law must give finite numbers at every state (a division by "
                    f"a vanishing norm, 0/0 at the target, an arcsin outside [-1, 1])")
        return (f"the state became non-finite between t = {times[k]:g} s and {times[k + 1]:g} s; "
                "reduce max_step or check the controller's gains")

    def _symbolic(self, controller: Any) -> bool:
        """Whether ``controller`` (after reset) runs as one CasADi function."""
        if self.python_loop or self.integrator != "rk4":
            return False
        reason = getattr(controller, "symbolic_error", None)
        return reason is not None and reason() is None

    def closed_loop_function(self, controller: Any, noise: SensorNoise,
                             sensors: SensorSuite | None = None) -> tuple[ClosedLoop, ca.Function, str]:
        """The one-sample closed-loop function of a symbolic law.

        Builds are kept per law (``Controller.symbolic_key``), noise shape, sensors and what the
        hold bakes in (:meth:`_structure`), in the model's :attr:`loop_cache`: every simulator of
        the model shares them, so a scenario run again builds no closed loop, while a long-lived
        process that meets law after law (a gain swept in a study) keeps only the most recent
        (the last :attr:`MAX_BUILDS` are also kept by the simulator itself).

        Parameters
        ----------
        controller : Controller
            A reset controller with a symbolic law.
        noise : SensorNoise
            Which noises the function takes as inputs (those with a non-zero deviation).
        sensors : SensorSuite, optional
            Sensors and estimator in the loop (:mod:`ocp.estimation`); ``None``: none.

        Returns
        -------
        loop : ClosedLoop
            Its builder.
        function : casadi.Function
            The function, interpreted, or its compiled twin.
        path : str
            ``"interpreted"`` or ``"compiled"``.
        """
        loop_key = self._structure(controller, noise, sensors)
        if loop_key not in self._loops:
            if len(self._loops) >= self.MAX_BUILDS:
                self._loops.clear()
            cache = self.loop_cache  # shared by the simulators of this model (and its runs)

            def build() -> ClosedLoop:
                return ClosedLoop(self.model, self._step, self.actuators, controller.symbolic_law().function,
                                  noise.attitude_std > 0, noise.rate_std > 0, noise.field_std > 0, sensors,
                                  plant=self.plant)

            loop = cache.get(loop_key, build)
            sample, path = loop.sample, "interpreted"
            if self.compile:
                try:  # a failed build raises out of the cache: nothing is stored, the next run tries again
                    sample, path = cache.get((*loop_key, "compiled"), lambda: compile_function(loop.sample)), "compiled"
                except CompilerUnavailable as error:
                    notice(f"{error}; the closed loop runs interpreted")
            self._loops[loop_key] = (loop, sample, path)
        return self._loops[loop_key]

    def _chunk_function(self, loop_key: tuple, path: str, loop: ClosedLoop, sample: ca.Function,
                        size: int) -> BufferedFunction:
        """``sample`` accumulated over ``size`` samples (``mapaccum`` unrolls its calls, so long runs
        go in chunks of at most :attr:`CHUNK` samples), cached as the loop is (:meth:`closed_loop_function`)."""
        return self.loop_cache.get((*loop_key, path, size), lambda: loop.run_function(sample, size))

    @property
    def loop_cache(self) -> RecentCache:
        """The model's closed-loop builds (:meth:`closed_loop_function`), shared by its simulators.

        A :class:`~ocp.cache.RecentCache` of :attr:`MODEL_BUILDS` entries, itself kept in the
        model's :class:`~ocp.SolverCache` (``model.solver_cache``): one per thread, and gone
        when the model's cache is pickled or cleared.

        Returns
        -------
        RecentCache
            The calling thread's store of this simulator's model.
        """
        return self.model.solver_cache.get(("closed_loops",), lambda: RecentCache(self.MODEL_BUILDS))

    def _structure(self, controller: Any, noise: SensorNoise, sensors: SensorSuite | None) -> tuple:
        """What a closed-loop build bakes in, the key of :meth:`closed_loop_function`'s builds in
        the model's :attr:`loop_cache` (the model's numbers are its own): the plant's
        numbers, the hold's integrator and sub-steps (the step integrates its dynamics), the law, which noises
        the loop takes and the sensors' models."""
        return ("closed_loop", None if self.plant is None else self.plant.fingerprint, self.integrator, self.substeps,
                self._tolerances, self._loop_key(controller, noise), None if sensors is None else sensors.key)

    @staticmethod
    def _loop_key(controller: Any, noise: SensorNoise) -> tuple:
        return (controller.symbolic_key(), noise.attitude_std > 0, noise.rate_std > 0, noise.field_std > 0)

    def _run_symbolic(self, controller: Any, x0: Array, times: Array, p: Array, noise: SensorNoise,
                      rng: np.random.Generator, reference: Any,
                      field_rng: np.random.Generator | None = None,
                      sensors: SensorSuite | None = None,
                      plant_noise: Array | None = None) -> SimulationResult:
        n_samples = times.size - 1
        loop, sample, path = self.closed_loop_function(controller, noise, sensors)
        loop_key = self._structure(controller, noise, sensors)
        rows = None
        if loop.shape.uses_reference:
            grid = times[:-1]
            rows = np.hstack([controller.reference_rows(reference, grid),
                              controller.reference_rows(reference, grid + self.sample_time)])
        drawn = None
        if noise.attitude_std > 0 or noise.rate_std > 0 or noise.field_std > 0:
            drawn = draw_noise(rng, n_samples, noise.attitude_std, noise.rate_std, field_rng, noise.field_std)
        nx, nu = self.model.nx, self.model.nu
        xz = np.concatenate([x0, np.asarray(controller.state_vector(), dtype=float)])
        sensor_states = None
        if sensors is not None:  # their noise after the nine of draw_noise, their state after z
            drawn = np.hstack([np.zeros((n_samples, 9)) if drawn is None else drawn,
                               draw_sensor_noise(sensors, noise.seed, times)])
            sensor_states = np.empty((n_samples + 1, SENSOR_STATE_SIZE))
            sensor_states[0] = initial_sensor_state(sensors, x0[0:4], noise.seed)
            xz = np.concatenate([xz, sensor_states[0]])
        states = np.empty((n_samples + 1, nx))
        commanded, applied = np.empty((n_samples, nu)), np.empty((n_samples, nu))
        saturated, torque = np.empty(n_samples), np.empty((n_samples, 3))
        states[0] = x0
        for start in range(0, n_samples, self.CHUNK):
            stop = min(start + self.CHUNK, n_samples)
            run = self._chunk_function(loop_key, path, loop, sample, stop - start)
            chunk = loop.evaluate(run, xz, times[start:stop + 1], None if drawn is None else drawn[start:stop],
                                  None if rows is None else rows[start:stop], p,
                                  None if plant_noise is None else plant_noise[start:stop])
            states[start + 1:stop + 1] = chunk[0][:, :nx]
            if sensor_states is not None:
                sensor_states[start + 1:stop + 1] = chunk[0][:, nx + loop.nz:]
            commanded[start:stop], applied[start:stop], saturated[start:stop], torque[start:stop] = chunk[1:]
            xz = chunk[0][-1]
            if not np.all(np.isfinite(xz)):
                break
        finite = np.isfinite(states).all(axis=1)
        if not finite.all():
            raise SimulationError(self._divergence(times, int(np.argmin(finite)) - 1, commanded, controller))
        return SimulationResult(self.simulated, self.sample_time, times, states, commanded, applied, torque,
                                saturated.astype(bool), path, sensor_states, sensors)

    def _measure(self, x: Array, t: float, noise: SensorNoise, rng: np.random.Generator,
                 field_rng: np.random.Generator | None = None) -> Any:
        field = None if self._field_numeric is None else self._field_numeric(x, t).copy()
        return measure(x, t, noise, rng, field, field_rng)

    def _grid_reference(self, reference: Any, grid: Array) -> GridSampledReference:
        """``reference`` served on ``grid``; the last one is kept, so that runs repeated with the
        same reference and grid (trade studies, Monte Carlo) sample it once. References are
        immutable results (``planners.Reference``)."""
        cached = self._last_grid
        if cached is not None and cached[0] is reference and np.array_equal(cached[1], grid):
            return cached[2]
        served = GridSampledReference(reference, grid)
        self._last_grid = (reference, grid, served)
        return served


_LAW_RAISED = "_slewbench_law_raised"
"""The attribute :meth:`Simulator.run` sets on an exception a controller's law raised."""


def law_raised(error: BaseException) -> tuple[str, float | None] | None:
    """Whether ``error`` came out of a controller's law in :meth:`Simulator.run`, and where.

    A caller running several laws (``slewbench run``) fails the row of a law that raises and runs
    the others, while an exception of the simulator's own code stays an internal error.

    Parameters
    ----------
    error : BaseException
        An exception :meth:`Simulator.run` raised.

    Returns
    -------
    tuple of (str, float or None) or None
        The controller's registry name (its class's name when it has none) and the sample time
        [s] of the call that raised (None: its ``reset``; a call that returned no ``Command``
        raises a ``TypeError`` there); None when the law did not raise ``error``.
    """
    where = getattr(error, _LAW_RAISED, None)
    return where if isinstance(where, tuple) else None


def _controller_name(controller: Any) -> str:
    """A controller's registry name (its class's name when it has none), for messages."""
    name = getattr(controller, "name", None)
    return name if isinstance(name, str) and name else type(controller).__name__


def _check_run_arguments(controller: Any, reference: Any, target: Any) -> None:
    """TypeError/ValueError naming the argument of :meth:`Simulator.run` that is not what it takes."""
    if isinstance(controller, type):
        raise TypeError(f"controller must be a controller instance, got the class {controller.__name__}; "
                        f"instantiate it: {controller.__name__}() or {controller.__name__}(options)")
    if not callable(getattr(controller, "reset", None)) or not callable(controller):
        raise TypeError(f"controller must be a controllers.Controller (reset and __call__), got {type(controller).__name__}")
    if reference is not None and not callable(getattr(reference, "sample", None)):
        hint = (f" (a planner's name? plan it first: PLANNERS[{reference!r}]().plan(problem))"
                if isinstance(reference, str) else "")
        raise TypeError(f"reference must be a planners.Reference (anything with sample(t)) or None, got "
                        f"{type(reference).__name__}{hint}")
    if target is None:
        return
    if not isinstance(target, (tuple, list)) or len(target) != 2:
        # the type and length, not the value: an object's repr (a whole ManeuverProblem) says nothing more
        got = (f"a {type(target).__name__} of {len(target)} items" if isinstance(target, (tuple, list))
               else f"type {type(target).__name__}")
        hint = ("; pass its (qf, omegaf): target=(problem.qf, problem.omegaf)"
                if hasattr(target, "qf") and hasattr(target, "omegaf") else "")
        raise ValueError(f"target must be a pair (q_f, omega_f): the final attitude (4 numbers, scalar first, or None) "
                         f"and body rate (3 numbers in rad/s, or None), got {got}{hint}")
    for index, (name, size, what) in enumerate((("q_f", 4, "a quaternion, scalar first"), ("omega_f", 3, "rad/s"))):
        value = target[index]
        if value is None:
            continue
        try:
            array = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            raise ValueError(f"target[{index}] ({name}) must be {size} numbers ({what}) or None, got {value!r:.80}") from None
        if array.shape != (size,) or not np.all(np.isfinite(array)):
            raise ValueError(f"target[{index}] ({name}) must be {size} finite numbers ({what}) or None, got shape "
                             f"{array.shape}: {array.tolist()}")
        if size == 4 and (problem := quat.unit_norm_error(array)) is not None:
            raise ValueError(f"target[0] (q_f): {problem}, got {array.tolist()}")

