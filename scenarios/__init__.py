"""Scenarios: YAML loading, the runner, tables, plots and the CLI.

Library use::

    import scenarios
    scenario = scenarios.load("scenarios/eigenaxis_demo.yaml")
    results = scenarios.run(scenario)
    print(results.to_markdown())
    study = scenarios.sweep("study.yaml")   # a trade study; .to_dataframe()
"""
from scenarios.loader import Scenario, load, parse_scenario
from scenarios.runner import Row, RunResults, run
from scenarios.study import Study, load_study, parse_study
from scenarios.sweep_engine import SweepInterrupted, SweepResults, sweep
from scenarios.yaml_node import ScenarioError

__all__ = ["Row", "RunResults", "Scenario", "ScenarioError", "Study", "SweepInterrupted", "SweepResults",
           "load", "load_study", "parse_scenario", "parse_study", "run", "sweep"]
