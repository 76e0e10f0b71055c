"""The ``slewbench`` command line: ``run``, ``validate``, ``list``, ``schema``, ``codegen``, ``sweep``.

What lives here: the parser, the single-scenario commands and ``schema``
(:mod:`~scenarios.cli.commands`) and the study commands (:mod:`~scenarios.cli.sweep`). ``python -m scenarios.cli`` runs it in one process;
the console script (:mod:`scenarios.console`) starts the plot process first.

May import: everything of :mod:`scenarios`, :mod:`planners` and :mod:`controllers` (their
registries) and :mod:`ocp.metrics` (the metric table); nothing imports it but the console script.
"""
from __future__ import annotations

from scenarios._faces import lazy_face

_HOMES = {"build_parser": "scenarios.cli.commands",
          "main": "scenarios.cli.commands"}

__all__ = ["build_parser", "main"]

__getattr__, __dir__ = lazy_face(__name__, _HOMES)
