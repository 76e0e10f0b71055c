"""Closed-loop simulation with zero-order hold, actuator saturation and sensor noise.

Each sample: the controller sees a (noisy) :class:`~ocp.actuators.Measurement` and returns a
:class:`~ocp.actuators.Command`; the :class:`~ocp.actuators.ActuatorModel` turns it into the
applied control, held constant while the full model is integrated to the next sample (a CasADi
RK4 map with sub-steps, or CVODES); the quaternion is then re-normalised.

Controllers are duck-typed (see ``controllers.base.Controller``): ``reset(spacecraft,
sample_time, target=None)`` and ``__call__(t, measurement, reference) -> Command``.
A reference, if given, is passed through to the controller untouched.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Protocol

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp import quat
from ocp.actuators import ActuatorModel, Command, Measurement
from ocp.fast_call import BufferedFunction
from ocp.integration import rk4_step
from ocp.model import AttitudeModel

Array = NDArray[np.float64]
INTEGRATORS = ("rk4", "cvodes")
MAX_SAMPLES = 1_000_000
"""Default bound on the samples of one run (a 100,000 s run at 0.1 s): more is refused, not attempted."""
SUBSTEPS_PER_SAMPLE = 20
"""A run may integrate at most this many RK4 sub-steps per allowed sample (``max_samples``)."""
MAX_SUBSTEPS = 1000
"""Bound on RK4 sub-steps per sample (the step is one unrolled CasADi graph)."""


class SimulationError(RuntimeError):
    """The integration diverged (non-finite state), e.g. a step far too long for the rates."""


class ControllerLike(Protocol):
    def reset(self, spacecraft: Any, sample_time: float, target: Any = None) -> None: ...
    def __call__(self, t: float, measurement: Measurement, reference: Any) -> Command: ...


@dataclass(frozen=True)
class SensorNoise:
    """Gaussian sensor noise: attitude as a random rotation vector (rad, per axis std), body rate
    (rad/s, per axis std); ``seed`` makes it repeatable."""

    attitude_std: float = 0.0
    rate_std: float = 0.0
    seed: int = 0

    def __post_init__(self) -> None:
        for name in ("attitude_std", "rate_std"):
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
    t : (N+1,) s, sample instants and the final time.
    x : (N+1, nx) states ``[q, ω, h_w]`` at ``t``.
    commanded_u : (N, nu) control asked for (before saturation), layout of ``model.control_slices``.
    applied_u : (N, nu) control applied over ``[t_k, t_k+1]``.
    applied_torque : (N, 3) N m, actuator torque on the body at ``t_k`` (body axes).
    saturated : (N,) bool, any actuator at its limit during sample k.
    """

    model: AttitudeModel
    sample_time: float
    t: Array
    x: Array
    commanded_u: Array
    applied_u: Array
    applied_torque: Array
    saturated: NDArray[np.bool_]

    @property
    def q(self) -> Array:
        return self.x[:, 0:4]

    @property
    def omega(self) -> Array:
        return self.x[:, 4:7]

    @property
    def wheel_momentum(self) -> Array:
        return self.x[:, 7:]


