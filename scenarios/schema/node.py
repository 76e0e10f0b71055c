"""YAML values with errors that name the path (``planners[1].options.weight``).

:class:`Node` wraps a parsed value with its path; typed accessors raise :class:`ScenarioError`
naming the path and what was expected, and :meth:`Node.finish` rejects keys that were never read.
Reading the file itself (:func:`~scenarios.schema.read.read_yaml`, with its limits) is
:mod:`scenarios.schema.read`.
"""
from __future__ import annotations

import difflib
import math
from collections.abc import Iterator
from typing import Any

import numpy as np

from ocp import quat
from ocp.errors import excerpt
from scenarios.errors import ScenarioError

__all__ = ["Node", "plain_value"]

PLAIN_DEPTH = 64
"""Deepest nesting :func:`plain_value` converts (a mapping nested deeper, or one holding itself, is
left as given: the schema refuses it where it reads it)."""


def plain_value(value: Any, depth: int = 0) -> Any:
    """``value`` with numpy numbers and arrays and tuples made the YAML values they stand for.

    A script builds a scenario mapping from numpy (``inertia=np.diag(...)``, ``duration=np.int64(60)``)
    and tuples; the schema reads what ``yaml.safe_load`` gives (lists, ``int``, ``float``, ``bool``,
    ``str``, mappings), so they are converted here, once, where a mapping enters it (the top
    :class:`Node`): a numpy scalar becomes the Python number (``np.bool_`` a bool, still refused
    where a number is wanted), a numpy array its nested list (``ndarray.tolist()``), a tuple a list.
    Other values are kept, and refused where read.

    Parameters
    ----------
    value : object
        A parsed YAML value or one built in Python.
    depth : int, optional
        Nesting level reached (internal).

    Returns
    -------
    object
        The converted value; ``value`` itself when nothing needed converting.
    """
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if depth >= PLAIN_DEPTH:
        return value
    if isinstance(value, (list, tuple)):
        items = [plain_value(item, depth + 1) for item in value]
        return value if isinstance(value, list) and all(a is b for a, b in zip(items, value)) else items
    if isinstance(value, dict):
        pairs = {plain_value(key, depth + 1): plain_value(item, depth + 1) for key, item in value.items()}
        unchanged = len(pairs) == len(value) and all(
            key in value and value[key] is item for key, item in pairs.items())
        return value if unchanged else pairs
    return value


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _is_finite(value: int | float) -> bool:
    """Whether a number is finite as a float (an integer too large for a float is not)."""
    try:
        return math.isfinite(value)
    except OverflowError:
        return False


_YAML_BOOLEAN = " (a YAML boolean: unquoted yes, no, on, off, true and false are read as one)"
"""Said of a boolean where a number is expected: ``duration: yes`` reads as ``True``, which the
message showed without saying where it came from."""


def _why_not_finite(value: Any) -> str:
    """Why a number is refused as one (NaN, an infinity, an integer beyond a float), else nothing."""
    if not _is_number(value) or _is_finite(value):
        return ""
    if isinstance(value, int):
        return " (too large: beyond the range of a float, about 1.8e308)"
    return " (NaN and infinities are not accepted)"


