"""Typed options for planners and controllers: a dataclass of fields with defaults, filled from a
mapping with checks that name the offending key (``planners[1].options.weight``).

Supported field types: ``float``, ``int``, ``bool``, ``str``, ``Literal[...]``, ``X | None``,
``list[float]`` (a vector), ``tuple[float, float, float]`` (a vector of that length, read from a
YAML list), ``list[list[float]]`` (a matrix), ``dict`` and ``list[dict]``;
``float | list[list[float]]`` accepts either.

Every numeric option declares its valid range next to its type, with ``typing.Annotated``::

    weight: Annotated[float, Range(ge=0.0)] = 0.0
    intervals: Annotated[int, Range(ge=1, le=2000)] = 50
    kp: Annotated[float | list[list[float]], Range(gt=0.0, shape=(3, 3))] = 0.06

The bounds apply to every number of the value (each entry of a vector or matrix); numbers must be
finite unless ``finite=False``. :func:`parse_options` enforces them and names the path, the
value and the range. Checks that relate several options live in the dataclass's
``__post_init__``, which raises :class:`InvalidOption` naming the option.
"""
from __future__ import annotations

import dataclasses
import functools
import math
import numbers
import types
import typing
from dataclasses import dataclass
from typing import Annotated, Any, ClassVar, Literal, Mapping, TypeVar, Union

import numpy as np
from numpy.typing import NDArray

from ocp.errors import InvalidOption, OptionsError, excerpt

T = TypeVar("T")

@dataclass(frozen=True)
class Range:
    """Valid range of a numeric option (applied to each number of a vector or matrix).

    Parameters
    ----------
    ge, gt, le, lt : float or None, optional
        Bounds ``>= ge``, ``> gt``, ``<= le``, ``< lt`` on every number, in the option's unit;
        ``None`` (default): no such bound.
    finite : bool, optional
        Reject infinities (default True); NaN is always rejected.
    size : int or None, optional
        Required number of entries of a vector option (``None``: any).
    shape : (int, int) or None, optional
        Required (rows, columns) of a matrix option (``None``: any).
    """

    ge: float | None = None
    gt: float | None = None
    le: float | None = None
    lt: float | None = None
    finite: bool = True
    size: int | None = None
    shape: tuple[int, int] | None = None

    def describe(self) -> str:
        """The range in words, for error messages.

        Returns
        -------
        str
            E.g. ``a finite number > 0 and <= 1``.
        """
        parts = [f"{op} {bound:g}" for op, bound in ((">=", self.ge), (">", self.gt), ("<=", self.le), ("<", self.lt))
                 if bound is not None]
        return ("a finite number" if self.finite else "a number") + (" " + " and ".join(parts) if parts else "")

    def violation(self, number: float) -> bool:
        """Whether ``number`` lies outside the range.

        Parameters
        ----------
        number : float
            One number of an option's value.

        Returns
        -------
        bool
            True if it is NaN, infinite while ``finite``, or beyond a bound.
        """
        if math.isnan(number) or (self.finite and math.isinf(number)):
            return True
        return ((self.ge is not None and not number >= self.ge) or (self.gt is not None and not number > self.gt)
                or (self.le is not None and not number <= self.le) or (self.lt is not None and not number < self.lt))


NUMERIC = (int, float)


def is_real(value: object) -> bool:
    """Whether ``value`` is a real number: a Python or NumPy integer or float (any
    :class:`numbers.Real`), not a bool (``True`` is no duration); finiteness is the caller's check.

    Parameters
    ----------
    value : object
        Anything.

    Returns
    -------
    bool
    """
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


_REAL_KINDS = "iuf"
"""NumPy dtype kinds of real numbers (signed and unsigned integers, floats); booleans (``b``), complex
numbers (``c``), text (``U``, ``S``), dates and durations (``M``, ``m``) are refused, and an object
array is judged entry by entry (:func:`is_real`)."""
_KIND_NAMES = {"b": "booleans", "c": "complex numbers", "U": "text", "S": "bytes", "M": "dates",
               "m": "durations", "V": "raw records"}