class Simulator:
    """Zero-order-hold simulator of an :class:`~ocp.model.AttitudeModel`.

    Parameters
    ----------
    model : the spacecraft in its environment.
    sample_time : s, controller period and zero-order-hold length.
    integrator : ``"rk4"`` (fixed step, at most ``max_step`` s per sub-step) or ``"cvodes"``
        (adaptive, ``rtol``/``atol``). RK4's local error grows as ``(h ‖ω‖)⁵``: the default
        0.05 s keeps closed-loop attitudes within ~1e-8 deg of CVODES at rates below ~0.5 rad/s;
        lower it for fast spins or conservation studies.
    """

    def __init__(
        self,
        model: AttitudeModel,
        sample_time: float,
        integrator: str = "rk4",
        max_step: float = 0.05,
        rtol: float = 1e-10,
        atol: float = 1e-12,
        max_samples: int = MAX_SAMPLES,
    ):
        if not isinstance(model, AttitudeModel):
            raise TypeError(f"model must be an ocp.AttitudeModel, got {type(model).__name__}")
        for name, value in (("sample_time", sample_time), ("max_step", max_step), ("rtol", rtol), ("atol", atol)):
            if not isinstance(value, (int, float)) or not math.isfinite(value) or not value > 0:
                raise ValueError(f"{name} must be a finite positive number of seconds, got {value!r}")
        if integrator not in INTEGRATORS:
            raise ValueError(f"integrator must be one of {INTEGRATORS}, got {integrator!r}")
        substeps = max(1, math.ceil(sample_time / max_step - 1e-9))
        if integrator == "rk4" and substeps > MAX_SUBSTEPS:
            raise ValueError(f"max_step = {max_step:g} s gives {substeps} RK4 sub-steps per {sample_time:g} s sample; "
                             f"at most {MAX_SUBSTEPS} are allowed (raise max_step or lower sample_time)")
        if not isinstance(max_samples, int) or max_samples < 1:
            raise ValueError(f"max_samples must be a positive integer, got {max_samples!r}")
        self.model = model
        self.sample_time = float(sample_time)
        self.max_samples = max_samples
        self.substeps = substeps if integrator == "rk4" else 1
        self.actuators = ActuatorModel(model.spacecraft, model.control_slices, model.nu)
        self._step = self._build_step(integrator, substeps, rtol, atol)
        self._step_numeric = BufferedFunction(self._step)
        self._field_numeric = None if model.field_body is None else BufferedFunction(model.field_body)

    def _build_step(self, integrator: str, substeps: int, rtol: float, atol: float) -> ca.Function:
        """``step(x, u, t, dt, p) -> x_next``: one hold interval of length ``dt`` starting at ``t``."""
        model = self.model
        x = ca.SX.sym("x", model.nx)
        u = ca.SX.sym("u", model.nu)
        t = ca.SX.sym("t")
        dt = ca.SX.sym("dt")
        p = ca.SX.sym("p", 3)
        if integrator == "rk4":
            h = dt / substeps
            x_next = x
            for k in range(substeps):
                x_next = rk4_step(lambda state, time: model.rhs(state, u, time, p), x_next, t + k * h, h)
            return ca.Function("zoh_step", [x, u, t, dt, p], [x_next], ["x", "u", "t", "dt", "p"], ["x_next"])
        # CVODES on normalised time s in [0, 1]: dx/ds = dt f(x, u, t + s dt, p).
        s = ca.SX.sym("s")
        params = ca.vertcat(u, t, dt, p)
        dae = {"x": x, "p": params, "t": s, "ode": dt * model.rhs(x, u, t + s * dt, p)}
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
    ) -> SimulationResult:
        """Simulate ``duration`` seconds from ``x0`` in closed loop with ``controller``.

        ``target`` (e.g. ``(q_f, ω_f)``) is handed to ``controller.reset`` for regulation;
        ``parameters`` overrides the model's disturbance torque ``p``.
        """
        model = self.model
        x = np.asarray(x0, dtype=float).copy()
        if x.shape != (model.nx,) or not np.all(np.isfinite(x)):
            raise ValueError(f"x0 must be {model.nx} finite numbers [q, omega, h_w], got shape {x.shape}")
        if not np.linalg.norm(x[0:4]) > 1e-6:
            raise ValueError(f"x0 must start with a non-zero quaternion, got {x[0:4]}")
        x[0:4] = quat.normalize(x[0:4])
        p = model.default_parameters if parameters is None else np.asarray(parameters, dtype=float)
        if p.shape != (3,) or not np.all(np.isfinite(p)):
            raise ValueError(f"parameters must be a finite 3-vector disturbance torque (N m), got {p}")
        if not isinstance(duration, (int, float)) or not math.isfinite(duration) or not duration > 0:
            raise ValueError(f"duration must be a finite positive number of seconds, got {duration!r}")
        n_samples = max(1, math.ceil(duration / self.sample_time - 1e-9))
        if n_samples > self.max_samples or n_samples * self.substeps > SUBSTEPS_PER_SAMPLE * self.max_samples:
            raise SimulationError(f"{duration:g} s at {self.sample_time:g} s samples is {n_samples} samples, over the "
                                  f"limit of {self.max_samples} samples or {SUBSTEPS_PER_SAMPLE} sub-steps each "
                                  "(simulation.max_samples raises it)")
        times = np.minimum(np.arange(n_samples + 1) * self.sample_time, duration)
        noise = noise or SensorNoise()
        rng = np.random.default_rng(noise.seed)
        controller.reset(model.spacecraft, self.sample_time, target=target)

        states = np.empty((n_samples + 1, model.nx))
        commanded = np.zeros((n_samples, model.nu))
        applied = np.zeros((n_samples, model.nu))
        saturated = np.zeros(n_samples, dtype=bool)
        states[0] = x
        for k in range(n_samples):
            t_k = times[k]
            measurement = self._measure(x, t_k, noise, rng)
            command = controller(t_k, measurement, reference)
            commanded[k] = self._command_vector(command)
            dt = times[k + 1] - t_k
            applied[k], saturated[k] = self.actuators.apply(command, x[7:], dt)
            x = self._step_numeric(x, applied[k], t_k, dt, p).copy()
            if not np.all(np.isfinite(x)):
                raise SimulationError(
                    f"the state became non-finite between t = {t_k:g} s and {times[k + 1]:g} s; "
                    "reduce max_step or check the controller's gains"
                )
            x[0:4] /= np.linalg.norm(x[0:4])
            states[k + 1] = x
        torque_map = model.body_torque.map(n_samples)
        applied_torque = torque_map(states[:-1].T, applied.T, times[:-1]).full().T
        return SimulationResult(model, self.sample_time, times, states, commanded, applied, applied_torque, saturated)

    def _measure(self, x: Array, t: float, noise: SensorNoise, rng: np.random.Generator) -> Measurement:
        q, omega = x[0:4], x[4:7]
        if noise.attitude_std > 0:
            q = quat.product(q, quat.from_rotation_vector(rng.normal(0.0, noise.attitude_std, 3)))
        if noise.rate_std > 0:
            omega = omega + rng.normal(0.0, noise.rate_std, 3)
        field = None if self._field_numeric is None else self._field_numeric(x, t).copy()
        return Measurement(t=t, q=q, omega=omega.copy(), wheel_momentum=x[7:].copy(), field_body=field)

    def _command_vector(self, command: Command) -> Array:
        """The command in the layout of ``u`` (zeros where nothing is asked)."""
        u = np.zeros(self.model.nu)
        for name, value in (("wheels", command.wheel_torque), ("dipole", command.dipole), ("torquers", command.torque)):
            if name in self.model.control_slices and value is not None:
                u[self.model.control_slices[name]] = value
        return u
