"""The mapping of a rigid-body control torque onto the actuators (:doc:`/architecture`), shared by
every controller through :class:`Allocation`.

Wheels take ``τ_w = u + ω × A h_w`` through ``g = −A⁺ τ_w`` (working wheels only); what the wheels
cannot give (fewer than three independent axes) goes to
:attr:`~ocp.dynamics.spacecraft.Spacecraft.residual_actuator`, the actuator whose kind has the lowest
:attr:`~ocp.dynamics.actuator_kinds.Actuator.residual_rank`: the torquers if there are any, else the
magnetorquers as ``m = B × τ / |B|²`` (the component of τ perpendicular to B). Without wheels that
actuator takes ``u``. The numeric map runs on Python floats (it is called at every sample);
:meth:`Allocation.allocate_symbolic` is the same map on CasADi expressions.

:func:`reference_demand` runs a reference's feed-forward torque through a law's own map, sample by
sample, and gives what it asks of each actuator (commands, and the states they drive, such as the
wheel momenta): the scenario's actuator requirement scores it against the limits.
:func:`unrealised_torque` is what those commands leave out of the feed-forward torque: the part no
working actuator gives (an axis of a failed or missing wheel, the component along the field for
magnetorquers), which no limit shows. Both evaluate all samples as one batch: the law's map and the
model's functions mapped over chunks of samples (:func:`model_rows`), the same expressions as
per sample.
"""
from __future__ import annotations

import copy
import math
from collections.abc import Callable, Hashable, Sequence
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp import AttitudeModel, Command, Measurement, SolverCache, Spacecraft, quat
from ocp.dynamics.actuator_kinds import Actuator
from ocp.dynamics.layout import actuator_blocks, control_layout, split_measurement
from ocp.fast_call import BufferedFunction, as_floats, buffered

Array = NDArray[np.float64]

__all__ = ["MAX_SUBSTEPS", "SUBSTEP_ANGLE", "Allocation", "Demand", "SymbolicConstants", "demand_limits", "float_rows",
           "model_rows", "reference_demand", "unrealised_torque"]


def float_rows(matrix: ArrayLike) -> tuple[tuple[float, ...], ...]:
    """A matrix as a tuple of rows of Python floats, for per-sample code (``sum(a * b for ...)``
    over a row costs far less than a NumPy product on 3-vectors).

    Parameters
    ----------
    matrix : (m, n) array_like

    Returns
    -------
    tuple of m tuples of n floats
    """
    return tuple(tuple(row) for row in np.asarray(matrix, dtype=float).tolist())


class SymbolicConstants:
    """The numbers a law reads through :meth:`Allocation.constant` while it is built as a function of
    them (``Controller.parametric_law``, for ``slewbench codegen``): named CasADi symbols, each with
    the value it has for the spacecraft and options of the last reset.

    Attributes
    ----------
    symbols : dict of str to (casadi.SX, ndarray)
        Name -> its symbol (the value's shape; a scalar is 1 x 1) and its value, in the order read.
    """

    def __init__(self) -> None:
        self.symbols: dict[str, tuple[ca.SX, Array]] = {}

    def get(self, name: str, value: ArrayLike) -> ca.SX:
        """The symbol of ``name`` (created on first use with ``value``'s shape).

        Parameters
        ----------
        name : str
            The number's name (a C identifier: it becomes a field of the generated parameter struct).
        value : float or array_like
            Its value for the last reset.

        Returns
        -------
        casadi.SX
            The symbol, the same for every read of ``name``.
        """
        if name not in self.symbols:
            array = np.asarray(value, dtype=np.float64)
            shape = (1, 1) if array.ndim == 0 else (array.shape[0], 1) if array.ndim == 1 else array.shape
            self.symbols[name] = (ca.SX.sym(name, *shape), array)
        return self.symbols[name][0]

    def vector(self) -> ca.SX:
        """Every symbol, flattened column by column and stacked in the order read.

        Returns
        -------
        (n, 1) casadi.SX
        """
        return ca.vertcat(*(ca.vec(symbol) for symbol, _ in self.symbols.values())) if self.symbols else ca.SX(0, 1)


def _pseudo_inverse_symbolic(axes: ca.SX, working: Array) -> ca.SX | None:
    """``A⁺`` of the working columns of ``axes`` (zero rows for failed wheels) as an expression, for
    full-rank cases (``Aᵀ(AAᵀ)⁻¹`` with three independent axes, ``(AᵀA)⁻¹Aᵀ`` with fewer); ``None``
    when the working axes are rank deficient (the pseudo-inverse is then a compiled-in number)."""
    index = [int(i) for i in np.flatnonzero(working)]
    if not index:
        return None
    reduced = axes[:, index]
    return_rows = ca.SX.zeros(axes.shape[1], 3)
    if len(index) >= 3:
        inner = ca.mtimes(reduced, reduced.T)
        rows = ca.mtimes(reduced.T, ca.inv_minor(inner))
    else:
        inner = ca.mtimes(reduced.T, reduced)
        rows = ca.mtimes(ca.inv_minor(inner), reduced.T)
    return_rows[index, :] = rows
    return return_rows