def real_array(value: object) -> NDArray[np.float64]:
    """``value`` (a number or a nesting of numbers, as given to the library) as a new float array,
    when it holds real numbers only: the one check of the library's numeric inputs (inertia,
    actuator limits, sensors, boundary conditions). NumPy alone would read ``True`` as 1, ``"2"`` in
    an object array as 2 and ``1+0j`` as 1 (with only a ``ComplexWarning``). Shape and finiteness are
    the caller's checks (its message names its field and what it expects).

    Parameters
    ----------
    value : object
        A number, a (nested) sequence of numbers or an ndarray.

    Returns
    -------
    ndarray of float
        A copy, of the shape of ``value`` (the caller's array is not kept).

    Raises
    ------
    ValueError
        Naming the first entry that is no real number and its type (a bool, complex number, text,
        ``None``, date ...), the array's kind, or a ragged nesting; the message is the reason alone,
        for the caller to prefix with its field and what it expects.
    """
    try:
        array = value if isinstance(value, np.ndarray) else np.array(value, dtype=object)
    except (TypeError, ValueError):  # a ragged nesting
        raise ValueError("a ragged nesting (rows of different lengths)") from None
    if array.dtype.kind == "O":
        if array.size == 0:
            raise ValueError("no numbers")
        odd = [item for item in array.ravel().tolist() if not is_real(item)]
        if odd:
            raise ValueError(f"{odd[0]!r:.60} ({type(odd[0]).__name__}) is no real number")
    elif array.dtype.kind not in _REAL_KINDS:
        raise ValueError(f"an array of {_KIND_NAMES.get(array.dtype.kind, array.dtype.name)} (dtype {array.dtype}), "
                         "not of real numbers")
    try:
        return np.array(array, dtype=float)
    except OverflowError:  # a Python integer beyond the floats (10**400)
        raise ValueError("a number beyond the floats' range (about 1.8e308)") from None


def _split(annotation: Any) -> tuple[Any, Range | None]:
    """``(type, Range or None)`` of a possibly ``Annotated`` type."""
    if typing.get_origin(annotation) is Annotated:
        base, *extras = typing.get_args(annotation)
        ranges = [extra for extra in extras if isinstance(extra, Range)]
        return base, (ranges[0] if ranges else None)
    return annotation, None


def numeric_leaves(annotation: Any) -> bool:
    """Whether an option type can hold numbers, which then need a :class:`Range`.

    Parameters
    ----------
    annotation : type
        A field type, without ``Annotated`` (``float``, ``list[float]``, ``int | None`` ...).

    Returns
    -------
    bool
        True if an ``int`` or ``float`` appears in it (in a union, list or tuple).
    """
    origin = typing.get_origin(annotation)
    if annotation in NUMERIC:
        return True
    if origin in (Union, types.UnionType, list, tuple):
        return any(numeric_leaves(arg) for arg in typing.get_args(annotation) if arg is not Ellipsis)
    return False


SUPPORTED = ("float, int, bool, str, Literal[...], X | None, list[float] (a vector; Range(size=3) fixes its "
             "length), tuple[float, float, float], list[list[float]] (a matrix), dict, list[dict]")


def supported(annotation: Any) -> bool:
    """Whether :func:`parse_options` can read an option of type ``annotation`` (see :data:`SUPPORTED`).

    Parameters
    ----------
    annotation : type
        A field type, without ``Annotated``.

    Returns
    -------
    bool
        True for the types listed in :data:`SUPPORTED` and unions of them.
    """
    origin = typing.get_origin(annotation)
    if origin is Literal:
        return True
    if origin in (Union, types.UnionType):
        return all(supported(arg) for arg in typing.get_args(annotation))
    if origin in (list, tuple):
        args = [arg for arg in typing.get_args(annotation) if arg is not Ellipsis]
        return bool(args) and all(supported(arg) for arg in args)
    return annotation in (float, int, bool, str, dict, type(None))


