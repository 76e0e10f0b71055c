"""Slew tables for schedulers: minimum slew time over eigen-axes and angles, and a fast fit of it.

What lives here: the grid of axes and angles (:mod:`~scenarios.slewtable.grid`), what a table
computes, read from a scenario or a table file (:mod:`~scenarios.slewtable.spec`), the computation
through the trade-study engine and its fit (:mod:`~scenarios.slewtable.compute`), the fit itself,
a callable ``slew_time(q0, qf)`` (:mod:`~scenarios.slewtable.fit`), its adaptive refinement to a
tolerance (:mod:`~scenarios.slewtable.refine`) and the files (:mod:`~scenarios.slewtable.files`: CSV,
NetCDF, ``fit.json``, the agility envelope plot).

May import: :mod:`ocp`, :mod:`planners`, :mod:`scenarios.errors`, :mod:`scenarios.requirements`,
:mod:`scenarios.schema`, :mod:`scenarios.output` and :mod:`scenarios.study`. Its names are imported on first use.
"""
from __future__ import annotations

from scenarios._faces import lazy_face

_HOMES = {"SlewTable": "scenarios.slewtable.compute",
          "SlewTimeFit": "scenarios.slewtable.fit",
          "TableSpec": "scenarios.slewtable.spec",
          "compute_table": "scenarios.slewtable.compute",
          "fibonacci_axes": "scenarios.slewtable.grid",
          "load_fit": "scenarios.slewtable.fit",
          "parse_table_spec": "scenarios.slewtable.spec",
          "write_table_files": "scenarios.slewtable.files"}

__all__ = ["SlewTable", "SlewTimeFit", "TableSpec", "compute_table", "fibonacci_axes", "load_fit", "parse_table_spec",
           "write_table_files"]

__getattr__, __dir__ = lazy_face(__name__, _HOMES)
