"""The assembled symbolic model ``ẋ = f(x, u, t, p)`` of a spacecraft in its environment.

State ``x = [q (4), ω (3), h_w (n_w)]``: scalar-first attitude quaternion (body to inertial),
body rate w.r.t. inertial in body axes (rad/s), then the actuators' states: wheel spin momenta
(N m s). Control ``u = [g (n_w), m (3), τ_t (3)]`` with only the blocks of the actuators present:
wheel motor torques (N m, ``ḣ_w = g``), magnetorquer dipole (A m², body axes), torquer torques
(N m, body axes). Parameter ``p`` (3): the constant disturbance torque in body axes (N m); its
default value is the environment's, and passing it lets one built model serve many runs.

Dynamics (:doc:`/architecture`):
``I ω̇ = −ω × (I ω + A h_w) − A g + m × B_B + τ_t + τ_gg + p``. The model names no actuator
kind: each of the spacecraft's actuators (:class:`~ocp.dynamics.actuator_kinds.Actuator`) gives its
torque on the body, the momentum its states store (``A h_w``) and their rates (``ḣ_w = g``).
"""
from __future__ import annotations

import hashlib
import threading
import uuid
import weakref
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp import quat
from ocp import quat_casadi as qc
from ocp.cache import RecentCache, SolverCache, Unkeyable, exact_key
from ocp.dynamics.environment import Environment, gravity_gradient_torque
from ocp.dynamics.layout import actuator_blocks, control_layout
from ocp.dynamics.spacecraft import Spacecraft
from ocp.quat_casadi import Expr

_LAZY = ("rhs", "body_torque", "environment_torque", "field_body", "field_rate_inertial")
"""The model's CasADi functions, built on first use (:meth:`AttitudeModel.__getattr__`)."""
_BUILT = RecentCache(size=32)
"""Built functions keyed by the model's fingerprint: models of equal fingerprint share them (a
scenario parsed again, a study's cases of one spacecraft). One set per thread, as CasADi functions
are; bounded, for a study sweeping the spacecraft."""


