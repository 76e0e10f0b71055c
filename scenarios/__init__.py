"""Scenarios: YAML schema and loading, the runner, outputs, trade studies, code generation and the CLI.

Library use::

    import scenarios
    scenario = scenarios.load("scenarios/eigenaxis_demo.yaml")
    results = scenarios.run(scenario)
    print(results.to_markdown())
    study = scenarios.sweep("study.yaml")   # a trade study; .to_dataframe()

Subpackages, from the bottom up (each may import only those before it, and :mod:`ocp`,
:mod:`planners` and :mod:`controllers`):

* :mod:`scenarios.requirements`: the requirements a scenario states once (sensors, pointing cones,
  the actuators' margin, a rate limit, the final error) and the scoring of every row against them;
* :mod:`scenarios.schema`: reading YAML safely, typed nodes that name their path, the scenario
  schema and its checks, and the schema reference generated from them;
* :mod:`scenarios.output`: a run's rows and results (:class:`~scenarios.output.results.Row`,
  :class:`~scenarios.output.results.RunResults`) as tables, files and figures, and the output
  directories slewbench owns;
* :mod:`scenarios.runner` (a module): plan, track and score every row of a scenario;
* :mod:`scenarios.codegen`: flight C of a scenario (the law, the saturation stage, every
  row's reference as a table, behind ``slewbench_step``);
* :mod:`scenarios.study`: trade studies: their schema, cases, store, engine and report;
* :mod:`scenarios.cli`: the ``slewbench`` command line.

The names below are imported on first use (PEP 562, :func:`scenarios._faces.lazy_face`), so that
``import scenarios`` costs nothing until one is used: the command line starts its plot process
before it loads the model (:mod:`scenarios.console`). The first use of one that reads a file also loads the installed
plugins (:func:`scenarios.schema.plugins.load_plugins`: the ``slewbench.plugins`` entry points and
``SLEWBENCH_PLUGINS``), once.
"""
from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from scenarios._faces import lazy_face

if TYPE_CHECKING:  # the names, for type checkers and readers
    from scenarios.errors import (
        OutputError,
        PlausibilityWarning,
        ScenarioError,
        SweepInterrupted,
    )
    from scenarios.output.results import Row, RunResults
    from scenarios.runner import run
    from scenarios.schema.loader import Scenario, load, parse_scenario
    from scenarios.study.engine import SweepResults, sweep
    from scenarios.study.spec import load_study, parse_study
    from scenarios.study.types import Study

_HOMES = {"Scenario": "scenarios.schema.loader", "load": "scenarios.schema.loader",
          "parse_scenario": "scenarios.schema.loader",
          "Row": "scenarios.output.results", "RunResults": "scenarios.output.results", "run": "scenarios.runner",
          "Study": "scenarios.study.types", "load_study": "scenarios.study.spec", "parse_study": "scenarios.study.spec",
          "SweepInterrupted": "scenarios.errors", "SweepResults": "scenarios.study.engine",
          "sweep": "scenarios.study.engine", "ScenarioError": "scenarios.errors", "OutputError": "scenarios.errors",
          "PlausibilityWarning": "scenarios.errors"}

__all__ = ["OutputError", "PlausibilityWarning", "Row", "RunResults", "Scenario", "ScenarioError", "Study",
           "SweepInterrupted", "SweepResults", "load", "load_study", "parse_study", "parse_scenario", "run", "sweep"]

_face_getattr, __dir__ = lazy_face(__name__, _HOMES)
_READERS = frozenset({"load", "parse_scenario", "load_study", "parse_study", "run", "sweep"})
"""The names whose first use loads the plugins: those that read registry names from a file."""
_plugins_loaded = False
"""Whether the face has loaded the plugins (a failed load leaves it ``False``: the next use tries again)."""


def __getattr__(name: str) -> Any:
    """A public name, from its home (:func:`scenarios._faces.lazy_face`), after loading the plugins once.

    Plugins (:mod:`scenarios.schema.plugins`) load on first use of a name that reads a scenario or
    study (``load``, ``parse_scenario``, ``load_study``, ``parse_study``, ``run``, ``sweep``), so
    that a file naming a plugin's planner loads from Python as from the command line.

    Parameters
    ----------
    name : str
        The attribute asked for.

    Returns
    -------
    Any
        The public name, or the submodule ``name``.
    """
    global _plugins_loaded
    if name in _READERS and not _plugins_loaded:
        importlib.import_module("scenarios.schema.plugins").load_plugins()
        _plugins_loaded = True
    return _face_getattr(name)
