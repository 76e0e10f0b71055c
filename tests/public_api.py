"""Audit of slewbench's public API: type hints and numpydoc docstrings (python-control style).

Public means: a module of ``ocp``, ``planners``, ``controllers`` or ``scenarios`` whose name has no
leading underscore, and in it every class and function defined there whose name has no leading
underscore, with the public methods and properties a class defines itself.

Rules (one message per breach):

* every public function, method, property and class has a docstring;
* every parameter but ``self``/``cls`` and every return is annotated;
* a function or method with parameters has a numpydoc ``Parameters`` section naming each of them
  (``*args``/``**kwargs`` by their bare names), and one that returns something other than ``None``
  has a ``Returns`` or ``Yields`` section;
* a class whose constructor takes arguments names each of them in a ``Parameters`` or
  ``Attributes`` section of the class docstring.

A method that overrides a documented base-class method inherits its docstring (``inspect.getdoc``),
so the contract is written once, on the base class.

Run ``python tests/public_api.py [PACKAGE ...]`` from the repository root to list the breaches by
file and count what was audited (modules, classes, functions and methods); ``tests/test_public_api.py``
fails on any breach, and if the count falls below the house's.
"""
from __future__ import annotations

import dataclasses
import enum
import importlib
import inspect
import pkgutil
import re
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

PACKAGES = ("ocp", "planners", "controllers", "scenarios")
_SECTION = re.compile(r"^(?P<name>[A-Z][A-Za-z ]+)\n-{3,}\s*$", re.MULTILINE)
_ENTRY = re.compile(r"^(?P<names>\*{0,2}[A-Za-z_][\w]*(?:\s*,\s*\*{0,2}[A-Za-z_][\w]*)*)\s*(?::|$)")


def public_modules(packages: tuple[str, ...] = PACKAGES) -> Iterator[Any]:
    """Import and yield every public module of ``packages``, subpackages at any depth (the packages included)."""
    for package_name in packages:
        package = importlib.import_module(package_name)
        yield package
        for info in pkgutil.walk_packages(package.__path__, prefix=f"{package_name}."):
            if any(part.startswith("_") for part in info.name.split(".")):
                continue  # private modules and __main__
            yield importlib.import_module(info.name)


def sections(doc: str) -> dict[str, str]:
    """numpydoc sections of ``doc`` by title (``Parameters``, ``Returns`` ...) with their bodies."""
    found = list(_SECTION.finditer(doc))
    return {m.group("name").strip(): doc[m.end():found[i + 1].start() if i + 1 < len(found) else len(doc)]
            for i, m in enumerate(found)}


def documented_names(body: str) -> set[str]:
    """Names documented in a Parameters/Attributes section body: its unindented ``name : type`` lines."""
    names: set[str] = set()
    lines = inspect.cleandoc("x\n" + body).splitlines()[1:]
    for line in lines:
        if not line.strip() or line[:1].isspace():
            continue
        match = _ENTRY.match(line.strip())
        if match:
            names.update(n.strip().lstrip("*") for n in match.group("names").split(","))
    return names


def _signature(obj: Callable[..., Any]) -> inspect.Signature | None:
    try:
        return inspect.signature(obj)
    except (TypeError, ValueError):
        return None


def _parameters(signature: inspect.Signature, bound: bool) -> list[inspect.Parameter]:
    params = list(signature.parameters.values())
    if bound and params and params[0].name in ("self", "cls"):
        params = params[1:]
    return params


def check_function(qualname: str, function: Callable[..., Any], method: bool = False,
                   doc: str | None = None) -> list[str]:
    """Breaches of the rules by one function or method (``doc`` overrides its own docstring)."""
    problems: list[str] = []
    doc = doc if doc is not None else inspect.getdoc(function)
    signature = _signature(function)
    if signature is None:
        return problems
    params = _parameters(signature, method)
    for p in params:
        if p.annotation is inspect.Parameter.empty:
            problems.append(f"{qualname}: parameter '{p.name}' has no type hint")
    returns = signature.return_annotation
    if returns is inspect.Signature.empty and function.__name__ != "__init__":
        problems.append(f"{qualname}: no return type hint")
    if not doc:
        problems.append(f"{qualname}: no docstring")
        return problems
    found = sections(doc)
    if params:
        if "Parameters" not in found:
            problems.append(f"{qualname}: docstring has no 'Parameters' section")
        else:
            missing = [p.name for p in params if p.name not in documented_names(found["Parameters"])]
            if missing:
                problems.append(f"{qualname}: 'Parameters' does not document {missing}")
    returns_nothing = returns in (None, "None", inspect.Signature.empty)
    if not returns_nothing and not ({"Returns", "Yields"} & found.keys()):
        problems.append(f"{qualname}: docstring has no 'Returns' section")
    return problems


def _constructor_parameters(cls: type) -> list[inspect.Parameter]:
    if issubclass(cls, (BaseException, enum.Enum)):
        return []
    init = cls.__dict__.get("__init__")
    if init is None and not dataclasses.is_dataclass(cls):
        return []
    signature = _signature(cls)
    return [] if signature is None else [p for p in signature.parameters.values()
                                         if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]