class AttitudeModel:
    """Symbolic model of one spacecraft in one environment (see the module docstring for the
    state ``x``, control ``u`` and parameter ``p``, and the dynamics).

    The CasADi functions are built on ``SX`` symbols on first use (not at construction), and shared
    by the models of equal :attr:`fingerprint` built in one thread; all take and return column
    vectors, ``t`` in s.

    Parameters
    ----------
    spacecraft : Spacecraft
        Rigid body and actuators; the actuators present fix the layout of ``u``.
    environment : Environment or None, optional
        Orbit, gravity gradient, magnetic field and disturbance; ``None`` (default): an empty
        :class:`~ocp.dynamics.environment.Environment` (no orbit, no external torque).

    Attributes
    ----------
    spacecraft : Spacecraft
        As given.
    environment : Environment
        As given, or the empty environment.
    n_wheels : int
        Number of wheels (failed ones included), ``n_w``.
    nx : int
        State size, ``7 +`` the actuators' states (``7 + n_w``).
    nu : int
        Control size: ``n_w`` with wheels, plus 3 with magnetorquers, plus 3 with torquers, plus
        the blocks of the other kinds present.
    rhs : casadi.Function
        ``f(x, u, t, p) -> xdot``, the state derivative.
    body_torque : casadi.Function
        ``body_torque(x, u, t) -> tau``: the actuators' torque on the body
        (``−A g + m × B_B + τ_t``) [N m], body axes.
    environment_torque : casadi.Function
        ``environment_torque(x, t, p) -> tau``: gravity gradient plus the disturbance ``p``
        [N m], body axes.
    field_body : casadi.Function or None
        ``field_body(x, t) -> b``: geomagnetic field [T], body axes; ``None`` without a field model.
    field_rate_inertial : casadi.Function or None
        ``field_rate_inertial(t) -> db``: time derivative of the inertial-frame field seen along
        the orbit [T/s], inertial axes; ``None`` without a field model.
    control_slices : dict of str to slice
        Slices of ``u`` for the blocks present among ``"wheels"``, ``"dipole"``, ``"torquers"``
        and those of other kinds (keyed by :attr:`~ocp.dynamics.actuator_kinds.Actuator.block`).
    solver_cache : SolverCache
        Solvers built on this model by planners given no cache of their own.
    """

    def __init__(self, spacecraft: Spacecraft, environment: Environment | None = None):
        self.spacecraft = spacecraft
        self.environment = environment if environment is not None else Environment()
        self.n_wheels = spacecraft.n_wheels
        self._blocks = actuator_blocks(spacecraft)
        self.nx = 7 + sum(block.actuator.state_size for block in self._blocks)
        self.control_slices: dict[str, slice]
        self.control_slices, self.nu = control_layout(spacecraft)
        self._momentum_matrix = np.hstack([np.zeros((3, 0))] + [block.actuator.momentum_matrix()
                                                                for block in self._blocks])
        """(3, nx - 7): the momentum stored in the actuators' states is this times ``x[7:]``."""
        self._fingerprint: str | None = None
        self.solver_cache = SolverCache()
        """Solvers built on this model by planners given no cache of their own."""

    rhs: ca.Function
    body_torque: ca.Function
    environment_torque: ca.Function
    field_body: ca.Function | None
    field_rate_inertial: ca.Function | None

    def __getattr__(self, name: str) -> Any:
        """The CasADi functions (:data:`_LAZY`), built on first use: those of an earlier model of
        equal fingerprint in this thread, else new ones. Any other missing name is an
        ``AttributeError``."""
        if name not in _LAZY or "_fingerprint" not in self.__dict__:  # not one, or not constructed
            raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")
        self.__dict__.update(_BUILT.get(("attitude_model", self.fingerprint), self._build))
        return self.__dict__[name]

    @property
    def fingerprint(self) -> str:
        """A hash of every number and choice of the spacecraft and environment that the symbolic
        graph bakes in: two models with equal fingerprints build identical functions.

        Numbers are stated exactly (:func:`~ocp.cache.exact_key`): models that differ in one bit of
        one number have different fingerprints. A spacecraft or environment holding an object that
        cannot be stated exactly (not a dataclass of numbers, arrays and text) gets a fingerprint of
        its own, equal to no other model's (its solvers are then not shared)."""
        if self._fingerprint is None:
            description = repr((_plain(self.spacecraft), _plain(self.environment)))
            self._fingerprint = hashlib.sha256(description.encode()).hexdigest()
        return self._fingerprint

    @property
    def default_parameters(self) -> NDArray:
        """(3,) default ``p``: the environment's constant disturbance torque [N m], body axes."""
        return np.asarray(self.environment.disturbance_torque, dtype=float)

    def split_state(self, x: Expr) -> tuple[Expr, Expr, Expr]:
        """The parts of a state vector.

        Parameters
        ----------
        x : (nx,) or (nx, 1) casadi.SX, MX, DM or ndarray
            State ``[q, ω, h_w]``.

        Returns
        -------
        q : (4,) slice of ``x``
            Attitude quaternion, scalar first, body to inertial.
        omega : (3,) slice of ``x``
            Body rate with respect to the inertial frame [rad/s], body axes.
        h_w : (nx - 7,) slice of ``x``
            The actuators' states: wheel spin momenta [N m s] (empty without wheels).
        """
        return x[0:4], x[4:7], x[7:self.nx]

    def magnetic_field_body(self, q: Expr, t: Expr) -> Expr | None:
        """Geomagnetic field seen by the spacecraft, ``R(q)ᵀ B_I(r(t), t)``.

        Parameters
        ----------
        q : (4, 1) casadi.SX, MX or DM
            Attitude quaternion, scalar first, body to inertial.
        t : float or scalar casadi.SX / MX
            Time [s].

        Returns
        -------
        (3, 1) casadi.SX, MX or DM, or None
            Field [T], body frame; ``None`` without a field model.
        """
        env = self.environment
        if env.magnetic_field is None or env.orbit is None:  # Environment requires an orbit for a field
            return None
        field_inertial = env.magnetic_field.field_inertial(env.orbit.position(t), t)
        return ca.mtimes(qc.rotation_matrix(q).T, field_inertial)

    def actuator_torque(self, x: Expr, u: Expr, t: Expr) -> Expr:
        """Torque of the actuators on the body, ``−A g + m × B_B + τ_t``.

        Parameters
        ----------
        x : (nx, 1) casadi.SX or MX
            State ``[q, ω, h_w]``; ``MX`` gives an ``MX`` result, anything else ``SX``.
        u : (nu, 1) casadi.SX or MX
            Control ``[g, m, τ_t]`` (the blocks present): wheel motor torques [N m], dipole
            [A m^2] and torquer torques [N m], body axes.
        t : float or scalar casadi.SX / MX
            Time [s] (for the magnetic field).

        Returns
        -------
        (3, 1) casadi.SX or MX
            Torque [N m], body frame. The dipole term is absent without a field model.
        """
        q, states = x[0:4], x[7:self.nx]
        torque = ca.MX.zeros(3, 1) if isinstance(x, ca.MX) else ca.SX.zeros(3, 1)
        field_body = None
        if any(block.actuator.needs_field for block in self._blocks):
            field_body = self.magnetic_field_body(q, t)
        for block in self._blocks:
            actuator = block.actuator
            part = actuator.body_torque(u[block.control], states[block.state],
                                        field_body if actuator.needs_field else None)
            if part is not None:
                torque += part
        return torque

    def external_torque(self, x: Expr, t: Expr, p: Expr) -> Expr:
        """Torque of the environment on the body: gravity gradient (if enabled) plus ``p``.

        Parameters
        ----------
        x : (nx, 1) casadi.SX, MX or DM
            State ``[q, ω, h_w]``.
        t : float or scalar casadi.SX / MX
            Time [s] (for the orbit position).
        p : (3, 1) casadi.SX, MX, DM or array_like
            Constant disturbance torque [N m], body frame.

        Returns
        -------
        (3, 1) casadi.SX, MX or DM
            Torque [N m], body frame.
        """
        env = self.environment
        torque = p
        if env.gravity_gradient and env.orbit is not None:  # Environment requires an orbit for it
            torque = torque + gravity_gradient_torque(
                x[0:4], env.orbit.position(t), self.spacecraft.inertia, env.orbit.mu
            )
        return torque

    def dynamics(self, x: Expr, u: Expr, t: Expr, p: Expr) -> Expr:
        """State derivative ``ẋ = [½ q ⊗ [0, ω], ω̇, g]`` with
        ``I ω̇ = −ω × (I ω + A h_w) − A g + m × B_B + τ_t + τ_gg + p``.

        Parameters
        ----------
        x : (nx, 1) casadi.SX or MX
            State ``[q, ω, h_w]``: quaternion (scalar first, body to inertial), body rate
            [rad/s] (body axes), wheel momenta [N m s].
        u : (nu, 1) casadi.SX or MX
            Control ``[g, m, τ_t]`` (the blocks present, :attr:`control_slices`).
        t : float or scalar casadi.SX / MX
            Time [s].
        p : (3, 1) casadi.SX, MX, DM or array_like
            Constant disturbance torque [N m], body frame.

        Returns
        -------
        (nx, 1) casadi.SX or MX
            ``ẋ``: quaternion rate [1/s], body angular acceleration [rad/s^2], wheel momentum
            rates [N m].
        """
        q, omega, states = self.split_state(x)
        inertia = ca.DM(self.spacecraft.inertia)
        momentum = ca.mtimes(inertia, omega)
        stateful = [block for block in self._blocks if block.actuator.state_size]
        for block in stateful:
            momentum += ca.mtimes(ca.DM(block.actuator.momentum_matrix()), states[block.state])
        torque = self.actuator_torque(x, u, t) + self.external_torque(x, t, p)
        omega_dot = ca.solve(inertia, -ca.cross(omega, momentum) + torque)
        parts = [qc.kinematics(q, omega), omega_dot]
        parts += [block.actuator.state_rate(u[block.control], states[block.state]) for block in stateful]
        return ca.vertcat(*parts)

    def _build(self) -> dict[str, ca.Function | None]:
        """The CasADi functions of :data:`_LAZY`, built anew, by name."""
        x = ca.SX.sym("x", self.nx)
        u = ca.SX.sym("u", self.nu)
        t = ca.SX.sym("t")
        p = ca.SX.sym("p", 3)
        built: dict[str, ca.Function | None] = {
            "rhs": ca.Function("f", [x, u, t, p], [self.dynamics(x, u, t, p)], ["x", "u", "t", "p"], ["xdot"]),
            "body_torque": ca.Function(
                "body_torque", [x, u, t], [self.actuator_torque(x, u, t)], ["x", "u", "t"], ["tau"]),
            "environment_torque": ca.Function(
                "environment_torque", [x, t, p], [self.external_torque(x, t, p)], ["x", "t", "p"], ["tau"]),
            "field_body": None,
            "field_rate_inertial": None,
        }
        field_body = self.magnetic_field_body(x[0:4], t)
        if field_body is not None:
            built["field_body"] = ca.Function("field_body", [x, t], [field_body], ["x", "t"], ["b"])
        env = self.environment
        if field_body is not None and env.magnetic_field is not None and env.orbit is not None:
            field_inertial = env.magnetic_field.field_inertial(env.orbit.position(t), t)
            built["field_rate_inertial"] = ca.Function(
                "field_rate_inertial", [t], [ca.jacobian(field_inertial, t)], ["t"], ["db"])
        return built

    def inertial_momentum(self, x: ArrayLike) -> NDArray:
        """Total angular momentum of body and wheels, ``R(q)(I ω + A h_w)``, conserved without
        external torque.

        Parameters
        ----------
        x : (..., nx) array_like
            State(s) ``[q, ω, h_w]``.

        Returns
        -------
        (..., 3) ndarray
            Angular momentum [N m s], inertial frame.
        """
        x = np.asarray(x, dtype=float)
        body = x[..., 4:7] @ self.spacecraft.inertia.T + x[..., 7:self.nx] @ self._momentum_matrix.T
        return quat.rotate(x[..., 0:4], body)


