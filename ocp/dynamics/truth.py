"""The truth model: the plant the closed loop integrates, beside the design model the planners and
controllers use.

:class:`Truth` holds what the real spacecraft has that its design model does not say, or says
differently: the full inertia tensor, misaligned wheel axes, the wheels' physical torque and
momentum limits, bearing friction (Coulomb and viscous) and a speed limit, motor torque noise, a
magnetorquer dipole scale error, a residual magnetic dipole and disturbance torques (constant, or
periodic at the orbit rate and twice it). :class:`TruthPlant` builds it on a design
:class:`~ocp.dynamics.model.AttitudeModel`: the truth model (the design's spacecraft with the truth's
values, in the design's environment) and its symbolic dynamics ``rhs(x, u, t, p)``, which
:class:`~ocp.simulation.simulator.Simulator` integrates in place of the design model's.

The state and control layouts are the design's (same actuators, same number of wheels). Per
sample, the command saturated by the truth's limits is *delivered* (:meth:`TruthPlant.deliver`):
each wheel's motor torque plus its noise, the dipole times ``1 + scale_error``. Within the
sample, the dynamics see each wheel's torque ``g − f(Ω)`` with ``Ω = h/J_s − aᵀω`` the wheel's
speed relative to the body: the motor torque is cut to zero when ``|Ω|`` is at the speed limit and
the motor would drive it further, and the friction ``f = c sign(Ω) + b Ω`` is internal (it acts on
the wheel, and oppositely on the body: total angular momentum is conserved). The residual dipole
gives ``m_res × B_B`` and the periodic disturbances
``Σ_k A_k ∘ sin(k n t + φ_k)`` (``n`` the orbit's mean motion), both in body axes, added to the
constant disturbance ``p``.
"""
from __future__ import annotations

import dataclasses
import hashlib
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp import quat
from ocp.dynamics.actuator_kinds import ReactionWheels
from ocp.dynamics.model import AttitudeModel, _plain
from ocp.dynamics.spacecraft import Spacecraft
from ocp.errors import ModelError

__all__ = ["MAX_MISALIGNMENT_DEG", "PeriodicTorque", "Truth", "TruthPlant"]

Array = NDArray[np.float64]
MAX_MISALIGNMENT_DEG = 10.0
"""Largest wheel axis misalignment accepted [deg]: beyond it an axis is another design, not an error."""


@dataclass(frozen=True)
class PeriodicTorque:
    """A disturbance torque periodic at a harmonic of the orbit rate, ``A ∘ sin(k n t + φ)``.

    Parameters
    ----------
    harmonic : int
        ``k``: 1 (orbit rate) or 2 (twice the orbit rate).
    amplitude : (3,) array_like
        ``A`` [N m] per body axis.
    phase : (3,) array_like, optional
        ``φ`` [rad] per body axis (default zeros).

    Raises
    ------
    ModelError
        For another harmonic or values that are not 3 finite numbers.
    """

    harmonic: int
    amplitude: Array
    phase: Array = dataclasses.field(default_factory=lambda: np.zeros(3))

    def __post_init__(self) -> None:
        if self.harmonic not in (1, 2) or isinstance(self.harmonic, bool):
            raise ModelError("harmonic", f"expected 1 (orbit rate) or 2 (twice the orbit rate), got {self.harmonic!r}")
        for name in ("amplitude", "phase"):
            value = np.asarray(getattr(self, name), dtype=float)
            if value.shape != (3,) or not np.all(np.isfinite(value)):
                raise ModelError(name, f"expected 3 finite numbers (body axes), got {getattr(self, name)!r}")
            object.__setattr__(self, name, value)


