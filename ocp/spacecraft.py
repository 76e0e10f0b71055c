"""Spacecraft rigid body and actuators: reaction wheels, magnetorquers, ideal torquers.

All quantities are SI and in body axes. Construction validates; a bad value raises
:class:`ModelError` whose ``field`` names the offending attribute so that callers (the YAML
loader) can point at the input that caused it.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

Array = NDArray[np.float64]


class ModelError(ValueError):
    """Invalid model parameter; ``field`` names the attribute (e.g. ``"inertia"``)."""

    def __init__(self, field_name: str, message: str):
        super().__init__(f"{field_name}: {message}")
        self.field = field_name
        self.message = message


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


@dataclass(frozen=True)
class ReactionWheels:
    """Array of ``n`` reaction wheels.

    Parameters
    ----------
    axes : (3, n) array
        Unit spin axes in body axes (normalised on construction).
    max_torque : scalar or (n,), N m
        Motor torque limit per wheel (``None``: unlimited).
    max_momentum : scalar or (n,), N m s
        Wheel momentum limit per wheel (``None``: unlimited).
    spin_inertia : scalar or (n,), kg m², optional
        Wheel spin inertia, only used to report wheel speeds.
    failed : tuple of int
        Indices of failed wheels; they produce no torque.
    """

    axes: Array
    max_torque: Array | float | None = None
    max_momentum: Array | float | None = None
    spin_inertia: Array | float | None = None
    failed: tuple[int, ...] = ()

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
    def from_body_axes(cls, n_axes: int = 3, **limits) -> "ReactionWheels":
        """Wheels along the first ``n_axes`` body axes."""
        return cls(axes=np.eye(3)[:, :n_axes], **limits)

    @property
    def count(self) -> int:
        """Number of wheels, failed ones included."""
        return self.axes.shape[1]

    @property
    def working(self) -> Array:
        """Boolean mask of working wheels."""
        mask = np.ones(self.count, dtype=bool)
        mask[list(self.failed)] = False
        return mask


SATURATION_MODES = ("per_axis", "scale")


@dataclass(frozen=True)
class Magnetorquers:
    """Three orthogonal magnetorquers along the body axes; dipole limit per axis in A m².

    ``saturation``: ``"per_axis"`` clips each axis to its limit (the direction may change);
    ``"scale"`` scales the whole dipole vector down until every axis is within its limit (the
    direction is kept).
    """

    max_dipole: Array | float | None = None
    saturation: str = "per_axis"

    def __post_init__(self) -> None:
        object.__setattr__(self, "max_dipole", _limit_vector(self.max_dipole, 3, "max_dipole"))
        if self.saturation not in SATURATION_MODES:
            raise ModelError("saturation", f"expected one of {SATURATION_MODES}, got {str(self.saturation)[:40]!r}")


@dataclass(frozen=True)
class Torquers:
    """Ideal body-axis torquers (thrusters); torque limit per axis in N m, no stored momentum."""

    max_torque: Array | float | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "max_torque", _limit_vector(self.max_torque, 3, "max_torque"))


@dataclass(frozen=True)
class Spacecraft:
    """Rigid spacecraft with its actuators.

    Parameters
    ----------
    inertia : (3,) or (3, 3), kg m²
        Principal moments or the full inertia matrix about the centre of mass, body axes.
        It must be symmetric positive definite and its principal moments must satisfy the
        triangle inequalities (``I_i + I_j >= I_k``).
    wheels, magnetorquers, torquers : optional actuators.
    """

    inertia: Array
    wheels: ReactionWheels | None = None
    magnetorquers: Magnetorquers | None = None
    torquers: Torquers | None = None
    _cache: dict = field(default_factory=dict, init=False, repr=False, compare=False)

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
        return 0 if self.wheels is None else self.wheels.count

    @property
    def wheel_axes(self) -> Array:
        """(3, n_w) wheel axes; (3, 0) without wheels."""
        return np.zeros((3, 0)) if self.wheels is None else self.wheels.axes

    @property
    def is_principal(self) -> bool:
        """True when the body axes are principal axes (diagonal inertia)."""
        return bool(np.allclose(self.inertia, np.diag(np.diag(self.inertia)), rtol=0, atol=1e-12 * np.max(self.inertia)))

    def body_torque_limit(self) -> Array:
        """Per-body-axis torque bound (N m) that the actuators can apply simultaneously on all axes.

        Torquers add their per-axis limit. For wheels the box ``|τ_i| <= b_i`` is the largest
        (smallest bound, then by sum) box whose every corner the working wheels realise through ``g = -A⁺ τ`` within
        their torque limits, found by a small linear programme; axes the wheels cannot reach get 0.
        Magnetorquers are not included: their torque depends on the field.
        """
        if "torque_limit" not in self._cache:
            limit = np.zeros(3)
            if self.torquers is not None:
                limit += self.torquers.max_torque
            if self.wheels is not None and np.any(self.wheels.working):
                limit += self._wheel_box()
            self._cache["torque_limit"] = limit
        return self._cache["torque_limit"].copy()

    def _wheel_box(self) -> Array:
        axes = self.wheels.axes[:, self.wheels.working]
        g_max = self.wheels.max_torque[self.wheels.working]
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
        from scipy.optimize import linprog  # lazily: scipy.optimize dominates the import of slewbench

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
