"""The scenario, study and slew-table schema reference, generated from the keys the parsers read.

Every entry comes from what validates it: the :class:`~scenarios.schema.keys.Key` declarations of
the scenario sections (:mod:`scenarios.schema.loader`, :mod:`scenarios.schema.model`), of the
study file (:mod:`scenarios.schema.study`, with its value generators and distributions) and of the
slew-table file (:mod:`scenarios.schema.table`, with the flags of ``slewbench table``), the typed
``Options`` dataclasses of the registered planners, controllers and magnetic field models. Each
entry gives the YAML path as errors name it, the type, unit, default, range or choices and the
meaning. :func:`schema_rst` renders the whole reference as a reStructuredText page,
:func:`schema_text` all or part of it for a terminal (``slewbench schema [KEY]``).

Keys (for :func:`schema_text`): a scenario key is its YAML path without list indices
(``maneuver.initial.omega``, ``planners.label``); a planner's option is
``planners.<planner>.<option>`` (``planners.collocation.intervals``), a controller's
``controller.<controller>.<option>``, a field model's ``environment.magnetic_field.<model>.<option>``;
``scenario`` selects every scenario key; study keys start with ``study.`` (``study.execution.workers``,
``study.grid.linspace``, ``study.monte_carlo.dispersions.normal``), and may also be written as the
reference prints their YAML path (``execution.workers``, ``grid.<path>.linspace``,
``monte_carlo.dispersions.<path>.normal``) or without ``study.`` (``grid.linspace``). A key selects
the entries it names and every entry below it; ``planners.options.intervals`` (the YAML path)
selects that option of every planner that has it. A slew-table file's keys start with ``table.``
(``table.refine.tolerance``); ``table`` selects them all.
"""
from __future__ import annotations

import dataclasses
import difflib
import inspect
import re
import sys
import textwrap
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from typing import Any

from controllers import CONTROLLERS
from ocp.dynamics.environment import MAGNETIC_FIELDS
from ocp.dynamics.orbits import ORBITS
from ocp.errors import excerpt
from planners import PLANNERS
from scenarios.errors import ScenarioError
from scenarios.schema.keys import (
    REQUIRED,
    Described,
    Key,
    OptionEntry,
    Section,
    option_entries,
    option_keys,
)
from scenarios.schema.loader import SCENARIO
from scenarios.schema.study import (
    CASE_SEED,
    COMBINATIONS,
    DISPERSION,
    DISTRIBUTIONS,
    EXECUTION,
    GRID_ENTRY,
    MONTE_CARLO,
    PRINCIPAL,
    PRINCIPAL_DISPERSION,
    ROBUSTNESS,
    STUDY,
    VALUE_GENERATORS,
)
from scenarios.schema.table import TABLE, TABLE_FILE, TABLE_FLAGS

__all__ = ["Entry", "Part", "options_text", "reference_parts", "schema_rst", "schema_text", "summary_line"]


@dataclass(frozen=True)
class Entry:
    """One key of the reference.

    Parameters
    ----------
    key : str
        How ``slewbench schema`` names it (see the module docstring).
    path : str
        Its YAML path as errors name it (``[i]`` for any list index, ``<path>`` for a scenario
        path of a study).
    type : str
        What it takes, in words.
    unit : str
        Unit as written in YAML; empty: none.
    default : str
        Its default in words (``required`` for a key that must be given).
    bounds : str
        Range or choices in reStructuredText; empty: none.
    meaning : str
        What it does (reStructuredText, one paragraph).
    aliases : tuple of str, optional
        Other names that select it (the YAML path of a registry entry's option).
    """

    key: str
    path: str
    type: str
    unit: str
    default: str
    bounds: str
    meaning: str
    aliases: tuple[str, ...] = ()


