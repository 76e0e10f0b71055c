"""Reference-motion planners. ``PLANNERS`` maps registry names to planner classes.

The contract is :mod:`planners.base` (:class:`Planner`; :class:`ManeuverProblem` in,
:class:`Reference` out, evaluated as :class:`ReferenceSample` rows) and :mod:`planners.conformance`
checks it for every registered planner. One module per method: :mod:`planners.collocation`,
:mod:`planners.costate_tpbvp`, :mod:`planners.eigenaxis`, :mod:`planners.natural_motion`,
:mod:`planners.shape_polynomial`, :mod:`planners.spin_extremal`.
"""
from planners.base import (BOUNDARY_CONDITIONS, FailedReference, ManeuverProblem, Planner, Reference, ReferenceSample,
                           inverse_dynamics_torque)
from planners.collocation import CollocationPlanner
from planners.costate_tpbvp import CostateTPBVPPlanner
from planners.eigenaxis import EigenaxisPlanner
from planners.natural_motion import NaturalMotionPlanner
from planners.shape_polynomial import ShapePolynomialPlanner
from planners.spin_extremal import SpinExtremalPlanner

PLANNERS: dict[str, type[Planner]] = {
    cls.name: cls for cls in (CollocationPlanner, CostateTPBVPPlanner, EigenaxisPlanner, NaturalMotionPlanner, ShapePolynomialPlanner, SpinExtremalPlanner)
}

__all__ = ["BOUNDARY_CONDITIONS", "FailedReference", "ManeuverProblem", "PLANNERS", "Planner", "Reference", "ReferenceSample",
           "inverse_dynamics_torque"]