class Allocation:
    """Mixin of ``controllers.base.Controller``: the torque-to-actuator map and its state.

    Capability flags (class attributes a law may override): :attr:`gyroscopic_compensation` and
    :attr:`wheels_only`. :meth:`_reset_allocation` (called by ``Controller.reset``) precomputes the
    wheel matrices for the spacecraft.
    """

    gyroscopic_compensation: bool = True
    """:meth:`allocate` adds the wheels' ``ω × A h_w`` (the law's ``u`` is for ``I ω̇ = −ω × I ω + u``).
    ``False``: ``u`` is the wheels' body torque itself (laws written for ``I ω̇ = u``, zero momentum)."""
    wheels_only: bool = False
    """Pure wheel mode: :meth:`allocate` drops what the wheels cannot give instead of sending it to
    torquers or magnetorquers (the two-wheel laws)."""

    spacecraft: Spacecraft | None
    _slices: dict[str, slice]
    _nu: int
    _constants: SymbolicConstants | None = None
    """Set while the law is built as a function of its numbers (:meth:`constant`)."""

    def constant(self, name: str, value: Any) -> Any:
        """A number the symbolic law reads (a gain, the inertia, the sample time, ...).

        Parameters
        ----------
        name : str
            Its name, a C identifier (the field of the generated parameter struct).
        value : float or array_like
            Its value for the spacecraft and options of the last reset.

        Returns
        -------
        float, casadi.DM or casadi.SX
            ``value`` itself (a Python float) or as a ``casadi.DM``; while the law is built as a
            function of its numbers (``Controller.parametric_law``), the named symbol instead.
        """
        if self._constants is not None:
            return self._constants.get(name, value)
        return value if isinstance(value, float) else ca.DM(np.asarray(value, dtype=np.float64))

    def _wheel_matrices_symbolic(self) -> tuple[Any, Any, Any]:
        """The wheel axes, the working axes and their pseudo-inverse for the symbolic law: numbers,
        or (parametric build) expressions of the ``wheel_axes`` symbol (the pseudo-inverse stays a
        number when the working axes are rank deficient)."""
        spacecraft = self._spacecraft()
        axes = self.constant("wheel_axes", spacecraft.wheel_axes)
        working_value = self._working_axes
        if working_value is None:
            raise RuntimeError("the symbolic wheel matrices need working wheels")
        if self._constants is None:
            return axes, ca.DM(working_value), ca.DM(self._wheel_pinv)
        working = np.any(working_value != 0.0, axis=0).astype(float)  # failed wheels: zero columns
        working_axes = ca.mtimes(axes, ca.diag(ca.DM(working)))
        rank_ok = np.linalg.matrix_rank(working_value) == min(3, int(working.sum()))
        pinv = _pseudo_inverse_symbolic(axes, working) if rank_ok else None
        return axes, working_axes, ca.DM(self._wheel_pinv) if pinv is None else pinv

    def _spacecraft(self) -> Spacecraft:
        """The spacecraft of the last reset (an error before any)."""
        if self.spacecraft is None:
            raise RuntimeError(f"{type(self).__name__}: call reset(spacecraft, sample_time, target) first")
        return self.spacecraft

    def _reset_allocation(self, spacecraft: Spacecraft) -> None:
        """Precompute the wheel matrices (NumPy for the symbolic map, rows of floats for the numeric one)."""
        wheels = spacecraft.wheels
        self._working_axes: Array | None = None
        self._wheel_pinv: Array = np.zeros((0, 3))
        # The same matrices as rows of Python floats, for the per-sample allocation.
        self._pinv_rows: tuple[tuple[float, ...], ...] | None = None
        self._axes_cols: tuple[tuple[float, ...], ...] = ()
        self._working_cols: tuple[tuple[float, ...], ...] = ()
        if wheels is not None and np.any(wheels.working):
            self._working_axes = wheels.axes * wheels.working
            # a failed wheel's row is zero, not the SVD's round-off (1e-17): asked nothing, it scores 0 x
            # its zero limit instead of inf x
            self._wheel_pinv = wheels.pseudo_inverse
            self._pinv_rows = float_rows(self._wheel_pinv)
            self._axes_cols = float_rows(spacecraft.wheel_axes.T)
            self._working_cols = float_rows(self._working_axes.T)
        self._sink: Actuator | None = None if self.wheels_only else spacecraft.residual_actuator
        """The actuator that takes what the wheels cannot give (``Spacecraft.residual_actuator``:
        torquers, else magnetorquers), if any."""

    def allocate(self, torque: ArrayLike, measurement: Measurement, rate: ArrayLike | None = None,
                 wheel_momentum: ArrayLike | None = None) -> Command:
        """Map a rigid-body control torque to the actuators (module docstring).

        Parameters
        ----------
        torque : (3,) array_like
            Control torque ``u`` of ``I ω̇ = −ω × I ω + u`` [N m], body axes.
        measurement : Measurement
            The sample's measurement (rate, wheel momenta, magnetometer reading).
        rate : (3,) array_like, optional
            The ``ω`` of the wheels' gyroscopic term ``ω × A h_w`` [rad/s], body axes; ``None``:
            the measured rate. A law that predicts it to mid-sample passes its prediction (see
            ``AugmentedQuaternionFeedback``).
        wheel_momentum : (n_w,) array_like, optional
            The ``h_w`` of that term [N m s]; ``None``: the measured momenta.

        Returns
        -------
        Command
            Wheel torques ``g`` [N m] (``None`` without working wheels), and what the wheels cannot
            give as torquer torque [N m] or magnetorquer dipole [A m^2], body axes (``None`` when
            nothing is asked of them).
        """
        return self._allocate(as_floats(torque), measurement, None if rate is None else as_floats(rate),
                              None if wheel_momentum is None else as_floats(wheel_momentum))

    def _allocate(self, torque: Sequence[float], measurement: Measurement, rate: Sequence[float] | None,
                  wheel_momentum: Sequence[float] | None) -> Command:
        """:meth:`allocate` on Python floats (per-sample code: no NumPy on 3-vectors)."""
        command = Command()
        r0, r1, r2 = torque
        if self._pinv_rows is not None:
            if self.gyroscopic_compensation:  # τ_w = u + ω × A h_w
                w0, w1, w2 = as_floats(measurement.omega) if rate is None else rate
                h0 = h1 = h2 = 0.0
                for (a0, a1, a2), h in zip(self._axes_cols, as_floats(measurement.wheel_momentum)
                                           if wheel_momentum is None else wheel_momentum):
                    h0 += a0 * h
                    h1 += a1 * h
                    h2 += a2 * h
                r0, r1, r2 = r0 + (w1 * h2 - w2 * h1), r1 + (w2 * h0 - w0 * h2), r2 + (w0 * h1 - w1 * h0)
            g = [-(a * r0 + b * r1 + c * r2) for a, b, c in self._pinv_rows]  # g = −A⁺ τ_w
            command.wheel_torque = np.array(g)
            if self._sink is None:
                return command
            t0, t1, t2 = r0, r1, r2
            for (a0, a1, a2), gi in zip(self._working_cols, g):  # what the wheels do not give
                r0 += a0 * gi
                r1 += a1 * gi
                r2 += a2 * gi
            if math.sqrt(r0 * r0 + r1 * r1 + r2 * r2) <= 1e-12 * max(math.sqrt(t0 * t0 + t1 * t1 + t2 * t2), 1e-300):
                return command
        sink = self._sink
        if sink is None:
            return command
        field = measurement.field_body
        value = sink.take_residual((r0, r1, r2), None if field is None else as_floats(field))
        if value is not None:
            command.set(sink.command, np.array(value))
        return command

    def allocate_symbolic(self, torque: ca.SX, y: ca.SX, rate: ca.SX | None = None,
                          wheel_momentum: ca.SX | None = None) -> ca.SX:
        """:meth:`allocate` on CasADi expressions.

        Parameters
        ----------
        torque : (3, 1) casadi.SX
            Rigid-body control torque ``u`` [N m], body axes.
        y : casadi.SX
            The measurement vector ``[q, ω, h_w, b]`` (:mod:`ocp.dynamics.layout`).
        rate : (3, 1) casadi.SX, optional
            ``ω`` of the wheels' gyroscopic term [rad/s]; ``None``: the measured one.
        wheel_momentum : (n_w, 1) casadi.SX, optional
            ``h_w`` of that term [N m s]; ``None``: the measured one.

        Returns
        -------
        (nu, 1) casadi.SX
            The command vector ``u`` in the control layout (zeros where nothing is asked).
        """
        spacecraft = self._spacecraft()
        _, omega, h_w, field = split_measurement(y, spacecraft.n_wheels)
        parts = {}
        residual = torque
        done = None
        if self._working_axes is not None:
            axes, working_axes, wheel_pinv = self._wheel_matrices_symbolic()
            w = omega if rate is None else rate
            h = ca.mtimes(axes, h_w if wheel_momentum is None else wheel_momentum)
            wheel_torque = residual + ca.cross(w, h) if self.gyroscopic_compensation else residual
            g = -ca.mtimes(wheel_pinv, wheel_torque)
            parts["wheels"] = g
            residual = wheel_torque + ca.mtimes(working_axes, g)
            done = ca.norm_2(residual) <= 1e-12 * ca.fmax(ca.norm_2(wheel_torque), 1e-300)
        sink = self._sink
        if sink is not None:
            value = sink.take_residual_symbolic(residual, field)
            parts[sink.block] = value if done is None else ca.if_else(done, ca.DM.zeros(sink.control_size), value)
        u = ca.SX.zeros(self._nu)
        for name, value in parts.items():
            u[self._slices[name]] = value
        return u


