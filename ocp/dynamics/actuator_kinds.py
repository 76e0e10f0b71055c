"""The actuator description: one class per kind of actuator (reaction wheels, magnetorquers, ideal
torquers) and the registry a new kind joins.

All quantities are SI and in body axes. Construction validates; a bad value raises
:class:`~ocp.errors.ModelError` whose ``field`` names the offending attribute so that callers (the
YAML loader) can point at the input that caused it.

An actuator kind is one :class:`Actuator` subclass registered with :func:`actuator_kind`: it
holds the kind's numbers and says everything the rest of the workbench needs of it, its block of
the control vector ``u`` and of the state ``x``, its bounds, its torque on the body and the rate
of its states, how a command is saturated (numerically and on CasADi expressions), its own
body torque box and whether the allocation may send it the residual torque. The model, the
saturation, the layouts, the collocation bounds and the closed loop iterate over
:attr:`~ocp.dynamics.spacecraft.Spacecraft.actuators`; none of them names a kind.
"""
from __future__ import annotations

import functools
import numbers
from abc import ABC, abstractmethod
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar, TypeVar

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp.errors import ModelError
from ocp.options import real_array

Array = NDArray[np.float64]
Expr = Any
"""A CasADi expression (``SX`` or ``MX``) or an ndarray."""

__all__ = ["ACTUATOR_KINDS", "SATURATION_MODES", "Actuator", "Magnetorquers", "ReactionWheels", "Torquers",
           "actuator_kind"]


def casadi_number(value: Any) -> Any:
    """A limit for the symbolic saturation: a ``casadi.DM`` of the number, or the symbol itself when
    code generation makes the limit an input (``slewbench codegen``).

    Parameters
    ----------
    value : array_like, casadi.SX or casadi.MX
        The limit (its unit).

    Returns
    -------
    casadi.DM, casadi.SX or casadi.MX
    """
    return value if isinstance(value, (ca.SX, ca.MX)) else ca.DM(value)


def _limit_vector(value: ArrayLike | None, size: int, field_name: str) -> Array:
    """Per-element positive limit; ``None`` means unlimited (inf). A read-only copy; a
    :class:`~ocp.errors.ModelError` naming the field, the value and its type for anything but real
    numbers (:func:`~ocp.options.real_array`: ``True``, ``1+0j``, ``"0.1"``)."""
    if value is None:
        return _frozen(np.full(size, np.inf))
    try:
        array = real_array(value)
    except ValueError as reason:
        raise ModelError(field_name, f"expected a number or {size} numbers, got {value!r:.200}: {reason}") from None
    if array.ndim == 0:
        array = np.full(size, float(array))
    if array.shape != (size,):
        raise ModelError(field_name, f"expected a scalar or {size} values, got shape {array.shape}")
    if np.any(~(array > 0)):
        raise ModelError(field_name, f"limits must be positive, got {array.tolist()}")
    return _frozen(array)


def _frozen(array: Array) -> Array:
    """``array`` (a private copy made by the caller), made read-only: an actuator's numbers do not
    change after the checks of its construction."""
    array.setflags(write=False)
    return array


