"""``Study.raw`` holds the plain values YAML gives (dict, list, str, int, float, bool, None), whatever
the study mapping was built from: a script's numpy numbers and arrays and tuples (which the schema
accepts wherever YAML takes a number or a list) are converted where the mapping enters the schema, so
``raw`` serialises with ``json`` (``allow_nan=False``) and ``yaml.safe_dump`` and compares equal to
the same study read from YAML.

Oracle: the same study written by hand as YAML text, read with ``yaml.safe_load``.
"""
from __future__ import annotations

import json
from typing import Any

import numpy as np
import yaml

from scenarios.study.report import resolved_study
from scenarios.study.spec import parse_study

PLAIN = (dict, list, str, int, float, bool, type(None))

YAML_TEXT = """
study: plain
scenario:
  name: plain
  spacecraft: {inertia: [2.0, 3.0, 4.0], wheels: {max_torque: 0.05}}
  maneuver:
    duration: 20
    initial: {q: [1, 0, 0, 0], omega: [0, 0, 0]}
    final: {q: [0.9238795, 0.3826834, 0.0, 0.0], omega: [0, 0, 0]}
  planners: [{name: eigenaxis}]
  controller: {name: augmented_quaternion_feedback, options: {kp: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]}}
grid:
  maneuver.duration: [20.0, 25.0, 30.0]
zip:
  controller.options.kd: [2.0, 3.0]
monte_carlo:
  samples: 2
  seed: 7
  dispersions:
    spacecraft.wheels.max_torque: {scale: {uniform: [0.5, 1.5]}}
summary: [cl.final_error_deg]
"""


def numpy_study() -> dict[str, Any]:
    """YAML_TEXT's study as a script builds it, with numpy and tuples wherever the schema takes them."""
    return {
        "study": "plain",
        "scenario": {
            "name": "plain",
            "spacecraft": {"inertia": np.array([2.0, 3.0, 4.0]), "wheels": {"max_torque": np.float64(0.05)}},
            "maneuver": {"duration": np.int64(20),
                         "initial": {"q": (1, 0, 0, 0), "omega": np.zeros(3, dtype=np.int32)},
                         "final": {"q": np.array([0.9238795, 0.3826834, 0.0, 0.0]), "omega": [np.int64(0)] * 3}},
            "planners": [{"name": "eigenaxis"}],
            "controller": {"name": "augmented_quaternion_feedback", "options": {"kp": np.eye(3)}}},
        "grid": {"maneuver.duration": np.linspace(20.0, 30.0, 3)},
        "zip": {"controller.options.kd": (np.float64(2.0), np.float64(3.0))},
        "monte_carlo": {"samples": np.int64(2), "seed": np.uint32(7),
                        "dispersions": {"spacecraft.wheels.max_torque": {"scale": {"uniform": np.array([0.5, 1.5])}}}},
        "summary": ("cl.final_error_deg",),
    }


def not_plain(value: Any, where: str = "raw") -> list[str]:
    """Where ``value`` holds anything but the plain YAML types (numpy included), with the type."""
    if not isinstance(value, PLAIN) or isinstance(value, np.generic):
        return [f"{where}: {type(value).__module__}.{type(value).__name__}"]
    if isinstance(value, dict):
        return [found for key, item in value.items()
                for found in [*not_plain(key, f"{where} key"), *not_plain(item, f"{where}.{key}")]]
    if isinstance(value, list):
        return [found for index, item in enumerate(value) for found in not_plain(item, f"{where}[{index}]")]
    return []


def test_the_walk_finds_numpy_and_tuples():  # the checker itself: it must see what it is to refuse
    assert not_plain({"a": [1, 2.0, "x", None, True]}) == []
    assert not_plain({"a": np.float64(1.0), "b": [np.int64(1)], "c": np.zeros(2), "d": (1, 2)}) == [
        "raw.a: numpy.float64", "raw.b[0]: numpy.int64", "raw.c: numpy.ndarray", "raw.d: builtins.tuple"]


def test_raw_of_a_study_built_from_numpy_is_plain_and_equals_the_yaml_studys():
    study = parse_study(numpy_study())
    assert not_plain(study.raw) == []
    assert study.raw == parse_study(yaml.safe_load(YAML_TEXT)).raw == yaml.safe_load(YAML_TEXT)
    assert json.loads(json.dumps(study.raw, allow_nan=False)) == study.raw
    assert yaml.safe_load(yaml.safe_dump(study.raw, sort_keys=False)) == study.raw


def test_study_yaml_of_a_study_built_from_numpy_is_safe_yaml():
    recorded = resolved_study(parse_study(numpy_study()))
    assert not_plain(recorded) == []
    assert yaml.safe_load(yaml.safe_dump(recorded, sort_keys=False)) == recorded


def test_raw_is_a_copy_the_callers_mapping_does_not_change():
    data = yaml.safe_load(YAML_TEXT)
    study = parse_study(data)
    data["grid"]["maneuver.duration"].append(35.0)
    assert study.raw["grid"]["maneuver.duration"] == [20.0, 25.0, 30.0]