@dataclass(frozen=True)
class Demand:
    """What a motion asks of one actuator quantity, sample by sample, and its limits.

    Attributes
    ----------
    name : str
        ``<kind>_<quantity>``: the kind's name (``wheels``, ``magnetorquers``, ``torquers``) and
        the last word of its command (``torque``, ``dipole``) for its command, ``momentum`` for
        states that store angular momentum, ``state`` for other states.
    values : (N, k) ndarray
        The demand at each sample, in the unit of the quantity (N m, A m², N m s).
    limit : (k,) ndarray
        The bound of each element (positive; ``inf``: none; 0: a failed element).
    """

    name: str
    values: Array
    limit: Array

    def ratios(self) -> Array:
        """``|values| / limit`` per sample and element: 0 where there is no limit (or nothing
        asked of a failed element), ``inf`` where a failed element is asked something.

        Returns
        -------
        (N, k) ndarray
        """
        magnitude = np.abs(self.values)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = magnitude / self.limit
        ratio = np.where(np.isinf(self.limit), 0.0, ratio)
        return np.where(self.limit == 0.0, np.where(magnitude > 0.0, np.inf, 0.0), ratio)

    @property
    def limited(self) -> bool:
        """Whether any element has a finite bound (else there is nothing to score)."""
        return bool(np.any(np.isfinite(self.limit)))


