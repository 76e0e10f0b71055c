"""Controller contract and its symbolic (CasADi) form.

A controller computes, at each sample, a :class:`~ocp.dynamics.actuators.Command`. Laws written for the
rigid body ``I ω̇ = −ω × I ω + u`` compute ``u`` and call :meth:`Controller.allocate`, which maps it
to the actuators as :doc:`/architecture` states (:mod:`controllers.allocation`);
:meth:`Controller.allocate_symbolic` is the same map on CasADi expressions. The vector layouts of
the symbolic form are in :mod:`ocp.dynamics.layout`.
"""
from __future__ import annotations

import hashlib
from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from controllers.allocation import Allocation, SymbolicConstants
from ocp import ActuatorModel, Command, Measurement, Spacecraft
from ocp.dynamics.layout import (
    REFERENCE_FIELDS,
    control_layout,
    measurement_size,
    reference_rows,
)
from ocp.errors import InvalidOption
from ocp.options import Configurable

Array = NDArray[np.float64]


@dataclass(frozen=True)
class SymbolicLaw:
    """A controller's law as one ``casadi.Function`` with an explicit state update.

    Attributes
    ----------
    function : ``law(t, y, z, r) -> (u, z_next)``, see :class:`Controller` ("Symbolic form").
    state0 : (n_z,) the controller state ``z`` right after ``reset`` (``state_vector()`` then).
    key : hex digest identifying every number the function bakes in (class, options, spacecraft,
        sample time, and the target for a law that needs one); equal keys mean identical functions
        (build caches use it).
    """

    function: ca.Function
    state0: Array
    key: str


