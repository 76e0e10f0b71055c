"""The whole closed loop over N samples as one CasADi function (issue 13).

When a controller provides a symbolic law (``controllers.base.Controller``, "Symbolic form"), one
sample of the closed loop, sensor noise, measurement, law, actuator saturation, the zero-order
hold integrated by RK4 sub-steps and the quaternion re-normalisation, is one SX function

    sample([x; z], t_k, dt_k, noise_k, r_k, p[, w_k]) -> ([x_{k+1}; z_{k+1}], u_commanded, u_applied, saturated, τ_k)

(``τ_k`` the actuators' body torque at ``t_k``) and ``sample.mapaccum(N)`` is the run. With a
truth plant (:class:`~ocp.dynamics.truth.TruthPlant`) the saturation is the truth's, the applied
control is what the truth delivers (its motor torque noise ``w_k``, one per wheel, is an input of
its own, present only when the truth has such noise), the step integrates the truth's dynamics and
the torque is the truth's; the measurement and the law are the design's. It computes what :meth:`ocp.simulation.simulator.Simulator.run`'s
Python loop computes, operation for operation: the noise is drawn in advance from the same seeded
generator in the same order (:func:`draw_noise`), so both paths agree to rounding. The function
is evaluated by CasADi's virtual machine, or compiled to C (:mod:`ocp.simulation.compiled`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ocp.dynamics.actuators import ActuatorModel
from ocp.dynamics.layout import REFERENCE_FIELDS
from ocp.dynamics.model import AttitudeModel
from ocp.dynamics.truth import TruthPlant
from ocp.estimation import (
    SENSOR_STATE_SIZE,
    SensorSuite,
    sensor_step_symbolic,
)
from ocp.fast_call import BufferedFunction

Array = NDArray[np.float64]
NOISE_SIZE = 9
"""Noise numbers per sample: rotation vector (rad), rate (rad/s), magnetometer (T)."""


def draw_noise(rng: np.random.Generator, n_samples: int, attitude_std: float, rate_std: float,
               field_rng: np.random.Generator | None = None, field_std: float = 0.0) -> Array:
    """Sensor noise of a whole run, drawn in the order the Python loop draws it.

    Per sample, the attitude's three normals (if ``attitude_std > 0``) then the rate's (if
    ``rate_std > 0``) come from ``rng``; the magnetometer's come from ``field_rng`` (if
    ``field_std > 0``).

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of the attitude and rate noise.
    n_samples : int
        Number of samples N.
    attitude_std : float
        Standard deviation of each component of the attitude error rotation vector [rad],
        body frame; 0: none.
    rate_std : float
        Standard deviation of each rate component [rad/s], body axes; 0: none.
    field_rng : numpy.random.Generator or None, optional
        Source of the magnetometer noise; ``None`` (default): none.
    field_std : float, optional
        Standard deviation of each magnetometer component [T], body axes (default 0: none).

    Returns
    -------
    (n_samples, 9) ndarray
        Rows ``[rotation vector (rad), rate (rad/s), magnetometer (T)]``; absent parts are zero.
    """
    parts = [std for std in (attitude_std, rate_std) if std > 0]
    noise = np.zeros((n_samples, NOISE_SIZE))
    if field_std > 0 and field_rng is not None:
        noise[:, 6:9] = field_rng.normal(0.0, field_std, (n_samples, 3))
    if not parts:
        return noise
    normals = rng.standard_normal((n_samples, 3 * len(parts)))
    column = 0
    for offset, std in ((0, attitude_std), (3, rate_std)):
        if std > 0:
            noise[:, offset:offset + 3] = std * normals[:, column:column + 3]
            column += 3
    return noise


def noisy_attitude(q: Any, rotvec: Any) -> Any:
    """Measured attitude ``q ⊗ exp(rotvec / 2)``: the attitude sensor's error is a body-frame
    rotation vector. The operations follow the Python loop's (:func:`ocp.simulation.simulator.measure`), so that
    both paths round alike.

    Parameters
    ----------
    q : (4, 1) casadi.SX
        True attitude, scalar first, body to inertial.
    rotvec : (3, 1) casadi.SX
        Error rotation vector [rad], body frame.

    Returns
    -------
    (4, 1) casadi.SX
        Noisy attitude, scalar first (unit when ``q`` is).
    """
    v0, v1, v2 = rotvec[0], rotvec[1], rotvec[2]
    angle = ca.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
    s = ca.if_else(angle > 0, ca.sin(0.5 * angle) / ca.if_else(angle > 0, angle, 1.0), 0.5)
    p0, p1, p2, p3 = ca.cos(0.5 * angle), s * v0, s * v1, s * v2
    q0, q1, q2, q3 = q[0], q[1], q[2], q[3]
    return ca.vertcat(q0 * p0 - q1 * p1 - q2 * p2 - q3 * p3,
                      q0 * p1 + p0 * q1 + q2 * p3 - q3 * p2,
                      q0 * p2 + p0 * q2 + q3 * p1 - q1 * p3,
                      q0 * p3 + p0 * q3 + q1 * p2 - q2 * p1)


@dataclass(frozen=True)
class LoopShape:
    """What one closed-loop build bakes in besides the law and the model's step.

    Parameters
    ----------
    attitude_noise : bool
        The measurement adds the attitude noise (a body-frame rotation vector).
    rate_noise : bool
        The measurement adds the rate noise.
    uses_reference : bool
        The law reads the reference input ``r``.
    uses_time : bool
        An output depends on the time ``t`` (law, field or environment).
    field_noise : bool, optional
        The magnetometer adds noise (only with a field model; default False).
    sensors : bool, optional
        The loop runs a :class:`~ocp.estimation.SensorSuite` (its noise rows follow the nine
        numbers of the noise input; default False).
    """

    attitude_noise: bool
    rate_noise: bool
    uses_reference: bool
    uses_time: bool
    field_noise: bool = False
    sensors: bool = False

    @property
    def noisy(self) -> bool:
        """Whether the run takes the noise input (any sensor noise)."""
        return self.attitude_noise or self.rate_noise or self.field_noise or self.sensors


class ClosedLoop:
    """Builder of the one-sample closed-loop function of a model, a step and a symbolic law.

    Parameters
    ----------
    model : AttitudeModel
        The spacecraft in its environment.
    step : casadi.Function
        ``step(x, u, t, dt, p) -> x_next``, one zero-order hold of length ``dt`` [s] (the
        simulator's RK4 sub-steps).
    actuators : ActuatorModel
        The saturation model (``apply_symbolic``).
    law : casadi.Function
        ``law(t, y, z, r) -> (u, z_next)`` (``controllers.base.SymbolicLaw.function``): time
        [s], measurement ``y`` (:mod:`ocp.dynamics.layout`), law state ``z``, two reference rows ``r``.
    attitude_noise, rate_noise : bool
        Whether the measurement adds the attitude (rotation vector [rad], body frame) and rate
        ([rad/s]) parts of the noise input ``noise = [rotation vector (3), rate (3),
        magnetometer (3)]``.
    field_noise : bool, optional
        Whether the magnetometer reading adds its part [T] (default False; ignored without a
        field model).
    sensors : SensorSuite or None, optional
        Sensors and estimator (:mod:`ocp.estimation.loop`): their state ``s`` follows ``z`` in
        the carried state ``[x; z; s]`` and their noise row (10 numbers) follows the nine above.
    plant : TruthPlant or None, optional
        The truth plant whose dynamics ``step`` integrates and whose limits ``actuators`` hold:
        the applied control is what it delivers (:meth:`~ocp.dynamics.truth.TruthPlant.deliver_symbolic`)
        and the torque its own; ``None`` (default): ``model`` is the plant.

    Attributes
    ----------
    sample : casadi.Function
        ``closed_loop_sample(xz, t, dt, noise, r, p[, plant_noise]) -> (xz_next, u_cmd, u_app,
        saturated, torque)``, one sample (see the module docstring; ``plant_noise`` only when the
        plant has motor torque noise).
    shape : LoopShape
        Which inputs the loop actually uses.
    nz : int
        Size of the law's state ``z``.
    noise_size : int
        Noise numbers per sample: 9, and ``sensors.noise_size`` more with sensors (10, and 4 per
        star tracker exclusion: the body's direction and its cone's cosine at the sample).
    """

    def __init__(self, model: AttitudeModel, step: ca.Function, actuators: ActuatorModel, law: ca.Function,
                 attitude_noise: bool, rate_noise: bool, field_noise: bool = False,
                 sensors: SensorSuite | None = None, plant: TruthPlant | None = None):
        self.model = model
        self.plant_noise_size = 0 if plant is None else plant.noise_size
        """Motor torque noises per sample the loop takes (0: no ``plant_noise`` input)."""
        nx, nz = model.nx, law.nnz_in(2)
        self.nz = nz
        ns = 0 if sensors is None else SENSOR_STATE_SIZE
        self.noise_size = NOISE_SIZE + (0 if sensors is None else sensors.noise_size)
        acc = ca.SX.sym("xz", nx + nz + ns)
        t, dt = ca.SX.sym("t"), ca.SX.sym("dt")
        noise = ca.SX.sym("noise", self.noise_size)
        r = ca.SX.sym("r", 2 * REFERENCE_FIELDS)
        p = ca.SX.sym("p", 3)
        x, z = acc[0:nx], acc[nx:nx + nz]
        q, omega, h_w = x[0:4], x[4:7], x[7:nx]
        if attitude_noise:
            q = noisy_attitude(q, noise[0:3])
        if rate_noise:
            omega = omega + noise[3:6]
        field = ca.SX.zeros(3) if model.field_body is None else model.field_body(x, t)
        if field_noise and model.field_body is not None:
            field = field + noise[6:9]
        s_next = ca.SX.zeros(0, 1)
        if sensors is not None:  # the sensors read the true state where declared (ocp.estimation.loop)
            q, omega, read, s_next = sensor_step_symbolic(
                sensors, acc[nx + nz:], x[0:4] if sensors.star_tracker is not None else q,
                x[4:7] if sensors.gyro is not None else omega, None if model.field_body is None else field,
                noise[NOISE_SIZE:], dt)
            field = field if read is None else read
        y = ca.vertcat(q, omega, h_w, field)
        u_cmd, z_next = law(t, y, z, r)
        u_applied, saturated = actuators.apply_symbolic(u_cmd, h_w, dt)
        plant_noise = ca.SX.sym("plant_noise", self.plant_noise_size) if self.plant_noise_size else None
        if plant is not None:
            u_applied = plant.deliver_symbolic(u_applied, plant_noise)
        x_next = step(x, u_applied, t, dt, p)
        x_next = ca.vertcat(x_next[0:4] / ca.norm_2(x_next[0:4]), x_next[4:nx])
        torque = (model if plant is None else plant).body_torque(x, u_applied, t)
        outputs = [ca.vertcat(x_next, z_next, s_next), u_cmd, u_applied, saturated, torque]
        self.shape = LoopShape(attitude_noise, rate_noise, bool(ca.depends_on(ca.vertcat(u_cmd, z_next), r)),
                               bool(ca.depends_on(ca.vertcat(*outputs), t)),
                               bool(field_noise and model.field_body is not None), sensors is not None)
        inputs = [acc, t, dt, noise, r, p] + ([plant_noise] if plant_noise is not None else [])
        self.sample = ca.Function("closed_loop_sample", inputs, outputs,
                                  ["xz", "t", "dt", "noise", "r", "p"] + (["plant_noise"] if plant_noise is not None else []),
                                  ["xz_next", "u_cmd", "u_app", "saturated", "torque"], {"cse": True})

    def run_function(self, sample: ca.Function, n_samples: int) -> BufferedFunction:
        """The run of ``n_samples`` samples as one function.

        Parameters
        ----------
        sample : casadi.Function
            :attr:`sample`, interpreted, or its compiled twin (:func:`ocp.simulation.compiled.compile_function`).
        n_samples : int
            Number of samples N.

        Returns
        -------
        BufferedFunction
            ``run(xz0, t (N), dt (N), [noise (noise_size N)], [r (26N)], p, [plant_noise (n_w N)]) ->
            (xz (N(nx+nz[+36])), u_cmd, u_app, saturated, torque)``, with :attr:`noise_size` 9, or
            19 + 4 E with sensors (E the star tracker's exclusions) and 36 the sensor state
            (:data:`~ocp.estimation.SENSOR_STATE_SIZE`): the noise and reference inputs
            exist only when the loop uses them (:attr:`shape`, :attr:`plant_noise_size`), and every
            input and output has its exact size, so that the function is evaluated through
            reusable buffers.
        """
        accumulated = sample.mapaccum("closed_loop", n_samples)
        xz0 = ca.MX.sym("xz0", sample.nnz_in(0))
        t, dt = ca.MX.sym("t", 1, n_samples), ca.MX.sym("dt", 1, n_samples)
        p = ca.MX.sym("p", 3)
        inputs = [xz0, t, dt]
        if self.shape.noisy:
            noise = ca.MX.sym("noise", self.noise_size, n_samples)
            inputs.append(noise)
        else:
            noise = ca.MX.zeros(self.noise_size, n_samples)
        if self.shape.uses_reference:
            r = ca.MX.sym("r", 2 * REFERENCE_FIELDS, n_samples)
            inputs.append(r)
        else:
            r = ca.MX.zeros(2 * REFERENCE_FIELDS, n_samples)
        inputs.append(p)
        arguments = [xz0, t, dt, noise, r, ca.repmat(p, 1, n_samples)]
        if self.plant_noise_size:
            plant_noise = ca.MX.sym("plant_noise", self.plant_noise_size, n_samples)
            inputs.append(plant_noise)
            arguments.append(plant_noise)
        outputs = accumulated.call(arguments)
        return BufferedFunction(ca.Function("closed_loop_run", inputs, outputs))

    def evaluate(self, run: BufferedFunction, xz0: Array, times: Array, noise: Array | None, rows: Array | None,
                 p: Array, plant_noise: Array | None = None) -> tuple[Array, Array, Array, Array, Array]:
        """Run the accumulated function over the sample times.

        Parameters
        ----------
        run : BufferedFunction
            The result of :meth:`run_function` for N = ``times.size - 1`` samples.
        xz0 : (nx + nz [+ 36],) ndarray
            Initial state ``x`` (quaternion, body rate [rad/s], wheel momenta [N m s]), law
            state ``z`` and, with sensors, their state ``s``.
        times : (N + 1,) ndarray
            Sample times [s]; the control computed at ``times[k]`` is held until ``times[k + 1]``.
        noise : (N, noise_size) ndarray or None
            Sensor noise per sample, :attr:`noise_size` numbers: the 9 of :func:`draw_noise`, then with
            sensors the ``10 + 4 E`` of :func:`ocp.estimation.draw_sensor_noise` (E the star tracker's
            exclusions), 19 + 4 E in all; required when ``shape.noisy``, otherwise ignored.
        rows : (N, 26) ndarray or None
            Reference rows at ``t_k`` and ``t_k + T_s`` per sample (:mod:`ocp.dynamics.layout`); required
            when ``shape.uses_reference``, otherwise ignored.
        p : (3,) ndarray
            Constant disturbance torque [N m], body frame.
        plant_noise : (N, n_w) ndarray or None, optional
            The truth's motor torque noise per sample and wheel [N m]
            (:meth:`~ocp.dynamics.truth.TruthPlant.draw_noise`); required when
            :attr:`plant_noise_size` is not 0, otherwise ignored.

        Returns
        -------
        xz : (N, nx + nz [+ 36]) ndarray
            States ``[x; z]`` after each sample, and with sensors their state ``s``.
        u_cmd, u_app : (N, nu) ndarray
            Commanded and applied (saturated) controls.
        saturated : (N,) ndarray
            Saturation flags (1.0 where an actuator was at its limit).
        torque : (N, 3) ndarray
            Actuators' body torque at each sample time [N m], body frame.
        """
        n = times.size - 1
        args = [xz0, times[:-1], times[1:] - times[:-1]]
        if self.shape.noisy:
            if noise is None:
                raise ValueError(f"this closed loop takes sensor noise: pass the (N, {self.noise_size}) noise")
            args.append(noise.ravel())  # (N, noise_size) row-major is the (noise_size, N) column-major input
        if self.shape.uses_reference:
            if rows is None:
                raise ValueError("this closed loop reads a reference: pass the (N, 26) rows")
            args.append(rows.ravel())
        args.append(p)
        if self.plant_noise_size:
            if plant_noise is None:
                raise ValueError("this closed loop takes the plant's motor torque noise: pass the (N, n_w) noise")
            args.append(plant_noise.ravel())
        xz, u_cmd, u_app, saturated, torque = run.all_outputs(*args)
        return (xz.reshape(n, -1).copy(), u_cmd.reshape(n, -1).copy(), u_app.reshape(n, -1).copy(),
                saturated.copy(), torque.reshape(n, 3).copy())