def _quantity(actuator: Actuator, state: bool) -> str:
    if not state:
        return f"{actuator.name}_{actuator.command.split('_')[-1]}"
    stores_momentum = bool(np.any(actuator.momentum_matrix()))
    return f"{actuator.name}_{'momentum' if stores_momentum else 'state'}"


def demand_limits(spacecraft: Spacecraft) -> dict[str, Array]:
    """The quantities :func:`reference_demand` reports for a spacecraft, and their limits.

    Parameters
    ----------
    spacecraft : ocp.Spacecraft
        The spacecraft (its actuators, in order).

    Returns
    -------
    dict of str to ndarray
        :attr:`Demand.name` -> :attr:`Demand.limit` (positive; ``inf``: none; 0: a failed
        element): each actuator kind's command, then its states when it has any.
    """
    limits: dict[str, Array] = {}
    for block in actuator_blocks(spacecraft):
        actuator = block.actuator
        limits[_quantity(actuator, False)] = np.asarray(actuator.control_bounds()[1], dtype=float)
        if actuator.state_size:
            limits[_quantity(actuator, True)] = np.asarray(actuator.state_bounds()[1], dtype=float)
    return limits


def reference_demand(allocation: Allocation, model: AttitudeModel, t: ArrayLike, q: ArrayLike, omega: ArrayLike,
                     torque: ArrayLike, state0: ArrayLike | None = None,
                     jumps: ArrayLike | None = None, torque_after: ArrayLike | None = None,
                     environment: ArrayLike | None = None) -> dict[str, Demand]:
    """What a reference asks of each actuator through a law's own allocation (module docstring).

    At each sample the feed-forward torque goes through the law's map (its flags included, except
    that the wheels' gyroscopic term ``ω × A h_w`` is always asked for: it is what following the
    reference demands, whether the law computes it, adds it in its allocation or neglects it; the
    map on CasADi expressions, :meth:`Allocation.allocate_symbolic`, which the symbolic-law tests
    hold equal to :meth:`Allocation.allocate`) with the reference's rate, the actuators' states
    and the field along the reference (zero without a field model); the commands reported are
    those at the states reported. The law itself is not changed (a copy is prepared for the
    spacecraft). The states, whatever the samples' spacing:

    * when the working wheels span three axes and are the only actuators with states, they take
      the whole torque, ``A ḣ_w = −(u + ω × A h_w)``: with ``u`` the inverse dynamics of the motion
      (:class:`planners.Reference`'s contract) less the environment's torque ``τ_e`` of ``model``
      (gravity gradient, constant disturbance; the actuators' share) the total angular momentum,
      the body's and the wheels', changes in the inertial frame by the environment's impulse
      alone, and the momenta are its closed form,
      ``A h_w(t) = R(q)ᵀ (R(q₀) (I ω₀ + A h_w0) + ∫₀ᵗ R(q) τ_e dt) − I ω(t)`` (``h_w`` moves along
      ``A⁺``'s range only: a failed wheel keeps its momentum, redundant wheels their null-space
      part; the impulse by the trapezoidal rule on the samples, where ``τ_e`` is smooth). Exact at
      any spacing without an environment torque: no step of the motion is integrated, a jump of
      the torque (a bang, the end of a reference) leaves no error, and ``torque`` is not read for
      the states (integrating it would read a reference's torque where it is not its motion's
      inverse dynamics, between a collocation reference's points, 0.1 % of a wheel's limit);
    * otherwise (fewer than three independent working axes, or other actuator states) the states
      are integrated by the classical Runge-Kutta method, each interval between samples cut into
      sub-steps over which the body turns at most :data:`SUBSTEP_ANGLE` (the wheels' gyroscopic
      term turns their momenta with the body: a step of one sample interval becomes unstable once
      the body turns about a radian in it), with the inputs interpolated linearly between the
      samples, the torque from its value just after the interval's start (``torque_after``) to its
      value at its end. Between samples the motion is known through that interpolation only: the
      samples must resolve the rate's own changes (the sub-steps resolve the rotation).

    A jump of the reference's body rate (``jumps``: a rate the reference starts at that is not the
    spacecraft's, a step such as natural motion's stop) is no torque the feed-forward holds: the
    body's momentum changes at once by ``I Δω``, and the working wheels take it up at once,
    ``Δh_w = −A⁺ I Δω`` (the total angular momentum is conserved across it: the closed form
    takes up every jump of ``ω`` between samples by itself, and reads row 0 only); what they cannot
    take (fewer than three independent axes) leaves no state. The impulse itself is no finite
    demand: the caller reports the jumps (:mod:`scenarios.requirements.scoring` breaks the actuator
    requirement on one).

    Parameters
    ----------
    allocation : Allocation
        The law whose map the closed loop will use (a :class:`controllers.base.Controller`).
    model : ocp.AttitudeModel
        The spacecraft and its environment (the field, for magnetorquers).
    t : (N,) array_like
        Increasing sample times [s].
    q : (N, 4) array_like
        Reference attitude (scalar first, body to inertial) at ``t``.
    omega : (N, 3) array_like
        Reference body rate [rad/s], body axes.
    torque : (N, 3) array_like
        Feed-forward torque ``u`` of ``I ω̇ = −ω × I ω + u`` [N m], body axes (its value at the
        sample: the commands reported read it).
    state0 : (nx - 7,) array_like or None, optional
        The actuators' states at ``t[0]`` (the initial wheel momenta [N m s]); ``None``: zero.
    jumps : (N, 3) array_like or None, optional
        Jumps of the body rate [rad/s], body axes, arriving at each sample: row 0 from the
        spacecraft's rate at ``t[0]`` to the reference's, row k between ``t[k-1]`` and ``t[k]``;
        ``None``: none.
    torque_after : (N, 3) array_like or None, optional
        The feed-forward torque just after each sample [N m], body axes, where it jumps there
        (a reference's end T: zero after it), for the integrated states; ``None``: ``torque``.
    environment : (N, 3) array_like or None, optional
        The environment's torque of ``model`` at the samples [N m], body axes, where the caller has
        it already (``model_rows(model, "environment_torque", ...)`` at the same states, times and
        the model's default parameters: the scorer's, which ``torque`` is net of); ``None``:
        evaluated here where the closed form of the momenta needs it.

    Returns
    -------
    dict of str to Demand
        Keyed by :attr:`Demand.name`: each actuator kind's command, and its states when it has
        any, in the order of ``spacecraft.actuators``.
    """
    spacecraft = model.spacecraft
    law = copy.copy(allocation)
    # Following the reference asks the wheels for ω × A h_w beside the feed-forward, whatever the
    # law's own formula: a law without gyroscopic compensation computes that term inside its u
    # (mrp_feedback's reference rate) or neglects it (the two-wheel laws' zero momentum), and
    # neither changes what the reference demands of the wheels.
    law.gyroscopic_compensation = True
    law.spacecraft = spacecraft
    law._slices, law._nu = control_layout(spacecraft)
    law._reset_allocation(spacecraft)
    t = np.asarray(t, dtype=float).reshape(-1)
    n = t.size
    q = np.asarray(q, dtype=float).reshape(n, 4)
    omega = np.asarray(omega, dtype=float).reshape(n, 3)
    torque = np.asarray(torque, dtype=float).reshape(n, 3)
    blocks = actuator_blocks(spacecraft)
    n_states = sum(block.actuator.state_size for block in blocks)
    fields = np.zeros((n, 3))
    if model.field_body is not None and n:
        fields = model_rows(model, "field_body", np.hstack([q, omega, np.zeros((n, model.nx - 7))]), t[:, None])
    inputs = np.hstack([torque, q, omega, fields])  # (N, 13): what the map reads at each sample
    kicks = np.zeros((n, n_states))  # the states' jumps at each sample: the wheels take up the rate's
    if jumps is not None and n and law._working_axes is not None:
        wheels = next(block for block in blocks if block.actuator.block == "wheels")
        momentum = np.asarray(jumps, dtype=float).reshape(n, 3) @ np.asarray(spacecraft.inertia, dtype=float).T
        kicks[:, wheels.state] = -momentum @ law._wheel_pinv.T  # Δh_w = −A⁺ I Δω
    start = np.zeros(n_states) if state0 is None else np.asarray(state0, dtype=float).reshape(n_states)
    # (the law's map depends on its class, its flags and the spacecraft: the key and the model)
    key = (type(law).__module__, type(law).__qualname__, law.gyroscopic_compensation, law.wheels_only, _CHUNK)
    if n == 0 or n_states == 0:
        states = np.zeros((n, n_states))
    elif _conserving(law, blocks, model):
        states = _momentum_by_conservation(law, spacecraft, q, omega, start + kicks[0],
                                           _environment_impulse(model, t, q, omega, environment))
    else:
        after = inputs.copy()
        if torque_after is not None:
            after[:, 0:3] = np.asarray(torque_after, dtype=float).reshape(n, 3)
        step = BufferedFunction(model.solver_cache.get(("reference_demand_step", *key), lambda: _demand_step(
            law, spacecraft, blocks, n_states).mapaccum("reference_demand", _CHUNK)))
        states = _integrated_states(step, t, after, inputs, start, kicks)
    commands = (_mapped_rows(model.solver_cache, ("reference_demand_command", *key),
                             lambda: _demand_command(law, spacecraft, n_states), states, inputs)
                if n else np.zeros((0, law._nu)))
    limits = demand_limits(spacecraft)
    demand: dict[str, Demand] = {}
    for block in blocks:
        actuator = block.actuator
        name = _quantity(actuator, False)
        demand[name] = Demand(name, commands[:, block.control], limits[name])
        if actuator.state_size:
            name = _quantity(actuator, True)
            demand[name] = Demand(name, states[:, block.state], limits[name])
    return demand