_TOKENS: dict[int, tuple[weakref.ref, str]] = {}
"""By ``id``: a live object :func:`_plain` cannot state exactly, and its token."""
_TOKENS_LOCK = threading.Lock()


def _token(value: Any) -> str:
    """A token of ``value`` equal to no other object's, the same for the object while it lives
    (its ``id`` is unique while it lives; the entry goes with it); a fresh one on each call for an
    object that takes no weak reference."""
    key = id(value)

    def forget(gone: weakref.ref) -> None:
        with _TOKENS_LOCK:
            if key in _TOKENS and _TOKENS[key][0] is gone:
                del _TOKENS[key]

    with _TOKENS_LOCK:
        found = _TOKENS.get(key)
        if found is not None and found[0]() is value:
            return found[1]
        token = uuid.uuid4().hex
        try:
            _TOKENS[key] = (weakref.ref(value, forget), token)
        except TypeError:  # no weak reference (a builtin, say): a token of this call alone
            pass
        return token


def _plain(value: Any) -> Any:
    """``value`` as the model's fingerprint states it: :func:`~ocp.cache.exact_key` (exact numbers,
    compared dataclass fields), or, for a value it cannot state exactly (an object of unknown kind),
    a token of that object (:func:`_token`), equal to no other object's: a fingerprint holding one
    is that object's alone, and shares no built solver with another rather than share one by
    accident, while repeated keys of the same object agree (a controller's closed loop is built
    once, not per run).

    Also the walker of :meth:`controllers.Controller.symbolic_key`.
    """
    try:
        return exact_key(value)
    except Unkeyable:
        return ("unkeyable", _token(value))