class Actuator(ABC):
    """An actuator kind: its numbers (the subclass's fields) and what the model, the saturation,
    the collocation bounds and the allocation need of it.

    A kind sets the class attributes :attr:`name`, :attr:`block` and :attr:`command`, implements
    the abstract methods, and is registered with :func:`actuator_kind`; it is then given to
    :class:`Spacecraft` as the keyword :attr:`name`. A kind with states (:attr:`state_size` > 0,
    e.g. wheel momenta) also implements :meth:`state_rate`, and :meth:`momentum_matrix` when its
    states store angular momentum.

    Control blocks and state blocks are laid out in the order the kinds were registered
    (:data:`ACTUATOR_KINDS`): the built-in kinds first, wheels, magnetorquers, torquers.
    """

    name: ClassVar[str]
    """Keyword of :class:`Spacecraft` (and its attribute for the built-in kinds), also the key of
    the kind's section under ``spacecraft`` in a scenario."""
    block: ClassVar[str]
    """Key of the kind's block of ``u`` in ``AttitudeModel.control_slices``."""
    command: ClassVar[str]
    """The :class:`~ocp.dynamics.actuators.Command` field the kind reads (a key of
    ``Command.other`` for kinds without a field of their own)."""
    needs_field: ClassVar[bool] = False
    """Its torque depends on the geomagnetic field (given to :meth:`body_torque`)."""
    residual_rank: ClassVar[int | None] = None
    """When not ``None``, the kind realises any body torque and the allocation may send it what
    the wheels cannot give (:meth:`take_residual`); the lowest rank present takes it
    (:attr:`Spacecraft.residual_actuator <ocp.dynamics.spacecraft.Spacecraft.residual_actuator>`,
    the one place that reads the ranks)."""

    @property
    @abstractmethod
    def control_size(self) -> int:
        """Length of the kind's block of ``u``."""

    @property
    def state_size(self) -> int:
        """Length of the kind's block of the state ``x`` (after ``q`` and ``ω``); 0 by default."""
        return 0

    @abstractmethod
    def control_bounds(self) -> tuple[Array, Array]:
        """Bounds of the kind's block of ``u``, as a planner imposes them.

        Returns
        -------
        low, high : (control_size,) ndarray
            Lower and upper bound, in the unit of the block; ``±inf``: none.
        """

    def state_bounds(self) -> tuple[Array, Array]:
        """Bounds of the kind's block of ``x`` (none by default).

        Returns
        -------
        low, high : (state_size,) ndarray
            Lower and upper bound, in the unit of the states; ``±inf``: none.
        """
        return np.full(self.state_size, -np.inf), np.full(self.state_size, np.inf)

    def momentum_matrix(self) -> Array:
        """Matrix ``M`` of the angular momentum stored in the kind's states, ``M s`` [N m s] in
        body axes (the wheels' ``A``); zeros by default.

        Returns
        -------
        (3, state_size) ndarray
        """
        return np.zeros((3, self.state_size))

    @abstractmethod
    def body_torque(self, u: Expr, state: Expr, field_body: Expr | None) -> Expr | None:
        """The kind's torque on the body.

        Parameters
        ----------
        u : (control_size, 1) casadi.SX or MX
            The kind's block of the control.
        state : (state_size, 1) casadi.SX or MX
            The kind's block of the state (empty without states).
        field_body : (3, 1) casadi.SX or MX, or None
            Geomagnetic field [T], body axes, for kinds that declare :attr:`needs_field`;
            ``None`` otherwise or without a field model.

        Returns
        -------
        (3, 1) casadi.SX or MX, or None
            Torque [N m], body axes; ``None``: no torque (e.g. no field to act on).
        """

    def state_rate(self, u: Expr, state: Expr) -> Expr:
        """Rate of the kind's states (kinds with states implement it).

        Parameters
        ----------
        u : (control_size, 1) casadi.SX or MX
            The kind's block of the control.
        state : (state_size, 1) casadi.SX or MX
            The kind's block of the state.

        Returns
        -------
        (state_size, 1) casadi.SX or MX
            Time derivative of the states.
        """
        raise NotImplementedError(f"{type(self).__name__} has states and must implement state_rate")

    @abstractmethod
    def saturate(self, asked: Sequence[float], state: Sequence[float], dt: float) -> tuple[list[float], bool]:
        """The applied block for a command held over ``dt`` (Python floats: per-sample code).

        Parameters
        ----------
        asked : sequence of float
            The commanded block (as many values as :attr:`control_size`, else ``ValueError``).
        state : sequence of float
            The kind's states at the start of the hold (empty without states).
        dt : float
            Length of the hold [s], positive.

        Returns
        -------
        applied : list of float
            The applied block.
        saturated : bool
            Whether the kind is at a limit.

        Raises
        ------
        ValueError
            For a command of the wrong length.
        """

    @abstractmethod
    def saturate_symbolic(self, u: Expr, state: Expr, dt: Expr) -> tuple[Expr, list[Expr]]:
        """:meth:`saturate` on CasADi expressions.

        Parameters
        ----------
        u : (control_size, 1) casadi.SX or MX
            The commanded block.
        state : (state_size, 1) casadi.SX or MX
            The kind's states at the start of the hold.
        dt : casadi.SX, casadi.MX or float
            Length of the hold [s].

        Returns
        -------
        applied : (control_size, 1) casadi.SX or MX
            The applied block, as :meth:`saturate` computes it.
        flags : list of casadi.SX or MX
            Expressions that are 1 where the kind is at a limit.
        """

    def body_torque_box(self) -> Array | None:
        """The kind's own per-axis torque box (none by default): the limits of the residual's rows
        in :meth:`Spacecraft.allocation_rows <ocp.dynamics.spacecraft.Spacecraft.allocation_rows>`
        when the kind takes the residual, whose box
        (:meth:`Spacecraft.body_torque_limit <ocp.dynamics.spacecraft.Spacecraft.body_torque_limit>`)
        counts the kind only where the allocation asks it.

        Returns
        -------
        (3,) ndarray or None
            Per-body-axis torque bound [N m] the kind can apply on all axes at once; ``None``:
            the kind gives none (e.g. its torque depends on the field).
        """
        return None

    def take_residual(self, residual: Sequence[float], field_body: Sequence[float] | None) -> list[float] | None:
        """The command that realises a body torque (kinds with a :attr:`residual_rank`).

        Parameters
        ----------
        residual : sequence of 3 float
            Body torque to realise [N m], body axes.
        field_body : sequence of 3 float or None
            Measured geomagnetic field [T], body axes; ``None`` without one.

        Returns
        -------
        list of float or None
            The kind's block; ``None``: nothing can be asked (e.g. no field).
        """
        raise NotImplementedError(f"{type(self).__name__} takes no residual torque")

    def take_residual_symbolic(self, residual: Expr, field_body: Expr) -> Expr:
        """:meth:`take_residual` on CasADi expressions.

        Parameters
        ----------
        residual : (3, 1) casadi.SX
            Body torque to realise [N m], body axes.
        field_body : (3, 1) casadi.SX
            Measured geomagnetic field [T], body axes (zeros without a field model).

        Returns
        -------
        (control_size, 1) casadi.SX
            The kind's block.
        """
        raise NotImplementedError(f"{type(self).__name__} takes no residual torque")


