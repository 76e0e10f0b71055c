"""A reference tracked by several controllers: its pointing and rate scores are computed once, its
actuator score once per controller (through that controller's allocation), and every row's reference
scores are those of scoring it alone with its own controller, in the same order."""
from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

import scenarios
from scenarios import runner
from scenarios.requirements.fields import VERDICT
from scenarios.requirements.scoring import plant_limits, score_reference

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "cubesat_12u_sun_keep_out.yaml"


def two_controllers() -> scenarios.Scenario:
    data = yaml.safe_load(SCENARIO.read_text())
    data["planners"] = [{"name": "eigenaxis"}, {"name": "natural_motion"}]
    del data["controller"]
    data["controllers"] = [{"name": "augmented_quaternion_feedback"}, {"name": "mrp_feedback"}]
    data["requirements"]["rate"] = {"max": 0.1}
    return scenarios.parse_scenario(data)


def test_a_reference_is_scored_once_for_pointing_and_rate_and_per_controller_for_actuators(monkeypatch) -> None:
    scenario = two_controllers()
    calls: list[tuple[Any, bool]] = []

    def spy(*args: Any, shared: bool = True, **kwargs: Any) -> Any:
        calls.append((args[4], shared))
        return score_reference(*args, shared=shared, **kwargs)

    monkeypatch.setattr(runner, "score_reference", spy)
    results = scenarios.run(scenario)
    assert len(results.rows) == 4
    allocations = [spec.controller for spec in scenario.controllers]
    # once per planner for what no controller changes; once per row for the actuators, with the row's controller
    assert [allocation for allocation, shared in calls if shared] == [None, None]
    assert [allocation for allocation, shared in calls if not shared] == allocations * 2
    for index, planner in enumerate(scenario.planners):
        reference, _, sampled = runner.plan_row(scenario, planner, None, True)
        assert sampled is not None
        for j, allocation in enumerate(allocations):
            alone = score_reference(scenario.requirements, scenario.problem, *sampled, allocation, reference,
                                    plant_limits(scenario.truth))
            expected = {name: {VERDICT: bool(score.met), **score.values} for name, score in alone.items()}
            row = results.rows[2 * index + j]
            assert row.requirements is not None
            got = row.requirements["reference"]
            assert list(got) == list(expected) == ["st_sun", "actuators", "rate"]
            assert got == expected