def _optional(value: ArrayLike | None, shape: tuple[int, ...], name: str, non_negative: bool = False,
              positive: bool = False) -> Array | None:
    """A float array of ``shape`` (a scalar is broadcast), or ``None``."""
    if value is None:
        return None
    array = np.asarray(value, dtype=float)
    if array.ndim == 0 and len(shape) == 1:
        array = np.full(shape, float(array))
    if array.shape != shape or np.any(np.isnan(array)):
        raise ModelError(name, f"expected {'a number or ' if len(shape) == 1 else ''}"
                               f"{' x '.join(map(str, shape))} numbers, got {np.asarray(value).tolist()!r:.80}")
    if np.any(np.isinf(array)) and not positive:
        raise ModelError(name, f"expected finite numbers, got {array.tolist()}")
    if non_negative and np.any(array < 0):
        raise ModelError(name, f"expected numbers >= 0, got {array.tolist()}")
    if positive and np.any(~(array > 0)):
        raise ModelError(name, f"expected numbers > 0, got {array.tolist()}")
    return array


@dataclass(frozen=True)
class Truth:
    """What the simulated plant has that the design model does not say, or says differently.

    Every field is optional (``None``: the design's value, or no such effect). Per-wheel values
    take one number for all wheels or one per wheel; the wheel count is checked against the design
    by :class:`TruthPlant`. Errors name the field as the scenario's ``truth:`` section spells it.

    Parameters
    ----------
    inertia : (3,) or (3, 3) array_like, optional
        Principal moments, or the full inertia tensor with its products of inertia [kg m^2], body
        frame, about the centre of mass (the design's rules: symmetric positive definite, triangle
        inequalities).
    wheel_misalignment : (n, 3) array_like, optional
        Per wheel, the rotation vector [rad], body frame, that turns its design axis into its true
        axis; norm at most :data:`MAX_MISALIGNMENT_DEG`.
    wheel_max_torque, wheel_max_momentum : float or (n,) array_like, optional
        The wheels' physical torque [N m] and momentum [N m s] limits, applied in the loop.
    wheel_coulomb : float or (n,) array_like, optional
        Coulomb friction torque per wheel [N m], >= 0.
    wheel_viscous : float or (n,) array_like, optional
        Viscous friction coefficient per wheel [N m s] (torque per rad/s of relative speed), >= 0.
    wheel_max_speed : float or (n,) array_like, optional
        Speed limit per wheel relative to the body [rad/s], > 0.
    wheel_torque_noise : float or (n,) array_like, optional
        Standard deviation of each wheel's motor torque noise [N m], >= 0, white per sample.
    dipole_scale_error : float or (3,) array_like, optional
        Per body axis, the delivered dipole is ``(1 + e)`` times the saturated command; ``e > -1``.
    residual_dipole : (3,) array_like, optional
        Residual magnetic dipole [A m^2], body frame (needs a magnetic field model).
    constant_disturbance : (3,) array_like, optional
        The plant's constant disturbance torque [N m], body frame, in place of the environment's.
    periodic_disturbance : sequence of PeriodicTorque, optional
        Disturbances periodic at the orbit rate or twice it (needs an orbit).

    Raises
    ------
    ModelError
        For a value of the wrong shape or range (its ``field`` is the ``truth:`` key).
    """

    inertia: Array | None = None
    wheel_misalignment: Array | None = None
    wheel_max_torque: Array | None = None
    wheel_max_momentum: Array | None = None
    wheel_coulomb: Array | None = None
    wheel_viscous: Array | None = None
    wheel_max_speed: Array | None = None
    wheel_torque_noise: Array | None = None
    dipole_scale_error: Array | None = None
    residual_dipole: Array | None = None
    constant_disturbance: Array | None = None
    periodic_disturbance: tuple[PeriodicTorque, ...] = ()

    def __post_init__(self) -> None:
        if self.inertia is not None:
            try:
                inertia = Spacecraft(self.inertia).inertia
            except ModelError as error:
                raise ModelError("spacecraft.inertia", error.message) from None
            object.__setattr__(self, "inertia", inertia)
        if self.wheel_misalignment is not None:
            angles = np.asarray(self.wheel_misalignment, dtype=float)
            if angles.ndim != 2 or angles.shape[1] != 3 or not np.all(np.isfinite(angles)):
                raise ModelError("wheels.misalignment_deg", "expected one rotation vector (3 numbers, body frame) per "
                                 f"wheel, got shape {angles.shape}")
            largest = float(np.degrees(np.linalg.norm(angles, axis=1)).max(initial=0.0))
            if largest > MAX_MISALIGNMENT_DEG + 1e-12:
                raise ModelError("wheels.misalignment_deg", f"a misalignment of {largest:.4g} deg exceeds "
                                 f"{MAX_MISALIGNMENT_DEG:g} deg: give the axis itself in spacecraft.wheels.axes")
            object.__setattr__(self, "wheel_misalignment", angles)
        for name, key, checks in (("wheel_max_torque", "wheels.max_torque", {"positive": True}),
                                  ("wheel_max_momentum", "wheels.max_momentum", {"positive": True}),
                                  ("wheel_coulomb", "wheels.friction.coulomb", {"non_negative": True}),
                                  ("wheel_viscous", "wheels.friction.viscous", {"non_negative": True}),
                                  ("wheel_max_speed", "wheels.max_speed_rpm", {"positive": True}),
                                  ("wheel_torque_noise", "wheels.torque_noise", {"non_negative": True})):
            value = getattr(self, name)
            if value is not None:
                array = np.asarray(value, dtype=float)
                if array.ndim > 1:
                    raise ModelError(key, f"expected a number or one number per wheel, got shape {array.shape}")
                object.__setattr__(self, name, _optional(array, array.shape if array.ndim else (1,), key, **checks))
        scale = _optional(self.dipole_scale_error, (3,), "magnetorquers.scale_error")
        if scale is not None and np.any(~(scale > -1.0)):
            raise ModelError("magnetorquers.scale_error", f"expected scale errors > -1 (a dipole that keeps its sign), "
                                                          f"got {scale.tolist()}")
        object.__setattr__(self, "dipole_scale_error", scale)
        object.__setattr__(self, "residual_dipole", _optional(self.residual_dipole, (3,), "residual_dipole"))
        object.__setattr__(self, "constant_disturbance",
                           _optional(self.constant_disturbance, (3,), "disturbance.constant"))
        periodic = tuple(self.periodic_disturbance)
        if not all(isinstance(item, PeriodicTorque) for item in periodic):
            raise ModelError("disturbance.orbit_periodic", "expected PeriodicTorque entries")
        object.__setattr__(self, "periodic_disturbance", periodic)