class Controller(Allocation, Configurable, ABC):
    """Base class of every feedback law.

    Parameters
    ----------
    options : mapping or Options, optional
        The law's options (its ``Options`` dataclass, or a mapping of its fields, as in the YAML
        ``controller.options``); ``None``: the defaults.
    path : str, optional
        YAML path of the options, named in error messages.

    Contract
    --------
    * ``name`` is the registry key; ``Options`` a dataclass of the law's options with defaults.
    * ``reset(spacecraft, sample_time, target=None)`` clears any state before a run; ``target``
      is ``(q_f, ω_f or None)``, used in regulation mode and by regulators.
    * ``__call__(t, measurement, reference)`` returns the :class:`Command` for the coming sample
      ``[t, t + sample_time]`` (held constant over it); ``reference`` is a ``planners.Reference``
      or ``None`` (regulation to the target). It is the reference implementation of the law.
    * ``needs_reference``: the law cannot regulate (``reference=None``) and raises ``ValueError``
      there; the scenario loader rejects regulation mode for it.
    * ``tracks_reference``: given a reference, the law follows it (``augmented_quaternion_feedback``;
      implied by ``needs_reference``); otherwise (the default) it regulates to the target whatever
      the reference (``eigenaxis_pd``, the two-wheel laws, the detumbling laws). A law that reads
      the reference (``τ*``, ``q*``, ``ω*`` from ``reference_rows``) must declare it: the
      conformance checks then run it along a reference, and
      :func:`~controllers.conformance.check_ignores_reference` fails a law that reads the
      reference without declaring it.
    * ``needs_target_attitude``: in regulation mode the law needs ``maneuver.final.q``. Laws that
      regulate the rate alone (detumbling: ``bdot``, ``tdfc``; ``none``) set it to ``False`` and
      then accept a free final attitude (``q: null``); their symbolic form must then not bake the
      target (``self.target``) in, as :meth:`symbolic_key` leaves it out.
    * ``needs_field_rate``: the law reads ``measurement.field_rate_inertial`` (ḃ_I, T/s), which
      the simulator then provides (only the ideal B-dot does; a real spacecraft cannot).
    * ``planner_error(name, options)`` says why the law cannot track references of that planner
      (``None`` if it can); the scenario loader reports it. Most laws track any reference.
    * ``environment_error(spacecraft, environment)`` and ``sample_time_error(sample_time)`` say why
      the law cannot run there (missing actuator or sensor; an option that must fit the sample time);
      the scenario loader reports them at the controller's entry.
    * Saturation is the simulator's actuator model's job, not the controller's.
    * Capability flags read by :meth:`allocate`: ``gyroscopic_compensation`` and ``wheels_only``.

    Symbolic form
    -------------
    A law that can be written as a CasADi expression implements :meth:`_law`; the simulator then
    runs the whole closed loop as one CasADi function (optionally compiled to C), and
    ``slewbench codegen`` exports it. After ``reset``, :meth:`symbolic_law` returns
    ``law(t, y, z, r) -> (u, z_next)`` with (layouts in :mod:`ocp.dynamics.layout`):

    * ``t`` (1): s, the sample instant.
    * ``y`` (``7 + n_w + 3``): the measurement ``[q, ω, h_w, b]``: attitude, body rate (rad/s),
      wheel momenta (N m s), magnetometer reading (T, body axes; **zeros when the model has no
      field**, and ``__call__`` must treat ``measurement.field_body is None`` as zeros too).
    * ``z`` (``n_z``, may be 0): the controller's own state (delay buffers, previous samples,
      switching modes as 0/1 numbers, integrators). ``z_next`` is its value for the next sample.
      The Python implementation keeps the same numbers: :meth:`state_vector` returns them, and
      after ``reset`` it must equal ``SymbolicLaw.state0``; after each ``__call__`` it must equal
      the ``z_next`` of the same inputs. A delay buffer of ``d`` samples of a 3-vector is
      ``z = [v_{k−1}, …, v_{k−d}]`` with ``z_next = [v_k, z[0:3(d−1)]]``.
    * ``r`` (``2 × 13``): the reference at ``t`` and at ``t + sample_time``, each
      ``[q*, ω*, ω̇*, τ*]`` (:data:`~ocp.dynamics.layout.REFERENCE_FIELDS`); in regulation mode
      the simulator fills it from the target (:meth:`reference_rows`).
    * ``u`` (``nu``): the command in the model's control layout ``[g, m, τ_t]`` (blocks of the
      actuators present; zeros where nothing is asked), before saturation.

    Branches and saturations inside a law are written with ``casadi.if_else`` / ``fmin`` /
    ``fmax``, never with Python ``if`` on symbols. A law that cannot be symbolic (a run-time
    least-squares fit, a call into a reference object) does not implement ``_law`` and overrides
    :meth:`symbolic_error` with the reason; the simulator then uses its Python loop.
    The test ``tests/test_symbolic_laws.py`` checks, for every registered controller, that
    ``__call__`` and the symbolic law agree to 1e-12 at random states over several samples;
    :mod:`controllers.conformance` checks that and the rest of this contract for any law
    (:func:`~controllers.conformance.check_controller`).
    """

    needs_reference: bool = False
    tracks_reference: bool = False
    needs_target_attitude: bool = True
    needs_field_rate: bool = False

    def __init__(self, options: Mapping[str, Any] | Any | None = None, path: str = "options"):
        super().__init__(options, path)
        self.spacecraft: Spacecraft | None = None
        self.sample_time = 0.0
        self.target: tuple[Array, Array | None] | None = None

    def planner_error(self, planner: str, options: Any) -> str | None:
        """Why this law cannot track the references of a planner.

        Parameters
        ----------
        planner : str
            The planner's registry name.
        options : planner options
            Its options (the planner's ``Options`` instance or mapping).

        Returns
        -------
        str or None
            The reason, or ``None`` when the law can track them (most laws track any reference).
        """
        return None

    def environment_error(self, spacecraft: Spacecraft, environment: Any) -> str | None:
        """Why the law cannot run on a spacecraft in an environment.

        Parameters
        ----------
        spacecraft : Spacecraft
            Its actuators.
        environment : ocp.Environment or None
            Orbit, magnetic field and disturbances (``None``: none).

        Returns
        -------
        str or None
            The reason (an actuator or a sensor the law needs is missing), or ``None``.
        """
        return None

    def initial_state_error(self, spacecraft: Spacecraft, omega0: Array, wheel_momentum0: Array,
                            omegaf: Array | None) -> tuple[str, str] | None:
        """Why the law cannot start from a manoeuvre's initial state or reach its final rate.

        Parameters
        ----------
        spacecraft : Spacecraft
        omega0 : (3,) ndarray
            Initial body rate [rad/s], body axes.
        wheel_momentum0 : (n_w,) ndarray
            Initial wheel momenta [N m s].
        omegaf : (3,) ndarray or None
            Final body rate [rad/s], body axes; ``None``: free.

        Returns
        -------
        (str, str) or None
            ``(YAML key under maneuver, message)``, or ``None`` when the law can.
        """
        return None

    def initial_attitude_error(self, spacecraft: Spacecraft, q0: Array, omega0: Array,
                               qf: Array | None) -> tuple[str, str] | None:
        """Why the law cannot start from an attitude and rate (a law defined on part of the
        attitudes: the two-wheel laws' ``q1² + q2² ≠ 0`` from rest).

        Parameters
        ----------
        spacecraft : Spacecraft
        q0 : (4,) ndarray
            The simulated initial attitude (``simulation.initial_attitude_error_deg`` applied),
            scalar first, body to inertial.
        omega0 : (3,) ndarray
            The simulated initial body rate (``simulation.initial_rate_error`` added) [rad/s],
            body axes.
        qf : (4,) ndarray or None
            The target attitude; ``None``: free.

        Returns
        -------
        (str, str) or None
            ``(YAML key under maneuver, message)``, or ``None`` when the law can (most laws).
        """
        return None

    def run_length_error(self, duration: float) -> tuple[str, str] | None:
        """Why an option does not fit a run of this length (``tdfc``'s delay, which must be shorter).

        Parameters
        ----------
        duration : float
            Length of the closed-loop run [s].

        Returns
        -------
        (str, str) or None
            ``(option name, message)``, or ``None`` when every option fits (most laws).
        """
        return None

    def sample_time_error(self, sample_time: float) -> tuple[str, str] | None:
        """Why an option does not fit the sample time.

        Parameters
        ----------
        sample_time : float
            Controller period [s].

        Returns
        -------
        (str, str) or None
            ``(option name, message)``, or ``None`` when every option fits.
        """
        return None

    def reset(self, spacecraft: Spacecraft, sample_time: float, target: Any = None) -> None:
        """Prepare for a run: clear any state, precompute what the law needs.

        Parameters
        ----------
        spacecraft : Spacecraft
            The controlled spacecraft (inertia, actuators).
        sample_time : float
            Controller period and zero-order-hold length [s].
        target : (q_f, ω_f or None), optional
            Final attitude (scalar-first quaternion; ``None`` for laws that regulate the rate
            alone) and final body rate [rad/s] (``None``: at rest), used in regulation mode and by
            regulators; ``None`` when only references are tracked.
        """
        self.spacecraft = spacecraft
        self.sample_time = sample_time
        self.target = target
        self._slices, self._nu = control_layout(spacecraft)
        self._reset_allocation(spacecraft)

    @abstractmethod
    def __call__(self, t: float, measurement: Measurement, reference: Any) -> Command:
        """The command for the sample starting at ``t`` (s)."""

    # ----------------------------------------------------------------------------------------
    # Symbolic form
    # ----------------------------------------------------------------------------------------
    def symbolic_error(self) -> str | None:
        """Why this law has no symbolic form.

        Returns
        -------
        str or None
            The reason, or ``None`` when it has one (it implements :meth:`_law`).
        """
        if type(self)._law is Controller._law:
            return f"controller {self.name} does not implement a symbolic law (_law)"
        return None

    def state_vector(self) -> Array:
        """The controller state of the Python implementation.

        Returns
        -------
        (n_z,) ndarray
            ``z`` in the layout of the symbolic form (empty for a static law).
        """
        return np.zeros(0)

    def _law(self, t: ca.SX, y: ca.SX, z: ca.SX, r: ca.SX) -> tuple[ca.SX, ca.SX]:
        """``(u, z_next)`` as expressions of the symbols (see "Symbolic form"); called after reset."""
        raise NotImplementedError

    def symbolic_key(self) -> str:
        """Digest of everything :meth:`_law` bakes in.

        The target is in it only for a law that declares it needs one (``needs_target_attitude``):
        a law that does not (``none``, the detumbling laws) bakes no target into :meth:`_law` (in
        regulation mode it gets the target's rows through ``r``, as every law does), so one closed
        loop serves every target.

        Returns
        -------
        str
            SHA-256 hex digest of the class, options, spacecraft, sample time and (when the law
            needs one) target.
        """
        from ocp.dynamics.model import _plain  # the model's fingerprint walker

        cache = self._spacecraft()._cache  # the spacecraft is frozen: its description is computed once
        if "description" not in cache:
            cache["description"] = repr(_plain(self.spacecraft))
        target = None if self.target is None or not self.needs_target_attitude else tuple(
            None if v is None else _plain(np.asarray(v, dtype=float)) for v in self.target)
        text = repr((type(self).__module__, type(self).__qualname__, _plain(self.options),
                     cache["description"], float(self.sample_time), target))
        return hashlib.sha256(text.encode()).hexdigest()

    def symbolic_law(self) -> SymbolicLaw:
        """The law as one CasADi function, for the spacecraft and sample time of the last :meth:`reset`.

        Returns
        -------
        SymbolicLaw
            ``law(t, y, z, r) -> (u, z_next)`` (see "Symbolic form"), its initial state and key.

        Raises
        ------
        NotImplementedError
            With :meth:`symbolic_error`'s reason, for a law that has no symbolic form.
        """
        reason = self.symbolic_error()
        if reason is not None:
            raise NotImplementedError(reason)
        if self.spacecraft is None:
            raise RuntimeError("call reset(spacecraft, sample_time, target) before symbolic_law()")
        state0 = np.asarray(self.state_vector(), dtype=float).ravel().copy()
        t = ca.SX.sym("t")
        y = ca.SX.sym("y", measurement_size(self.spacecraft))
        z = ca.SX.sym("z", state0.size)
        r = ca.SX.sym("r", 2 * REFERENCE_FIELDS)
        u, z_next = self._law(t, y, z, r)
        u = ca.SX(u) if not isinstance(u, ca.SX) else u
        if u.shape != (self._nu, 1):
            raise ValueError(f"{self.name}._law returned u of shape {u.shape}, expected ({self._nu}, 1)")
        z_next = ca.SX(z_next) if not isinstance(z_next, ca.SX) else z_next
        if z_next.numel() != state0.size:
            raise ValueError(f"{self.name}._law returned z_next of size {z_next.numel()}, expected {state0.size}")
        function = ca.Function(f"law_{self.name}", [t, y, z, r], [u, ca.reshape(z_next, state0.size, 1)],
                               ["t", "y", "z", "r"], ["u", "z_next"])
        return SymbolicLaw(function, state0, self.symbolic_key())

    def parametric_law(self, constants: SymbolicConstants) -> tuple[list[ca.SX], list[ca.SX]]:
        """The law's expressions with the numbers it reads through :meth:`constant` (gains, inertia,
        wheel axes, sample time, ...) as symbols, for code generation that makes them inputs.

        Laws that read their numbers through :meth:`constant` have them all as symbols; numbers a law
        bakes in otherwise stay numbers (the generated code then compiles them in).

        Parameters
        ----------
        constants : SymbolicConstants
            Receives the named symbols and their values for the last :meth:`reset` (shared with other
            parametric expressions, such as the saturation stage's).

        Returns
        -------
        inputs : list of casadi.SX
            The symbols ``t``, ``y``, ``z``, ``r`` (see "Symbolic form").
        outputs : list of casadi.SX
            ``u`` and ``z_next``, expressions of the inputs and of ``constants``' symbols.

        Raises
        ------
        NotImplementedError
            For a law that has no symbolic form.
        """
        law = self.symbolic_law()  # checks the law and gives the initial state's size
        inputs = law.function.sx_in()
        self._constants = constants
        try:
            u, z_next = self._law(*inputs)
        finally:
            self._constants = None
        return inputs, [ca.SX(u), ca.reshape(ca.SX(z_next), law.state0.size, 1)]

    def reference_rows(self, reference: Any, times: Array) -> Array:
        """Reference rows in the layout of the symbolic form.

        Parameters
        ----------
        reference : planners.Reference or None
            The reference (anything with a vectorised ``sample(t)``); ``None``: the target of the
            last :meth:`reset` (rate ``ω_f`` or zero, no acceleration or torque).
        times : (N,) array_like
            Sample times [s].

        Returns
        -------
        (N, 13) ndarray
            Rows ``[q*, ω*, ω̇*, τ*]``: attitude quaternion, body rate [rad/s], body acceleration
            [rad/s^2], feed-forward torque [N m], body axes.
        """
        return reference_rows(reference, times, self.target)

    def command_vector(self, command: Command) -> Array:
        """A command as the vector ``u`` of the symbolic form.

        Parameters
        ----------
        command : Command

        Returns
        -------
        (nu,) ndarray
            ``[g, m, τ_t]`` (blocks of the actuators present): wheel torques [N m], dipole
            [A m^2], torquer torque [N m]; zeros where the command asks nothing.
        """
        return ActuatorModel(self._spacecraft(), self._slices, self._nu).command_vector(command)