def _describe(annotation: Any) -> str:
    origin = typing.get_origin(annotation)
    if origin is Literal:
        return "one of " + ", ".join(repr(a) for a in typing.get_args(annotation))
    if origin in (Union, types.UnionType):
        return " or ".join(_describe(a) for a in typing.get_args(annotation))
    if annotation is type(None):
        return "null"
    if origin is list or (origin is tuple and typing.get_args(annotation)[-1] is Ellipsis):
        inner = typing.get_args(annotation)[0]
        return {float: "a list of numbers", int: "a list of integers", str: "a list of names",
                dict: "a list of mappings"}.get(inner, "a matrix (list of lists of numbers)")
    if origin is tuple:
        args = typing.get_args(annotation)
        if all(arg is float for arg in args):
            return f"a list of {len(args)} numbers"
        return f"a list of {len(args)} values (" + ", ".join(_describe(a) for a in args) + ")"
    return {float: "a number", int: "an integer", bool: "true or false", str: "a string",
            dict: "a mapping"}.get(annotation, str(annotation))


def _convert(value: Any, annotation: Any) -> Any:
    """Converted value, or raise ``TypeError`` if it does not fit ``annotation``."""
    origin = typing.get_origin(annotation)
    if origin is Literal:
        if isinstance(value, typing.Hashable) and value in typing.get_args(annotation):
            return value
        raise TypeError
    if origin in (Union, types.UnionType):
        for option in typing.get_args(annotation):
            try:
                return _convert(value, option)
            except TypeError:
                continue
        raise TypeError
    if annotation is type(None):
        if value is None:
            return None
        raise TypeError
    if annotation is bool:
        if isinstance(value, bool):
            return value
        raise TypeError
    if annotation is int:
        if isinstance(value, int) and not isinstance(value, bool):
            return value
        raise TypeError
    if annotation is float:
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            try:
                return float(value)
            except OverflowError:  # an integer too large for a float is not a number here
                raise TypeError from None
        raise TypeError
    if annotation is str:
        if isinstance(value, str):
            return value
        raise TypeError
    if annotation is dict:
        if isinstance(value, Mapping):
            return dict(value)
        raise TypeError
    if origin is list:
        if not isinstance(value, (list, tuple)):
            raise TypeError
        inner = typing.get_args(annotation)[0]
        return [_convert(item, inner) for item in value]
    if origin is tuple:
        if not isinstance(value, (list, tuple)):
            raise TypeError
        args = typing.get_args(annotation)
        if args[-1] is Ellipsis:
            return tuple(_convert(item, args[0]) for item in value)
        if len(value) != len(args):
            raise TypeError
        return tuple(_convert(item, arg) for item, arg in zip(value, args))
    raise TypeError


def _check_range(value: Any, bounds: Range, path: str) -> None:
    """Raise :class:`OptionsError` if a number of ``value`` is outside ``bounds`` or the shape is wrong."""
    if isinstance(value, (list, tuple)):
        if bounds.size is not None and value and not isinstance(value[0], list) and len(value) != bounds.size:
            raise OptionsError(path, f"expected {bounds.size} numbers, got {len(value)}")
        if bounds.shape is not None and value and isinstance(value[0], list):
            rows, cols = bounds.shape
            if len(value) != rows or any(len(row) != cols for row in value):
                raise OptionsError(path, f"expected a {rows}x{cols} matrix, got {excerpt(value)}")
        for index, item in enumerate(value):
            _check_range(item, bounds, f"{path}[{index}]")
        return
    if isinstance(value, NUMERIC) and not isinstance(value, bool) and bounds.violation(float(value)):
        raise OptionsError(path, f"expected {bounds.describe()}, got {excerpt(value)}")


