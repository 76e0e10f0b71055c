"""Scenarios: YAML loading, the runner, tables, plots and the CLI.

Library use::

    import scenarios
    scenario = scenarios.load("scenarios/eigenaxis_demo.yaml")
    results = scenarios.run(scenario)
    print(results.to_markdown())
"""
from scenarios.loader import Scenario, load, parse_scenario
from scenarios.runner import Row, RunResults, run
from scenarios.yaml_node import ScenarioError

__all__ = ["Row", "RunResults", "Scenario", "ScenarioError", "load", "parse_scenario", "run"]
