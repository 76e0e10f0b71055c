"""The vocabulary the scenario and study schema is written in.

A :class:`Key` says how one YAML key is read (its reader calls the typed accessors of
:class:`~scenarios.schema.node.Node`, whose errors name the YAML path) and how the reference
describes it: type, unit, default, range or choices, and a one-line meaning. A :class:`Section` is
a mapping of keys. The parse code reads every value through its key (:meth:`Key.value`,
:meth:`Section.read`), and :mod:`scenarios.schema.reference` renders the same keys, so that the
reference cannot drift from what is accepted.

Options declared as a typed dataclass (:mod:`ocp.options`: planners, controllers, magnetic field
models) are described by :func:`option_entries`; :func:`option_keys` reads such a dataclass with the
scenario's own checks (the magnetic field models' options).
"""
from __future__ import annotations

import dataclasses
import datetime
import functools
import inspect
import re
import types
import typing
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal, Union

import numpy as np

from ocp import quat
from ocp.errors import excerpt
from ocp.options import Range, numeric_leaves, option_fields
from scenarios.errors import ScenarioError
from scenarios.schema.node import Node

__all__ = ["QUATERNION_BOUNDS", "REQUIRED", "Described", "Key", "OptionEntry", "Section", "boolean", "choice", "custom",
           "integer", "mapping", "number", "option_entries", "option_keys", "quaternion", "read_mapping", "text",
           "vector"]


class _Required:
    """The default of a key that must be given."""

    def __repr__(self) -> str:
        return "REQUIRED"


REQUIRED: Any = _Required()
"""Default of a key that must be given (a missing one is ``required key is missing``)."""


@dataclass(frozen=True)
class Described:
    """The default of a key that depends on other keys, in words (``the planner's name``): the
    key's reader receives this object for a missing key and computes the value.

    Parameters
    ----------
    words : str
        The default as the reference states it.
    """

    words: str

    def __str__(self) -> str:
        return self.words


@dataclass(frozen=True)
class Key:
    """One YAML key: how it is read and how the reference describes it.

    Parameters
    ----------
    name : str
        The key as written in YAML.
    type : str
        What it takes, in words (``number``, ``list of 3 numbers``, ``mapping`` ...).
    meaning : str
        One line (reStructuredText) on what it does.
    read : callable or None, optional
        ``read(node) -> value`` from the key's node (at its YAML path, the default's node when
        the key is missing); ``None`` (default): :meth:`value` returns the node itself, for a
        value whose check needs what the caller knows (the number of wheels, the planner's
        registry entry).
    unit : str, optional
        Unit of the numbers as written in YAML (``s``, ``deg``, ``rad/s``); empty: none.
    default : object, optional
        Value of a missing key; :data:`REQUIRED` (default): the key must be given.
    bounds : str, optional
        The range in words (``> 0 and <= 120``); empty: none.
    choices : tuple of str or mapping, optional
        The accepted words; a mapping (a registry) is read when used, so that entries
        registered later are listed.
    section : Section or None, optional
        The keys of a nested mapping (of each entry of a list when ``entries``).
    entries : bool, optional
        The key holds a list of ``section`` mappings (``planners[i]``).
    named : bool, optional
        The key holds a mapping of names (chosen by the user) to ``section`` mappings
        (``requirements.pointing.<name>``).
    """

    name: str
    type: str
    meaning: str
    read: Callable[[Node], Any] | None = None
    unit: str = ""
    default: Any = REQUIRED
    bounds: str = ""
    choices: tuple[str, ...] | Mapping[str, Any] = ()
    section: Section | None = None
    entries: bool = False
    named: bool = False

    def node(self, parent: Node) -> Node:
        """This key's node in ``parent`` (marked as read), or its default's.

        Parameters
        ----------
        parent : Node
            The mapping that holds the key.

        Returns
        -------
        Node
            The value at ``<parent path>.<name>``.

        Raises
        ------
        ScenarioError
            ``parent`` is not a mapping, or a required key is missing.
        """
        return parent.get(self.name) if self.default is REQUIRED else parent.get(self.name, self.default)

    def value(self, parent: Node) -> Any:
        """The key's value in ``parent``, read and checked.

        Parameters
        ----------
        parent : Node
            The mapping that holds the key.

        Returns
        -------
        object
            What :attr:`read` returns, or the node when it is ``None``.

        Raises
        ------
        ScenarioError
            Naming the key's YAML path and what was expected.
        """
        child = self.node(parent)
        return child if self.read is None else self.read(child)

    @property
    def choice_names(self) -> tuple[str, ...]:
        """The accepted words (a registry's names as they are now)."""
        return tuple(self.choices)


