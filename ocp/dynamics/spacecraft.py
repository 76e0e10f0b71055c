"""Spacecraft rigid body and actuators: reaction wheels, magnetorquers, ideal torquers.

All quantities are SI and in body axes. Construction validates; a bad value raises
:class:`ModelError` whose ``field`` names the offending attribute so that callers (the YAML
loader) can point at the input that caused it.
"""
from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp.errors import ModelError

Array = NDArray[np.float64]


def _limit_vector(value: ArrayLike | None, size: int, field_name: str) -> Array:
    """Per-element positive limit; ``None`` means unlimited (inf)."""
    if value is None:
        return np.full(size, np.inf)
    array = np.broadcast_to(np.asarray(value, dtype=float), (size,)).copy() if np.ndim(value) == 0 \
        else np.asarray(value, dtype=float)
    if array.shape != (size,):
        raise ModelError(field_name, f"expected a scalar or {size} values, got shape {array.shape}")
    if np.any(~(array > 0)):
        raise ModelError(field_name, f"limits must be positive, got {array.tolist()}")
    return array


@dataclass(frozen=True, init=False)
class ReactionWheels:
    """Array of ``n`` reaction wheels; wheel ``i`` stores spin momentum ``h_i`` about its axis and
    its motor torque ``g_i = ḣ_i`` reacts on the body as ``−a_i g_i``.

    The attributes hold the normalised values: ``axes`` unit columns, the limits as (n,) arrays
    (``inf`` where unlimited).

    Parameters
    ----------
    axes : (3, n) array_like
        Spin axes, body frame, one column per wheel; normalised on construction.
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
        axes = np.asarray(self.axes, dtype=float)
        if axes.ndim != 2 or axes.shape[0] != 3 or axes.shape[1] < 1:
            raise ModelError("axes", f"expected a 3 x n matrix of wheel axes, got shape {axes.shape}")
        norms = np.linalg.norm(axes, axis=0)
        if np.any(norms < 1e-9):
            raise ModelError("axes", "a wheel axis is the zero vector")
        n = axes.shape[1]
        object.__setattr__(self, "axes", axes / norms)
        object.__setattr__(self, "max_torque", _limit_vector(self.max_torque, n, "max_torque"))
        object.__setattr__(self, "max_momentum", _limit_vector(self.max_momentum, n, "max_momentum"))
        if self.spin_inertia is not None:
            object.__setattr__(self, "spin_inertia", _limit_vector(self.spin_inertia, n, "spin_inertia"))
        failed = tuple(int(i) for i in self.failed)
        if any(i < 0 or i >= n for i in failed):
            raise ModelError("failed", f"failed wheel indices must be in 0..{n - 1}, got {list(failed)}")
        if len(set(failed)) != len(failed):
            raise ModelError("failed", f"each failed wheel is listed once, got {list(failed)}")
        object.__setattr__(self, "failed", failed)

    @classmethod
    def from_body_axes(cls, n_axes: int = 3, **limits: Any) -> "ReactionWheels":
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
        """
        return cls(axes=np.eye(3)[:, :n_axes], **limits)

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


SATURATION_MODES = ("per_axis", "scale")


@dataclass(frozen=True, init=False)
class Magnetorquers:
    """Three orthogonal magnetorquers along the body axes; the dipole ``m`` [A m^2], body frame,
    gives the torque ``m × B`` with ``B`` the geomagnetic field in body axes.

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


@dataclass(frozen=True, init=False)
class Torquers:
    """Ideal body-axis torquers (e.g. thrusters): the commanded torque acts on the body directly,
    with no stored momentum.

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

    max_torque: Array

    def __init__(self, max_torque: ArrayLike | None = None) -> None:
        object.__setattr__(self, "max_torque", max_torque)
        self.__post_init__()

    def __post_init__(self) -> None:
        object.__setattr__(self, "max_torque", _limit_vector(self.max_torque, 3, "max_torque"))


