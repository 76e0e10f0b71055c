"""Every public class and function of ocp, planners, controllers and scenarios is typed and carries a
numpydoc docstring (Parameters, Returns), as python-control's docstring test enforces for its API.

The rules and the audit live in ``tests/public_api.py``; ``python tests/public_api.py`` lists the
breaches by file.
"""
from __future__ import annotations

import importlib
import pkgutil
from dataclasses import dataclass
from typing import Protocol

import pytest

from tests.public_api import (
    PACKAGES,
    audit_module,
    audited,
    census,
    check_class,
    check_function,
    public_modules,
)

MODULES = [module.__name__ for module in public_modules(PACKAGES)]
MODULES_FLOOR, NAMES_FLOOR = 102, 579
"""What the audit covered once the packages were cut into subpackages (91 modules and 578 names
before): a walk that stops seeing subpackages, or names that leave the audit, falls below it."""


@pytest.mark.parametrize("module", MODULES)
def test_public_api_is_typed_and_documented(module: str) -> None:
    problems = audit_module(importlib.import_module(module))
    assert not problems, f"{module}: {len(problems)} breaches\n" + "\n".join(problems)


def test_the_audit_covers_every_subpackage() -> None:
    modules, classes, functions = census()
    assert modules >= MODULES_FLOOR and classes + functions >= NAMES_FLOOR, (
        f"the audit covers {modules} modules and {classes + functions} names, fewer than the "
        f"{MODULES_FLOOR} and {NAMES_FLOOR} of the house: does it still walk every subpackage?")


def test_a_walk_that_misses_subpackages_falls_below_the_floor() -> None:
    flat = [importlib.import_module(name) for package in PACKAGES for name in
            [package] + [f"{package}.{info.name}" for info in pkgutil.iter_modules(importlib.import_module(package).__path__)
                         if not info.ispkg and not info.name.startswith("_")]]
    names = sum(len(audited(module)) for module in flat)
    assert len(flat) < MODULES_FLOOR and names < NAMES_FLOOR


# The audit itself must catch each kind of breach, or the test above proves nothing.

def _good(angle: float, axis: tuple[float, float, float], *args: float, **kwargs: float) -> float:
    """Rotation about an axis.

    Parameters
    ----------
    angle : float
        Rotation angle [rad].
    axis : tuple of float
        Unit axis, body frame.
    *args, **kwargs : float
        Ignored.

    Returns
    -------
    float
        The angle [rad].
    """
    return angle


def _undocumented_parameter(angle: float, axis: float) -> float:
    """Rotation.

    Parameters
    ----------
    angle : float
        Rotation angle [rad].

    Returns
    -------
    float
        The angle [rad].
    """
    return angle


def _no_returns(angle: float) -> float:
    """Rotation.

    Parameters
    ----------
    angle : float
        Rotation angle [rad].
    """
    return angle


def _untyped(angle, axis: float):  # type: ignore[no-untyped-def]
    """Rotation.

    Parameters
    ----------
    angle, axis : float
        Rotation angle [rad] and axis.

    Returns
    -------
    float
        The angle [rad].
    """
    return angle


def _no_docstring(angle: float) -> None:
    return None


@dataclass
class _Documented:
    """A gain.

    Parameters
    ----------
    gain : float
        Proportional gain [N m/rad].
    """

    gain: float = 1.0


@dataclass
class _UndocumentedField:
    """A gain without its field documented."""

    gain: float = 1.0


def test_audit_accepts_a_complete_function_and_class() -> None:
    assert check_function("good", _good) == []
    assert check_class("Documented", _Documented) == []


@pytest.mark.parametrize("function, breach", [
    (_undocumented_parameter, "does not document ['axis']"),
    (_no_returns, "no 'Returns' section"),
    (_untyped, "parameter 'angle' has no type hint"),
    (_untyped, "no return type hint"),
    (_no_docstring, "no docstring"),
])
def test_audit_reports_each_breach(function, breach: str) -> None:  # type: ignore[no-untyped-def]
    assert any(breach in problem for problem in check_function("f", function))


def test_audit_reports_an_undocumented_dataclass_field() -> None:
    assert any("['gain']" in problem for problem in check_class("C", _UndocumentedField))


class _Law(Protocol):
    """What a caller needs of a law (typing.Protocol writes its own ``__init__``)."""

    def command(self, t: float) -> float:
        """The command at ``t``.

        Parameters
        ----------
        t : float
            Time [s].

        Returns
        -------
        float
            Torque [N m].
        """


class _UntypedInit:
    """A class whose own constructor lacks a hint.

    Parameters
    ----------
    gain : float
        Gain.
    """

    def __init__(self, gain):  # type: ignore[no-untyped-def]
        self.gain = gain


def test_audit_judges_the_constructor_a_class_writes_not_one_a_library_installs() -> None:
    assert check_class("Law", _Law) == []
    assert any("parameter 'gain' has no type hint" in problem for problem in check_class("C", _UntypedInit))