def check_class(qualname: str, cls: type) -> list[str]:
    """Breaches of the rules by one class, its constructor and its own public methods."""
    problems: list[str] = []
    doc = cls.__doc__ if "__doc__" in cls.__dict__ else None
    if dataclasses.is_dataclass(cls) and doc and re.match(rf"{cls.__name__}\(.*\)$", doc.strip()):
        doc = None                       # the signature dataclasses write when there is no docstring
    if not doc:
        problems.append(f"{qualname}: no class docstring")
    else:
        params = _constructor_parameters(cls)
        if params:
            found = sections(inspect.cleandoc(doc))
            names = documented_names(found.get("Parameters", "")) | documented_names(found.get("Attributes", ""))
            missing = [p.name for p in params if p.name not in names]
            if missing:
                problems.append(f"{qualname}: class docstring does not document constructor arguments {missing}")
    init = cls.__dict__.get("__init__")
    # An __init__ written elsewhere is not the class's (typing.Protocol installs its own).
    if inspect.isfunction(init) and init.__module__ == cls.__module__:
        signature = _signature(init)
        for p in _parameters(signature, True) if signature else []:
            if p.annotation is inspect.Parameter.empty:
                problems.append(f"{qualname}.__init__: parameter '{p.name}' has no type hint")
    for name, member in class_members(cls):
        where = f"{qualname}.{name}"
        if isinstance(member, property):
            if member.fget is not None:
                problems += [p for p in check_function(where, member.fget, method=True,
                                                       doc=inspect.getdoc(getattr(cls, name, member)) or None)
                             if "Returns" not in p]
        elif isinstance(member, (staticmethod, classmethod)):
            problems += check_function(where, member.__func__, method=isinstance(member, classmethod),
                                       doc=_inherited_doc(cls, name, member.__func__))
        elif inspect.isfunction(member):
            problems += check_function(where, member, method=True, doc=_inherited_doc(cls, name, member))
        elif inspect.isclass(member):
            problems += check_class(where, member)
    return problems


def class_members(cls: type) -> Iterator[tuple[str, Any]]:
    """The public members a class defines itself that the audit checks: functions, properties,
    static and class methods, and the classes nested in it."""
    for name, member in cls.__dict__.items():
        if name.startswith("_"):
            continue
        if (isinstance(member, (property, staticmethod, classmethod)) or inspect.isfunction(member)
                or (inspect.isclass(member) and member.__qualname__.startswith(cls.__qualname__ + "."))):
            yield name, member


def module_members(module: Any) -> Iterator[tuple[str, Any]]:
    """The public classes and functions defined in ``module`` (not those it imports)."""
    for name, obj in vars(module).items():
        if name.startswith("_") or getattr(obj, "__module__", None) != module.__name__:
            continue
        if inspect.isclass(obj) or inspect.isfunction(obj):
            yield name, obj


def audited(module: Any) -> list[tuple[str, Any]]:
    """``(qualified name, object)`` of everything the audit checks in ``module``: its classes and
    functions, and the members of its classes (nested classes' members too)."""
    found: list[tuple[str, Any]] = []

    def walk(qualname: str, obj: Any) -> None:
        found.append((qualname, obj))
        if inspect.isclass(obj):
            for name, member in class_members(obj):
                walk(f"{qualname}.{name}", member)

    for name, obj in module_members(module):
        walk(f"{module.__name__}.{name}", obj)
    return found


def census(packages: tuple[str, ...] = PACKAGES) -> tuple[int, int, int]:
    """How much the audit covers: ``(modules, classes, functions)``, the public modules walked
    (subpackages at any depth), the classes audited (nested ones included), and the functions,
    methods and properties audited."""
    modules = classes = functions = 0
    for module in public_modules(packages):
        modules += 1
        for _, obj in audited(module):
            if inspect.isclass(obj):
                classes += 1
            else:
                functions += 1
    return modules, classes, functions


def _inherited_doc(cls: type, name: str, function: Callable[..., Any]) -> str | None:
    if function.__doc__:
        return inspect.cleandoc(function.__doc__)
    for base in cls.__mro__[1:]:
        inherited = base.__dict__.get(name)
        inherited = getattr(inherited, "__func__", inherited)
        if inherited is not None and getattr(inherited, "__doc__", None):
            return inspect.cleandoc(inherited.__doc__)
    return None


def audit_module(module: Any) -> list[str]:
    """Every breach of the rules by the public classes and functions defined in ``module``."""
    problems: list[str] = []
    for name, obj in module_members(module):
        where = f"{module.__name__}.{name}"
        if inspect.isclass(obj):
            problems += check_class(where, obj)
        elif inspect.isfunction(obj):
            problems += check_function(where, obj)
    return problems


def audit(packages: tuple[str, ...] = PACKAGES) -> dict[str, list[str]]:
    """Every breach of the rules in ``packages``, by source file."""
    report: dict[str, list[str]] = {}
    for module in public_modules(packages):
        problems = audit_module(module)
        if problems:
            report[module.__file__ or module.__name__] = problems
    return report


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    result = audit(tuple(sys.argv[1:]) or PACKAGES)
    total = 0
    for path, problems in sorted(result.items()):
        print(f"{path} ({len(problems)})")
        for problem in problems:
            print(f"    {problem}")
        total += len(problems)
    print(f"{total} breaches in {len(result)} files")
    modules, classes, functions = census(tuple(sys.argv[1:]) or PACKAGES)
    print(f"audited {modules} modules: {classes} classes and {functions} functions, methods and properties "
          f"({classes + functions} names)")
    sys.exit(1 if total else 0)
