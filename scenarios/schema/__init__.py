"""The scenario, study and slew-table schema: reading YAML safely, values that name their path, the keys of every
section, the checks, and the schema reference generated from the keys.

What lives here: bounded, duplicate-refusing YAML reading (:mod:`~scenarios.schema.read`), typed
nodes whose errors name the YAML path (:mod:`~scenarios.schema.node`), the vocabulary the keys are
declared in (:mod:`~scenarios.schema.keys`), the model sections (``spacecraft``, ``orbit``,
``environment``; :mod:`~scenarios.schema.model`), the epoch, the sensors and the
requirements (:mod:`~scenarios.schema.requirements`), the attitudes in mission terms (axis and
angle, Euler angles, pointing targets, orbit frames; :mod:`~scenarios.schema.targets`), the whole scenario and the
:class:`~scenarios.schema.loader.Scenario` it builds (:mod:`~scenarios.schema.loader`), how planner
and controller labels name the rows (:mod:`~scenarios.schema.labels`), the names of the metric
columns (:mod:`~scenarios.schema.columns`), the checks of a parsed scenario as a whole
(:mod:`~scenarios.schema.checks`), the plausibility warnings on likely unit slips
(:mod:`~scenarios.schema.plausibility`), the study file's keys, value generators and distributions
(:mod:`~scenarios.schema.study`), the slew-table file's keys (:mod:`~scenarios.schema.table`), and the
reference of them all (:mod:`~scenarios.schema.reference`: ``slewbench schema``).

May import: :mod:`ocp`, :mod:`planners`, :mod:`controllers`, :mod:`scenarios.errors` and
:mod:`scenarios.requirements`; nothing else of :mod:`scenarios`. Its names are imported on first use.
"""
from __future__ import annotations

from scenarios._faces import lazy_face

_HOMES = {"ATTITUDE_FORMS": "scenarios.schema.targets",
          "ControllerSpec": "scenarios.schema.loader",
          "DISTRIBUTIONS": "scenarios.schema.study",
          "Key": "scenarios.schema.keys",
          "Node": "scenarios.schema.node",
          "PlannerSpec": "scenarios.schema.loader",
          "RowLabel": "scenarios.schema.labels",
          "Scenario": "scenarios.schema.loader",
          "Section": "scenarios.schema.keys",
          "SimulationSpec": "scenarios.schema.loader",
          "VALUE_GENERATORS": "scenarios.schema.study",
          "load": "scenarios.schema.loader",
          "parse_scenario": "scenarios.schema.loader",
          "parse_yaml_text": "scenarios.schema.read",
          "read_yaml": "scenarios.schema.read",
          "metric_columns": "scenarios.schema.columns",
          "row_labels": "scenarios.schema.labels",
          "schema_rst": "scenarios.schema.reference",
          "schema_text": "scenarios.schema.reference"}

__all__ = ["ATTITUDE_FORMS", "DISTRIBUTIONS", "VALUE_GENERATORS", "ControllerSpec", "Key", "Node", "PlannerSpec", "RowLabel", "Scenario",
           "Section", "SimulationSpec", "load", "metric_columns", "parse_scenario", "parse_yaml_text", "read_yaml",
           "row_labels", "schema_rst", "schema_text"]

__getattr__, __dir__ = lazy_face(__name__, _HOMES)