_CHUNK = 512
"""Samples (or sub-steps) per call of the mapped map and the accumulated step of :func:`reference_demand`,
and of :func:`model_rows`."""

_TAIL = 64
"""Samples per call of the smaller map that evaluates the rows past the last whole chunk of
:data:`_CHUNK` (2110 samples: four chunks and one call of 64, not a fifth chunk padded with 450)."""


def _mapped_rows(cache: SolverCache, key: tuple[Hashable, ...], build: Callable[[], ca.Function], *inputs: Array) -> Array:
    """The first output of ``build()`` at each of N samples, by chunks of :data:`_CHUNK` samples
    through its map (cached under ``key``), the rows past the last whole chunk by :data:`_TAIL`
    through a smaller map, and their buffers (:func:`ocp.fast_call.buffered`: made once per map and
    thread): no map is built per call and no matrix converted to CasADi's (which cost more than the
    evaluation itself); each call's rows are written into the input buffers in place, a shared value
    once a map, the last call padded with the last sample. ``inputs``: (N, k_i) rows, or (1, k_i)
    for a value shared by every sample. Returns (N, m)."""
    n = max((rows.shape[0] for rows in inputs if rows.shape[0] != 1), default=1)
    out: Array | None = None
    whole = n - n % _CHUNK
    for size, begin, end in ((_CHUNK, 0, whole), (_TAIL, whole, n)):
        if begin == end:
            continue
        mapped = buffered(cache.get((*key, "rows", size), lambda: build().map(size)))
        width = mapped.outputs[0].size // size
        if out is None:
            out = np.empty((n, width))
        result = mapped.outputs[0].reshape(size, width)  # column-major (m, size): a row per sample
        per_sample = []
        for buffer, values in zip(mapped.inputs, inputs):
            rows = buffer.reshape(size, values.shape[1])
            if values.shape[0] == 1:
                rows[:] = values
            else:
                per_sample.append((rows, values))
        for first in range(begin, end, size):
            count = min(size, end - first)
            for rows, values in per_sample:
                rows[:count] = values[first:first + count]
                rows[count:] = values[n - 1]
            mapped.evaluate()
            out[first:first + count] = result[:count]
    assert out is not None  # n >= 1
    return out