ACTUATOR_KINDS: dict[str, type[Actuator]] = {}
"""The registered actuator kinds by :attr:`Actuator.name`, in registration order (the order of
their blocks in ``u`` and ``x``)."""

_Kind = TypeVar("_Kind", bound=type[Actuator])


def actuator_kind(cls: _Kind) -> _Kind:
    """Register an actuator kind (a class decorator).

    Parameters
    ----------
    cls : type
        A concrete :class:`Actuator` subclass with its ``name``, ``block`` and ``command``.

    Returns
    -------
    type
        ``cls``, now in :data:`ACTUATOR_KINDS`.

    Raises
    ------
    TypeError
        If ``cls`` is no Actuator subclass.
    ValueError
        If its name or block is already taken by another kind.
    """
    if not (isinstance(cls, type) and issubclass(cls, Actuator)):
        raise TypeError(f"an actuator kind subclasses ocp.dynamics.actuator_kinds.Actuator, got {cls!r}")
    for other in ACTUATOR_KINDS.values():
        if other is not cls and (other.name == cls.name or other.block == cls.block):
            raise ValueError(f"actuator kind {cls.__name__}: name {cls.name!r} or block {cls.block!r} is "
                             f"taken by {other.__name__}")
    ACTUATOR_KINDS[cls.name] = cls
    return cls


class _BodyAxisVector(Actuator):
    """Base of the kinds whose block is a body-axis 3-vector with a limit per axis: clipped per
    axis, or (:attr:`_scaled`) scaled down as a whole until every axis is within its limit (the
    direction kept)."""

    @property
    @abstractmethod
    def _axis_limit(self) -> Array:
        """(3,) per-axis limit, in the unit of the block."""

    @property
    def _scaled(self) -> bool:
        """Whether the vector is scaled as a whole (else clipped per axis)."""
        return False

    @functools.cached_property
    def _floats(self) -> tuple[tuple[float, float, float], tuple[float, float, float], bool]:
        """The limits and the values at which an axis counts as at its limit, as Python floats
        (per-sample code), and whether the vector is scaled."""
        l0, l1, l2 = self._axis_limit.tolist()
        near = 1 - 1e-12
        return (l0, l1, l2), (l0 * near, l1 * near, l2 * near), self._scaled

    @property
    def control_size(self) -> int:
        """3: a vector in body axes."""
        return 3

    def control_bounds(self) -> tuple[Array, Array]:
        """Minus and plus the per-axis limit.

        Returns
        -------
        low, high : (3,) ndarray
            In the unit of the block, body axes.
        """
        return -self._axis_limit, self._axis_limit.copy()

    def saturate(self, asked: Sequence[float], state: Sequence[float], dt: float) -> tuple[list[float], bool]:
        """Each axis clipped to its limit, or the vector scaled down as a whole.

        Parameters
        ----------
        asked : sequence of 3 float
            The commanded vector, body axes.
        state : sequence of float
            Empty.
        dt : float
            Length of the hold [s] (not used).

        Returns
        -------
        applied : list of 3 float
            The applied vector.
        saturated : bool
            Whether an axis asks its limit or more.

        Raises
        ------
        ValueError
            For other than 3 values.
        """
        (l0, l1, l2), (n0, n1, n2), scaled = self._floats
        if len(asked) != 3:
            raise ValueError(f"{self.command} needs 3 values (body axes), got {len(asked)}")
        a0, a1, a2 = asked  # written out: no generator per sample
        if scaled:  # the whole vector is scaled down until every axis is within its limit: direction kept
            ratio = max(abs(a0) / l0, abs(a1) / l1, abs(a2) / l2)
            applied = [a0 / ratio, a1 / ratio, a2 / ratio] if ratio > 1.0 else [a0, a1, a2]
        else:
            applied = [min(max(a0, -l0), l0), min(max(a1, -l1), l1), min(max(a2, -l2), l2)]
        return applied, abs(a0) >= n0 or abs(a1) >= n1 or abs(a2) >= n2

    def saturate_symbolic(self, u: Expr, state: Expr, dt: Expr) -> tuple[Expr, list[Expr]]:
        """:meth:`saturate` on CasADi expressions.

        Parameters
        ----------
        u : (3, 1) casadi.SX or MX
            The commanded vector.
        state : casadi.SX or MX
            Empty.
        dt : casadi.SX, casadi.MX or float
            Not used.

        Returns
        -------
        applied : (3, 1) casadi.SX or MX
            The applied vector.
        flags : list of casadi.SX or MX
            1 where an axis asks its limit or more.
        """
        bound = casadi_number(self._axis_limit)
        if self._scaled:  # as the numeric form: the vector scaled as a whole
            ratio = ca.mmax(ca.fabs(u) / bound)
            applied = ca.if_else(ratio > 1.0, u / ratio, u)
        else:
            applied = ca.fmin(ca.fmax(u, -bound), bound)
        return applied, [ca.fabs(u) >= bound * (1 - 1e-12)]


