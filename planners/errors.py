"""The exceptions of :mod:`planners`, derived from :class:`ocp.errors.SlewbenchError`.

A planner that cannot plan returns a :class:`~planners.reference.FailedReference` (a failed row
with its message), it does not raise: these are for contract breaches. Imports only
:mod:`ocp.errors`.
"""
from __future__ import annotations

from collections.abc import Iterable
from difflib import get_close_matches

from ocp.errors import SlewbenchError

__all__ = ["ConformanceError", "UnknownNameError"]


class ConformanceError(SlewbenchError, AssertionError):
    """A reference breaks the planner contract (:func:`planners.conformance.check_reference`);
    the message says what to fix.

    A law that breaks the controller contract raises :class:`controllers.ConformanceError`
    instead, a class of its own (each package's errors import only :mod:`ocp.errors`); catch
    both as ``AssertionError`` or :class:`~ocp.errors.SlewbenchError`.
    """


class UnknownNameError(SlewbenchError, KeyError):
    """A registry (``PLANNERS``, ``CONTROLLERS``) has no entry of that name; the message lists
    the registered names.

    A ``KeyError``, so that ``except KeyError`` still catches it; its message is plain text (a bare
    ``KeyError`` shows only the quoted key).

    Parameters
    ----------
    kind : str
        What the registry holds (``"planner"``, ``"controller"``).
    name : object
        The name looked up, kept as :attr:`name`.
    registered : iterable of str
        The registry's names, kept sorted as :attr:`registered`.
    """

    def __init__(self, kind: str, name: object, registered: Iterable[str]) -> None:
        self.kind = kind
        self.name = name
        self.registered = sorted(registered)
        close = get_close_matches(name, self.registered, n=1) if isinstance(name, str) else []
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        super().__init__(f"unknown {kind} {name!r}; registered: {self.registered}{hint}")

    def __str__(self) -> str:
        return str(self.args[0])
