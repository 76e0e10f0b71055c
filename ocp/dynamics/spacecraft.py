"""The spacecraft: a rigid body with its actuators (:mod:`ocp.dynamics.actuator_kinds`).

All quantities are SI and in body axes. Construction validates; a bad value raises
:class:`~ocp.errors.ModelError` whose ``field`` names the offending attribute so that callers (the
YAML loader) can point at the input that caused it.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp.dynamics.actuator_kinds import (
    ACTUATOR_KINDS,
    Actuator,
    Magnetorquers,
    ReactionWheels,
    Torquers,
)
from ocp.errors import ModelError
from ocp.options import real_array

__all__ = ["MAX_INERTIA", "MIN_INERTIA", "Spacecraft"]

MAX_INERTIA = 1.0e12
"""Largest entry [kg m²] of a spacecraft's inertia (the library's and ``spacecraft.inertia``'s
bound): ten thousand times the International Space Station's (about 1e8 kg m²). Far beyond it the
planners' arithmetic overflows (1e300 printed NumPy's overflow warning and a bound of 150 digits);
an inertia merely too large for its torque (g mm² written as kg m², 1e9 too large) warns (``slew_time``)."""

MIN_INERTIA = 1.0e-9
"""Least principal moment [kg m²] of a spacecraft (the library's and ``spacecraft.inertia``'s bound):
a gram at a millimetre, a hundred times below the smallest spacecraft flown (chip-sats of a few grams
over a few centimetres, about 1e-7 kg m²). Far below it a run hung (1e-250 kg m²: the torque-free
coast after a bang-coast-bang slew never ended); one of 0 or below is not positive definite."""

Array = NDArray[np.float64]
_Instance = TypeVar("_Instance", bound=Actuator)


@dataclass(frozen=True, init=False)
class Spacecraft:
    """Rigid spacecraft with its actuators. ``inertia`` holds the (3, 3) matrix after construction:
    a read-only copy of the given array (a later change to the caller's array does not reach the
    spacecraft; build a new spacecraft for another inertia).

    Parameters
    ----------
    inertia : (3,) or (3, 3) array_like
        Principal moments, or the full inertia matrix, about the centre of mass [kg m^2], body
        frame. It must be symmetric positive definite, its entries within :data:`MAX_INERTIA`
        (1e12 kg m^2), its least principal moment at least :data:`MIN_INERTIA` (1e-9 kg m^2), and its principal moments must satisfy the triangle
        inequalities (``I_i + I_j >= I_k``).
    wheels : ReactionWheels or None, optional
        Reaction wheels (default none).
    magnetorquers : Magnetorquers or None, optional
        Magnetorquers (default none); they need a magnetic field in the environment to act.
    torquers : Torquers or None, optional
        Ideal body-axis torquers (default none).
    **actuators : Actuator or None
        Actuators of the other registered kinds (:data:`ACTUATOR_KINDS`), each given by its
        kind's :attr:`Actuator.name`.

    Attributes
    ----------
    actuators : tuple of Actuator
        The actuators present, in the order of their kinds' registration (the order of their
        blocks in ``u`` and ``x``).

    Raises
    ------
    ModelError
        For an unknown actuator kind, an actuator of the wrong type or an inertia that is not a
        valid rigid body's, or not real numbers (booleans, complex numbers, text and dates are
        refused, not converted). :class:`~ocp.errors.ModelError` is a ``ValueError``.
    """

    inertia: Array
    actuators: tuple[Actuator, ...]
    _cache: dict[str, Any] = field(default_factory=dict, init=False, repr=False, compare=False)

    def __init__(self, inertia: ArrayLike, wheels: ReactionWheels | None = None,
                 magnetorquers: Magnetorquers | None = None, torquers: Torquers | None = None,
                 **actuators: Actuator | None) -> None:
        given = {"wheels": wheels, "magnetorquers": magnetorquers, "torquers": torquers, **actuators}
        for name, value in given.items():
            kind = ACTUATOR_KINDS.get(name)
            if kind is None:
                raise ModelError(name, f"not a registered actuator kind; expected one of {list(ACTUATOR_KINDS)}")
            if value is not None and not isinstance(value, kind):
                raise ModelError(name, f"expected an {kind.__module__.split('.')[0]}.{kind.__name__} or None, "
                                       f"got {type(value).__name__}")
        present = tuple(given[name] for name in ACTUATOR_KINDS if given.get(name) is not None)
        object.__setattr__(self, "inertia", inertia)
        object.__setattr__(self, "actuators", present)
        object.__setattr__(self, "_cache", {})
        self.__post_init__()

    def __post_init__(self) -> None:
        inertia = _real_array(self.inertia)  # a private copy: the caller's array is not kept
        if inertia.shape == (3,):
            inertia = np.diag(inertia)
        if inertia.shape != (3, 3):
            raise ModelError("inertia", f"expected 3 principal moments or a 3x3 matrix, got shape {inertia.shape}")
        if not np.all(np.isfinite(inertia)):
            raise ModelError("inertia", f"the inertia must be finite, got {inertia.tolist()}")
        scale = np.max(np.abs(inertia))
        if scale > MAX_INERTIA:
            raise ModelError("inertia", f"expected entries within ±{MAX_INERTIA:g} kg m^2 (MAX_INERTIA, ten thousand "
                                        f"times the International Space Station's), got {inertia.tolist()!r:.200}")
        if scale == 0:
            raise ModelError("inertia", f"the inertia matrix must be non-zero, got {inertia.tolist()}")
        mismatch = np.abs(inertia - inertia.T)
        if np.max(mismatch) > 1e-9 * scale:
            i, j = sorted(np.unravel_index(int(np.argmax(mismatch)), mismatch.shape))
            raise ModelError(
                "inertia",
                f"the inertia matrix must be symmetric, got [{i}][{j}] = {inertia[i, j]:g} but [{j}][{i}] = "
                f"{inertia[j, i]:g} in {inertia.tolist()}; a product of inertia appears twice with the same "
                "value and sign",
            )
        moments = np.linalg.eigvalsh(inertia)
        if moments[0] <= 0:
            raise ModelError("inertia", f"the inertia matrix must be positive definite (eigenvalues {moments.tolist()})")
        if moments[0] < MIN_INERTIA:
            raise ModelError("inertia", f"the least principal moment must be at least {MIN_INERTIA:g} kg m^2 (MIN_INERTIA, "
                                        f"a gram at a millimetre), got {moments[0]:.6g} (principal moments "
                                        f"{[float(f'{m:.6g}') for m in moments]})")
        if moments[0] + moments[1] < moments[2] * (1 - 1e-12):
            raise ModelError(
                "inertia",
                f"principal moments {moments.tolist()} violate the triangle inequality I1 + I2 >= I3",
            )
        inertia.setflags(write=False)  # read-only: an edit in place would bypass these checks
        object.__setattr__(self, "inertia", inertia)

    def actuator(self, name: str) -> Actuator | None:
        """The actuator of a kind.

        Parameters
        ----------
        name : str
            The kind's :attr:`Actuator.name` (``"wheels"``, ``"magnetorquers"``, ...).

        Returns
        -------
        Actuator or None
            The spacecraft's actuator of that kind; ``None`` when it has none.
        """
        for actuator in self.actuators:
            if actuator.name == name:
                return actuator
        return None

    @property
    def wheels(self) -> ReactionWheels | None:
        """The reaction wheels, or ``None``."""
        return self._kind(ReactionWheels)

    @property
    def magnetorquers(self) -> Magnetorquers | None:
        """The magnetorquers, or ``None``."""
        return self._kind(Magnetorquers)

    @property
    def torquers(self) -> Torquers | None:
        """The ideal torquers, or ``None``."""
        return self._kind(Torquers)

    def _kind(self, kind: type[_Instance]) -> _Instance | None:
        for actuator in self.actuators:
            if type(actuator) is kind:
                return actuator
        return None

    @property
    def n_wheels(self) -> int:
        """Number of wheels, failed ones included (0 without wheels)."""
        wheels = self.wheels
        return 0 if wheels is None else wheels.count

    @property
    def wheel_axes(self) -> Array:
        """(3, n_w) unit wheel spin axes, body frame, the matrix ``A`` of the dynamics; (3, 0)
        without wheels."""
        wheels = self.wheels
        return np.zeros((3, 0)) if wheels is None else wheels.axes

    @property
    def is_principal(self) -> bool:
        """True when the body axes are principal axes (diagonal inertia)."""
        return bool(np.allclose(self.inertia, np.diag(np.diag(self.inertia)), rtol=0, atol=1e-12 * np.max(self.inertia)))

    @property
    def residual_actuator(self) -> Actuator | None:
        """The actuator the allocation sends what the working wheels cannot give (all of the torque
        without working wheels): the one whose kind has the lowest
        :attr:`~ocp.dynamics.actuator_kinds.Actuator.residual_rank` (the torquers, else the
        magnetorquers; on equal ranks the first in :attr:`actuators`), or ``None`` when no kind
        has a rank.

        This is the one statement of the rule: the controllers' allocation
        (``controllers.allocation``), the collocation planner's allocation constraints
        (``planners.collocation.allocation``) and :meth:`allocation_rows` read it here.

        Returns
        -------
        Actuator or None
        """
        ranked = [(actuator.residual_rank, index) for index, actuator in enumerate(self.actuators)
                  if actuator.residual_rank is not None]
        return self.actuators[min(ranked)[1]] if ranked else None

    def wheel_span(self) -> Array:
        """An orthonormal basis of the body torques the working wheels give (the range of their
        axes; singular values below ``1e-9`` of the largest count as zero).

        Returns
        -------
        (3, r) ndarray
            ``r`` columns, body axes: 3 when the working wheels span three axes, 0 without
            working wheels. The projector ``A A⁺`` of the allocation is ``S Sᵀ``; what the wheels
            leave to :attr:`residual_actuator` is ``(1 − S Sᵀ) τ``. A copy.
        """
        if "wheel_span" not in self._cache:
            wheels = self.wheels
            span = np.zeros((3, 0))
            if wheels is not None and np.any(wheels.working):
                left, singular, _ = np.linalg.svd(wheels.axes[:, wheels.working])
                span = left[:, :int(np.sum(singular > 1e-9 * singular.max()))]
            self._cache["wheel_span"] = span
        return self._cache["wheel_span"].copy()

    def body_torque_limit(self) -> Array:
        """Per-body-axis torque bound that the controllers' allocation gives simultaneously on all
        axes: the largest box ``|τ_i| <= b_i`` every corner of which it realises.

        The box lies inside the set the allocation realises, ``|M τ| <= L``
        (:meth:`allocation_rows`): the largest common bound first, then, no axis below it, the
        largest sum (a small linear programme; per row when each row bounds one axis, as with
        wheels along the body axes or torquers alone). An axis that a row with the limit 0 touches
        (a direction no actuator gives: failed or missing wheels without torquers, magnetorquers,
        whose torque depends on the field) gets 0; an axis no finite limit bounds, ``inf``.
        Torquers beside wheels that span three axes add nothing: the allocation never asks them.

        The box is conservative where the realised set is no box (a skewed wheel array, such as a
        four-wheel pyramid: along a single body axis the wheels give more,
        :meth:`torque_along`); :meth:`torque_box_is_exact` tells which.

        Returns
        -------
        (3,) ndarray
            Bound ``b`` [N m], body axes; ``inf`` on an axis whose actuators are unlimited. A copy
            (computed once per spacecraft).
        """
        if "torque_limit" not in self._cache:
            self._cache["torque_limit"] = _largest_box(*self.allocation_rows())
        return self._cache["torque_limit"].copy()

    def torque_box_is_exact(self) -> bool:
        """Whether :meth:`body_torque_limit` is the whole set the allocation realises (each row of
        :meth:`allocation_rows` bounds one body axis), rather than a box inside it.

        Returns
        -------
        bool
            ``True``: a torque is realised exactly when each component is within the box (wheels
            along the body axes, torquers); ``False``: the box is conservative.
        """
        matrix, _ = self.allocation_rows()
        return bool(np.all(np.sum(_significant(matrix), axis=1) <= 1))

    def allocation_rows(self) -> tuple[Array, Array]:
        """The body torques the controllers' allocation realises within the actuators' limits, as
        ``|M τ| <= L`` row by row.

        The allocation (``controllers.allocation``) gives the working wheels ``g = −A⁺ τ`` (``A⁺``
        the pseudo-inverse of the working wheels' axes): a row ``(A⁺)_i`` with the limit
        ``g_max,i`` per working wheel. What the wheels cannot give, ``(1 − A A⁺) τ`` (none when the
        working wheels span three axes), goes to the actuator kind of lowest
        :attr:`~ocp.dynamics.actuator_kinds.Actuator.residual_rank` (torquers, else magnetorquers;
        all of ``τ`` without wheels): rows of that projector with the kind's per-axis
        :meth:`~ocp.dynamics.actuator_kinds.Actuator.body_torque_box` as limits (torquers: their
        ``max_torque``). A direction no actuator realises (failed or missing wheels without
        torquers; magnetorquers, whose torque depends on the field and are counted as giving none,
        as in :meth:`body_torque_limit`) gets rows with the limit 0.

        Unlike :meth:`body_torque_limit` (the sum of each actuator's per-axis box: conservative for
        a skewed wheel array such as a four-wheel pyramid, and optimistic with torquers beside
        wheels that span three axes, which the allocation never asks), these rows describe the
        realised set exactly; with wheels along the three body axes and nothing else the two agree
        (``M`` the identity, ``L`` the wheels' limits).

        Returns
        -------
        M : (m, 3) ndarray
            Rows, body axes.
        L : (m,) ndarray
            Their limits [N m], ``inf`` for an unlimited actuator, 0 for a direction no actuator
            gives. Copies (computed once per spacecraft).
        """
        if "allocation_rows" not in self._cache:
            rows, limits = [], []
            wheels = self.wheels
            if wheels is not None and np.any(wheels.working):
                rows.append(wheels.pseudo_inverse[wheels.working])  # as the allocation
                limits.append(wheels.max_torque[wheels.working])
            span = self.wheel_span()
            if span.shape[1] < 3:
                residual = np.eye(3) - span @ span.T  # what the working wheels do not give: 1 − A A⁺
                residual[np.abs(residual) <= 1e-12] = 0.0  # rounding of exact zeros (entries within ±1)
                sink = self.residual_actuator
                box = None if sink is None else sink.body_torque_box()
                rows.append(residual)
                limits.append(np.zeros(3) if box is None else np.asarray(box, dtype=float))
            self._cache["allocation_rows"] = (np.vstack(rows) if rows else np.zeros((0, 3)),
                                              np.concatenate(limits) if limits else np.zeros(0))
        matrix, bound = self._cache["allocation_rows"]
        return matrix.copy(), bound.copy()

    def torque_along(self, direction: ArrayLike) -> float:
        """The largest body torque along a direction that the actuators give through the
        controllers' allocation within their limits (:meth:`allocation_rows`).

        Parameters
        ----------
        direction : (3,) array_like
            A non-zero direction, body axes (normalised here).

        Returns
        -------
        float
            ``s`` [N m]: ``s d̂`` is realised, any larger multiple is not (``min_j L_j / |M_j d̂|``;
            a four-wheel pyramid: ``min_i g_max,i / |(A⁺ d̂)_i|``); 0 when an actuator that the
            direction needs gives nothing, ``inf`` when every actuator it needs is unlimited.

        Raises
        ------
        ValueError
            For a zero or non-finite direction.
        """
        d = np.asarray(direction, dtype=float).reshape(3)
        norm = float(np.linalg.norm(d))
        if not (np.isfinite(norm) and norm > 0):
            raise ValueError(f"direction must be a finite non-zero 3-vector, got {d.tolist()}")
        matrix, bound = self.allocation_rows()
        demand = np.abs(matrix @ (d / norm))
        demand[demand <= 1e-12 * np.linalg.norm(matrix, axis=1)] = 0.0  # rounding of exact zeros
        used = demand > 0
        return float(np.min(bound[used] / demand[used], initial=np.inf))


def _real_array(value: Any) -> Array:
    """``value`` (the inertia as given) as a new float array (:func:`~ocp.options.real_array`), or a
    :class:`~ocp.errors.ModelError` naming it when it holds anything but real numbers."""
    try:
        return real_array(value)
    except ValueError as reason:
        raise ModelError("inertia", f"expected 3 principal moments or a 3x3 matrix of numbers, got {value!r:.200}: "
                                    f"{reason} (moments of inertia are real, in kg m^2)") from None


def _significant(matrix: Array) -> NDArray[np.bool_]:
    """The entries of each row above rounding (``1e-12`` of the row's norm)."""
    magnitude = np.abs(matrix)
    return magnitude > 1e-12 * np.linalg.norm(matrix, axis=1, keepdims=True)


def _largest_box(matrix: Array, bound: Array) -> Array:
    """The largest box ``|τ_i| <= b_i`` within ``|M τ| <= L`` (see :meth:`Spacecraft.body_torque_limit`)."""
    demand = np.where(_significant(matrix), np.abs(matrix), 0.0)
    closed = np.any(demand[bound == 0] > 0, axis=0)  # touched by a direction no actuator gives
    finite = np.isfinite(bound) & (bound > 0)
    demand, limit = demand[finite][:, ~closed], bound[finite]
    box = np.zeros(3)
    free = np.flatnonzero(~closed)
    bounded = np.any(demand > 0, axis=0)
    box[free[~bounded]] = np.inf
    demand = demand[:, bounded]
    used = np.any(demand > 0, axis=1)
    demand, limit = demand[used], limit[used]
    if not demand.size:
        return box
    if np.all(np.sum(demand > 0, axis=1) == 1):  # each row bounds one axis: the tightest row per axis
        ratios = np.where(demand > 0, limit[:, None] / np.where(demand > 0, demand, 1.0), np.inf)
        box[free[bounded]] = ratios.min(axis=0)
        return box
    from scipy.optimize import (
        linprog,  # lazily: scipy.optimize dominates the import of slewbench
    )

    # Lexicographic: the largest bound common to every axis, then the largest sum with no axis
    # below it, so that no axis is sacrificed for the others.
    n = demand.shape[1]
    common = float(np.min(limit / demand.sum(axis=1)))  # every corner of this cube is within every row
    result = linprog(c=-np.ones(n), A_ub=demand, b_ub=limit, bounds=[(common * (1 - 1e-9), None)] * n)
    # the cube unless an axis really grows (not the rounding that the 1e-9 slack lets trade between axes)
    grows = result.success and float(result.x.sum()) > common * n * (1 + 1e-6)
    box[free[bounded]] = result.x if grows else common
    return box
