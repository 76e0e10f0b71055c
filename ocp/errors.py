"""The exceptions of :mod:`ocp`, their common base :class:`SlewbenchError`, and bounded excerpts of
offending values for their messages.

Every exception slewbench raises on purpose derives from :class:`SlewbenchError`, so that a caller
can catch slewbench's errors apart from Python's. Each package has one exceptions module
(``ocp.errors``, ``planners.errors``, ``controllers.errors``, ``scenarios.errors``) whose classes
derive from the base defined here. This module imports nothing of slewbench.
"""
from __future__ import annotations

from typing import Any


class SlewbenchError(Exception):
    """Base of every exception slewbench raises on purpose (a user's mistake or a refused operation).

    Catch it to tell slewbench's errors from Python's own; each package's ``errors`` module derives
    its exceptions from it.

    Every one survives :mod:`pickle` (a sweep's worker process or a Dask worker sends an exception
    back to the sweep) and :func:`copy.copy` with its text, ``args`` and attributes unchanged:
    it is made again without its ``__init__`` (whose parameters are not its ``args``, the text),
    from its ``args`` and its attributes.
    """

    def __reduce__(self) -> tuple[Any, ...]:
        return _remade, (type(self), self.args), self.__dict__ or None


def _remade(cls: type[BaseException], args: tuple[Any, ...]) -> BaseException:
    """An exception of class ``cls`` with ``args``, its ``__init__`` not called (the unpickling of a
    :class:`SlewbenchError`; its attributes are restored after)."""
    error = cls.__new__(cls, *args)
    error.args = args
    return error


MAX_REPR = 80
"""Characters of an offending value shown in an error message."""


def excerpt(value: Any, limit: int = MAX_REPR) -> str:
    """``repr(value)`` cut to ``limit`` characters, so that an error never embeds a huge value.

    Parameters
    ----------
    value : any value, possibly a very large nested structure.
    limit : maximum number of characters of the result.

    Returns
    -------
    str
        The representation, with ``...`` and the total length when it was cut.
    """
    text = _bounded_repr(value, limit + 1)
    return text if len(text) <= limit else f"{text[:limit]}... (cut)"


def _bounded_repr(value: Any, budget: int) -> str:
    """``repr`` that stops building once ``budget`` characters are produced (alias bombs)."""
    if isinstance(value, (list, tuple)):
        parts, used = [], 1
        for item in value:
            if used >= budget:
                parts.append("...")
                break
            part = _bounded_repr(item, budget - used)
            parts.append(part)
            used += len(part) + 2
        return "[" + ", ".join(parts) + "]"
    if isinstance(value, dict):
        parts, used = [], 1
        for key, item in value.items():
            if used >= budget:
                parts.append("...")
                break
            part = f"{_bounded_repr(key, budget - used)}: {_bounded_repr(item, budget - used)}"
            parts.append(part)
            used += len(part) + 2
        return "{" + ", ".join(parts) + "}"
    text = repr(value)
    return text[:budget] if len(text) > budget else text


class OptionsError(SlewbenchError, ValueError):
    """An option is unknown, of the wrong type or out of range.

    Parameters
    ----------
    path : str
        YAML path of the offending value (``planners[1].options.weight``), kept as :attr:`path`.
    message : str
        What was expected and what was given, kept as :attr:`message`.
    """

    def __init__(self, path: str, message: str):
        super().__init__(f"{path}: {message}")
        self.path = path
        self.message = message


class InvalidOption(SlewbenchError, ValueError):
    """Raised by an ``Options.__post_init__`` for a value that is wrong in relation to the others.

    Parameters
    ----------
    option : str
        The field's name, kept as :attr:`option` (:func:`parse_options` prefixes the YAML path).
    message : str
        What is wrong, kept as :attr:`message`.
    """

    def __init__(self, option: str, message: str):
        super().__init__(f"{option}: {message}")
        self.option = option
        self.message = message


class ModelError(SlewbenchError, ValueError):
    """Invalid model parameter.

    Parameters
    ----------
    field_name : str
        The offending attribute (e.g. ``"inertia"``), kept as :attr:`field` so that the YAML
        loader can point at the input.
    message : str
        What was wrong and what was expected, kept as :attr:`message`.
    """

    def __init__(self, field_name: str, message: str):
        super().__init__(f"{field_name}: {message}")
        self.field = field_name
        self.message = message


class SimulationError(SlewbenchError, RuntimeError):
    """The integration diverged (non-finite state), e.g. a step far too long for the rates.

    A run refused before it starts, for its arguments, raises the subclass
    :class:`SimulationArgumentError` (also a ``ValueError``).
    """


class SimulationArgumentError(SimulationError, ValueError):
    """A run refused for its arguments before any step: a ``duration`` over the work limit
    (``max_samples``) or past a tabulated magnetic field. A ``ValueError``, as every bad argument
    is, and a :class:`SimulationError`, as the run's work limit has always been reported."""


class CompilerUnavailable(SlewbenchError, RuntimeError):
    """No working C compiler (the caller falls back to the interpreted function)."""