@actuator_kind
@dataclass(frozen=True, init=False)
class ReactionWheels(Actuator):
    """Array of ``n`` reaction wheels; wheel ``i`` stores spin momentum ``h_i`` about its axis and
    its motor torque ``g_i = ḣ_i`` reacts on the body as ``−a_i g_i``.

    The attributes hold the normalised values: ``axes`` unit columns, the limits as (n,) arrays
    (``inf`` where unlimited). Control block ``"wheels"``: the motor torques ``g`` [N m]; states:
    the momenta ``h_w`` [N m s].

    Parameters
    ----------
    axes : (3, n) array_like
        Spin axes, body frame, one column per wheel (the allocation matrix; a scenario file's
        ``spacecraft.wheels.axes`` lists one row per wheel: pass its transpose); normalised on
        construction.
    max_torque : float or (n,) array_like, optional
        Motor torque limit per wheel [N m], positive; ``None`` (default): unlimited.
    max_momentum : float or (n,) array_like, optional
        Spin momentum limit per wheel [N m s], positive; ``None`` (default): unlimited.
    spin_inertia : float or (n,) array_like, optional
        Wheel spin inertia [kg m^2], positive, only used to report wheel speeds; ``None``
        (default): not known, stays ``None``.
    failed : iterable of int, optional
        Indices (0-based) of failed wheels, each listed once; they produce no torque. Stored as a
        tuple.

    Raises
    ------
    ModelError
        For a malformed axis matrix, a zero axis, a non-positive or mis-sized limit, or a bad
        failed-wheel index.
    """

    name: ClassVar[str] = "wheels"
    block: ClassVar[str] = "wheels"
    command: ClassVar[str] = "wheel_torque"

    axes: Array
    max_torque: Array
    max_momentum: Array
    spin_inertia: Array | None
    failed: tuple[int, ...]

    def __init__(self, axes: ArrayLike, max_torque: ArrayLike | None = None, max_momentum: ArrayLike | None = None,
                 spin_inertia: ArrayLike | None = None, failed: Iterable[int] = ()) -> None:
        for name, value in (("axes", axes), ("max_torque", max_torque), ("max_momentum", max_momentum),
                            ("spin_inertia", spin_inertia), ("failed", failed)):
            object.__setattr__(self, name, value)
        self.__post_init__()

    def __post_init__(self) -> None:
        try:
            axes = real_array(self.axes)
        except ValueError as reason:
            raise ModelError("axes", f"expected a 3 x n matrix of wheel axes (numbers), got {self.axes!r:.200}: "
                                     f"{reason}") from None
        if axes.ndim != 2 or axes.shape[0] != 3 or axes.shape[1] < 1:
            raise ModelError("axes", f"expected a 3 x n matrix of wheel axes, got shape {axes.shape}")
        if not np.all(np.isfinite(axes)):
            raise ModelError("axes", f"expected finite wheel axes, got {axes.tolist()}")
        scale = np.max(np.abs(axes), axis=0)  # scaled first: the norm of [1e300, 1e300, 0] overflows
        if np.any(scale * np.linalg.norm(axes / np.where(scale > 0, scale, 1.0), axis=0) < 1e-9):
            raise ModelError("axes", "a wheel axis is the zero vector")
        n = axes.shape[1]
        axes = axes / scale
        object.__setattr__(self, "axes", _frozen(axes / np.linalg.norm(axes, axis=0)))
        object.__setattr__(self, "max_torque", _limit_vector(self.max_torque, n, "max_torque"))
        object.__setattr__(self, "max_momentum", _limit_vector(self.max_momentum, n, "max_momentum"))
        if self.spin_inertia is not None:
            object.__setattr__(self, "spin_inertia", _limit_vector(self.spin_inertia, n, "spin_inertia"))
        try:
            listed = list(self.failed)
        except TypeError:
            raise ModelError("failed", f"expected a list of wheel indices, got {self.failed!r:.80}") from None
        odd = [i for i in listed if not isinstance(i, numbers.Integral) or isinstance(i, bool)]
        if odd:
            raise ModelError("failed", f"expected wheel indices (integers), got {odd[0]!r:.60} ({type(odd[0]).__name__}) "
                                       f"in {listed!r:.120}")
        failed = tuple(int(i) for i in listed)
        if any(i < 0 or i >= n for i in failed):
            raise ModelError("failed", f"failed wheel indices must be in 0..{n - 1}, got {list(failed)}")
        if len(set(failed)) != len(failed):
            raise ModelError("failed", f"each failed wheel is listed once, got {list(failed)}")
        object.__setattr__(self, "failed", failed)

    @classmethod
    def from_body_axes(cls, n_axes: int = 3, **limits: Any) -> ReactionWheels:
        """Wheels along the first ``n_axes`` body axes (x, then y, then z).

        Parameters
        ----------
        n_axes : int, optional
            Number of wheels, 1 to 3 (default 3).
        **limits : float, array_like or None
            ``max_torque``, ``max_momentum``, ``spin_inertia`` or ``failed``, as in the
            constructor.

        Returns
        -------
        ReactionWheels
            Wheels with ``axes = eye(3)[:, :n_axes]``.

        Raises
        ------
        ModelError
            For an ``n_axes`` that is not an integer from 1 to 3 (``4`` gave three wheels, ``"3"`` a
            slicing ``TypeError``).
        """
        if not isinstance(n_axes, numbers.Integral) or isinstance(n_axes, bool) or not 1 <= n_axes <= 3:
            raise ModelError("n_axes", f"expected 1, 2 or 3 wheels along the body axes, got {n_axes!r:.60} "
                                       f"({type(n_axes).__name__}); ReactionWheels(axes) takes any others")
        return cls(axes=np.eye(3)[:, :int(n_axes)], **limits)

    @property
    def count(self) -> int:
        """Number of wheels ``n``, failed ones included."""
        return self.axes.shape[1]

    @property
    def working(self) -> NDArray[np.bool_]:
        """(n,) bool mask, True for the wheels that are not in :attr:`failed`."""
        mask = np.ones(self.count, dtype=bool)
        mask[list(self.failed)] = False
        return mask

    @property
    def pseudo_inverse(self) -> Array:
        """``A⁺`` of the working wheels: the minimum-norm wheel torques of a body torque in their span.

        Returns
        -------
        (n, 3) ndarray
            Rows per wheel, failed ones included: the pseudo-inverse of the axes with the failed
            wheels' columns zeroed, and those wheels' rows set to exact zeros (the SVD leaves
            rounding there, 1e-19 N m asked of a failed wheel). The controllers' allocation
            ``g = −A⁺ τ`` and every planner mapping a body torque or momentum to wheels use it.
        """
        working = self.working
        inverse: Array = np.zeros((self.count, 3))
        if np.any(working):
            inverse = np.asarray(np.linalg.pinv(self.axes * working), dtype=float)
        inverse[~working] = 0.0
        return inverse

    @property
    def control_size(self) -> int:
        """``n``: one motor torque per wheel, failed ones included."""
        return self.count

    @property
    def state_size(self) -> int:
        """``n``: one spin momentum per wheel."""
        return self.count

    def control_bounds(self) -> tuple[Array, Array]:
        """``±max_torque`` [N m], 0 for a failed wheel.

        Returns
        -------
        low, high : (n,) ndarray
        """
        limit = np.where(self.working, self.max_torque, 0.0)
        return -limit, limit

    def state_bounds(self) -> tuple[Array, Array]:
        """``±max_momentum`` [N m s].

        Returns
        -------
        low, high : (n,) ndarray
        """
        return -self.max_momentum, self.max_momentum.copy()

    def momentum_matrix(self) -> Array:
        """The axes ``A``: the wheels store ``A h_w`` [N m s], body axes.

        Returns
        -------
        (3, n) ndarray
        """
        return self.axes

    def body_torque(self, u: Expr, state: Expr, field_body: Expr | None) -> Expr:
        """``−A g`` [N m], body axes (the reaction of the motor torques ``u = g``).

        Parameters
        ----------
        u : (n, 1) casadi.SX or MX
            Motor torques ``g`` [N m].
        state : (n, 1) casadi.SX or MX
            Wheel momenta [N m s] (not used).
        field_body : casadi.SX, MX or None
            Not used.

        Returns
        -------
        (3, 1) casadi.SX or MX
        """
        return -ca.mtimes(ca.DM(self.axes), u)

    def state_rate(self, u: Expr, state: Expr) -> Expr:
        """``ḣ_w = g`` [N m].

        Parameters
        ----------
        u : (n, 1) casadi.SX or MX
            Motor torques ``g`` [N m].
        state : (n, 1) casadi.SX or MX
            Wheel momenta [N m s] (not used).

        Returns
        -------
        (n, 1) casadi.SX or MX
        """
        return u

    @functools.cached_property
    def _floats(self) -> tuple[tuple[float, float, float, float, float, float], ...]:
        """Per wheel, as Python floats (per-sample code): working (1.0 / 0.0), ``g_max``,
        ``−g_max``, ``h_max``, ``−h_max``, and the torque at which the wheel counts as at its limit."""
        return tuple((working, g_max, -g_max, h_max, -h_max, g_max * (1 - 1e-12)) for working, g_max, h_max in
                     zip(self.working.astype(float).tolist(), self.max_torque.tolist(), self.max_momentum.tolist()))

    def saturate(self, asked: Sequence[float], state: Sequence[float], dt: float) -> tuple[list[float], bool]:
        """Motor torques within ``±g_max`` and such that ``h_w + g dt`` stays within ``±h_max``
        (``ḣ_w = g`` is constant over the hold, so this is exact); a failed wheel gives nothing.

        Parameters
        ----------
        asked : sequence of n float
            Commanded motor torques [N m].
        state : sequence of n float
            Wheel momenta at the start of the hold [N m s].
        dt : float
            Length of the hold [s], positive.

        Returns
        -------
        applied : list of n float
            Applied motor torques [N m].
        saturated : bool
            Whether a wheel is at a torque or momentum limit.

        Raises
        ------
        ValueError
            When ``asked`` or ``state`` has other than one value per wheel.
        """
        wheels = self._floats
        if len(asked) != len(wheels) or len(state) != len(wheels):
            raise ValueError(f"wheel_torque and wheel_momentum need {len(wheels)} values (one per wheel), "
                             f"got {len(asked)} and {len(state)}")
        saturated = False
        applied_wheels = []
        for (working, limit, minus_limit, h_limit, minus_h_limit, at_limit), g_asked, h in zip(wheels, asked, state):
            # Written as comparisons (no min/max calls); each line is the NumPy/CasADi
            # max/min of saturate_symbolic, with the command first so that a NaN stays NaN.
            g = g_asked * working
            low = (minus_h_limit - h) / dt
            if not low > minus_limit:
                low = minus_limit
            high = (h_limit - h) / dt
            if not high < limit:
                high = limit
            if low > high:  # noqa: PLR1730 (comparisons: no call per wheel and sample)
                high = low
            applied = low if low > g else g  # noqa: FURB136 (max(g, low), g kept when NaN)
            if high < applied:  # noqa: PLR1730
                applied = high
            size = abs(g)
            scale = size if size > 1.0 else 1.0  # noqa: FURB136 (max(1.0, |g|))
            if abs(applied - g) > 1e-12 * scale or abs(applied) >= at_limit:
                saturated = True
            applied_wheels.append(applied)
        return applied_wheels, saturated

    def saturate_symbolic(self, u: Expr, state: Expr, dt: Expr) -> tuple[Expr, list[Expr]]:
        """:meth:`saturate` on CasADi expressions.

        Parameters
        ----------
        u : (n, 1) casadi.SX or MX
            Commanded motor torques [N m].
        state : (n, 1) casadi.SX or MX
            Wheel momenta at the start of the hold [N m s].
        dt : casadi.SX, casadi.MX or float
            Length of the hold [s].

        Returns
        -------
        applied : (n, 1) casadi.SX or MX
            Applied motor torques [N m].
        flags : list of casadi.SX or MX
            1 where a wheel was clipped, and where a wheel is at its torque limit.
        """
        g = u * ca.DM(self.working.astype(float))
        g_max, h_max = casadi_number(self.max_torque), casadi_number(self.max_momentum)
        low = ca.fmax(-g_max, (-h_max - state) / dt)
        high = ca.fmax(ca.fmin(g_max, (h_max - state) / dt), low)
        applied = ca.fmin(ca.fmax(g, low), high)
        return applied, [ca.fabs(applied - g) > 1e-12 * ca.fmax(1.0, ca.fabs(g)),
                         ca.fabs(applied) >= g_max * (1 - 1e-12)]

    def body_torque_box(self) -> Array | None:
        """The largest per-axis box every corner of which the working wheels realise through
        ``g = −A⁺ τ`` within their torque limits (see :meth:`Spacecraft.body_torque_limit`).

        Returns
        -------
        (3,) ndarray or None
            Bound [N m], body axes, 0 on axes the wheels cannot reach; ``None`` when every wheel
            failed.
        """
        return _wheel_box(self) if np.any(self.working) else None


