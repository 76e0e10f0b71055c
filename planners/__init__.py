"""Reference-motion planners. ``PLANNERS`` (:mod:`planners.registry`) maps registry names to planner classes.

The contract is :mod:`planners.base` (:class:`Planner`; :class:`ManeuverProblem` in,
:class:`Reference` out, evaluated as :class:`ReferenceSample` rows) and :mod:`planners.conformance`
checks it for every registered planner. One module per method: :mod:`planners.collocation.planner`,
:mod:`planners.costate.tpbvp`, :mod:`planners.eigenaxis`, :mod:`planners.natural_motion`,
:mod:`planners.shape_polynomial`, :mod:`planners.spin_extremal`.

May import: :mod:`ocp`; never :mod:`controllers` or :mod:`scenarios`. Inside, the contract modules
(``errors``, ``problem``, ``reference``, ``torque_free``, ``base``, ``registry``, ``capabilities``,
``conformance``) import no planner; a planner imports the contract, and other planners only through
the registry or, for :mod:`planners.costate`, :mod:`planners.eigenaxis` (its cold start).
"""
from planners.base import Planner
from planners.collocation.planner import CollocationPlanner
from planners.costate.tpbvp import CostateTPBVPPlanner
from planners.eigenaxis import EigenaxisPlanner
from planners.errors import ConformanceError, UnknownNameError
from planners.natural_motion import NaturalMotionPlanner
from planners.problem import ManeuverProblem
from planners.reference import (
    BOUNDARY_CONDITIONS,
    FailedReference,
    Reference,
    ReferenceSample,
    inverse_dynamics_torque,
)
from planners.registry import PLANNERS
from planners.shape_polynomial import ShapePolynomialPlanner
from planners.spin_extremal import SpinExtremalPlanner

PLANNERS.update({cls.name: cls for cls in (CollocationPlanner, CostateTPBVPPlanner, EigenaxisPlanner,
                                            NaturalMotionPlanner, ShapePolynomialPlanner, SpinExtremalPlanner)})

__all__ = ["BOUNDARY_CONDITIONS", "PLANNERS", "ConformanceError", "FailedReference", "ManeuverProblem", "Planner",
           "Reference", "ReferenceSample", "UnknownNameError", "inverse_dynamics_torque"]


def __dir__() -> list[str]:
    """What ``dir()`` lists: the public names (``__all__``) and the module's dunder attributes."""
    return sorted({*__all__, *(name for name in globals() if name.startswith("__") and name.endswith("__"))})