@dataclass(frozen=True)
class Section:
    """The keys of one YAML mapping, in the order they are read.

    Parameters
    ----------
    keys : tuple of Key
        Its keys.
    meaning : str, optional
        What the mapping holds (one line, reStructuredText).
    """

    keys: tuple[Key, ...]
    meaning: str = ""
    _index: dict[str, Key] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "_index", {key.name: key for key in self.keys})

    def __getitem__(self, name: str) -> Key:
        return self._index[name]

    def read(self, node: Node) -> dict[str, Any]:
        """Every key of ``node`` by :meth:`Key.value`, then reject the keys not described.

        Parameters
        ----------
        node : Node
            The mapping.

        Returns
        -------
        dict
            Key name -> value.

        Raises
        ------
        ScenarioError
            ``node`` is not a mapping, a value is wrong, or an unknown key is present.
        """
        return read_mapping(node, self.keys)


def read_mapping(node: Node, keys: Sequence[Key]) -> dict[str, Any]:
    """Every key of ``keys`` from the mapping ``node`` by :meth:`Key.value`, then reject the keys
    not read (:meth:`Node.finish`).

    A required key missing beside a key the mapping gives and nothing reads (``orbit: {tle: ...}``,
    not a form of orbit) is reported at that unknown key, the missing one said too: the unknown key
    is the mistake to see first, and the required key's error alone never named it (one that looks
    like a misspelling of the missing key is named in that key's error, :meth:`Node.get`).

    Parameters
    ----------
    node : Node
        The mapping.
    keys : sequence of Key
        Its keys (others read before, such as a ``type`` that chose them, are accepted too).

    Returns
    -------
    dict
        Key name -> value.

    Raises
    ------
    ScenarioError
        ``node`` is not a mapping, a value is wrong, a required key is missing, or an unknown key
        is present.
    """
    node.mapping()
    try:
        values = {key.name: key.value(node) for key in keys}
    except ScenarioError as error:
        names = {key.name for key in keys}
        missing = {node.path + "." + name if node.path else name for name in names}
        unknown = [k for k in node.value if isinstance(k, str) and k not in names and k not in node.read_keys]
        # (a misspelling of the missing key is named by its error already: "'altitud_km' is given")
        if (error.path in missing and error.message.startswith("required key is missing") and unknown
                and "a misspelling of" not in error.message):
            where = f"{node.path}.{unknown[0]}" if node.path else unknown[0]
            raise ScenarioError(where, f"unknown key; expected one of {sorted(names | node.read_keys)} "
                                       f"({error.path}: {error.message})") from None
        raise
    node.finish()
    return values


# --- keys of each kind: a reader built on Node's checks and the words that describe it ---------

def _number_words(value: float) -> str:
    return str(value) if isinstance(value, int) else f"{value:g}"


def _bounds(positive: bool = False, non_negative: bool = False, minimum: float | None = None,
            maximum: float | None = None) -> str:
    parts = (["> 0"] if positive else []) + ([">= 0"] if non_negative else []) + \
        ([f">= {_number_words(minimum)}"] if minimum is not None else []) + \
        ([f"<= {_number_words(maximum)}"] if maximum is not None else [])
    return " and ".join(parts)


def number(name: str, meaning: str, *, unit: str = "", default: Any = REQUIRED, positive: bool = False,
           non_negative: bool = False, maximum: float | None = None, nullable: bool = False,
           minimum: float | None = None) -> Key:
    """A finite number (``null`` too when ``nullable``).

    Parameters
    ----------
    name, meaning : str
        The YAML key and what it does.
    unit : str, optional
        Its unit as written.
    default : object, optional
        Value when missing (:data:`REQUIRED`: none).
    positive, non_negative : bool, optional
        Require ``> 0`` or ``>= 0``.
    maximum : float or None, optional
        Inclusive upper bound.
    nullable : bool, optional
        Accept ``null`` (read as ``None``).
    minimum : float or None, optional
        Inclusive lower bound.

    Returns
    -------
    Key
        Reading a float (or ``None``).
    """
    if nullable:
        def read(node: Node) -> Any:
            return node.optional_number(positive, non_negative, maximum, minimum)
    else:
        def read(node: Node) -> Any:
            return node.number(positive, non_negative, maximum, minimum)
    return Key(name, "number or null" if nullable else "number", meaning, read, unit, default,
               _bounds(positive, non_negative, minimum=minimum, maximum=maximum))