SATURATION_MODES = ("per_axis", "scale")


@actuator_kind
@dataclass(frozen=True, init=False)
class Magnetorquers(_BodyAxisVector):
    """Three orthogonal magnetorquers along the body axes; the dipole ``m`` [A m^2], body frame,
    gives the torque ``m × B`` with ``B`` the geomagnetic field in body axes. Control block
    ``"dipole"``.

    Parameters
    ----------
    max_dipole : float or (3,) array_like, optional
        Dipole limit per body axis [A m^2], positive; stored as a (3,) array. ``None`` (default):
        unlimited (``inf``).
    saturation : {"per_axis", "scale"}, optional
        ``"per_axis"`` (default) clips each axis to its limit (the direction may change);
        ``"scale"`` scales the whole dipole vector down until every axis is within its limit
        (the direction is kept).

    Raises
    ------
    ModelError
        For a non-positive or mis-sized limit or an unknown saturation mode.
    """

    name: ClassVar[str] = "magnetorquers"
    block: ClassVar[str] = "dipole"
    command: ClassVar[str] = "dipole"
    needs_field: ClassVar[bool] = True
    residual_rank: ClassVar[int | None] = 1

    max_dipole: Array
    saturation: str

    def __init__(self, max_dipole: ArrayLike | None = None, saturation: str = "per_axis") -> None:
        object.__setattr__(self, "max_dipole", max_dipole)
        object.__setattr__(self, "saturation", saturation)
        self.__post_init__()

    def __post_init__(self) -> None:
        object.__setattr__(self, "max_dipole", _limit_vector(self.max_dipole, 3, "max_dipole"))
        if self.saturation not in SATURATION_MODES:
            raise ModelError("saturation", f"expected one of {SATURATION_MODES}, got {str(self.saturation)[:40]!r}")

    @property
    def _axis_limit(self) -> Array:
        return self.max_dipole

    @property
    def _scaled(self) -> bool:
        return self.saturation == "scale"

    def body_torque(self, u: Expr, state: Expr, field_body: Expr | None) -> Expr | None:
        """``m × B`` [N m], body axes; ``None`` without a field.

        Parameters
        ----------
        u : (3, 1) casadi.SX or MX
            Dipole ``m`` [A m^2], body axes.
        state : casadi.SX or MX
            Empty.
        field_body : (3, 1) casadi.SX or MX, or None
            Geomagnetic field ``B`` [T], body axes.

        Returns
        -------
        (3, 1) casadi.SX or MX, or None
        """
        return None if field_body is None else ca.cross(u, field_body)

    def take_residual(self, residual: Sequence[float], field_body: Sequence[float] | None) -> list[float] | None:
        """``m = B × τ / |B|²``: the part of ``τ`` perpendicular to ``B`` (none without a field).

        Parameters
        ----------
        residual : sequence of 3 float
            Body torque [N m], body axes.
        field_body : sequence of 3 float or None
            Measured field [T], body axes.

        Returns
        -------
        list of 3 float or None
            Dipole [A m^2], body axes; ``None`` without a field.
        """
        if field_body is None:
            return None
        r0, r1, r2 = residual
        b0, b1, b2 = field_body
        b2_norm = max(b0 * b0 + b1 * b1 + b2 * b2, 1e-30)
        return [(b1 * r2 - b2 * r1) / b2_norm, (b2 * r0 - b0 * r2) / b2_norm, (b0 * r1 - b1 * r0) / b2_norm]

    def take_residual_symbolic(self, residual: Expr, field_body: Expr) -> Expr:
        """:meth:`take_residual` on CasADi expressions (a zero field gives a zero dipole).

        Parameters
        ----------
        residual : (3, 1) casadi.SX
            Body torque [N m], body axes.
        field_body : (3, 1) casadi.SX
            Measured field [T], body axes.

        Returns
        -------
        (3, 1) casadi.SX
            Dipole [A m^2], body axes.
        """
        return ca.cross(field_body, residual) / ca.fmax(ca.dot(field_body, field_body), 1e-30)