def model_rows(model: AttitudeModel, name: str, *inputs: ArrayLike) -> Array:
    """One of a model's CasADi functions at each of N samples (``environment_torque``,
    ``body_torque``, ``field_body``, ...), as a batch: the function's own expression evaluated by
    chunks through a cached map (:data:`_CHUNK` samples a call, the rest :data:`_TAIL` a call) and
    its buffers.

    Parameters
    ----------
    model : ocp.AttitudeModel
        The model (its ``solver_cache`` keeps the map).
    name : str
        The attribute of ``model`` holding the function (dense inputs).
    *inputs : array_like
        The function's inputs in order: (N, k_i) rows, one per sample, or (k_i,) for a value
        shared by every sample (a scalar input's N values as an (N, 1) column).

    Returns
    -------
    (N, m) ndarray
        The function's first output at each sample.
    """
    function = getattr(model, name)
    if not isinstance(function, ca.Function):
        raise TypeError(f"model.{name} is no CasADi function")
    rows = [np.atleast_2d(np.asarray(values, dtype=float)) for values in inputs]
    n = max((values.shape[0] for values in rows if values.shape[0] != 1), default=1)
    if any(values.shape[0] not in (1, n) for values in rows):
        raise ValueError(f"model_rows({name}): inputs of {[values.shape[0] for values in rows]} rows")
    if n == 0:
        return np.zeros((0, function.nnz_out(0)))
    return _mapped_rows(model.solver_cache, ("model_rows", name), lambda: function, *rows)

SUBSTEP_ANGLE = 0.05
"""[rad]: the most the body turns (``|ω| Δt``, the larger rate of the interval's ends) in one step
of :func:`reference_demand`'s integrated states. The classical Runge-Kutta step of a rotation by
``θ`` (the wheels' gyroscopic term) errs by ``θ⁵/120``: 5e-8 of the momentum per radian turned
(Heun's method on whole sample intervals, as before, multiplied it by ``(1 + θ⁴/4)^½`` a step:
1.3e249 times the wheels' limit in a 140 s run spinning at 20 rad/s)."""


MAX_SUBSTEPS = 5_000_000
"""The most sub-steps :func:`reference_demand` integrates (about 5 s; 250 000 rad turned): the
states of the samples after them are nan (not computed), never an under-resolved number."""


def _conserving(law: Allocation, blocks: Sequence[Any], model: AttitudeModel) -> bool:
    """Whether the total angular momentum changes along the reference by the environment's impulse
    alone: the working wheels span three axes, so they take every torque, and they are the only
    actuators with states. The allocation then asks any other actuator nothing (torquers and
    magnetorquers beside them take the residual ``(1 − A A⁺) τ``, zero; a kind without a
    ``residual_rank`` is never commanded), so no torque of theirs is external to the balance."""
    return (all(block.actuator.state_size == 0 for block in blocks if block.actuator.block != "wheels")
            and law._working_axes is not None and int(np.linalg.matrix_rank(law._working_axes)) == 3)