def _per_wheel(value: Array | None, n: int, key: str) -> Array | None:
    if value is None:
        return None
    if value.size == 1:
        return np.full(n, float(value.reshape(-1)[0]))
    if value.shape != (n,):
        raise ModelError(key, f"expected a number or {n} numbers (one per wheel), got {value.size}")
    return value


class TruthPlant:
    """The truth model built on a design model: what the closed loop integrates.

    Parameters
    ----------
    design : AttitudeModel
        The design model (the planners' and controllers').
    truth : Truth
        The plant's own values.

    Attributes
    ----------
    design : AttitudeModel
        As given.
    truth : Truth
        As given.
    model : AttitudeModel
        The design's spacecraft with the truth's inertia, wheel axes and limits, in the design's
        environment (same state and control layouts).
    rhs : casadi.Function
        ``f(x, u, t, p) -> xdot`` of the plant (friction, speed limit, residual dipole and periodic
        disturbances included; ``u`` the delivered control).
    body_torque : casadi.Function
        ``body_torque(x, u, t) -> tau``: the actuators' torque on the body [N m], body axes, with
        the wheels' friction and speed limit.
    noise_size : int
        Motor torque noises per sample (the number of wheels when there is noise, else 0).

    Raises
    ------
    ModelError
        A truth value that does not fit the design (wheel count, an effect on an actuator the
        design lacks, friction without the wheels' spin inertia, a residual dipole without a
        field, a periodic disturbance without an orbit); its ``field`` is the ``truth:`` key.
    """

    def __init__(self, design: AttitudeModel, truth: Truth):
        if not isinstance(design, AttitudeModel):
            raise TypeError(f"design must be an ocp.AttitudeModel, got {type(design).__name__}")
        if not isinstance(truth, Truth):
            raise TypeError(f"truth must be an ocp.dynamics.truth.Truth, got {type(truth).__name__}")
        self.design = design
        self.truth = truth
        spacecraft = design.spacecraft
        wheels = spacecraft.wheels
        n = spacecraft.n_wheels
        wheel_fields = {"wheel_misalignment": "wheels.misalignment_deg", "wheel_max_torque": "wheels.max_torque",
                        "wheel_max_momentum": "wheels.max_momentum", "wheel_coulomb": "wheels.friction.coulomb",
                        "wheel_viscous": "wheels.friction.viscous", "wheel_max_speed": "wheels.max_speed_rpm",
                        "wheel_torque_noise": "wheels.torque_noise"}
        if wheels is None:
            for name, key in wheel_fields.items():
                if getattr(truth, name) is not None:
                    raise ModelError(key, "the spacecraft has no wheels (spacecraft.wheels)")
        self._coulomb = _per_wheel(truth.wheel_coulomb, n, wheel_fields["wheel_coulomb"])
        self._viscous = _per_wheel(truth.wheel_viscous, n, wheel_fields["wheel_viscous"])
        self._max_speed = _per_wheel(truth.wheel_max_speed, n, wheel_fields["wheel_max_speed"])
        noise = _per_wheel(truth.wheel_torque_noise, n, wheel_fields["wheel_torque_noise"])
        actuators = {actuator.name: actuator for actuator in spacecraft.actuators}
        if wheels is not None:
            axes = wheels.axes
            if truth.wheel_misalignment is not None:
                if truth.wheel_misalignment.shape != (n, 3):
                    raise ModelError(wheel_fields["wheel_misalignment"], f"expected {n} rotation vectors (one per "
                                     f"wheel), got {truth.wheel_misalignment.shape[0]}")
                axes = np.column_stack([quat.rotate(quat.from_rotation_vector(v), a)
                                        for v, a in zip(truth.wheel_misalignment, axes.T)])
            limits = {}
            for name, key, design_value in (("wheel_max_torque", "max_torque", wheels.max_torque),
                                            ("wheel_max_momentum", "max_momentum", wheels.max_momentum)):
                value = _per_wheel(getattr(truth, name), n, wheel_fields[name])
                limits[key] = design_value if value is None else value
            needs_inertia = [key for key, value in (("wheels.friction.viscous", self._viscous),
                                                    ("wheels.friction.coulomb", self._coulomb),
                                                    ("wheels.max_speed_rpm", self._max_speed)) if value is not None]
            if needs_inertia and wheels.spin_inertia is None:
                raise ModelError(needs_inertia[0], "the wheels' speed needs their spin inertia "
                                                   "(spacecraft.wheels.spin_inertia)")
            actuators["wheels"] = ReactionWheels(axes, failed=wheels.failed, spin_inertia=wheels.spin_inertia,
                                                 **limits)
        inertia = spacecraft.inertia if truth.inertia is None else truth.inertia
        try:
            truth_spacecraft = Spacecraft(inertia, **actuators)  # type: ignore[arg-type]  # kinds by their names
        except ModelError as error:
            raise ModelError(f"spacecraft.{error.field}", error.message) from None
        self.model = AttitudeModel(truth_spacecraft, design.environment)
        env = design.environment
        if truth.dipole_scale_error is not None and spacecraft.magnetorquers is None:
            raise ModelError("magnetorquers.scale_error", "the spacecraft has no magnetorquers")
        if truth.residual_dipole is not None and design.field_body is None:
            raise ModelError("residual_dipole", "a residual dipole needs a magnetic field model "
                                                     "(environment.magnetic_field)")
        if truth.periodic_disturbance and not isinstance(getattr(env.orbit, "mean_motion", None), float):
            raise ModelError("disturbance.orbit_periodic", "an orbit-periodic disturbance needs an orbit with a mean "
                                                           "motion, its rate (orbit:)")
        self._wheel_slice = design.control_slices.get("wheels")
        self._dipole_slice = design.control_slices.get("dipole")
        working = np.zeros(0) if wheels is None else wheels.working.astype(float)
        self._noise_std = None if noise is None or not np.any(noise > 0) else noise * working
        self.noise_size = 0 if self._noise_std is None else n
        self._scale = None if truth.dipole_scale_error is None else 1.0 + truth.dipole_scale_error
        self._fingerprint: str | None = None
        self._build()

    @property
    def fingerprint(self) -> str:
        """A hash of the design model and every number of the truth (two plants with equal
        fingerprints integrate the same dynamics)."""
        if self._fingerprint is None:
            text = repr((self.design.fingerprint, _plain(self.truth)))
            self._fingerprint = hashlib.sha256(text.encode()).hexdigest()
        return self._fingerprint

    @property
    def default_parameters(self) -> Array:
        """(3,) the plant's constant disturbance torque ``p`` [N m], body axes: the truth's, else the
        environment's."""
        given = self.truth.constant_disturbance
        return self.design.default_parameters if given is None else given.copy()

    @property
    def wheel_max_speed(self) -> Array | None:
        """Each wheel's speed limit relative to the body [rad/s] (``truth.wheels.max_speed_rpm``);
        ``None``: none."""
        return None if self._max_speed is None else np.array(self._max_speed, dtype=float)

    def wheel_speed(self, x: Any) -> Any:
        """Each wheel's speed relative to the body, ``Ω = h_w / J_s − Aᵀ ω`` (truth axes).

        Parameters
        ----------
        x : (nx, 1) casadi.SX or MX
            State ``[q, ω, h_w]``.

        Returns
        -------
        (n_w, 1) casadi.SX or MX
            Speeds [rad/s].
        """
        wheels = self.model.spacecraft.wheels
        assert wheels is not None and wheels.spin_inertia is not None
        omega, h_w = x[4:7], x[7:self.model.nx]
        return h_w * ca.DM(1.0 / wheels.spin_inertia) - ca.mtimes(ca.DM(wheels.axes.T), omega)

    def effective_control(self, x: Any, u: Any) -> Any:
        """The control the dynamics see: each wheel's motor torque cut at its speed limit, less
        its bearing friction.

        Parameters
        ----------
        x : (nx, 1) casadi.SX or MX
            State ``[q, ω, h_w]``.
        u : (nu, 1) casadi.SX or MX
            Delivered control (:meth:`deliver`).

        Returns
        -------
        (nu, 1) casadi.SX or MX
            ``u`` with the wheel block ``g − c sign(Ω) − b Ω`` (``g`` zero where ``|Ω|`` is at the
            limit and ``g Ω > 0``).
        """
        where = self._wheel_slice
        if where is None or (self._coulomb is None and self._viscous is None and self._max_speed is None):
            return u
        speed = self.wheel_speed(x)
        g = u[where]
        if self._max_speed is not None:
            g = g * (1 - (ca.fabs(speed) >= ca.DM(self._max_speed)) * (g * speed > 0))
        if self._coulomb is not None:
            g = g - ca.DM(self._coulomb) * ca.sign(speed)
        if self._viscous is not None:
            g = g - ca.DM(self._viscous) * speed
        parts = [u[i] for i in range(u.shape[0])]
        parts[where.start:where.stop] = [g[i] for i in range(g.shape[0])]
        return ca.vertcat(*parts)

    def plant_torque(self, x: Any, t: Any) -> Any:
        """The truth's torques besides the actuators': residual dipole and periodic disturbances.

        Parameters
        ----------
        x : (nx, 1) casadi.SX or MX
            State ``[q, ω, h_w]``.
        t : casadi.SX or MX
            Time [s].

        Returns
        -------
        (3, 1) casadi.SX or MX, or None
            Torque [N m], body axes; ``None`` when the truth has neither.
        """
        torque = None
        if self.truth.residual_dipole is not None:
            field = self.design.magnetic_field_body(x[0:4], t)
            assert field is not None  # checked at construction
            torque = ca.cross(ca.DM(self.truth.residual_dipole), field)
        orbit = self.design.environment.orbit
        if self.truth.periodic_disturbance:
            # A sin(k θ + φ) = (A cos φ) sin kθ + (A sin φ) cos kθ, θ = n t: one sine and one cosine
            # per time, the second harmonic by the double-angle formulas.
            angle = getattr(orbit, "mean_motion") * t  # noqa: B009 - checked at construction, any orbit kind
            sine, cosine = ca.sin(angle), ca.cos(angle)
            harmonics = {1: (sine, cosine), 2: (2 * sine * cosine, 1 - 2 * sine * sine)}
            for item in self.truth.periodic_disturbance:
                sin_k, cos_k = harmonics[item.harmonic]
                part = (ca.DM(item.amplitude * np.cos(item.phase)) * sin_k
                        + ca.DM(item.amplitude * np.sin(item.phase)) * cos_k)
                torque = part if torque is None else torque + part
        return torque

    def _build(self) -> None:
        model = self.model
        x, u = ca.SX.sym("x", model.nx), ca.SX.sym("u", model.nu)
        t, p = ca.SX.sym("t"), ca.SX.sym("p", 3)
        extra = self.plant_torque(x, t)
        effective = self.effective_control(x, u)
        xdot = model.dynamics(x, effective, t, p if extra is None else p + extra)
        self.rhs = ca.Function("f_truth", [x, u, t, p], [xdot], ["x", "u", "t", "p"], ["xdot"])
        self.body_torque = ca.Function("body_torque_truth", [x, u, t], [model.actuator_torque(x, effective, t)],
                                       ["x", "u", "t"], ["tau"])

    def draw_noise(self, seed: int, n_samples: int) -> Array | None:
        """The motor torque noise of a run, from the stream ``numpy.random.default_rng([seed, 2])``.

        Parameters
        ----------
        seed : int
            The run's noise seed (``SensorNoise.seed``).
        n_samples : int
            Number of samples N.

        Returns
        -------
        (N, n_w) ndarray or None
            Per sample and wheel [N m] (zero for failed wheels); ``None`` without noise.
        """
        if self._noise_std is None:
            return None
        return np.random.default_rng([seed, 2]).standard_normal((n_samples, self.noise_size)) * self._noise_std

    def deliver(self, u: list[float], noise: Sequence[float] | None) -> list[float]:
        """What the actuators deliver for a saturated command (Python floats, per-sample code).

        Parameters
        ----------
        u : list of float
            The saturated control (the truth's limits), changed in place.
        noise : sequence of float or None
            This sample's motor torque noise [N m] (:meth:`draw_noise`).

        Returns
        -------
        list of float
            ``u`` with the noise added to the wheel torques and the dipole times ``1 + e``.
        """
        if noise is not None and self._wheel_slice is not None:
            start = self._wheel_slice.start
            for i, value in enumerate(noise):
                u[start + i] += value
        if self._scale is not None and self._dipole_slice is not None:
            start = self._dipole_slice.start
            for i, factor in enumerate(self._scale.tolist()):
                u[start + i] *= factor
        return u

    def deliver_symbolic(self, u: Any, noise: Any) -> Any:
        """:meth:`deliver` on CasADi expressions.

        Parameters
        ----------
        u : (nu, 1) casadi.SX
            The saturated control.
        noise : (noise_size, 1) casadi.SX or None
            This sample's motor torque noise [N m].

        Returns
        -------
        (nu, 1) casadi.SX
            The delivered control.
        """
        parts = [u[i] for i in range(u.shape[0])]
        if noise is not None and self._wheel_slice is not None:
            for i in range(self.noise_size):
                parts[self._wheel_slice.start + i] = parts[self._wheel_slice.start + i] + noise[i]
        if self._scale is not None and self._dipole_slice is not None:
            for i, factor in enumerate(self._scale.tolist()):
                parts[self._dipole_slice.start + i] = parts[self._dipole_slice.start + i] * factor
        return ca.vertcat(*parts)