@dataclass(frozen=True)
class Part:
    """A section of the reference: one YAML mapping, or one registry entry's options.

    Parameters
    ----------
    key : str
        Its key (``simulation``, ``planners.collocation``, ``study.execution``).
    group : str
        The heading it is listed under (``Scenario file``, ``Planner options`` ...).
    title : str
        Its heading (reStructuredText).
    intro : str
        One paragraph (reStructuredText).
    entries : tuple of Entry
        Its keys.
    """

    key: str
    group: str
    title: str
    intro: str
    entries: tuple[Entry, ...]


def _literal(value: str) -> str:
    return f"``{value}``"


def _value_words(value: Any) -> str:
    """A default as YAML would write it."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(int(value)) + ".0" if value.is_integer() and abs(value) < 1e15 else f"{value:g}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_value_words(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k}: {_value_words(v)}" for k, v in value.items()) + "}"
    return str(value)


def _default(value: Any) -> str:
    if value is REQUIRED:
        return "required"
    if isinstance(value, Described):
        return value.words
    return _literal(_value_words(value))


def _bounds(bounds: str, choices: Iterable[str]) -> str:
    names = list(choices)
    listed = ("one of " + ", ".join(_literal(name) for name in names)) if names else ""
    return "; ".join(part for part in (bounds, listed) if part)


def _key_entry(key: Key, path: str, name: str, aliases: tuple[str, ...] = (), form: bool = False) -> Entry:
    """The entry of ``key``; a ``form`` (one way of writing a value, such as ``{linspace: ...}``)
    has no default."""
    return Entry(name, path, key.type, key.unit, "" if form else _default(key.default),
                 _bounds(key.bounds, key.choice_names), key.meaning, aliases)


def _walk(section: Section, path: str, name: str, aliases: tuple[str, ...] = ()) -> Iterator[Entry]:
    """Entries of ``section`` at YAML path ``path`` (empty: the top level) and key ``name``, and of
    the mappings nested in it."""
    for key in section.keys:
        key_path = f"{path}.{key.name}" if path else key.name
        key_name = f"{name}.{key.name}" if name else key.name
        key_aliases = tuple(f"{alias}.{key.name}" for alias in aliases)
        yield _key_entry(key, key_path, key_name, key_aliases)
        if key.section is not None:
            nested = f"{key_path}[i]" if key.entries else f"{key_path}.<name>" if key.named else key_path
            if key.named:  # the entry a name heads (its name is the user's)
                yield Entry(f"{key_name}.<name>", nested, "mapping", "", "", "", key.section.meaning,
                            tuple(f"{alias}.<name>" for alias in key_aliases))
            yield from _walk(key.section, nested, key_name, key_aliases)


def summary_line(cls: type, module_first: bool = True) -> str:
    """The first sentence of a registered class's docs, as ``slewbench list`` shows it: plain text
    for a terminal.

    Parameters
    ----------
    cls : type
        A planner, controller or field model class.
    module_first : bool, optional
        Take the sentence from the class's module docstring when it has one (one module per
        planner or controller); else from the class docstring. A class with a docstring of its
        own whose module registers several planners and controllers (a plugin's module) takes its
        own, as does a class whose module is not in ``sys.modules`` (loaded from a file by a
        plugin).

    Returns
    -------
    str
        The sentence, ending with a full stop, without reStructuredText markup: inline literals
        and emphasis lose their marks, a role keeps its text (the last dotted name after ``~``).
    """
    return _plain(_summary_rst(cls, module_first))


def _summary_rst(cls: type, module_first: bool = True) -> str:
    """:func:`summary_line` as reStructuredText (the schema page's part introductions)."""
    own = cls.__dict__.get("__doc__")  # not the base class's (a plugin's class without a docstring)
    module = sys.modules.get(cls.__module__)  # absent: a plugin's file loaded without sys.modules
    shared = own and sum(registered.__module__ == cls.__module__
                         for registered in (*PLANNERS.values(), *CONTROLLERS.values())) > 1
    module_doc = module.__doc__ if module_first and module is not None and not shared else None
    doc = (module_doc or (inspect.cleandoc(own) if own else "") or "(no description: its class has no docstring)").strip()
    paragraph = " ".join(doc.split("\n\n")[0].split())
    sentence = re.match(r"(.+?[.:])\s+(?=[A-Z*`])", paragraph)  # not at "eq. 38"
    return (sentence.group(1) if sentence else paragraph).rstrip(".:") + "."


def _option_entry(option: OptionEntry, path: str, key: str, aliases: tuple[str, ...]) -> Entry:
    return Entry(key, path, option.type, option.unit, _default(option.default),
                 _bounds(option.bounds, option.choices), option.meaning, aliases)


_SCENARIO_KEY = "scenario"
"""The key of the part that holds every scenario key (``slewbench schema scenario``)."""


def _scenario_parts() -> list[Part]:
    group = "Scenario file"
    parts = [Part(_SCENARIO_KEY, group, "Top-level keys", SCENARIO.meaning + " Its keys:",
                  tuple(_key_entry(key, key.name, key.name, (f"scenario.{key.name}",)) for key in SCENARIO.keys))]
    for key in SCENARIO.keys:
        if key.section is None or key.name == "controllers":
            continue
        path = f"{key.name}[i]" if key.entries else key.name
        intro = key.section.meaning
        aliases: tuple[str, ...] = (f"scenario.{key.name}",)
        if key.name == "controller":
            intro += " Each entry of ``controllers`` takes the same keys (``controllers[i].name`` ...)."
            aliases += ("controllers", "scenario.controllers")
        entries = tuple(_walk(key.section, path, key.name, aliases))
        parts.append(Part(key.name, group, _literal(key.name), intro, entries))
    return parts


def _registry_parts() -> list[Part]:
    parts = []
    for name, planner in PLANNERS.items():
        entries = tuple(_option_entry(option, f"planners[i].options.{option.name}", f"planners.{name}.{option.name}",
                                      (f"planners.options.{option.name}", f"scenario.planners.{name}.{option.name}"))
                        for option in option_entries(planner.Options))
        parts.append(Part(f"planners.{name}", "Planner options", _literal(name),
                          f"{_summary_rst(planner)} Options under ``planners[i].options`` when ``planners[i].name`` is "
                          f"{_literal(name)}" + (":" if entries else "; it has none."), entries))
    for name, controller in CONTROLLERS.items():
        entries = tuple(_option_entry(option, f"controller.options.{option.name}", f"controller.{name}.{option.name}",
                                      (f"controllers.{name}.{option.name}", f"controller.options.{option.name}",
                                       f"controllers.options.{option.name}",
                                       f"scenario.controller.{name}.{option.name}"))
                        for option in option_entries(controller.Options))
        parts.append(Part(f"controller.{name}", "Controller options", _literal(name),
                          f"{_summary_rst(controller)} Options under ``controller.options`` (or "
                          f"``controllers[i].options``) when its ``name`` is {_literal(name)}"
                          + (":" if entries else "; it has none."), entries))
    for name, kind in ORBITS.items():
        base = f"orbit.{name}"
        entries = tuple(_key_entry(key, f"orbit.{key.name}", f"{base}.{key.name}",
                                   (f"orbit.{key.name}", f"scenario.{base}.{key.name}"))
                        for key in option_keys(kind.Options))
        parts.append(Part(base, "Orbit kinds", _literal(name),
                          f"{_summary_rst(kind, module_first=False)} Keys next to ``type: {name}`` in ``orbit``:",
                          entries))
    for name, model in MAGNETIC_FIELDS.items():
        base = f"environment.magnetic_field.{name}"
        entries = tuple(_key_entry(key, f"environment.magnetic_field.{key.name}", f"{base}.{key.name}",
                                   (f"environment.magnetic_field.{key.name}", f"scenario.{base}.{key.name}"))
                        for key in option_keys(model.Options))
        parts.append(Part(base, "Magnetic field models", _literal(name),
                          f"{_summary_rst(model, module_first=False)} Keys next to ``model: {name}`` in "
                          "``environment.magnetic_field`` "
                          f"(``magnetic_field: {name}`` takes the defaults):", entries))
    return parts


def _study_parts() -> list[Part]:
    group = "Study file"
    root = Part("study", group, "Top-level study keys", STUDY.meaning + " Its keys:",
                tuple(_key_entry(key, key.name, f"study.{key.name}") for key in STUDY.keys))
    values: list[Entry] = [_key_entry(GRID_ENTRY, "grid.<path>", "study.grid.<path>", ("study.zip.<path>",),
                                      form=True)]
    for name, generator in VALUE_GENERATORS.items():
        values.append(_key_entry(generator.argument, f"grid.<path>.{name}", f"study.grid.{name}",
                                 (f"study.zip.{name}",), form=True))
        if generator.argument.section is not None:
            values += _walk(generator.argument.section, f"grid.<path>.{name}", f"study.grid.{name}",
                            (f"study.zip.{name}",))
    dispersions = "monte_carlo.dispersions.<path>"
    forms: list[Entry] = [_key_entry(DISPERSION, dispersions, f"study.{dispersions}", form=True)]
    for name, distribution in DISTRIBUTIONS.items():
        forms.append(_key_entry(distribution.argument, f"{dispersions}.{name}", f"study.monte_carlo.dispersions.{name}",
                                form=True))
        if distribution.argument.section is not None:
            forms += _walk(distribution.argument.section, f"{dispersions}.{name}",
                           f"study.monte_carlo.dispersions.{name}")
    for name, (key, _) in COMBINATIONS.items():
        forms.append(_key_entry(key, f"{dispersions}.{name}", f"study.monte_carlo.dispersions.{name}", form=True))
    principal = PRINCIPAL_DISPERSION.name
    forms.append(_key_entry(PRINCIPAL_DISPERSION, f"{dispersions}.{principal}",
                            f"study.monte_carlo.dispersions.{principal}", form=True))
    forms += _walk(PRINCIPAL, f"{dispersions}.{principal}", f"study.monte_carlo.dispersions.{principal}")
    forms.append(_key_entry(CASE_SEED, f"{dispersions}: {CASE_SEED.name}",
                            f"study.monte_carlo.dispersions.{CASE_SEED.name}", form=True))
    return [
        root,
        Part("study.grid", group, "``grid`` and ``zip`` entries",
             "Each entry of ``grid`` and ``zip`` is keyed by a scenario path and takes a list of values or "
             "``{<generator>: <argument>}``, a value generator of ``VALUE_GENERATORS`` (the same under ``zip``):",
             tuple(values)),
        Part("study.monte_carlo", group, "``monte_carlo``", MONTE_CARLO.meaning,
             tuple(_walk(MONTE_CARLO, "monte_carlo", "study.monte_carlo"))),
        Part("study.monte_carlo.dispersions", group, "Dispersions",
             "Each entry of ``monte_carlo.dispersions`` is keyed by a scenario path and draws from a distribution "
             "of ``DISTRIBUTIONS``, in the units of that key (a ``_deg`` key: degrees):", tuple(forms)),
        Part("study.execution", group, "``execution``", EXECUTION.meaning,
             tuple(_walk(EXECUTION, "execution", "study.execution"))),
        Part("study.robustness", group, "``robustness``", ROBUSTNESS.meaning,
             tuple(_walk(ROBUSTNESS, "robustness", "study.robustness"))),
    ]


_TABLE_KEY = "table"
"""The top-level key of a slew-table file (``slewbench schema table``)."""


def _flagged(entry: Entry) -> Entry:
    """A slew-table entry with the ``slewbench table`` flag that sets it (:data:`TABLE_FLAGS`)."""
    flag = TABLE_FLAGS.get(entry.path.removeprefix(f"{_TABLE_KEY}."))
    if flag is None:
        return entry
    return dataclasses.replace(entry, meaning=f"{entry.meaning} Flag: ``{flag}`` (wins over the file).")


def _table_parts() -> list[Part]:
    group = "Slew-table file"
    top = TABLE_FILE[_TABLE_KEY]
    root = Part(_TABLE_KEY, group, "``table``", TABLE_FILE.meaning + " Its keys:",
                (_key_entry(top, _TABLE_KEY, _TABLE_KEY),) + tuple(
                    _flagged(_key_entry(key, f"{_TABLE_KEY}.{key.name}", f"{_TABLE_KEY}.{key.name}"))
                    for key in TABLE.keys))
    parts = [root]
    for key in TABLE.keys:
        if key.section is not None:
            path = f"{_TABLE_KEY}.{key.name}"
            parts.append(Part(path, group, _literal(path), key.section.meaning,
                              tuple(_flagged(entry) for entry in _walk(key.section, path, path))))
    return parts


def reference_parts() -> list[Part]:
    """Every part of the reference, built from the keys and registries as they are now.

    Returns
    -------
    list of Part
        The scenario file's sections, every registered planner's, controller's and field
        model's options, the study file's sections, then the slew-table file's.
    """
    return _scenario_parts() + _registry_parts() + _study_parts() + _table_parts()


# --- reStructuredText ------------------------------------------------------------------------------

_INTRO = """\
Every key a scenario, study or slew-table file accepts, generated from the code that reads it: a
key that is not listed here is an error, and every listed default is the one applied. A path such as
``planners[i].options.weight`` is how errors name the key; ``[i]`` stands for any list index and
``<path>`` for a scenario path of a study. Units are those written in the file (``_deg`` keys in
degrees, ``_km`` in kilometres, ``_s`` in seconds); the loader converts them to SI. Unknown and
duplicate keys are errors. ``slewbench schema KEY`` prints the entries below a key, for example
``slewbench schema maneuver``, ``slewbench schema planners.collocation``,
``slewbench schema study.execution`` or ``slewbench schema table.refine``."""

_GROUPS = {
    "Scenario file": "The keys of a scenario file, by section.",
    "Planner options": "The options of each registered planner (``planners[i].options``).",
    "Controller options": "The options of each registered controller (``controller.options`` or "
                          "``controllers[i].options``).",
    "Orbit kinds": "The kinds of ``orbit`` (``ORBITS``, by ``orbit.type``) and their keys.",
    "Magnetic field models": "The models of ``environment.magnetic_field`` (``MAGNETIC_FIELDS``) and their options.",
    "Study file": "The keys of a trade-study file (``slewbench sweep``).",
    "Slew-table file": "The keys of a slew-table file (``slewbench table``), and the flags that set them.",
}


def _one_line(text: str) -> str:
    return " ".join(text.split())


def _cell(text: str) -> str:
    return _one_line(text) or "\N{EM DASH}"


def _plain_cell(text: str) -> str:
    """Words that are not reStructuredText, escaped."""
    return _cell(re.sub(r"([\\*`|_])", r"\\\1", text))


def _label(key: str) -> str:
    return "schema-" + re.sub(r"[^a-z0-9]+", "-", key.lower()).strip("-")


def _table(entries: tuple[Entry, ...]) -> list[str]:
    lines = [".. list-table::", "   :header-rows: 1", "   :widths: 24 14 7 11 14 30", "",
             "   * - YAML path", "     - Type", "     - Unit", "     - Default", "     - Range / choices",
             "     - Meaning"]
    for entry in entries:
        default = entry.default if entry.default.startswith("``") else _plain_cell(entry.default)
        lines += [f"   * - {_literal(entry.path)}", f"     - {_plain_cell(entry.type)}",
                  f"     - {_plain_cell(entry.unit)}", f"     - {default}", f"     - {_cell(entry.bounds)}",
                  f"     - {_cell(entry.meaning)}"]
    return lines


def _heading(text: str, mark: str) -> list[str]:
    return [text, mark * len(text), ""]


def schema_rst() -> str:
    """The whole reference as one reStructuredText page.

    Returns
    -------
    str
        A page titled "Scenario, study and slew-table schema": one section per group (scenario
        file, planner, controller and field model options, study file, slew-table file), one
        subsection with a table
        per part; each part has the label ``schema-<key>`` (``schema-planners-collocation``).
    """
    lines = _heading("Scenario, study and slew-table schema", "=") + [_INTRO, ""]
    group = None
    for part in reference_parts():
        if part.group != group:
            group = part.group
            lines += _heading(group, "-") + [_GROUPS[group], ""]
        lines += [f".. _{_label(part.key)}:", ""] + _heading(part.title, "~") + [_one_line(part.intro), ""]
        if part.entries:
            lines += _table(part.entries) + [""]
    return "\n".join(lines)


# --- terminal ----------------------------------------------------------------------------------------

_ROLE = re.compile(r":[a-z:]+:`~?([^`<]*?)(?:\s*<[^>]*>)?`")
_LITERAL = re.compile(r"``(.+?)``")
_EMPHASIS = re.compile(r"(?<![\w*\\])(\*\*?)(?=\S)(.+?)(?<=\S)\1(?![\w*])")
"""``*emphasis*`` or ``**strong**`` as reStructuredText recognises it: its marks next to the words."""


def _plain(text: str) -> str:
    """reStructuredText reduced to plain words for a terminal: ``x`` and *x* give x,
    :math:`x` gives x, :class:`~a.b.C` gives C."""
    def role(match: re.Match[str]) -> str:
        target = match.group(1)
        return target.rsplit(".", 1)[-1] if match.group(0).startswith(":") and "`~" in match.group(0) else target
    pieces = _LITERAL.split(_ROLE.sub(role, text))  # odd pieces: the literals' contents, kept as they are
    return "".join(piece if i % 2 else _EMPHASIS.sub(r"\2", piece) for i, piece in enumerate(pieces)).replace("\\", "")


def _normal(key: str) -> str:
    return re.sub(r"\[[^\]]*\]", "", key.strip()).strip(".")


def _names(entry: Entry) -> tuple[str, ...]:
    """The keys that select ``entry``: its key, its YAML path without indices and its aliases; a
    study entry also by its path as the reference prints it (``grid.<path>.linspace``,
    ``monte_carlo.samples``) and by its key without ``study.`` (``grid.linspace``), except the
    study's ``scenario``: that name selects the scenario file's keys."""
    if not entry.key.startswith("study."):
        return (entry.key, _normal(entry.path)) + entry.aliases
    bare = (_normal(entry.path),) + tuple(name.removeprefix("study.") for name in (entry.key,) + entry.aliases)
    return (entry.key,) + entry.aliases + tuple(name for name in bare if name != _SCENARIO_KEY)


def _selected(part: Part, key: str) -> list[Entry]:
    return [entry for entry in part.entries
            if any(name == key or name.startswith(key + ".") for name in _names(entry))]


def _close_matches(key: str, parts: list[Part]) -> list[str]:
    names = sorted({entry.key for part in parts for entry in part.entries} | {part.key for part in parts})
    last = key.rsplit(".", 1)[-1]
    ending = [name for name in names if name.endswith("." + last) or name == last]
    close = difflib.get_close_matches(key, names, n=8, cutoff=0.6)
    return list(dict.fromkeys(ending + close))[:8]


def _entry_text(entry: Entry) -> list[str]:
    facts = [entry.type + (f" [{entry.unit}]" if entry.unit else "")]
    if entry.default:
        facts.append(entry.default if entry.default.startswith("required") else f"default {_plain(entry.default)}")
    if entry.bounds:
        facts.append(_plain(entry.bounds))
    return [entry.path] + [f"{'    ' if i == 0 else '      '}{line}" for i, line in
                           enumerate(textwrap.wrap("; ".join(facts), 94))] + \
        textwrap.wrap(_plain(_one_line(entry.meaning)), 96, initial_indent="    ", subsequent_indent="    ")


def schema_text(key: str | None = None) -> str:
    """The reference, or the part of it under ``key``, as plain text for a terminal.

    Parameters
    ----------
    key : str or None, optional
        A key as the module docstring spells it (``maneuver``, ``simulation.sensor_noise.seed``,
        ``planners.collocation``, ``study.execution``, ``table.refine``; list indices such as ``[0]`` are
        ignored); ``None`` (default): everything.

    Returns
    -------
    str
        One block per entry (YAML path; type, unit, default and range; meaning) under the
        heading of its part.

    Raises
    ------
    ScenarioError
        At ``key`` when it selects nothing; the message lists close matches.
    """
    parts = reference_parts()
    wanted = None if key is None else _normal(key)
    lines: list[str] = []
    for part in parts:
        named = wanted is not None and part.key == wanted  # the part itself (a controller without options too)
        entries = part.entries if wanted is None or named else tuple(_selected(part, wanted))
        if not entries and not named and (wanted is not None or not part.intro):
            continue
        title = f"{part.group}: {_plain(part.title)}"
        lines += [title, "=" * len(title)] + textwrap.wrap(_plain(_one_line(part.intro)), 100) + [""]
        for entry in entries:
            lines += _entry_text(entry) + [""]
    if not lines:
        matches = _close_matches(wanted or "", parts)
        raise ScenarioError("", f"{excerpt(key)} is not a key of the scenario, study or slew-table schema"  # quoted, bounded
                            + (f"; close matches: {', '.join(matches)}" if matches else ""))
    return "\n".join(lines).rstrip() + "\n"


_REGISTRY_PARTS: tuple[tuple[str, str, dict[str, Any]], ...] = (("planners.", "planner", PLANNERS),
                                                                  ("controller.", "controller", CONTROLLERS))
"""The reference parts of a registry entry's options: the key prefix, what the entry is, its registry."""


def options_text(name: str) -> str:
    """The options of a registered planner or controller as a table for a terminal (``slewbench
    list --options NAME``), from the same entries as the schema reference.

    Parameters
    ----------
    name : str
        A registry name of :data:`planners.PLANNERS` or :data:`controllers.CONTROLLERS` (both
        are listed if it names one of each).

    Returns
    -------
    str
        Per registry entry: a heading (its name, kind and summary), one line per option (name,
        type, unit, default, range or choices), and where the options are explained.

    Raises
    ------
    ScenarioError
        ``name`` is neither a planner nor a controller; the message lists close matches.
    """
    parts = {part.key: part for part in reference_parts()}
    lines: list[str] = []
    for prefix, kind, registry in _REGISTRY_PARTS:
        part = parts.get(prefix + name)
        if part is None:
            continue
        lines += [f"{name} ({kind}): {summary_line(registry[name])}"]
        if not part.entries:
            lines += ["  no options", ""]
            continue
        table = [("option", "type", "unit", "default", "range")]
        table += [(entry.key.rsplit(".", 1)[-1], entry.type, entry.unit or "-", _plain(entry.default) or "-",
                   _plain(entry.bounds) or "-") for entry in part.entries]
        widths = [max(len(line[i]) for line in table) for i in range(4)]
        lines += ["  " + "  ".join(cell.ljust(width) for cell, width in zip(line, widths)) + "  " + line[4]
                  for line in table]
        lines += [f"(meanings: slewbench schema {part.key})", ""]
    if not lines:
        names = sorted({entry for _, _, registry in _REGISTRY_PARTS for entry in registry})
        close = difflib.get_close_matches(name, names, n=5, cutoff=0.5)
        raise ScenarioError("", f"{excerpt(name)} is neither a registered planner nor controller"
                            + (f"; close matches: {', '.join(close)}" if close else
                               "; `slewbench list` shows them"))
    return "\n".join(lines).rstrip() + "\n"