class Node:
    """A YAML value with its path; typed accessors raise :class:`ScenarioError` naming the path.

    Parameters
    ----------
    value : object
        The parsed YAML value (mapping, list, number, string, bool or ``None``). At the top level
        (``path`` empty) numpy numbers and arrays and tuples are converted first
        (:func:`plain_value`), so that a mapping built in Python reads as its YAML would.
    path : str, optional
        Its YAML path (``planners[1].options.weight``); empty for the top level.
    """

    def __init__(self, value: Any, path: str = ""):
        self.value = value if path else plain_value(value)
        self.path = path
        self._read: set[str] = set()

    def error(self, message: str) -> ScenarioError:
        """An error at this node's path (to raise).

        Parameters
        ----------
        message : str
            What was expected (and what was found).

        Returns
        -------
        ScenarioError
            The error, at ``(top level)`` for the root.
        """
        return ScenarioError(self.path or "(top level)", message)

    @property
    def read_keys(self) -> frozenset[str]:
        """The keys of this mapping read so far (by :meth:`get`, a missing required one included)."""
        return frozenset(self._read)

    def _child_path(self, key: str | int) -> str:
        if isinstance(key, int):
            return f"{self.path}[{key}]"
        return f"{self.path}.{key}" if self.path else key

    def mapping(self) -> Node:
        """This node, checked to hold a mapping.

        Returns
        -------
        Node
            ``self``.

        Raises
        ------
        ScenarioError
            The value is not a mapping.
        """
        if not isinstance(self.value, dict):
            raise self.error(f"expected a mapping, got {excerpt(self.value)}")
        return self

    def __contains__(self, key: str) -> bool:
        return isinstance(self.value, dict) and key in self.value and self.value[key] is not None

    def get(self, key: str, default: Any = ..., required: bool = False) -> Node:
        """A child of this mapping, marked as read (see :meth:`finish`).

        Parameters
        ----------
        key : str
            The key.
        default : object, optional
            Value of a missing key; not given (``...``): the key is required.
        required : bool, optional
            A missing key is an error even with a default.

        Returns
        -------
        Node
            The child (``default`` at the child's path when the key is missing).

        Raises
        ------
        ScenarioError
            This node is not a mapping, or a required key is missing.
        """
        self.mapping()
        self._read.add(key)
        if key not in self.value:
            if required or default is ...:
                close = self._given_like(key)
                raise ScenarioError(self._child_path(key), "required key is missing" + (
                    f"; {close!r} is given: a misspelling of {key!r}?" if close else ""))
            return Node(default, self._child_path(key))
        return Node(self.value[key], self._child_path(key))

    def _given_like(self, key: str) -> str | None:
        """A key given but not read that looks like a misspelling of ``key``, or ``None``."""
        given = [k for k in self.value if isinstance(k, str) and k not in self._read]
        close = difflib.get_close_matches(key, given, n=1, cutoff=0.7)
        return close[0] if close else None

    def exactly_one(self, names: tuple[str, ...], given: list[str], what: str = "") -> ScenarioError:
        """The error for a mapping that gives ``given`` where exactly one of ``names`` is wanted.

        With none given, a key of the mapping that looks like a misspelling of one of ``names``
        (``keepout`` for ``keep_out``) is named at its own path, as :meth:`get` names one for a
        required key; otherwise the error is at this node.

        Parameters
        ----------
        names : tuple of str
            The keys of which exactly one must be given.
        given : list of str
            Those the mapping gives (not exactly one).
        what : str, optional
            Words after the list of names (what each one takes).

        Returns
        -------
        ScenarioError
            The error (to raise).
        """
        listed = ", ".join(names[:-1]) + f" and {names[-1]}" if len(names) > 1 else names[0]
        wanted = f"give exactly one of {listed}{what}"
        if not given and isinstance(self.value, dict):
            for name in names:
                close = self._given_like(name)
                if close is not None:
                    return ScenarioError(self._child_path(close),
                                         f"unknown key {close!r}: a misspelling of {name!r}? ({wanted})")
        return self.error(f"{wanted}; got {', '.join(given) if given else 'none of them'}")

    def finish(self) -> None:
        """Reject keys that were not read."""
        if isinstance(self.value, dict):
            for key in self.value:
                if key not in self._read:
                    if not isinstance(key, str):  # `~: 1`, `1: 2`: YAML read a null or a number, not a name
                        raise ScenarioError(self.path, f"a key must be a name, got {excerpt(key)} (a YAML null or "
                                                       f"number); expected one of {sorted(self._read)}")
                    raise ScenarioError(self._child_path(key), f"unknown key; expected one of {sorted(self._read)}")

    def items(self) -> Iterator[Node]:
        """The entries of this list, each at its path (``planners[0]``, ...).

        Returns
        -------
        iterator of Node
            One node per entry.

        Raises
        ------
        ScenarioError
            The value is not a list.
        """
        if not isinstance(self.value, list):
            raise self.error(f"expected a list, got {excerpt(self.value)}")
        return (Node(item, self._child_path(i)) for i, item in enumerate(self.value))

    def is_null(self) -> bool:
        """Whether the value is ``null`` (or the text ``none``, any case).

        Returns
        -------
        bool
            ``True`` for a missing or null value.
        """
        return self.value is None or (isinstance(self.value, str) and self.value.lower() == "none")

    def number(self, positive: bool = False, non_negative: bool = False, maximum: float | None = None,
               minimum: float | None = None) -> float:
        """The value as a finite number (booleans are not numbers).

        Parameters
        ----------
        positive : bool, optional
            Require ``> 0``.
        non_negative : bool, optional
            Require ``>= 0``.
        maximum : float or None, optional
            Upper bound (inclusive); ``None``: none.
        minimum : float or None, optional
            Lower bound (inclusive); ``None``: none.

        Returns
        -------
        float
            The number.

        Raises
        ------
        ScenarioError
            Not a finite number, or outside the bounds.
        """
        if not _is_number(self.value) or not _is_finite(self.value):
            raise self.error(f"expected a number, got {excerpt(self.value)}{_why_not_finite(self.value)}"
                             + (_YAML_BOOLEAN if isinstance(self.value, bool) else ""))
        if positive and not self.value > 0:
            raise self.error(f"expected a positive number, got {excerpt(self.value)}")
        if non_negative and self.value < 0:
            raise self.error(f"expected a non-negative number, got {excerpt(self.value)}")
        if maximum is not None and self.value > maximum:
            raise self.error(f"expected a number <= {maximum:g}, got {excerpt(self.value)}")
        if minimum is not None and self.value < minimum:
            raise self.error(f"expected a number >= {minimum:g}, got {excerpt(self.value)}")
        return float(self.value)

    def optional_number(self, positive: bool = False, non_negative: bool = False,
                        maximum: float | None = None, minimum: float | None = None) -> float | None:
        """:meth:`number`, or ``None`` for a null value.

        Parameters
        ----------
        positive, non_negative : bool, optional
            Require ``> 0`` or ``>= 0``.
        maximum, minimum : float or None, optional
            Inclusive bounds; ``None``: none.

        Returns
        -------
        float or None
            The number, or ``None``.
        """
        return None if self.is_null() else self.number(positive, non_negative, maximum, minimum)

    def integer(self, minimum: int | None = None, maximum: int | None = None) -> int:
        """The value as an integer (not a float, not a boolean).

        Parameters
        ----------
        minimum, maximum : int or None, optional
            Inclusive bounds; ``None``: none.

        Returns
        -------
        int
            The integer.

        Raises
        ------
        ScenarioError
            Not an integer, or outside ``[minimum, maximum]``.
        """
        if not isinstance(self.value, int) or isinstance(self.value, bool):
            raise self.error(f"expected an integer, got {excerpt(self.value)}")
        if (minimum is not None and self.value < minimum) or (maximum is not None and self.value > maximum):
            low = "" if minimum is None else f" >= {minimum}"
            high = "" if maximum is None else f" <= {maximum}"
            raise self.error(f"expected an integer{low}{' and' if low and high else ''}{high}, got {excerpt(self.value)}")
        return self.value

    def boolean(self) -> bool:
        """The value as ``true`` or ``false``.

        Returns
        -------
        bool
            The value.

        Raises
        ------
        ScenarioError
            Not a boolean.
        """
        if not isinstance(self.value, bool):
            raise self.error(f"expected true or false, got {excerpt(self.value)}")
        return self.value

    def string(self, choices: tuple[str, ...] | None = None) -> str:
        """The value as text.

        Parameters
        ----------
        choices : tuple of str or None, optional
            The accepted values; ``None``: any text.

        Returns
        -------
        str
            The text.

        Raises
        ------
        ScenarioError
            Not a string, or not one of ``choices``.
        """
        if not isinstance(self.value, str):
            raise self.error(f"expected a string, got {excerpt(self.value)}")
        if choices is not None and self.value not in choices:
            raise self.error(f"expected one of {list(choices)}, got {excerpt(self.value)}")
        return self.value

    def vector(self, size: int | None = None, allow_scalar: bool = False) -> np.ndarray:
        """The value as a list of finite numbers.

        Parameters
        ----------
        size : int or None, optional
            Required number of entries; ``None``: any.
        allow_scalar : bool, optional
            Accept a single number too (returned as a 0-d array).

        Returns
        -------
        (size,) or () ndarray
            The numbers as floats.

        Raises
        ------
        ScenarioError
            Not a list of numbers, the wrong length, or a non-finite entry.
        """
        if allow_scalar and _is_number(self.value):
            return np.asarray(self.number())
        if not isinstance(self.value, list) or not all(_is_number(v) for v in self.value):
            expected = f"a list of {size} numbers" if size else "a list of numbers"
            raise self.error(f"expected {expected}{' or a number' if allow_scalar else ''}, got {excerpt(self.value)}")
        if size is not None and len(self.value) != size:
            raise self.error(f"expected {size} numbers, got {len(self.value)}")
        bad = next((i for i, v in enumerate(self.value) if not _is_finite(v)), None)
        if bad is not None:
            raise self.error(f"expected finite numbers, got {excerpt(self.value[bad])} at [{bad}] of "
                             f"{excerpt(self.value)}")
        array = np.asarray(self.value, dtype=float)
        return array

    def optional_vector(self, size: int | None = None) -> np.ndarray | None:
        """:meth:`vector`, or ``None`` for a null value.

        Parameters
        ----------
        size : int or None, optional
            Required number of entries; ``None``: any.

        Returns
        -------
        (size,) ndarray or None
            The numbers, or ``None``.
        """
        return None if self.is_null() else self.vector(size)

    def quaternion(self) -> np.ndarray:
        """The value as a unit quaternion (in the order written; the loader converts scalar-last).

        Returns
        -------
        (4,) ndarray
            The quaternion normalised (its norm must be within ``ocp.quat.UNIT_NORM_TOLERANCE`` of
            1, the library's tolerance too).

        Raises
        ------
        ScenarioError
            Not 4 numbers, zero, or a norm farther than ``ocp.quat.UNIT_NORM_TOLERANCE`` from 1
            (the message shows the value, its norm and the normalised quaternion to write).
        """
        q = self.vector(4)
        scale = float(np.max(np.abs(q)))
        unit = q / scale if scale > 0.0 else q  # the direction, whose norm cannot overflow (entries of 1e300 did,
        # with NumPy's RuntimeWarning printed before the error and "must be finite" said of finite entries)
        if scale > 2.0:  # an entry beyond 2: no unit quaternion, whatever the tolerance
            norm = scale * float(np.linalg.norm(unit))
            shown = f"{norm:.6g}" if math.isfinite(norm) else "beyond a float's range"
            problem: str | None = f"a quaternion must have unit norm (got norm {shown})"
        else:
            problem = quat.unit_norm_error(q)
        if problem is not None:
            hint = ""
            if scale > 0.0:
                hint = (f"; normalise it (q / ‖q‖ = {[round(float(v), 7) for v in unit / np.linalg.norm(unit)]}) if "
                        "it is the attitude you mean, or check it for a typo")
            raise self.error(f"{problem} for {excerpt(self.value)}{hint}")
        return q / float(np.linalg.norm(q))
