"""The sign-off record of a run's ``report.html``: what was run, on which plant, with which sensors,
against which requirements, and what each row achieved.

Everything here is read from the run's objects, never written per key: the provenance is
:func:`~scenarios.output.provenance.run_provenance`'s (every entry but the scenario's data, nested
entries flattened to dotted names); the plant is the scenario's ``truth:`` section as written,
each truth key beside the design model's value at the same key of the scenario (``truth.wheels.X``
beside ``spacecraft.wheels.X``, ``truth.spacecraft.X`` beside ``spacecraft.X``); the sensors are the
:class:`~ocp.estimation.loop.SensorSuite`'s members present and the scenario's ``simulation.sensors``,
``simulation.estimator`` and ``simulation.sensor_noise`` as written; the requirements are each
requirement's own words (``describe()``), and per row and scope each bounded field of its score
(:data:`BOUNDS`) with its unit from :func:`~scenarios.requirements.fields.field_info`, the bound, the
value achieved and the run's verdict on the requirement in that scope: the score's own verdict, its
field ``met`` (:data:`~scenarios.requirements.fields.VERDICT`, the scoring's
:attr:`~scenarios.requirements.scoring.Score.met`), never read from the row's message. This module
may not import the scoring, which loads the model: ``tests/test_report_record.py`` checks that the
bound of the unrealised torque, :data:`UNREALISED_SHARE`, is the scoring's.
"""
from __future__ import annotations

import dataclasses
import json
from collections.abc import Callable, Iterator
from typing import TYPE_CHECKING, Any

import numpy as np

from planners.reference import JUMP_TOLERANCE
from scenarios.output.provenance import run_provenance
from scenarios.output.report.page import Column, Page
from scenarios.requirements.fields import VERDICT, field_info, requirement_kind

if TYPE_CHECKING:
    from scenarios.output.results import Row, RunResults
    from scenarios.requirements.spec import Requirements
    from scenarios.schema.loader import Scenario

__all__ = ["BOUNDS", "DESIGN_KEYS", "UNREALISED_SHARE", "Bound", "add_record", "plant_entries", "provenance_entries", "requirement_lines",
           "sensor_entries"]

UNREALISED_SHARE = 0.01
"""The unrealised torque allowed, as a share of the reference's peak torque
(:data:`~scenarios.requirements.scoring.UNREALISED_TOLERANCE`)."""

Bound = tuple[str, str | None, str, Any]
"""A bounded field of a requirement's score: ``(field, time field or None, relation, bound)``; the
bound a number, or words when it is relative to something the score does not hold."""


def _pointing(requirement: Any, fields: dict[str, Any]) -> list[Bound]:
    return [("min_margin_deg", "min_margin_time_s", "≥", 0.0)]


def _actuators(requirement: Any, fields: dict[str, Any]) -> list[Bound]:
    bounds: list[Bound] = []
    for name in fields:
        if name.endswith("_time_s") or name in (VERDICT, "unrealised_torque_allowed"):
            continue
        if name == "rate_jump":
            bounds.append((name, "rate_jump_time_s", "≤", JUMP_TOLERANCE))
        elif name == "unrealised_torque":  # the score's bound; in words for a run scored without it
            allowed = fields.get("unrealised_torque_allowed")
            bounds.append((name, "unrealised_torque_time_s", "≤", allowed if isinstance(allowed, (int, float))
                           else f"{UNREALISED_SHARE:.0%} of the reference's peak torque"))
        elif field_info(f"actuators.{name}").unit == "–":  # an actuator quantity's demand over its limit
            bounds.append((name, f"{name}_time_s", "≤", requirement.allowed))
    return bounds


def _rate(requirement: Any, fields: dict[str, Any]) -> list[Bound]:
    return [("peak_rate", "peak_time_s", "≤", requirement.max_rate)]


def _final(requirement: Any, fields: dict[str, Any]) -> list[Bound]:
    return [(name, "from_s", "≤", "none (scored only)" if bound is None else bound)
            for name, bound in (("worst_error_deg", requirement.error_deg), ("worst_rate_error", requirement.rate))]


DESIGN_KEYS = {"disturbance.constant": "environment.disturbance_torque"}
"""The design model's key of a ``truth:`` key that is not ``spacecraft.<key>`` or ``<key>`` (without
the ``truth.`` prefix)."""

BOUNDS: dict[str, Callable[[Any, dict[str, Any]], list[Bound]]] = {
    "pointing": _pointing, "actuators": _actuators, "rate": _rate, "final": _final}
"""Per requirement kind, the bounded fields of its score given the requirement and the fields scored."""


def _flat(value: Any, path: str) -> Iterator[tuple[str, Any]]:
    """``(dotted path, value)`` of the leaves of nested dicts (lists are leaves)."""
    if isinstance(value, dict) and value:
        for key, item in value.items():
            yield from _flat(item, f"{path}.{key}" if path else str(key))
    else:
        yield path, value