def _environment_impulse(model: AttitudeModel, t: Array, q: Array, omega: Array,
                         known: ArrayLike | None = None) -> Array:
    """``∫₀ᵗ R(q) τ_e dt`` [N m s], inertial axes, at each sample: the environment's torque of
    ``model`` (gravity gradient, constant disturbance) along the motion, by the trapezoidal rule;
    zeros without one. ``known``: that torque at the samples [N m], body axes, when the caller has
    it (:func:`reference_demand`'s ``environment``); ``None``: evaluated here."""
    environment = model.environment
    if environment is None or not (environment.gravity_gradient or np.any(environment.disturbance_torque)):
        return np.zeros((t.size, 3))
    if known is not None:
        torque = np.asarray(known, dtype=float).reshape(t.size, 3)
    else:
        x = np.hstack([q, omega, np.zeros((t.size, model.nx - 7))])
        torque = model_rows(model, "environment_torque", x, t[:, None],
                            np.asarray(model.default_parameters, dtype=float).ravel())
    inertial = quat.rotate(quat.normalize(q), torque)
    steps = 0.5 * (inertial[1:] + inertial[:-1]) * np.diff(t)[:, None]
    return np.vstack([np.zeros((1, 3)), np.cumsum(steps, axis=0)])


def _momentum_by_conservation(law: Allocation, spacecraft: Spacecraft, q: Array, omega: Array, start: Array,
                              impulse: Array) -> Array:
    """The wheel momenta along the motion by the balance of the total angular momentum (working
    wheels spanning three axes, :func:`reference_demand`): ``A h_w = R(q)ᵀ (R(q₀) (I ω₀ + A h₀) + J) − I ω``,
    ``J`` the environment's ``impulse`` (inertial, :func:`_environment_impulse`),
    ``h_w = h₀ + A⁺ (A h_w − A h₀)``; ``start`` is ``h₀`` after the jump at the first sample."""
    inertia = np.asarray(spacecraft.inertia, dtype=float)
    axes = np.asarray(spacecraft.wheel_axes, dtype=float)
    attitude = quat.normalize(q)
    total = quat.rotate(attitude[0], inertia @ omega[0] + axes @ start) + impulse  # inertial
    stored = quat.rotate_inverse(attitude, total) - omega @ inertia.T  # A h_w, body axes
    return np.asarray(start + (stored - axes @ start) @ law._wheel_pinv.T, dtype=np.float64)


