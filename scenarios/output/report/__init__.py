"""The interactive HTML report (``report.html``): self-contained pages of sortable tables and plotly figures.

What lives here: the page itself, with plotly.js inline, the data as one JSON document and the script
that draws the tables and figures (:mod:`~scenarios.output.report.page`), a run's interactive figures
(:mod:`~scenarios.output.report.figures`), a run's sign-off record (:mod:`~scenarios.output.report.record`)
and a run's report (:mod:`~scenarios.output.report.run`).
A trade study's report (:mod:`scenarios.study.html`) is built on the same page.

May import: :mod:`ocp`, :mod:`planners` (the jump tolerance of a reference's rate),
:mod:`scenarios.requirements.fields` (the requirement fields' units),
:mod:`scenarios.schema` and :mod:`scenarios.output`. plotly.js comes from the
``plotly`` package's files (the package itself is not imported).
"""
from __future__ import annotations

from scenarios._faces import lazy_face

_HOMES = {"Column": "scenarios.output.report.page",
          "Page": "scenarios.output.report.page",
          "attitude_figure": "scenarios.output.report.figures",
          "column_unit": "scenarios.output.report.page",
          "margin_figure": "scenarios.output.report.figures",
          "row_figure": "scenarios.output.report.figures",
          "run_page": "scenarios.output.report.run",
          "run_report": "scenarios.output.report.run",
          "sky_figure": "scenarios.output.report.figures"}

__all__ = ["Column", "Page", "attitude_figure", "column_unit", "margin_figure", "row_figure", "run_page", "run_report",
           "sky_figure"]

__getattr__, __dir__ = lazy_face(__name__, _HOMES)