def _text(value: Any) -> str:
    """A value as plain text: numbers as written, lists and mappings as compact JSON."""
    if isinstance(value, str):
        return value
    if isinstance(value, np.ndarray):
        value = value.tolist()
    return json.dumps(value, ensure_ascii=False, default=str)


def _at(data: Any, path: str) -> tuple[bool, Any]:
    """The value at a dotted path of nested dicts, and whether it is there."""
    for key in path.split("."):
        if not isinstance(data, dict) or key not in data:
            return False, None
        data = data[key]
    return True, data


def provenance_entries(results: RunResults) -> list[tuple[str, str]]:
    """The run's provenance as ``(entry, value)`` texts.

    Parameters
    ----------
    results : RunResults
        The run.

    Returns
    -------
    list of (str, str)
        Every entry of :func:`~scenarios.output.provenance.run_provenance` but ``scenario`` (the
        scenario's data, shown in the other tables), nested ones as dotted names
        (``libraries.numpy``, ``seeds.simulation.sensor_noise.seed``).
    """
    provenance = run_provenance(results.scenario, results.finished)
    provenance.pop("scenario", None)
    entries = []
    for key, value in provenance.items():
        if isinstance(value, dict) and value:
            entries += [(f"{key}.{path}", _text(item)) for path, item in _flat(value, "")]
        else:
            entries.append((key, "-" if value is None else _text(value)))
    return entries


def plant_entries(scenario: Scenario) -> list[tuple[str, str, str]]:
    """What the closed loop's plant (the truth model) has that differs from the design model.

    Parameters
    ----------
    scenario : Scenario
        The run's scenario.

    Returns
    -------
    list of (str, str, str)
        ``(truth key, design value, truth value)`` per key of the scenario's ``truth:`` section as
        written (the design value: the scenario's at ``spacecraft.<key>`` for ``truth.spacecraft.<key>``
        and ``truth.wheels.<key>`` (``spacecraft.wheels.<key>``), at :data:`DESIGN_KEYS`' key for
        those it names, ``-`` when the scenario states none: a default, or an effect the design
        model does not have); for a scenario built without its data, the truth model's fields that
        are set, with ``-`` for the design. Empty without a truth model.
    """
    truth = scenario.truth
    if truth is None:
        return []
    data = scenario.data
    if data is None or not isinstance(data.get("truth"), dict):
        return [(item.name, "-", _text(getattr(truth.truth, item.name)))
                for item in dataclasses.fields(truth.truth)
                if getattr(truth.truth, item.name) is not None and getattr(truth.truth, item.name) != ()]
    entries = []
    for path, value in _flat(data["truth"], ""):
        candidates = [DESIGN_KEYS[path]] if path in DESIGN_KEYS else [path, f"spacecraft.{path.removeprefix('spacecraft.')}"]
        design = next((found for found in (_at(data, c) for c in candidates) if found[0]), (False, None))
        entries.append((f"truth.{path}", _text(design[1]) if design[0] else "-", _text(value)))
    return entries


def sensor_entries(scenario: Scenario) -> tuple[str, list[tuple[str, str]]]:
    """The sensors and estimator in the loop: a sentence and the scenario's settings of them.

    Parameters
    ----------
    scenario : Scenario
        The run's scenario.

    Returns
    -------
    sentence : str
        Which members of the :class:`~ocp.estimation.loop.SensorSuite` the loop has (and their
        models' class names), or that the controller measures through ``sensor_noise`` alone.
    entries : list of (str, str)
        ``(key, value)`` of ``simulation.sensors``, ``simulation.estimator`` and
        ``simulation.sensor_noise`` as the scenario writes them (empty without its data).
    """
    suite = scenario.simulation.sensors
    present = [] if suite is None else [(item.name.replace("_", " "), type(getattr(suite, item.name)).__name__)
                                        for item in dataclasses.fields(suite) if getattr(suite, item.name) is not None]
    if present:
        sentence = ("In the loop: " + ", ".join(f"{name} ({model})" for name, model in present)
                    + ("" if suite is not None and suite.estimator is not None
                       else "; no estimator: the controller is fed the measurements") + ".")
    else:
        sentence = ("No sensor models and no estimator: the controller is fed the true state through "
                    "simulation.sensor_noise only.")
    simulation = (scenario.data or {}).get("simulation") or {}
    entries = [(f"simulation.{key}.{path}" if path else f"simulation.{key}", _text(value))
               for key in ("sensors", "estimator", "sensor_noise") if simulation.get(key) is not None
               for path, value in _flat(simulation[key], "")]
    return sentence, entries


def _requirement(requirements: Requirements, name: str) -> Any:
    kind = requirement_kind(name)
    if kind == "pointing":
        return next((r for r in requirements.pointing if r.name == name), None)
    return getattr(requirements, kind)


def _scope_words(scope: str) -> str:
    return scope.replace("_", " ")