def integer(name: str, meaning: str, *, default: Any = REQUIRED, minimum: int | None = None,
            maximum: int | None = None) -> Key:
    """An integer (not a float, not a boolean).

    Parameters
    ----------
    name, meaning : str
        The YAML key and what it does.
    default : object, optional
        Value when missing (:data:`REQUIRED`: none).
    minimum, maximum : int or None, optional
        Inclusive bounds.

    Returns
    -------
    Key
        Reading an int.
    """
    return Key(name, "integer", meaning, lambda node: node.integer(minimum, maximum), default=default,
               bounds=_bounds(minimum=minimum, maximum=maximum))


def boolean(name: str, meaning: str, *, default: Any = REQUIRED) -> Key:
    """``true`` or ``false``.

    Parameters
    ----------
    name, meaning : str
        The YAML key and what it does.
    default : object, optional
        Value when missing.

    Returns
    -------
    Key
        Reading a bool.
    """
    return Key(name, "true or false", meaning, Node.boolean, default=default)


def text(name: str, meaning: str, *, default: Any = REQUIRED) -> Key:
    """Any text.

    Parameters
    ----------
    name, meaning : str
        The YAML key and what it does.
    default : object, optional
        Value when missing.

    Returns
    -------
    Key
        Reading a str.
    """
    return Key(name, "text", meaning, lambda node: node.string(), default=default)


def choice(name: str, meaning: str, choices: tuple[str, ...] | Mapping[str, Any], *, default: Any = REQUIRED) -> Key:
    """One word of ``choices``.

    Parameters
    ----------
    name, meaning : str
        The YAML key and what it does.
    choices : tuple of str or mapping
        The accepted words, or a registry whose names they are (read when the key is).
    default : object, optional
        Value when missing.

    Returns
    -------
    Key
        Reading a str.
    """
    return Key(name, "text", meaning, lambda node: node.string(tuple(choices)), default=default, choices=choices)


def vector(name: str, meaning: str, size: int, *, unit: str = "", default: Any = REQUIRED,
           nullable: bool = False, magnitude: float | None = None) -> Key:
    """A list of ``size`` finite numbers (each at most ``magnitude`` in absolute value).

    Parameters
    ----------
    name, meaning : str
        The YAML key and what it does.
    size : int
        Number of entries.
    unit : str, optional
        Unit of the entries.
    default : object, optional
        Value when missing.
    nullable : bool, optional
        Accept ``null`` (read as ``None``).
    magnitude : float or None, optional
        The largest absolute value of an entry; ``None`` (default): any finite number.

    Returns
    -------
    Key
        Reading a ``(size,)`` float array (or ``None``).
    """
    def read(node: Node) -> Any:
        value = node.optional_vector(size) if nullable else node.vector(size)
        if magnitude is not None and value is not None and np.any(np.abs(value) > magnitude):
            raise node.error(f"expected entries within ±{magnitude:g}, got {np.asarray(value).tolist()}")
        return value

    return Key(name, f"list of {size} numbers" + (" or null" if nullable else ""), meaning, read, unit, default,
               bounds="" if magnitude is None else f"each within ±{magnitude:g}")


QUATERNION_BOUNDS = f"norm within {quat.UNIT_NORM_TOLERANCE:g} of 1 (``ocp.quat.UNIT_NORM_TOLERANCE``); normalised"
"""The range the reference states for a quaternion (:meth:`~scenarios.schema.node.Node.quaternion`)."""


