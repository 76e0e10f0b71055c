"""The planner registry: ``PLANNERS`` maps a registry name (the YAML ``planners[i].name``) to its class.

The package's face (:mod:`planners`) fills it with the planners slewbench ships; a user's planner is
added with ``PLANNERS[MyPlanner.name] = MyPlanner`` (:doc:`/extending/planner`). Planners that plan
from other planners' references (``collocation``'s warm starts and seeds) look them up here: the
registry is complete by the time any planner runs, because importing any module of
:mod:`planners` imports the package, and so its face, first.

May import: :mod:`planners.base` (for the type); nothing else of slewbench.
"""
from __future__ import annotations

from planners.base import Planner

__all__ = ["PLANNERS"]

PLANNERS: dict[str, type[Planner]] = {}
"""Registry name -> planner class."""
