"""Lazy package faces: a subpackage's public names imported from their modules on first use (PEP 562).

The command line forks its plot process before anything imports NumPy or the model
(:mod:`scenarios.console`), so importing a package of :mod:`scenarios` must cost nothing until one
of its names is used. Each face lists where its names live and takes its ``__getattr__`` and
``__dir__`` from :func:`lazy_face`. This module imports only the standard library.
"""
from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from typing import Any


def lazy_face(package: str, homes: Mapping[str, str]) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """The ``__getattr__`` and ``__dir__`` of a package whose public names are imported on first use.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    homes : mapping of str to str
        Public name -> the module that defines it.

    Returns
    -------
    tuple of callable
        ``(__getattr__, __dir__)`` for the package's namespace: ``__getattr__(name)`` returns the
        public name from its home, or the submodule ``name`` (imported), and raises
        ``AttributeError`` otherwise; ``__dir__()`` lists the public names (``__all__``) and the
        module's dunder attributes, not its helpers or imports (submodules stay reachable).
    """
    def __getattr__(name: str) -> Any:
        home = homes.get(name)
        if home is not None:
            return getattr(importlib.import_module(home), name)
        if not name.startswith("__"):  # a submodule, as when the package imported them all
            try:
                return importlib.import_module(f"{package}.{name}")
            except ModuleNotFoundError as error:
                if error.name != f"{package}.{name}":
                    raise
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__() -> list[str]:
        namespace = vars(importlib.import_module(package))
        return sorted(set(namespace.get("__all__", homes)) | {name for name in namespace if _is_dunder(name)})

    return __getattr__, __dir__


def _is_dunder(name: str) -> bool:
    """``__name__``, ``__all__`` ...: the module attributes ``dir()`` keeps beside the public names."""
    return name.startswith("__") and name.endswith("__")