def quaternion(name: str, meaning: str, *, nullable: bool = False) -> Key:
    """A required unit quaternion, normalised (``null`` too when ``nullable``).

    Parameters
    ----------
    name, meaning : str
        The YAML key and what it does.
    nullable : bool, optional
        Accept ``null`` (read as ``None``).

    Returns
    -------
    Key
        Reading a ``(4,)`` array in the order written (or ``None``).
    """
    def read(node: Node) -> Any:
        return None if nullable and node.is_null() else node.quaternion()
    return Key(name, "list of 4 numbers" + (" or null" if nullable else ""), meaning, read,
               bounds=QUATERNION_BOUNDS)


def mapping(name: str, meaning: str, section: Section, *, default: Any = REQUIRED, null: str = "error") -> Key:
    """A nested mapping read by ``section``.

    Parameters
    ----------
    name, meaning : str
        The YAML key and what it does.
    section : Section
        Its keys.
    default : object, optional
        Value when missing (``{}``: the section's defaults; ``None``: absent).
    null : {"error", "defaults", "none"}, optional
        What ``null`` (or ``none``) means: an error (``expected a mapping``), the section's
        defaults, or no value (``None``).

    Returns
    -------
    Key
        Reading a dict of the section's values (or ``None``).
    """
    def read(node: Node) -> Any:
        if null != "error" and node.is_null():
            return section.read(Node({}, node.path)) if null == "defaults" else None
        return section.read(node)
    return Key(name, "mapping" + ("" if null == "error" else " or null"), meaning, read, default=default,
               section=section)


def custom(name: str, meaning: str, type: str, read: Callable[[Node], Any] | None, *, unit: str = "",
           default: Any = REQUIRED, bounds: str = "", section: Section | None = None, entries: bool = False,
           choices: tuple[str, ...] | Mapping[str, Any] = (), named: bool = False) -> Key:
    """A key with a reader of its own (a value of several forms, a check across entries).

    Parameters
    ----------
    name, meaning, type : str
        The YAML key, what it does, and what it takes in words.
    read : callable or None
        ``read(node) -> value``; ``None``: the caller reads the node (see :class:`Key`).
    unit, bounds : str, optional
        Unit and range in words.
    default : object, optional
        Value when missing.
    section : Section or None, optional
        Keys of a nested mapping (of each entry when ``entries``).
    entries : bool, optional
        A list of ``section`` mappings.
    choices : tuple of str or mapping, optional
        Accepted words.
    named : bool, optional
        A mapping of names to ``section`` mappings.

    Returns
    -------
    Key
        The key.
    """
    return Key(name, type, meaning, read, unit, default, bounds, choices, section, entries, named)


# --- options declared as typed dataclasses (ocp.options) --------------------------------------

_SECTION_TITLE = re.compile(r"^(Attributes|Parameters)\n-{3,}\s*$", re.MULTILINE)
_ANY_TITLE = re.compile(r"^[A-Z][A-Za-z ]+\n-{3,}\s*$", re.MULTILINE)
_ENTRY = re.compile(r"^([A-Za-z_]\w*(?:\s*,\s*[A-Za-z_]\w*)*)\s*(?::|$)")
def _unit(meaning: str, position: int = 0, count: int = 1) -> str:
    """The unit a description gives in brackets (``[rad/s]``), outside parentheses; of several
    options documented together (``a, b : float``), the one at ``position`` of a comma-separated
    list (``[N m, N m s]``). A bracket with commas otherwise is an interval, not a unit, and one
    that opens on a quote an index (``stats["switch_refinement"]``)."""
    depth, start = 0, -1
    for index, char in enumerate(meaning):
        if start >= 0:
            if char == "]":
                units = [unit.strip() for unit in meaning[start + 1:index].split(",")]
                if meaning[start + 1:start + 2] in ("'", '"'):  # an index (stats["switch_refinement"]), no unit
                    start = -1
                elif any(c.isalpha() or c in "°µ" for c in meaning[start + 1:index]):
                    if len(units) == 1:
                        return units[0]
                    return units[position] if len(units) == count else ""
                start = -1
        elif char == "(":
            depth += 1
        elif char == ")":
            depth = max(depth - 1, 0)
        elif char == "[" and depth == 0:
            start = index
    return ""


