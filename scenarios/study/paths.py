"""Scenario paths as a trade study spells them: ``planners[1].options.weight``,
``spacecraft.inertia[2]``, ``planners[label=smooth].options.torque_fraction``.

:func:`parse_path` splits a path into steps; :func:`get_path` and :func:`set_path` read and write
a parsed scenario mapping (plain YAML data) along it, raising :class:`ScenarioError` naming the
step that does not reach the scenario.
"""
from __future__ import annotations

import re
from typing import Any

from ocp.errors import excerpt
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
        raise ScenarioError(where, f"expected a scenario path such as 'maneuver.duration', got {excerpt(path)}")
    steps: list[Step] = []
    position = 0
    while position < len(path):
        match = _TOKEN.match(path, position)
        if not match or (position == 0 and path.startswith(".")):
            raise ScenarioError(where, f"cannot read the scenario path {excerpt(path)} at {path[position:][:30]!r}; "
                                       "expected key.key, key[index] or key[label=value]")
        key, index, selector, value = match.groups()
        if key is not None:
            if position > 0 and not path[position] == ".":
                raise ScenarioError(where, f"expected '.' before {excerpt(key)} in {excerpt(path)}")
            steps.append(key)
        elif index is not None:
            steps.append(int(index))
        else:
            steps.append((selector, value.strip().strip("'\"")))
        position = match.end()
    if not isinstance(steps[0], str):
        raise ScenarioError(where, f"a scenario path starts with a key, got {excerpt(path)}")
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
    if isinstance(step, str):
        if not isinstance(container, dict):
            raise ScenarioError(where, f"{_describe(done) or '(top level)'} is not a mapping, so it has no key "
                                       f"{excerpt(step)}")
        if step not in container and not create:
            raise ScenarioError(where, f"{_describe(done + [step])} is not in the base scenario")
        return step
    if not isinstance(container, list):
        raise ScenarioError(where, f"{_describe(done) or '(top level)'} is not a list (got {type(container).__name__})")
    if isinstance(step, int):
        if not -len(container) <= step < len(container):
            raise ScenarioError(where, f"{_describe(done) or '(top level)'} has {len(container)} entries; index "
                                       f"{step} is out of range")
        return step
    key, value = step
    matches = [i for i, item in enumerate(container) if isinstance(item, dict) and str(item.get(key)) == value]
    if len(matches) != 1:
        found = excerpt([item.get(key) for item in container if isinstance(item, dict)])
        raise ScenarioError(where, f"{_describe(done) or '(top level)'} has {'no' if not matches else 'several'} "
                                   f"entries with {key[:60]} = {excerpt(value)}; found {found}")
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


def with_values(data: Any, updates: list[tuple[list[Step], Any, str]]) -> Any:
    """``data`` with each value set at its path, as :func:`set_path` applied in order to a deep copy
    would give, without copying what the paths do not reach.

    Only the mappings and lists along each path are copied (once); everything else is shared with
    ``data``, which is not changed. A study's cases share the base scenario this way: treat the
    result as read-only.

    Parameters
    ----------
    data : Any
        A scenario mapping (plain YAML data), not changed.
    updates : list of (steps, value, where)
        Parsed paths (:func:`parse_path`), the values to set and the study entries that set them
        (for error messages).

    Returns
    -------
    Any
        The new mapping.

    Raises
    ------
    ScenarioError
        Naming the step that does not reach ``data``.
    """
    fresh: set[int] = set()

    def own(container: Any) -> Any:
        if id(container) in fresh:
            return container
        copied = dict(container) if isinstance(container, dict) else list(container)
        fresh.add(id(copied))
        return copied

    root = own(data) if isinstance(data, (dict, list)) else data
    for steps, value, where in updates:
        node = root
        for position, step in enumerate(steps[:-1]):
            key = _child(node, step, steps[:position], where, create=True)
            if isinstance(node, dict) and (key not in node or node[key] is None):
                child: Any = {}
                fresh.add(id(child))
            else:
                child = node[key]
                if isinstance(child, (dict, list)):
                    child = own(child)
            node[key] = child
            node = child
        node[_child(node, steps[-1], steps[:-1], where, create=True)] = value
    return root