@dataclass(frozen=True, init=False)
class Spacecraft:
    """Rigid spacecraft with its actuators. ``inertia`` holds the (3, 3) matrix after construction.

    Parameters
    ----------
    inertia : (3,) or (3, 3) array_like
        Principal moments, or the full inertia matrix, about the centre of mass [kg m^2], body
        frame. It must be symmetric positive definite and its principal moments must satisfy the
        triangle inequalities (``I_i + I_j >= I_k``).
    wheels : ReactionWheels or None, optional
        Reaction wheels (default none).
    magnetorquers : Magnetorquers or None, optional
        Magnetorquers (default none); they need a magnetic field in the environment to act.
    torquers : Torquers or None, optional
        Ideal body-axis torquers (default none).

    Raises
    ------
    ModelError
        For an actuator of the wrong type or an inertia that is not a valid rigid body's.
    """

    inertia: Array
    wheels: ReactionWheels | None
    magnetorquers: Magnetorquers | None
    torquers: Torquers | None
    _cache: dict[str, Any] = field(default_factory=dict, init=False, repr=False, compare=False)

    def __init__(self, inertia: ArrayLike, wheels: ReactionWheels | None = None,
                 magnetorquers: Magnetorquers | None = None, torquers: Torquers | None = None) -> None:
        for name, value in (("inertia", inertia), ("wheels", wheels), ("magnetorquers", magnetorquers),
                            ("torquers", torquers), ("_cache", {})):
            object.__setattr__(self, name, value)
        self.__post_init__()

    def __post_init__(self) -> None:
        for name, kind in (("wheels", ReactionWheels), ("magnetorquers", Magnetorquers), ("torquers", Torquers)):
            value = getattr(self, name)
            if value is not None and not isinstance(value, kind):
                raise ModelError(name, f"expected an ocp.{kind.__name__} or None, got {type(value).__name__}")
        try:
            inertia = np.asarray(self.inertia, dtype=float)
        except (TypeError, ValueError):
            raise ModelError("inertia", "expected 3 principal moments or a 3x3 matrix of numbers") from None
        if inertia.shape == (3,):
            inertia = np.diag(inertia)
        if inertia.shape != (3, 3) or not np.all(np.isfinite(inertia)):
            raise ModelError("inertia", f"expected 3 principal moments or a 3x3 matrix, got shape {inertia.shape}")
        scale = np.max(np.abs(inertia))
        if scale == 0 or np.max(np.abs(inertia - inertia.T)) > 1e-9 * scale:
            raise ModelError("inertia", "the inertia matrix must be symmetric and non-zero")
        moments = np.linalg.eigvalsh(inertia)
        if moments[0] <= 0:
            raise ModelError("inertia", f"the inertia matrix must be positive definite (eigenvalues {moments.tolist()})")
        if moments[0] + moments[1] < moments[2] * (1 - 1e-12):
            raise ModelError(
                "inertia",
                f"principal moments {moments.tolist()} violate the triangle inequality I1 + I2 >= I3",
            )
        object.__setattr__(self, "inertia", inertia)

    @property
    def n_wheels(self) -> int:
        """Number of wheels, failed ones included (0 without wheels)."""
        return 0 if self.wheels is None else self.wheels.count

    @property
    def wheel_axes(self) -> Array:
        """(3, n_w) unit wheel spin axes, body frame, the matrix ``A`` of the dynamics; (3, 0)
        without wheels."""
        return np.zeros((3, 0)) if self.wheels is None else self.wheels.axes

    @property
    def is_principal(self) -> bool:
        """True when the body axes are principal axes (diagonal inertia)."""
        return bool(np.allclose(self.inertia, np.diag(np.diag(self.inertia)), rtol=0, atol=1e-12 * np.max(self.inertia)))

    def body_torque_limit(self) -> Array:
        """Per-body-axis torque bound that the actuators can apply simultaneously on all axes.

        Torquers add their per-axis limit. For wheels the box ``|τ_i| <= b_i`` is the largest
        (smallest bound, then by sum) box whose every corner the working wheels realise through ``g = -A⁺ τ`` within
        their torque limits, found by a small linear programme; axes the wheels cannot reach get 0.
        Magnetorquers are not included: their torque depends on the field.

        Returns
        -------
        (3,) ndarray
            Bound ``b`` [N m], body axes; ``inf`` on an axis whose actuators are unlimited. A copy
            (computed once per spacecraft).
        """
        if "torque_limit" not in self._cache:
            limit = np.zeros(3)
            if self.torquers is not None:
                limit += self.torquers.max_torque
            if self.wheels is not None and np.any(self.wheels.working):
                limit += _wheel_box(self.wheels)
            self._cache["torque_limit"] = limit
        return self._cache["torque_limit"].copy()


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