def _described(options_class: type) -> dict[str, tuple[str, str]]:
    """Option name -> (its numpydoc description in one line, its unit) from the dataclass's docstring."""
    doc = inspect.getdoc(options_class) or ""
    meanings: dict[str, str] = {}
    groups: dict[str, list[str]] = {}
    for title in _SECTION_TITLE.finditer(doc):
        following = _ANY_TITLE.search(doc, title.end())
        body = doc[title.end():following.start() if following else len(doc)]
        names: list[str] = []
        for line in body.splitlines():
            if not line.strip():
                continue
            if not line[:1].isspace():
                match = _ENTRY.match(line.strip())
                names = [n.strip() for n in match.group(1).split(",")] if match else []
                for name in names:
                    meanings[name] = ""
                    groups[name] = names
            else:
                for name in names:
                    meanings[name] = (meanings[name] + " " + line.strip()).strip()
    return {name: (meaning, _unit(meaning, groups[name].index(name), len(groups[name])))
            for name, meaning in meanings.items()}


def _words(annotation: Any) -> str:
    """An option's type in words."""
    origin = typing.get_origin(annotation)
    if origin is Literal:
        return "text"
    if origin in (Union, types.UnionType):
        return " or ".join(dict.fromkeys(_words(arg) for arg in typing.get_args(annotation)))
    if annotation is type(None):
        return "null"
    if origin in (list, tuple):
        args = [arg for arg in typing.get_args(annotation) if arg is not Ellipsis]
        if origin is tuple and Ellipsis not in typing.get_args(annotation) and all(arg is float for arg in args):
            return f"list of {len(args)} numbers"
        inner = args[0]
        if typing.get_origin(inner) is list:
            return "matrix (list of lists of numbers)"
        return {float: "list of numbers", int: "list of integers", str: "list of names",
                dict: "list of mappings"}.get(inner, "list")
    return {float: "number", int: "integer", bool: "true or false", str: "text", dict: "mapping"}.get(annotation,
                                                                                                     str(annotation))


def _range_words(bounds: Range | None) -> str:
    if bounds is None:
        return ""
    parts = [f"{op} {value:g}" for op, value in ((">=", bounds.ge), (">", bounds.gt), ("<=", bounds.le),
                                                 ("<", bounds.lt)) if value is not None]
    if bounds.size is not None:
        parts.append(f"{bounds.size} numbers")
    if bounds.shape is not None:
        parts.append(f"{bounds.shape[0]}x{bounds.shape[1]} matrix")
    return " and ".join(parts)


def _literal_choices(annotation: Any) -> tuple[str, ...]:
    origin = typing.get_origin(annotation)
    if origin is Literal:
        return tuple(str(arg) for arg in typing.get_args(annotation))
    if origin in (Union, types.UnionType):
        return tuple(c for arg in typing.get_args(annotation) for c in _literal_choices(arg))
    return ()


_NO_DEFAULT = dataclasses.MISSING


def _default(spec: dataclasses.Field) -> Any:
    if spec.default is not _NO_DEFAULT:
        return spec.default
    if spec.default_factory is not _NO_DEFAULT:
        return spec.default_factory()
    return REQUIRED


@dataclass(frozen=True)
class OptionEntry:
    """One option of a typed ``Options`` dataclass, described for the reference.

    Parameters
    ----------
    name : str
        The option (a YAML key under ``options``).
    type : str
        What it takes, in words.
    unit : str
        The first unit its description gives in brackets (``[rad/s]``); empty: none.
    default : object
        Its default (:data:`REQUIRED` if it has none).
    bounds : str
        Its declared :class:`~ocp.options.Range` in words.
    choices : tuple of str
        The words a ``Literal`` type accepts.
    meaning : str
        Its description from the dataclass's docstring (reStructuredText, one line).
    """

    name: str
    type: str
    unit: str
    default: Any
    bounds: str
    choices: tuple[str, ...]
    meaning: str


@functools.cache
def option_entries(options_class: type) -> tuple[OptionEntry, ...]:
    """The options of a typed dataclass (:mod:`ocp.options`), described from its fields and docstring.

    Parameters
    ----------
    options_class : type
        A planner's, controller's or field model's ``Options`` dataclass.

    Returns
    -------
    tuple of OptionEntry
        In field order (computed once per class).
    """
    described = _described(options_class)
    specs = {spec.name: spec for spec in dataclasses.fields(options_class)}
    entries = []
    for name, (annotation, bounds) in option_fields(options_class).items():
        meaning, unit = described.get(name, ("", ""))
        unit = unit if numeric_leaves(annotation) else ""
        entries.append(OptionEntry(name, _words(annotation), unit, _default(specs[name]), _range_words(bounds),
                                   _literal_choices(annotation), meaning))
    return tuple(entries)


