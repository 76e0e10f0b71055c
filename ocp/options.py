"""Typed options for planners and controllers: a dataclass of fields with defaults, filled from a
mapping with checks that name the offending key (``planners[1].options.weight``).

Supported field types: ``float``, ``int``, ``bool``, ``str``, ``Literal[...]``, ``X | None``,
``list[float]`` (a vector) and ``list[list[float]]`` (a matrix); ``float | list[list[float]]``
accepts either.
"""
from __future__ import annotations

import dataclasses
import types
import typing
from typing import Any, ClassVar, Literal, Mapping, TypeVar, Union

T = TypeVar("T")


class OptionsError(ValueError):
    """An option is unknown or of the wrong type; ``path`` locates it, ``message`` says what was expected."""

    def __init__(self, path: str, message: str):
        super().__init__(f"{path}: {message}")
        self.path = path
        self.message = message


def _describe(annotation: Any) -> str:
    origin = typing.get_origin(annotation)
    if origin is Literal:
        return "one of " + ", ".join(repr(a) for a in typing.get_args(annotation))
    if origin in (Union, types.UnionType):
        return " or ".join(_describe(a) for a in typing.get_args(annotation))
    if annotation is type(None):
        return "null"
    if origin is list:
        inner = typing.get_args(annotation)[0]
        return {float: "a list of numbers", str: "a list of names", dict: "a list of mappings"}.get(
            inner, "a matrix (list of lists of numbers)")
    return {float: "a number", int: "an integer", bool: "true or false", str: "a string"}.get(annotation, str(annotation))


def _convert(value: Any, annotation: Any) -> Any:
    """Converted value, or raise ``TypeError`` if it does not fit ``annotation``."""
    origin = typing.get_origin(annotation)
    if origin is Literal:
        if value in typing.get_args(annotation):
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
            return float(value)
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
    raise TypeError


def parse_options(options_class: type[T], values: Mapping[str, Any] | T | None, path: str = "options") -> T:
    """Build ``options_class`` from ``values`` (a mapping, an instance, or ``None`` for defaults).

    Raises
    ------
    OptionsError
        For an unknown key (listing the known ones) or a value of the wrong type.
    """
    if values is None:
        return options_class()
    if isinstance(values, options_class):
        return values
    if not isinstance(values, Mapping):
        raise OptionsError(path, "expected a mapping of option names to values")
    hints = typing.get_type_hints(options_class)
    known = {f.name for f in dataclasses.fields(options_class)}
    kwargs = {}
    for key, value in values.items():
        if key not in known:
            raise OptionsError(f"{path}.{key}", f"unknown option; expected one of {sorted(known)}")
        try:
            kwargs[key] = _convert(value, hints[key])
        except TypeError:
            raise OptionsError(f"{path}.{key}", f"expected {_describe(hints[key])}, got {value!r}") from None
    try:
        return options_class(**kwargs)
    except ValueError as error:  # __post_init__ checks of ranges
        raise OptionsError(path, str(error)) from None


class Configurable:
    """Base of registered components (planners, controllers): a registry ``name`` and a frozen
    dataclass ``Options`` whose typed fields, with defaults, are the component's options."""

    name: ClassVar[str]

    @dataclasses.dataclass(frozen=True)
    class Options:
        pass

    def __init__(self, options: Mapping[str, Any] | Any | None = None, path: str = "options"):
        self.options = parse_options(self.Options, options, path)
