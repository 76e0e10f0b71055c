"""Scenario requirements: declared once, applied to every row, scored for reference and closed loop.

What lives here: the requirement objects a scenario's ``spacecraft.sensors`` and ``requirements``
build (:mod:`~scenarios.requirements.spec`: sensors, pointing cones about a registered direction or
an inertial vector, the actuator margin, the body-rate limit, the final error) and the scoring of a
row against them (:mod:`~scenarios.requirements.scoring`: the reference on its dense sampling, its
actuator demand through the row's controller's allocation, the closed loop on its samples and its
pointing between them, the end points before planning), and what each field of a score holds: its
unit, words and definition (:mod:`~scenarios.requirements.fields`, plain data). The schema reads them (:mod:`scenarios.schema.requirements`), the runner
turns the scores into statuses and messages.

May import: :mod:`ocp`, :mod:`planners`, :mod:`controllers` and :mod:`scenarios.errors`; nothing else
of :mod:`scenarios`. Its names are imported on first use.
"""
from __future__ import annotations

from scenarios._faces import lazy_face

_HOMES = {"ActuatorRequirement": "scenarios.requirements.spec",
          "Direction": "scenarios.requirements.spec",
          "FinalRequirement": "scenarios.requirements.spec",
          "PointingRequirement": "scenarios.requirements.spec",
          "RateRequirement": "scenarios.requirements.spec",
          "Requirements": "scenarios.requirements.spec",
          "REQUIREMENT_FIELDS": "scenarios.requirements.fields",
          "RequirementField": "scenarios.requirements.fields",
          "Score": "scenarios.requirements.scoring",
          "Sensor": "scenarios.requirements.spec",
          "field_info": "scenarios.requirements.fields",
          "score_closed_loop": "scenarios.requirements.scoring",
          "score_reference": "scenarios.requirements.scoring"}

__all__ = ["REQUIREMENT_FIELDS", "ActuatorRequirement", "Direction", "FinalRequirement", "PointingRequirement",
           "RateRequirement", "RequirementField", "Requirements", "Score", "Sensor", "field_info", "score_closed_loop",
           "score_reference"]

__getattr__, __dir__ = lazy_face(__name__, _HOMES)
