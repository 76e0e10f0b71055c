"""Scenarios: YAML loading, the runner, tables, plots and the CLI.

Library use::

    import scenarios
    scenario = scenarios.load("scenarios/eigenaxis_demo.yaml")
    results = scenarios.run(scenario)
    print(results.to_markdown())
    study = scenarios.sweep("study.yaml")   # a trade study; .to_dataframe()

The names below are imported on first use (PEP 562), so that ``import scenarios`` costs nothing
until one is used: the command line starts its plot process before it loads the model
(:mod:`scenarios.console`).
"""
from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # the names, for type checkers and readers
    from scenarios.loader import Scenario, load, parse_scenario
    from scenarios.runner import Row, RunResults, run
    from scenarios.study import Study, load_study, parse_study
    from scenarios.sweep_engine import SweepInterrupted, SweepResults, sweep
    from scenarios.yaml_node import ScenarioError

_HOMES = {"Scenario": "scenarios.loader", "load": "scenarios.loader", "parse_scenario": "scenarios.loader",
          "Row": "scenarios.runner", "RunResults": "scenarios.runner", "run": "scenarios.runner",
          "Study": "scenarios.study", "load_study": "scenarios.study", "parse_study": "scenarios.study",
          "SweepInterrupted": "scenarios.sweep_engine", "SweepResults": "scenarios.sweep_engine",
          "sweep": "scenarios.sweep_engine", "ScenarioError": "scenarios.yaml_node"}

__all__ = ["Row", "RunResults", "Scenario", "ScenarioError", "Study", "SweepInterrupted", "SweepResults",
           "load", "load_study", "parse_scenario", "parse_study", "run", "sweep"]


def __getattr__(name: str) -> Any:
    """The public name ``name``, imported from its module on first use.

    Parameters
    ----------
    name : str
        One of ``__all__``.

    Returns
    -------
    object
        The class or function.
    """
    home = _HOMES.get(name)
    if home is None:
        raise AttributeError(f"module 'scenarios' has no attribute {name!r}")
    return getattr(importlib.import_module(home), name)


def __dir__() -> list[str]:
    """The module's names, the lazily imported ones included.

    Returns
    -------
    list of str
        Sorted names.
    """
    return sorted(set(globals()) | set(_HOMES))
