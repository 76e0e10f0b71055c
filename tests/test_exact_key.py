"""ocp.cache.exact_key, the one statement of a value that the model's fingerprint and a study's
planning key (scenarios.runner.planning_key) are built from: two different values never give the same
key, however deep or small the difference; a value it cannot state exactly raises ``Unkeyable``, and
the planning key is then ``None`` (the row is planned every time)."""
from __future__ import annotations

import copy
import dataclasses

import numpy as np
import pytest

import scenarios
from ocp.cache import Unkeyable, exact_key
from scenarios.runner import planning_key

BASE = {
    "name": "exact-key",
    "spacecraft": {"inertia": [3.0, 3.5, 4.0], "wheels": {"max_torque": 0.05}},
    "maneuver": {"duration": 30.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.9238795, 0.3826834, 0, 0], "omega": [0, 0, 0]}},
    "planners": [{"name": "eigenaxis"}],
    "controller": {"name": "augmented_quaternion_feedback", "options": {"kp": 0.2, "kd": 0.6}},
    "simulation": {"sample_time": 1.0, "duration": 35.0},
}


@dataclasses.dataclass(frozen=True)
class _Box:
    table: dict[str, list[np.ndarray]]
    memo: dict[str, float] = dataclasses.field(default_factory=dict, compare=False)


def _nudged(values: np.ndarray, index: int) -> np.ndarray:
    out = values.copy()
    out[index] = np.nextafter(out[index], np.inf)
    return out


def test_values_that_differ_one_bit_deep_inside_give_different_keys():
    a = np.linspace(0.1, 0.9, 2000)  # long enough for numpy's repr to elide it
    first = _Box({"x": [a, a]})
    assert exact_key(first) == exact_key(_Box({"x": [a.copy(), a.copy()]}))
    assert exact_key(first) != exact_key(_Box({"x": [a, _nudged(a, 1000)]}))
    assert exact_key(first) != exact_key(_Box({"x": (a, a)}))  # a tuple is not a list
    assert exact_key(0.0) != exact_key(-0.0) and exact_key(1) != exact_key(1.0) != exact_key(True)


def test_fields_excluded_from_equality_are_not_in_the_key():
    assert exact_key(_Box({}, {"seen": 1.0})) == exact_key(_Box({}))


@pytest.mark.parametrize("value", [object(), print, lambda: 0, np.array([object()]), {"k": [1.0, object()]}])
def test_an_object_of_unknown_kind_is_refused_not_made_equal_to_another(value):
    with pytest.raises(Unkeyable):
        exact_key(value)


def test_planning_keys_differ_when_the_problem_differs_deep_inside():
    one, other = (scenarios.parse_scenario(copy.deepcopy(BASE)) for _ in range(2))
    key = planning_key(one.planners[0].planner, one.problem)
    assert key is not None and key == planning_key(other.planners[0].planner, other.problem)
    nudged = dataclasses.replace(other.problem, omega0=_nudged(np.asarray(other.problem.omega0, dtype=float), 2))
    assert planning_key(other.planners[0].planner, nudged) != key


def test_a_planner_holding_an_object_of_unknown_kind_has_no_planning_key():
    scenario = scenarios.parse_scenario(copy.deepcopy(BASE))
    planner = copy.copy(scenario.planners[0].planner)
    planner.hook = object()  # type: ignore[attr-defined]
    assert planning_key(planner, scenario.problem) is None