@functools.cache
def option_fields(options_class: type) -> dict[str, tuple[Any, Range | None]]:
    """The fields of an options dataclass with their types and declared ranges.

    Computed once per class (a trade study validates every case's options): do not mutate the
    result.

    Parameters
    ----------
    options_class : type
        A dataclass whose fields are options (see the module docstring).

    Returns
    -------
    dict of str to (type, Range or None)
        ``{name: (type without Annotated, its Range or None)}`` in field order.
    """
    hints = typing.get_type_hints(options_class, include_extras=True)
    return {f.name: _split(hints[f.name]) for f in dataclasses.fields(options_class)}


def parse_options(options_class: type[T], values: Mapping[str, Any] | T | None, path: str = "options") -> T:
    """Build ``options_class`` from ``values`` (a mapping, an instance, or ``None`` for defaults).

    Parameters
    ----------
    options_class : type
        A dataclass whose fields are the options (see the module docstring).
    values : mapping, options_class instance or None
        The user's options (YAML keys to values); an instance is re-validated; ``None``: the
        defaults.
    path : str, optional
        YAML path of ``values``, used in error messages (default ``"options"``).

    Returns
    -------
    options_class
        The validated options, numbers converted (an ``int`` given for a ``float`` option
        becomes a ``float``).

    Raises
    ------
    OptionsError
        For an unknown key (listing the known ones), a value of the wrong type, or a value out of
        its declared range; the message names the path, the value and what was expected.
    """
    if values is None:
        values = {}
    elif isinstance(values, options_class):
        values = dataclasses.asdict(values)  # type: ignore[call-overload]
    if not isinstance(values, Mapping):
        raise OptionsError(path, f"expected a mapping of option names to values, got {excerpt(values)}")
    dataclass_type: type = options_class  # type[T] is hashable, which mypy cannot tell for a bare T
    fields = option_fields(dataclass_type)
    for name, (annotation, _) in fields.items():
        if not supported(annotation):
            raise TypeError(f"{options_class.__qualname__}.{name}: option type {annotation} is not supported; "
                            f"write one of {SUPPORTED}")
    kwargs = {}
    for key, value in values.items():
        if key not in fields:
            raise OptionsError(f"{path}.{key}", f"unknown option; expected one of {sorted(fields)}")
        annotation, bounds = fields[key]
        try:
            converted = _convert(value, annotation)
        except TypeError:
            raise OptionsError(f"{path}.{key}", f"expected {_describe(annotation)}, got {excerpt(value)}") from None
        if bounds is not None:
            _check_range(converted, bounds, f"{path}.{key}")
        kwargs[key] = converted
    try:
        return options_class(**kwargs)
    except InvalidOption as error:
        raise OptionsError(f"{path}.{error.option}", error.message) from None
    except ValueError as error:
        raise OptionsError(path, str(error)) from None


class Configurable:
    """Base of registered components (planners, controllers): a registry ``name`` and a frozen
    dataclass ``Options`` whose typed fields, with defaults and declared ranges, are the
    component's options.

    Parameters
    ----------
    options : mapping, Options instance or None, optional
        Option values by name (the YAML ``options`` mapping), an ``Options`` instance, or
        ``None`` (default) for the defaults; validated by :func:`parse_options` into
        :attr:`options`.
    path : str, optional
        YAML path of the options, for error messages (default ``"options"``).

    Raises
    ------
    OptionsError
        For an unknown option, a value of the wrong type or out of its range.
    TypeError
        If the subclass's ``Options`` is not a dataclass.
    """

    name: ClassVar[str]

    @dataclasses.dataclass(frozen=True)
    class Options:
        """The component's options: subclasses replace this empty dataclass by their own
        ``@dataclass(frozen=True) class Options`` whose fields are the YAML keys, each typed with
        its :class:`Range` and given a default."""

    def __init__(self, options: Mapping[str, Any] | Any | None = None, path: str = "options"):
        if not dataclasses.is_dataclass(self.Options):
            raise TypeError(f"{type(self).__name__}.Options must be a dataclass: decorate it with "
                            "@dataclass(frozen=True)")
        self.options = parse_options(self.Options, options, path)