def _integrated_states(step: BufferedFunction, t: Array, after: Array, inputs: Array, start: Array,
                       kicks: Array) -> Array:
    """The actuators' states at the samples by Runge-Kutta sub-steps (:func:`reference_demand`): each
    interval cut into ``m`` equal sub-steps, ``m`` the least that keeps ``|ω| Δt / m`` within
    :data:`SUBSTEP_ANGLE`; the inputs interpolated linearly from ``after`` (the interval's start,
    the torque just after it) to ``inputs`` (its end); the jump ``kicks[k]`` at sample k. The
    samples past :data:`MAX_SUBSTEPS` sub-steps (or past a rate that is not finite) are nan: a
    demand not computed, which the scorer breaks the requirement on."""
    n, n_states = kicks.shape
    states = np.full((n, n_states), np.nan)
    states[0] = start
    if n > 1:
        dt = np.diff(t)
        turn = dt * np.maximum(np.linalg.norm(inputs[:-1, 7:10], axis=1), np.linalg.norm(inputs[1:, 7:10], axis=1))
        counts = np.full(n - 1, np.inf)  # a rate that is not finite: no sub-step resolves it
        finite = np.isfinite(turn)
        counts[finite] = np.maximum(np.ceil(turn[finite] / SUBSTEP_ANGLE - 1e-9), 1.0)
        within = int(np.searchsorted(np.cumsum(counts), MAX_SUBSTEPS, side="right"))  # whole intervals in the budget
        counts = counts[:within].astype(np.int64)
        interval = np.repeat(np.arange(within), counts)
        firsts = np.cumsum(counts) - counts
        index = np.arange(interval.size) - firsts[interval]  # the sub-step within its interval
        total = -(-interval.size // _CHUNK) * _CHUNK  # whole chunks: the last sub-step's end held, zero lengths
        size = interval.size
        now = np.empty((total, inputs.shape[1]))
        if size:
            now[size:] = inputs[interval[-1] + 1]
        then = now.copy()
        parts = counts[interval].astype(float)[:, None]
        begin, end = after[interval], inputs[interval + 1]
        now[:size] = begin + index[:, None] / parts * (end - begin)  # every sub-step's inputs at once
        then[:size] = begin + (index[:, None] + 1.0) / parts * (end - begin)
        lengths = np.zeros(total)
        lengths[:size] = dt[interval] / parts[:, 0]
        jumps = np.zeros((total, n_states))
        starting = index == 0
        jumps[:size][starting] = kicks[interval[starting]]
        ends = np.zeros((total, n_states))
        state = start
        for first in range(0, total, _CHUNK):  # one call per chunk of sub-steps
            chunk = slice(first, first + _CHUNK)
            ends[chunk] = step(state, now[chunk].ravel(), then[chunk].ravel(), lengths[chunk],
                               jumps[chunk].ravel()).reshape(_CHUNK, n_states)  # column-major: a row per sub-step
            state = ends[first + _CHUNK - 1].copy()
        states[1:within + 1] = ends[firsts + counts - 1]
    return states + kicks  # each sample's state after its jump (the step from it started there)


def unrealised_torque(model: AttitudeModel, t: ArrayLike, q: ArrayLike, omega: ArrayLike, torque: ArrayLike,
                      demand: dict[str, Demand]) -> Array:
    """The part of a reference's feed-forward torque that the actuators' commands do not give.

    The commands and states of ``demand`` (:func:`reference_demand`, through a law's allocation)
    give the body the torque ``τ_a − ω × A h_w``: the actuators' own (``−A g`` of the wheels,
    ``m × B`` of the magnetorquers at the model's field, the torquers') and the gyroscopic term of
    the momentum the actuators store (``A h_w``, each kind's ``momentum_matrix``) along the
    reference. What the feed-forward ``u`` asks
    beyond it, ``u − (τ_a − ω × A h_w)``, no command gives: torque about an axis the working
    actuators do not span (one wheel, failed wheels without torquers), or along the field for
    magnetorquers alone. Rounding leaves about 1e-16 of ``|u|`` on a fully actuated spacecraft.

    Parameters
    ----------
    model : ocp.AttitudeModel
        The spacecraft and its environment (the field, for magnetorquers).
    t : (N,) array_like
        Sample times [s].
    q : (N, 4) array_like
        Reference attitude (scalar first, body to inertial).
    omega : (N, 3) array_like
        Reference body rate [rad/s], body axes.
    torque : (N, 3) array_like
        Feed-forward torque ``u`` of ``I ω̇ = −ω × I ω + u`` [N m], body axes.
    demand : dict of str to Demand
        :func:`reference_demand` of the same samples.

    Returns
    -------
    (N, 3) ndarray
        The unrealised torque [N m], body axes.
    """
    spacecraft = model.spacecraft
    t = np.asarray(t, dtype=float).reshape(-1)
    n = t.size
    _, nu = control_layout(spacecraft)
    u = np.zeros((n, nu))
    x = np.zeros((n, model.nx))
    x[:, 0:4] = np.asarray(q, dtype=float).reshape(n, 4)
    x[:, 4:7] = np.asarray(omega, dtype=float).reshape(n, 3)
    for block in actuator_blocks(spacecraft):
        u[:, block.control] = demand[_quantity(block.actuator, False)].values
        if block.actuator.state_size:
            x[:, 7:][:, block.state] = demand[_quantity(block.actuator, True)].values
    given = model_rows(model, "body_torque", x, u, t[:, None]) if n else np.zeros((0, 3))
    momentum = np.zeros((n, 3))  # stored in the actuators' states: the wheels' A h_w (momentum_matrix)
    for block in actuator_blocks(spacecraft):
        if block.actuator.state_size:
            momentum += x[:, 7:][:, block.state] @ np.asarray(block.actuator.momentum_matrix(), dtype=float).T
    given -= np.cross(x[:, 4:7], momentum)
    return np.asarray(torque, dtype=float).reshape(n, 3) - given


def _demand_command(law: Allocation, spacecraft: Spacecraft, n_states: int) -> ca.Function:
    """``command(state, inputs) -> u``: the law's map at a sample, ``inputs`` = [τ, q, ω, b]."""
    inputs = ca.SX.sym("inputs", 13)
    state = ca.SX.sym("state", n_states)
    measurement = ca.vertcat(inputs[3:7], inputs[7:10], state[:spacecraft.n_wheels], inputs[10:13])  # [q, ω, h_w, b]
    return ca.Function("demand_command", [state, inputs], [law.allocate_symbolic(inputs[0:3], measurement)])


def _demand_step(law: Allocation, spacecraft: Spacecraft, blocks: Sequence[Any], n_states: int) -> ca.Function:
    """``step(state_k, inputs_k, inputs_k+1, dt, kick_k) -> state_k+1``: the state's jump ``kick_k``
    at step k (the wheels taking up a jump of the rate), then the classical Runge-Kutta step of the
    actuators' states under the law's map, the inputs linear over the step; ``inputs`` = [τ, q, ω, b]."""
    inputs = ca.SX.sym("inputs", 13)
    state = ca.SX.sym("state", n_states)
    n_w = spacecraft.n_wheels

    def rate(at: ca.SX, states: ca.SX) -> ca.SX:
        measurement = ca.vertcat(at[3:7], at[7:10], states[:n_w], at[10:13])  # y = [q, ω, h_w, b]
        u = law.allocate_symbolic(at[0:3], measurement)
        parts = [block.actuator.state_rate(u[block.control], states[block.state]) for block in blocks
                 if block.actuator.state_size]
        return ca.vertcat(*parts) if parts else ca.SX(0, 1)

    after = ca.SX.sym("after", 13)
    dt = ca.SX.sym("dt")
    kick = ca.SX.sym("kick", n_states)
    kicked = state + kick
    middle = 0.5 * (inputs + after)  # the inputs are linear over the step
    k1 = rate(inputs, kicked)
    k2 = rate(middle, kicked + 0.5 * dt * k1)
    k3 = rate(middle, kicked + 0.5 * dt * k2)
    k4 = rate(after, kicked + dt * k3)
    following = kicked + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    return ca.Function("demand_step", [state, inputs, after, dt, kick], [following])
