"""Mission geometry: pointing constraints and the directions they are measured from.

What lives here: :mod:`~ocp.geometry.pointing` (a body boresight kept out of or inside a cone about a
direction tabulated along the run, scored in NumPy and imposed in CasADi) and
:mod:`~ocp.geometry.directions` (the epoch and orbit as a :class:`~ocp.geometry.directions.Geometry`
in the GCRF, the registry :data:`~ocp.geometry.directions.DIRECTIONS` of the direction kinds a
requirement names: the Sun, the Moon, the Earth's centre, the Earth's limb, the orbital velocity,
and their tables along a run) and :mod:`~ocp.geometry.targets` (attitudes in mission terms: a
boresight on a target with a second axis fixing the roll, the LVLH and RTN frames, WGS-84 ground
points in the GCRF).

May import: NumPy, CasADi and the top-level modules of :mod:`ocp`, and :mod:`ocp.dynamics` (the
orbit, the ephemeris); never the other subpackages of ``ocp``.
"""
from ocp.geometry.directions import (
    DIRECTIONS,
    FRAMES,
    INTERPOLATION_TOLERANCE,
    DirectionKind,
    Geometry,
    direction_kind,
    direction_table,
)
from ocp.geometry.pointing import PointingConstraint, PointingScore, violation_intervals
from ocp.geometry.targets import (
    ATTITUDE_FRAMES,
    AttitudeFrame,
    geodetic_to_ecef,
    ground_point,
    itrs_to_gcrf,
    two_vector_attitude,
)

__all__ = ["ATTITUDE_FRAMES", "DIRECTIONS", "FRAMES", "INTERPOLATION_TOLERANCE", "AttitudeFrame", "DirectionKind",
           "Geometry", "PointingConstraint", "PointingScore", "direction_kind", "direction_table", "geodetic_to_ecef",
           "ground_point", "itrs_to_gcrf", "two_vector_attitude", "violation_intervals"]


def __dir__() -> list[str]:
    """What ``dir()`` lists: the public names (``__all__``) and the module's dunder attributes."""
    return sorted({*__all__, *(name for name in globals() if name.startswith("__") and name.endswith("__"))})
