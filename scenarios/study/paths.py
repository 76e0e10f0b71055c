"""Scenario paths as a trade study spells them: ``planners[1].options.weight``,
``spacecraft.inertia[2]``, ``planners[label=smooth].options.torque_fraction``.

:func:`parse_path` splits a path into steps; :func:`get_path` and :func:`set_path` read and write
a parsed scenario mapping (plain YAML data) along it, raising :class:`ScenarioError` naming the
step that does not reach the scenario.
"""
from __future__ import annotations

import re
from typing import Any

from scenarios.errors import ScenarioError

Step = str | int | tuple[str, str]  # mapping key, list index, (key, value) selector
_TOKEN = re.compile(r"\.?([A-Za-z_][A-Za-z0-9_]*)|\[(-?\d+)\]|\[([A-Za-z_][A-Za-z0-9_]*)=([^\]]+)\]")


def parse_path(path: str, where: str) -> list[Step]:
    """Steps of ``path``; ``where`` names the study entry in errors.

    Parameters
    ----------
    path : str
        A scenario path, for example ``planners[label=smooth].options.weight``.
    where : str
        The study path of the entry (``grid.<path>``), for error messages.

    Returns
    -------
    list of Step
        ``str`` keys, ``int`` list indices, ``(key, value)`` list selectors.
    """
    if not isinstance(path, str) or not path:
        raise ScenarioError(where, f"expected a scenario path such as 'maneuver.duration', got {path!r}")
    steps: list[Step] = []
    position = 0
    while position < len(path):
        match = _TOKEN.match(path, position)
        if not match or (position == 0 and path.startswith(".")):
            raise ScenarioError(where, f"cannot read the scenario path {path!r} at {path[position:][:30]!r}; "
                                       "expected key.key, key[index] or key[label=value]")
        key, index, selector, value = match.groups()
        if key is not None:
            if position > 0 and not path[position] == ".":
                raise ScenarioError(where, f"expected '.' before {key!r} in {path!r}")
            steps.append(key)
        elif index is not None:
            steps.append(int(index))
        else:
            steps.append((selector, value.strip().strip("'\"")))
        position = match.end()
    if not isinstance(steps[0], str):
        raise ScenarioError(where, f"a scenario path starts with a key, got {path!r}")
    return steps


def _describe(steps: list[Step]) -> str:
    out = ""
    for step in steps:
        if isinstance(step, str):
            out += f".{step}" if out else step
        elif isinstance(step, int):
            out += f"[{step}]"
        else:
            out += f"[{step[0]}={step[1]}]"
    return out


def _child(container: Any, step: Step, done: list[Step], where: str, create: bool) -> Any:
    """The index or key under which ``step`` is found in ``container``."""
    here = _describe(done) or "(top level)"
    if isinstance(step, str):
        if not isinstance(container, dict):
            raise ScenarioError(where, f"{here} is not a mapping, so it has no key {step!r}")
        if step not in container and not create:
            raise ScenarioError(where, f"{_describe(done + [step])} is not in the base scenario")
        return step
    if not isinstance(container, list):
        raise ScenarioError(where, f"{here} is not a list (got {type(container).__name__})")
    if isinstance(step, int):
        if not -len(container) <= step < len(container):
            raise ScenarioError(where, f"{here} has {len(container)} entries; index {step} is out of range")
        return step
    key, value = step
    matches = [i for i, item in enumerate(container) if isinstance(item, dict) and str(item.get(key)) == value]
    if len(matches) != 1:
        found = [item.get(key) for item in container if isinstance(item, dict)]
        raise ScenarioError(where, f"{here} has {'no' if not matches else 'several'} entries with "
                                   f"{key} = {value!r}; found {found}")
    return matches[0]


def get_path(data: Any, steps: list[Step], where: str) -> Any:
    """The value at ``steps`` in ``data``.

    Parameters
    ----------
    data : Any
        A scenario mapping (plain YAML data).
    steps : list of Step
        The parsed path (:func:`parse_path`).
    where : str
        The study entry, for error messages.

    Returns
    -------
    Any
        The value found there (not a copy).

    Raises
    ------
    ScenarioError
        Naming the step that does not reach ``data``.
    """
    node = data
    for position, step in enumerate(steps):
        node = node[_child(node, step, steps[:position], where, create=False)]
    return node


def set_path(data: Any, steps: list[Step], value: Any, where: str) -> None:
    """Set ``value`` at ``steps`` in ``data`` (in place).

    Missing mapping keys are created (the scenario loader then rejects a key it does not know, so
    a misspelt path cannot pass silently); list indices and label selectors must reach an existing
    entry.

    Parameters
    ----------
    data : Any
        A scenario mapping (plain YAML data), changed in place.
    steps : list of Step
        The parsed path (:func:`parse_path`).
    value : Any
        The value to set.
    where : str
        The study entry, for error messages.

    Raises
    ------
    ScenarioError
        Naming the step that does not reach ``data``.
    """
    node = data
    for position, step in enumerate(steps[:-1]):
        key = _child(node, step, steps[:position], where, create=True)
        if isinstance(node, dict) and (key not in node or node[key] is None):
            node[key] = {}
        node = node[key]
    node[_child(node, steps[-1], steps[:-1], where, create=True)] = value
