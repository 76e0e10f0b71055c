"""What a run writes: tables, time series and figures, in output directories slewbench owns.

What lives here: a run's rows and results (:mod:`~scenarios.output.results`), file names from
labels (:mod:`~scenarios.output.names`), the table forms of rows (flattened by the column names of
:mod:`scenarios.schema.columns`) and the one rule for missing and non-finite values
(:mod:`~scenarios.output.tables`), output directories, their
manifest and staged commits (:mod:`~scenarios.output.directory`), writing a run's files into one
(:mod:`~scenarios.output.writer`), the figures' data as arrays
(:mod:`~scenarios.output.plot_data`), the matplotlib drawing (:mod:`~scenarios.output.plots`),
the plot process that draws while the run goes on (:mod:`~scenarios.output.renderer`), the
interactive ``report.html`` (:mod:`scenarios.output.report`), where results come from:
versions, platform, date and seeds (:mod:`~scenarios.output.provenance`), and exports of a finished
run into other tools' formats (:mod:`~scenarios.output.export`, the ``EXPORT_FORMATS`` registry;
CCSDS attitude ephemeris messages in :mod:`~scenarios.output.aem`; a reference as Basilisk's
``waypointReference`` data file in :mod:`~scenarios.output.basilisk`).

May import: :mod:`ocp`, :mod:`planners` (types), :mod:`scenarios.errors`,
:mod:`scenarios.requirements.fields` (the requirement fields' units and words: plain data) and
:mod:`scenarios.schema`. :mod:`~scenarios.output.plots` and :mod:`~scenarios.output.renderer` import
no model (the plot process starts before it is loaded), so this face imports its names on first
use.
"""
from __future__ import annotations

from scenarios._faces import lazy_face

_HOMES = {"EXPORT_FORMATS": "scenarios.output.export",
          "Renderer": "scenarios.output.renderer",
          "WaypointFile": "scenarios.output.basilisk",
          "Row": "scenarios.output.results",
          "RunResults": "scenarios.output.results",
          "claim_output_directory": "scenarios.output.directory",
          "export_run": "scenarios.output.export",
          "read_aem": "scenarios.output.aem",
          "read_manifest": "scenarios.output.directory",
          "row_stems": "scenarios.output.names",
          "flatten_row": "scenarios.output.tables",
          "row_columns": "scenarios.output.tables",
          "sanitize": "scenarios.output.names",
          "to_csv": "scenarios.output.tables",
          "to_dataframe": "scenarios.output.tables",
          "to_json": "scenarios.output.tables",
          "to_markdown": "scenarios.output.tables",
          "to_terminal": "scenarios.output.tables",
          "write_results": "scenarios.output.writer",
          "write_waypoint_reference": "scenarios.output.basilisk"}

__all__ = ["EXPORT_FORMATS", "Renderer", "Row", "RunResults", "WaypointFile", "claim_output_directory", "export_run",
           "flatten_row", "read_aem", "read_manifest",
           "row_columns", "row_stems", "sanitize", "to_csv", "to_dataframe", "to_json", "to_markdown", "to_terminal",
           "write_results", "write_waypoint_reference"]

__getattr__, __dir__ = lazy_face(__name__, _HOMES)
