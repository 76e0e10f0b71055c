"""The scenario schema: reading YAML safely, values that name their path, the sections and the checks.

What lives here: bounded, duplicate-refusing YAML reading (:mod:`~scenarios.schema.read`), typed
nodes whose errors name the YAML path (:mod:`~scenarios.schema.node`), the model sections
(``spacecraft``, ``orbit``, ``environment``; :mod:`~scenarios.schema.model`), the whole scenario and
the :class:`~scenarios.schema.loader.Scenario` it builds (:mod:`~scenarios.schema.loader`), how
planner and controller labels name the rows (:mod:`~scenarios.schema.labels`) and the checks of a
parsed scenario as a whole (:mod:`~scenarios.schema.checks`).

May import: :mod:`ocp`, :mod:`planners`, :mod:`controllers` and :mod:`scenarios.errors`; nothing
else of :mod:`scenarios`. Its names are imported on first use.
"""
from __future__ import annotations

from scenarios._faces import lazy_face

_HOMES = {"ControllerSpec": "scenarios.schema.loader",
          "Node": "scenarios.schema.node",
          "PlannerSpec": "scenarios.schema.loader",
          "RowLabel": "scenarios.schema.labels",
          "Scenario": "scenarios.schema.loader",
          "SimulationSpec": "scenarios.schema.loader",
          "load": "scenarios.schema.loader",
          "parse_scenario": "scenarios.schema.loader",
          "parse_yaml_text": "scenarios.schema.read",
          "read_yaml": "scenarios.schema.read",
          "row_labels": "scenarios.schema.labels"}

__all__ = ["ControllerSpec", "Node", "PlannerSpec", "RowLabel", "Scenario", "SimulationSpec", "load", "parse_scenario",
           "parse_yaml_text", "read_yaml", "row_labels"]

__getattr__, __dir__ = lazy_face(__name__, _HOMES)