def _option_key(name: str, annotation: Any, bounds: Range | None, default: Any, meaning: str, unit: str) -> Key:
    """A :class:`Key` reading one option with the scenario's checks."""
    optional = typing.get_origin(annotation) in (Union, types.UnionType) and type(None) in typing.get_args(annotation)
    base = [arg for arg in typing.get_args(annotation) if arg is not type(None)] if optional else [annotation]
    kind = base[0] if len(base) == 1 else None
    if kind is float:
        bounds = bounds or Range()
        closed = bounds.ge is not None and bounds.le is not None  # a range such as [0, 180]: named whole
        if bounds.gt in (None, 0.0) and bounds.ge in (None, 0.0) and bounds.lt is None and bounds.finite and not closed:
            # the scenario's own number checks (and their messages, which name the side crossed)
            return number(name, meaning, unit=unit, default=default, positive=bounds.gt == 0.0,
                          non_negative=bounds.ge == 0.0, maximum=bounds.le, nullable=optional)
        declared = bounds

        def read_bounded(node: Node) -> float | None:  # any other declared Range, in its own words
            if optional and node.is_null():
                return None
            value = node.number() if declared.finite else node.value
            if not isinstance(value, (int, float)) or isinstance(value, bool) or declared.violation(float(value)):
                raise node.error(f"expected {declared.describe()}, got {excerpt(node.value)}")
            return float(value)
        return Key(name, "number or null" if optional else "number", meaning, read_bounded, unit, default,
                   _range_words(declared))
    unit = unit if numeric_leaves(annotation) else ""
    args = typing.get_args(kind)
    if typing.get_origin(kind) is tuple and args and all(arg is float for arg in args) and not optional:
        if bounds is not None and bounds != Range(size=bounds.size):
            raise TypeError(f"option {name}: a vector option is read as finite numbers, without bounds; got {bounds}")

        def read_vector(node: Node) -> tuple[float, ...]:
            return tuple(float(v) for v in node.vector(len(args)))
        return custom(name, meaning, f"list of {len(args)} numbers", read_vector, unit=unit, default=default)
    if kind is str and not optional:
        def read_text(node: Node) -> str:
            # a date written in Python data (YAML files keep dates as text) is read as its ISO text
            if isinstance(node.value, datetime.date):
                return node.value.isoformat()
            return node.string()
        return custom(name, meaning, "text", read_text, default=default)
    if kind is bool and not optional:
        return boolean(name, meaning, default=default)
    if typing.get_origin(kind) is Literal and not optional:
        return choice(name, meaning, _literal_choices(kind), default=default)
    raise TypeError(f"option {name}: type {annotation} is not read by the scenario schema; use float, "
                    "float | None, tuple[float, ...] (a vector), str, bool or Literal[...]")


@functools.cache
def option_keys(options_class: type) -> tuple[Key, ...]:
    """Keys reading the fields of a typed ``Options`` dataclass with the scenario's own checks.

    Numbers are checked as :func:`number` checks them (``Range(gt=0)``: positive,
    ``Range(ge=0)``: non-negative, ``Range(le=x)``: at most ``x``), a ``tuple[float, float,
    float]`` as :func:`vector` does (finite numbers, read as a tuple); the dataclass's docstring
    gives each key its meaning and unit.

    Parameters
    ----------
    options_class : type
        A dataclass whose fields are float, float | None, tuple of floats, str, bool or Literal
        options.

    Returns
    -------
    tuple of Key
        One per field, in field order (computed once per class).

    Raises
    ------
    TypeError
        A field of a type or range these keys cannot read.
    """
    described = _described(options_class)
    specs = {spec.name: spec for spec in dataclasses.fields(options_class)}
    return tuple(_option_key(name, annotation, bounds, _default(specs[name]), *described.get(name, ("", "")))
                 for name, (annotation, bounds) in option_fields(options_class).items())
