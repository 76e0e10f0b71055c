"""A scenario's requirements as objects: named sensors, pointing cones, the actuator margin, the
body-rate limit and the final error, declared once and applied to every row.

The schema (:mod:`scenarios.schema.requirements`) builds them from ``spacecraft.sensors`` and
``requirements``; :meth:`PointingRequirement.constraint` makes a pointing requirement concrete for
one run (an :class:`~ocp.geometry.pointing.PointingConstraint`, its direction tabulated along the
run by :func:`~ocp.geometry.directions.direction_table`), which the planners that honour pointing
impose and :mod:`scenarios.requirements.scoring` scores.

Units: SI inside (rad, rad/s, s); the schema converts ``angle_deg``.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp.geometry.directions import Geometry, direction_table
from ocp.geometry.pointing import PointingConstraint

__all__ = ["RESERVED_NAMES", "ActuatorRequirement", "Direction", "FinalRequirement", "PointingRequirement",
           "RateRequirement", "Requirements", "Sensor"]

Array = NDArray[np.float64]

RESERVED_NAMES = ("actuators", "rate", "final")
"""The names of the requirements that are not pointing requirements (a pointing requirement may not
take one: they name the result columns ``ref.req.<name>.<field>``)."""


def _unit(vector: ArrayLike, what: str) -> Array:
    array = np.asarray(vector, dtype=float).reshape(-1)
    norm = float(np.linalg.norm(array)) if array.shape == (3,) else 0.0
    if array.shape != (3,) or not np.all(np.isfinite(array)) or not norm > 1e-12:
        raise ValueError(f"{what} must be a non-zero finite 3-vector, got {array.tolist()}")
    return array / norm


@dataclass(frozen=True, eq=False)
class Sensor:
    """A named sensor (star tracker, camera, antenna, panel normal): its boresight in body axes.

    Parameters
    ----------
    name : str
        Its key under ``spacecraft.sensors``.
    boresight : (3,) array_like
        Boresight, body axes (normalised here; zero refused with a ``ValueError``).
    """

    name: str
    boresight: Array

    def __post_init__(self) -> None:
        object.__setattr__(self, "boresight", _unit(self.boresight, f"sensor {self.name}'s boresight"))


@dataclass(frozen=True, eq=False)
class Direction:
    """What a cone is measured from: a registered kind (:data:`~ocp.geometry.directions.DIRECTIONS`)
    or a fixed inertial vector.

    Parameters
    ----------
    kind : str or None
        A name of ``DIRECTIONS`` (``sun``, ``moon``, ``earth``, ``earth_limb``, ``velocity``);
        ``None`` for a fixed inertial vector.
    vector : (3,) array_like or None, optional
        The fixed direction, inertial frame (normalised here), when ``kind`` is ``None``.
    """

    kind: str | None
    vector: Array | None = None

    def __post_init__(self) -> None:
        if (self.kind is None) == (self.vector is None):
            raise ValueError("a direction is either a registered kind or an inertial vector")
        if self.vector is not None:
            object.__setattr__(self, "vector", _unit(self.vector, "an inertial direction"))

    def describe(self) -> str:
        """The direction in words (``sun``, ``inertial [0, 1, 0]``), for messages and plots.

        Returns
        -------
        str
        """
        if self.kind is not None:
            return self.kind
        assert self.vector is not None
        return "inertial [" + ", ".join(f"{v:.4g}" for v in self.vector) + "]"

    def table(self, geometry: Geometry, duration: float) -> tuple[Array, Array, Array]:
        """The direction tabulated over ``[0, duration]``.

        Parameters
        ----------
        geometry : Geometry
            The epoch and the orbit.
        duration : float
            Length of the run [s].

        Returns
        -------
        times : (n,) ndarray
            Times [s] (one row at 0 for a fixed direction).
        directions : (n, 3) ndarray
            Unit vectors, inertial frame.
        growth : (n,) ndarray
            Growth of the cone [rad].

        Raises
        ------
        ocp.ModelError
            Without the epoch or orbit the kind needs, or for a run that leaves the ephemeris.
        """
        if self.kind is not None:
            return direction_table(self.kind, geometry, duration)
        assert self.vector is not None
        return np.zeros(1), self.vector.reshape(1, 3), np.zeros(1)


@dataclass(frozen=True, eq=False)
class PointingRequirement:
    """A sensor's boresight kept out of (or inside) a cone about a direction, over a window.

    Parameters
    ----------
    name : str
        Its key under ``requirements.pointing`` (names the result columns).
    sensor : Sensor
        The sensor whose boresight it constrains.
    keep_out : bool
        ``True``: at least ``angle`` from the direction; ``False`` (keep-in): at most.
    angle : float
        Cone half-angle [rad], in (0, π).
    direction : Direction
        What the angle is measured from.
    window : (float, float or None), optional
        Start and end [s] of the time it applies; ``None`` end: to the end of the run (default
        ``(0, None)``).
    """

    name: str
    sensor: Sensor
    keep_out: bool
    angle: float
    direction: Direction
    window: tuple[float, float | None] = (0.0, None)

    def describe(self) -> str:
        """The requirement in words (``star_tracker keep-out 30 deg about sun``, its window when it
        is not the whole run), for messages and ``slewbench validate``.

        Returns
        -------
        str
        """
        words = self._cone()
        if self.window != (0.0, None):
            end = "the end" if self.window[1] is None else f"{self.window[1]:g} s"
            words += f" from {self.window[0]:g} s to {end}"
        return words

    def _cone(self) -> str:
        return (f"{self.sensor.name} {'keep-out' if self.keep_out else 'keep-in'} {np.rad2deg(self.angle):g} deg "
                f"about {self.direction.describe()}")

    def constraint(self, geometry: Geometry, duration: float) -> PointingConstraint:
        """This requirement made concrete for a run: its direction tabulated over ``[0, duration]``.

        Parameters
        ----------
        geometry : Geometry
            The epoch and the orbit.
        duration : float
            Length of the table [s] (the run's; after it the last direction is held).

        Returns
        -------
        ocp.geometry.PointingConstraint
            Named after the requirement, its window ending at ``inf`` for a ``None`` end.

        Raises
        ------
        ocp.ModelError
            Without the epoch or orbit the direction needs.
        """
        times, directions, growth = self.direction.table(geometry, duration)
        end = np.inf if self.window[1] is None else float(self.window[1])
        return PointingConstraint(self.name, self.sensor.boresight, self.keep_out, self.angle, times, directions,
                                  growth, (float(self.window[0]), end), description=self._cone())


@dataclass(frozen=True)
class ActuatorRequirement:
    """The reference may ask at most ``1 − margin`` of each actuator limit.

    Parameters
    ----------
    margin : float
        In [0, 1).
    stated : bool, optional
        Whether the scenario states it (``requirements.actuators``); ``False`` for the margin-0
        requirement every scenario carries, which a row's message does not mention unless broken.
    """

    margin: float
    stated: bool = field(default=True, compare=False)

    def __post_init__(self) -> None:
        if not (0.0 <= self.margin < 1.0):
            raise ValueError(f"the actuator margin must lie in [0, 1), got {self.margin!r}")

    @property
    def allowed(self) -> float:
        """The largest demand-to-limit ratio allowed, ``1 − margin``."""
        return 1.0 - self.margin

    def describe(self) -> str:
        """The requirement in words, for ``slewbench validate``.

        Returns
        -------
        str
        """
        return f"the reference's demand at most {100.0 * self.allowed:g} % of each actuator limit"


@dataclass(frozen=True)
class RateRequirement:
    """A bound on the body-rate norm ``‖ω‖``, reference and closed loop.

    Parameters
    ----------
    max_rate : float
        The bound [rad/s], positive.
    """

    max_rate: float

    def __post_init__(self) -> None:
        if not (np.isfinite(self.max_rate) and self.max_rate > 0.0):
            raise ValueError(f"the rate bound must be positive, got {self.max_rate!r}")

    def describe(self) -> str:
        """The requirement in words, for ``slewbench validate``.

        Returns
        -------
        str
        """
        return f"‖ω‖ at most {self.max_rate:g} rad/s (reference and closed loop)"


@dataclass(frozen=True)
class FinalRequirement:
    """Closed loop, from ``T + after_s`` to the end of the run: the error angle to the target and
    the rate error ``‖ω − ω_f‖`` within bounds.

    Parameters
    ----------
    after_s : float
        Time after the manoeuvre's end ``T`` from which it applies [s], non-negative.
    error_deg : float or None
        Bound on the error angle to the target attitude [deg]; ``None``: none.
    rate : float or None
        Bound on ``‖ω − ω_f‖`` [rad/s]; ``None``: none.
    """

    after_s: float
    error_deg: float | None = None
    rate: float | None = None

    def describe(self) -> str:
        """The requirement in words, for ``slewbench validate``.

        Returns
        -------
        str
        """
        bounds = ([] if self.error_deg is None else [f"error to the target at most {self.error_deg:g} deg"]) \
            + ([] if self.rate is None else [f"‖ω − ω_f‖ at most {self.rate:g} rad/s"])
        return (", ".join(bounds) or "no bound (scored, never broken)") \
            + f" in the closed loop from T + {self.after_s:g} s to the end of the run"


@dataclass(frozen=True)
class Requirements:
    """Every requirement of a scenario (all optional).

    Parameters
    ----------
    pointing : tuple of PointingRequirement, optional
        Keep-out and keep-in cones, in the order written.
    actuators : ActuatorRequirement or None, optional
        The reference's actuator demand.
    rate : RateRequirement or None, optional
        The body-rate limit.
    final : FinalRequirement or None, optional
        The final error and rate.
    """

    pointing: tuple[PointingRequirement, ...] = ()
    actuators: ActuatorRequirement | None = None
    rate: RateRequirement | None = None
    final: FinalRequirement | None = None
    _names: tuple[str, ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "pointing", tuple(self.pointing))
        names = [requirement.name for requirement in self.pointing]
        clashes = sorted({n for n in names if names.count(n) > 1 or n in RESERVED_NAMES})
        if clashes:
            raise ValueError(f"pointing requirement names must be distinct and none of {RESERVED_NAMES}: {clashes}")
        names += [name for name in RESERVED_NAMES if getattr(self, name) is not None]
        object.__setattr__(self, "_names", tuple(names))

    @property
    def names(self) -> tuple[str, ...]:
        """Every requirement's name: the pointing ones, then ``actuators``, ``rate``, ``final``."""
        return self._names

    @property
    def kinds(self) -> frozenset[str]:
        """The kinds present: ``pointing``, ``actuators``, ``rate``, ``final`` (the first three are
        :data:`planners.base.REQUIREMENT_KINDS`, which a planner may honour)."""
        return frozenset((["pointing"] if self.pointing else [])
                         + [name for name in RESERVED_NAMES if getattr(self, name) is not None])

    def __bool__(self) -> bool:
        return bool(self._names)

    def describe(self) -> list[str]:
        """One line per requirement, ``name: words``, in the order of :attr:`names` (the actuator
        requirement every scenario carries unstated, margin 0, left out), for ``slewbench validate``.

        Returns
        -------
        list of str
        """
        lines = [f"{requirement.name}: {requirement.describe()}" for requirement in self.pointing]
        if self.actuators is not None and self.actuators.stated:
            lines.append(f"actuators: {self.actuators.describe()}")
        lines += [f"{name}: {getattr(self, name).describe()}" for name in ("rate", "final")
                  if getattr(self, name) is not None]
        return lines