def _verdict(row: Row, scope: str, name: str, fields: dict[str, Any]) -> str:
    """``met`` or ``broken``: the score's verdict (its field :data:`~scenarios.requirements.fields.VERDICT`)."""
    met = fields.get(VERDICT)
    if not isinstance(met, bool):
        raise TypeError(f"row {row.label!r}: the {_scope_words(scope)} score of requirement {name!r} has no verdict "
                         f"(its field {VERDICT!r} is {met!r}, not true or false): the runner stores one with every score")
    return "met" if met else "broken"


def requirement_lines(results: RunResults) -> list[list[Any]]:
    """Per row, scope, requirement and bounded field: the bound, the value achieved and the verdict.

    Parameters
    ----------
    results : RunResults
        The run.

    Returns
    -------
    list of list
        ``[row, scope, requirement, field, unit, relation and bound, achieved, at [s], within bound,
        verdict]``: the bounded fields of :data:`BOUNDS`, the unit from
        :func:`~scenarios.requirements.fields.field_info`, when (the field's time; for the final
        requirement its window's start), whether this quantity is within its bound (``yes``, ``no``;
        ``-`` for a bound in words or a value missing; a plain comparison, without the scoring's
        rounding slack of 1e-9 relative) and the verdict ``met`` or ``broken`` (the run's, on the
        whole requirement in that scope, all its quantities: the score's field ``met``; the same on
        each of its lines). Rows without scores give none.

    Raises
    ------
    TypeError
        A score without its verdict (``met`` missing or not a bool).
    """
    lines = []
    requirements = results.scenario.requirements
    for row in results.rows:
        for scope, scored in (row.requirements or {}).items():
            for name, fields in scored.items():
                requirement = _requirement(requirements, name)
                if requirement is None:
                    continue
                verdict = _verdict(row, scope, name, fields)
                for field, when, relation, bound in BOUNDS[requirement_kind(name)](requirement, fields):
                    value = fields.get(field)
                    numeric = isinstance(bound, (int, float))
                    bound_text = f"{relation} {bound:.6g}" if numeric else f"{relation} {bound}"
                    within = ("-" if not numeric or value is None
                              else "yes" if (value >= bound if relation == "≥" else value <= bound) else "no")
                    lines.append([row.label, _scope_words(scope), name, field, field_info(f"{name}.{field}").unit,
                                  bound_text, value, None if when is None else fields.get(when), within, verdict])
    return lines


def _requirement_words(requirements: Requirements) -> list[list[str]]:
    rows = [[r.name, "pointing", r.describe()] for r in requirements.pointing]
    for name in ("actuators", "rate", "final"):
        requirement = getattr(requirements, name)
        if requirement is not None:
            stated = getattr(requirement, "stated", True)
            rows.append([name, name, requirement.describe() + ("" if stated else " (not stated: margin 0)")])
    return rows


def add_record(page: Page, results: RunResults) -> None:
    """Add the sign-off record's sections to a run's page (module docstring).

    Parameters
    ----------
    page : Page
        The run's page.
    results : RunResults
        The run.
    """
    scenario = results.scenario
    page.section("Provenance", "What ran, when, and with which seeds (as results.json's provenance).")
    page.table("provenance", [Column("entry"), Column("value")], provenance_entries(results), wrap=True)
    plant = plant_entries(scenario)
    if plant:
        page.section("Plant", "The closed loop integrates a truth model that differs from the design model the "
                              "planners and controllers use, in these keys of the scenario's truth section (design "
                              "model: the scenario's value at the same key; -: none stated, a default or an effect "
                              "the design model does not have):")
        page.table("plant", [Column("truth key"), Column("design model"), Column("truth model")], plant, wrap=True)
    else:
        page.section("Plant", "The closed loop integrates the design model (the scenario has no truth section).")
    sentence, sensors = sensor_entries(scenario)
    page.section("Sensors and estimator", sentence)
    if sensors:
        page.table("sensors", [Column("setting"), Column("value")], sensors, wrap=True)
    words = _requirement_words(scenario.requirements)
    if not words:
        page.section("Requirements", "The scenario states no requirements.")
        return
    page.section("Requirements", "Each requirement as stated, then per row and scope its bounded quantities: the "
                                 "bound, the value achieved, when (for the final requirement: its window's start), "
                                 "whether this quantity is within its bound, and the run's verdict on the whole "
                                 "requirement in that scope, all its quantities together: a requirement is broken "
                                 "when any one of them is, so a quantity within its bound may sit on a line whose "
                                 "requirement is broken by another.")
    page.table("requirements", [Column("requirement"), Column("kind"), Column("bound")], words, wrap=True)
    lines = requirement_lines(results)
    if lines:
        page.table("requirement-scores",
                   [Column("row"), Column("scope"), Column("requirement"), Column("quantity"), Column("unit"),
                    Column("required"), Column("achieved", numeric=True), Column("at", "s", numeric=True),
                    Column("this quantity within its bound", order=("no", "yes")),
                    Column("requirement (all its quantities)", order=("broken", "met"))], lines,
                   wrap=True)