@actuator_kind
@dataclass(frozen=True, init=False)
class Torquers(_BodyAxisVector):
    """Ideal body-axis torquers (e.g. thrusters): the commanded torque acts on the body directly,
    with no stored momentum. Control block ``"torquers"``.

    Parameters
    ----------
    max_torque : float or (3,) array_like, optional
        Torque limit per body axis [N m], positive; stored as a (3,) array. ``None`` (default):
        unlimited (``inf``).

    Raises
    ------
    ModelError
        For a non-positive or mis-sized limit.
    """

    name: ClassVar[str] = "torquers"
    block: ClassVar[str] = "torquers"
    command: ClassVar[str] = "torque"
    residual_rank: ClassVar[int | None] = 0

    max_torque: Array

    def __init__(self, max_torque: ArrayLike | None = None) -> None:
        object.__setattr__(self, "max_torque", max_torque)
        self.__post_init__()

    def __post_init__(self) -> None:
        object.__setattr__(self, "max_torque", _limit_vector(self.max_torque, 3, "max_torque"))

    @property
    def _axis_limit(self) -> Array:
        return self.max_torque

    def body_torque(self, u: Expr, state: Expr, field_body: Expr | None) -> Expr:
        """The commanded torque itself [N m], body axes.

        Parameters
        ----------
        u : (3, 1) casadi.SX or MX
            Torque [N m], body axes.
        state : casadi.SX or MX
            Empty.
        field_body : casadi.SX, MX or None
            Not used.

        Returns
        -------
        (3, 1) casadi.SX or MX
        """
        return u

    def body_torque_box(self) -> Array:
        """``max_torque`` [N m] on each body axis.

        Returns
        -------
        (3,) ndarray
        """
        return self.max_torque

    def take_residual(self, residual: Sequence[float], field_body: Sequence[float] | None) -> list[float]:
        """The residual torque itself.

        Parameters
        ----------
        residual : sequence of 3 float
            Body torque [N m], body axes.
        field_body : sequence of 3 float or None
            Not used.

        Returns
        -------
        list of 3 float
            Torque [N m], body axes.
        """
        return list(residual)

    def take_residual_symbolic(self, residual: Expr, field_body: Expr) -> Expr:
        """The residual torque itself.

        Parameters
        ----------
        residual : (3, 1) casadi.SX
            Body torque [N m], body axes.
        field_body : (3, 1) casadi.SX
            Not used.

        Returns
        -------
        (3, 1) casadi.SX
        """
        return residual


