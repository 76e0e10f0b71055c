"""Reference-motion planners. ``PLANNERS`` maps registry names to planner classes."""
from planners.base import (FailedReference, ManeuverProblem, Planner, Reference, ReferenceSample,
                           inverse_dynamics_torque)
from planners.eigenaxis import EigenaxisPlanner

PLANNERS: dict[str, type[Planner]] = {
    cls.name: cls for cls in (EigenaxisPlanner,)
}

__all__ = ["FailedReference", "ManeuverProblem", "PLANNERS", "Planner", "Reference", "ReferenceSample",
           "inverse_dynamics_torque"]
