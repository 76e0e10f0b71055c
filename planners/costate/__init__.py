"""``costate_tpbvp``: Vepa's indirect method, states and co-states as a two-point boundary-value problem.

What lives here: the planner and its reference (:mod:`~planners.costate.tpbvp`), the Hamiltonian
systems' common contract and the rigid body's (:mod:`~planners.costate.hamiltonian`) and the
problem forms of sections 3 and 6 (:mod:`~planners.costate.systems`).

May import: :mod:`ocp` and the contract modules of :mod:`planners` (``base``, ``problem``,
``reference``), :mod:`planners.eigenaxis` (the cold start from rest) and :mod:`planners.torque_free`
(the cold start from a spin).
"""
from planners.costate.hamiltonian import HamiltonianSystem, RigidBodySystem
from planners.costate.systems import (
           AttitudeAcquisitionSystem,
           MinimumEnergySystem,
           RateAcquisitionSystem,
)
from planners.costate.tpbvp import CostateReference, CostateTPBVPPlanner

__all__ = ["AttitudeAcquisitionSystem", "CostateReference", "CostateTPBVPPlanner", "HamiltonianSystem",
           "MinimumEnergySystem", "RateAcquisitionSystem", "RigidBodySystem"]


def __dir__() -> list[str]:
    """What ``dir()`` lists: the public names (``__all__``) and the module's dunder attributes."""
    return sorted({*__all__, *(name for name in globals() if name.startswith("__") and name.endswith("__"))})
