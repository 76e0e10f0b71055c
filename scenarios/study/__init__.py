"""Trade studies: a scenario swept over grids, zips and Monte Carlo dispersions, run crash-safely.

What lives here: the study's data (:mod:`~scenarios.study.types`), scenario paths as a study spells
them (:mod:`~scenarios.study.paths`), dispersions (:mod:`~scenarios.study.dispersions`), reading a
study and expanding it into cases (:mod:`~scenarios.study.spec`; the study file's keys are declared
in :mod:`scenarios.schema.study`), the crash-safe store and the sweep directory that holds it
(:mod:`~scenarios.study.store`), what a worker runs (:mod:`~scenarios.study.worker`), the engine on a
local pool or Dask (:mod:`~scenarios.study.engine`), the report's tables
(:mod:`~scenarios.study.report`), robustness tables of a Monte Carlo study
(:mod:`~scenarios.study.robustness`), figures (:mod:`~scenarios.study.plots`) and interactive
``report.html`` (:mod:`~scenarios.study.html`), and a stored sweep read back with one of its cases
re-run in full (:mod:`~scenarios.study.rerun`).

May import: :mod:`ocp`, :mod:`scenarios.errors`, :mod:`scenarios.requirements` (the requirement
columns a summary may name), :mod:`scenarios.schema`, :mod:`scenarios.output` and
:mod:`scenarios.runner`. Its names are imported on first use.
"""
from __future__ import annotations

from scenarios._faces import lazy_face

_HOMES = {"Case": "scenarios.study.types",
          "DaskCluster": "scenarios.study.engine",
          "Dispersion": "scenarios.study.dispersions",
          "Execution": "scenarios.study.types",
          "Study": "scenarios.study.types",
          "SweepResults": "scenarios.study.engine",
          "SweepStore": "scenarios.study.store",
          "connect_scheduler": "scenarios.study.engine",
          "load_study": "scenarios.study.spec",
          "parse_study": "scenarios.study.spec",
          "rerun_case": "scenarios.study.rerun",
          "stored_results": "scenarios.study.rerun",
          "sweep": "scenarios.study.engine"}

__all__ = ["Case", "DaskCluster", "Dispersion", "Execution", "Study", "SweepResults", "SweepStore", "connect_scheduler",
           "load_study", "parse_study", "rerun_case", "stored_results", "sweep"]

__getattr__, __dir__ = lazy_face(__name__, _HOMES)