def _wheel_box(wheels: ReactionWheels) -> Array:
    """Per-axis torque box [N m] of the working wheels (see :meth:`Spacecraft.body_torque_limit`)."""
    axes = wheels.axes[:, wheels.working]
    g_max = wheels.max_torque[wheels.working]
    if np.all(np.isinf(g_max)):
        return np.full(3, np.inf)
    pinv = np.linalg.pinv(axes)
    reachable = np.linalg.norm(axes @ pinv - np.eye(3), axis=0) < 1e-9
    finite = np.isfinite(g_max)
    demand = np.abs(pinv[finite]) * reachable
    significant = demand > 1e-12 * max(float(demand.max(initial=0.0)), 1e-300)
    if np.all(significant.sum(axis=1) <= 1):
        # Each wheel drives one body axis (e.g. wheels along the body axes): the programme
        # decouples and each axis gets the bound of its tightest wheel.
        ratios = np.where(significant, g_max[finite][:, None] / np.where(significant, demand, 1.0), np.inf)
        return np.where(reachable, ratios.min(axis=0, initial=np.inf), 0.0)
    from scipy.optimize import (
        linprog,  # lazily: scipy.optimize dominates the import of slewbench
    )

    # Lexicographic: first the largest bound common to every reachable axis, then the
    # largest sum with no axis below it, so that no axis is sacrificed for the others.
    n_reach = int(reachable.sum())
    common = linprog(
        c=[-1.0], A_ub=demand.sum(axis=1, keepdims=True), b_ub=g_max[finite], bounds=[(0, None)]
    ).x[0] if n_reach else 0.0
    result = linprog(
        c=-reachable.astype(float),
        A_ub=demand,
        b_ub=g_max[finite],
        bounds=[(common * (1 - 1e-9), None) if r else (0, 0) for r in reachable],
    )
    return np.where(reachable, result.x, 0.0)
