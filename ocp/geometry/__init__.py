"""Mission geometry: pointing constraints and the directions they are measured from.

What lives here: :mod:`~ocp.geometry.pointing` (a body boresight kept out of or inside a cone about a
direction tabulated along the run, scored in NumPy and imposed in CasADi).

May import: NumPy, CasADi and the top-level modules of :mod:`ocp`, and :mod:`ocp.dynamics` (the
orbit); never the other subpackages of ``ocp``.
"""
from ocp.geometry.pointing import PointingConstraint, PointingScore, violation_intervals

__all__ = ["PointingConstraint", "PointingScore", "violation_intervals"]
