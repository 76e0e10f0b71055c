"""``collocation``: direct optimal control on the full model, the workbench's numerical reference.

What lives here: the planner and its options (:mod:`~planners.collocation.planner`), the problem
side (its own cones from YAML, the endpoints checked against the pointing constraints, variable
bounds from the spacecraft; :mod:`~planners.collocation.problem`), the reference of a solution and
seeds from other references, bent round keep-out cones (:mod:`~planners.collocation.reference`),
the requirements it honours and their dense check (:mod:`~planners.collocation.requirements`),
the controllers' allocation imposed on its controls (:mod:`~planners.collocation.allocation`),
the search strategy's tuned constants (:mod:`~planners.collocation.strategy`) and the certificate of
an optimum, with the co-states in the collocation multipliers (:mod:`~planners.collocation.certificate`).

May import: :mod:`ocp` (transcriptions and the NLP core) and the contract modules of
:mod:`planners` (``base``, ``problem``, ``reference``, ``conformance``); other planners only through the
``PLANNERS`` registry (:mod:`planners.registry`), to seed from their references.
"""
from planners.collocation.planner import CollocationOptions, CollocationPlanner
from planners.collocation.reference import CollocationReference

__all__ = ["CollocationOptions", "CollocationPlanner", "CollocationReference"]


def __dir__() -> list[str]:
    """What ``dir()`` lists: the public names (``__all__``) and the module's dunder attributes."""
    return sorted({*__all__, *(name for name in globals() if name.startswith("__") and name.endswith("__"))})