def check_gain(option: str, gain: float | list[list[float]]) -> None:
    """Raise :class:`~ocp.options.InvalidOption` unless ``gain`` is a non-negative scalar or a 3x3
    matrix whose symmetric part is positive semi-definite (a gain that pumps energy in is an error).

    Parameters
    ----------
    option : the option's name, for the message.
    gain : the scalar (times the inertia) or the 3x3 matrix.
    """
    if isinstance(gain, (int, float)):
        if gain < 0:
            raise InvalidOption(option, f"expected a non-negative gain, got {gain!r}")
        return
    matrix = np.asarray(gain, dtype=float)
    if np.linalg.eigvalsh(0.5 * (matrix + matrix.T)).min() < -1e-12 * max(1.0, float(np.abs(matrix).max())):
        raise InvalidOption(option, "expected a 3x3 gain matrix with a positive semi-definite symmetric part")


def gain_matrix(gain: float | list[list[float]], inertia: Array) -> Array:
    """A gain as a 3x3 matrix.

    Parameters
    ----------
    gain : float or (3, 3) nested list
        A scalar (times the inertia: the spin paper's choice) or a full matrix.
    inertia : (3, 3) ndarray
        Inertia [kg m^2], body axes.

    Returns
    -------
    (3, 3) ndarray
        ``gain * inertia`` for a scalar, else the matrix.
    """
    if isinstance(gain, (int, float)):
        return float(gain) * inertia
    matrix = np.asarray(gain, dtype=float)
    if matrix.shape != (3, 3):
        raise ValueError(f"a gain matrix must be 3x3, got shape {matrix.shape}")
    return matrix
