"""CasADi functions compiled to C with the system compiler, cached on disk by a hash of their code.

:func:`compile_function` writes the CasADi-generated C of a function, builds a shared library
with the system C compiler and loads it with ``casadi.external``. The build and its cache are
:func:`ocp.native.build_library`'s (the user's cache directory, keyed by the SHA-256 of the
generated source, the compiler and its flags): the source encodes every number of the model and the
law, so a changed model or law is a new build and an unchanged one is loaded without compiling.
"""
from __future__ import annotations

import sys
from pathlib import Path

import casadi as ca

from ocp import native

CFLAGS = ("-O1", "-fPIC", "-shared")
"""-O1: the generated code is long straight-line arithmetic; -O2/-O3 build several times slower
for a few per cent of run time."""


def compile_function(function: ca.Function, directory: Path | None = None) -> ca.Function:
    """The compiled twin of ``function`` (same name, inputs and outputs), built or loaded from cache.

    Parameters
    ----------
    function : casadi.Function
        A function that supports code generation (SX, MX, map/mapaccum of those).
    directory : pathlib.Path or None, optional
        Cache directory, created if needed; ``None`` (default): :func:`ocp.native.cache_directory`.

    Returns
    -------
    casadi.Function
        ``casadi.external`` of the shared library.

    Raises
    ------
    CompilerUnavailable
        No compiler found, or the build failed (its message says why).
    KeyboardInterrupt
        Ctrl-C stopped the compiler (it takes Ctrl-C's default action, also where the caller ignores
        Ctrl-C: a trade study's worker).
    """
    name = function.name()
    source = ca.CodeGenerator(f"{name}.c", {"with_header": False})
    source.add(function)
    library = native.build_library(source.dump(), name, CFLAGS, directory)
    return ca.external(name, str(library))


def notice(message: str) -> None:
    """Print one line, prefixed ``slewbench:``, on standard error (the fallback notice).

    Parameters
    ----------
    message : str
        The notice, e.g. why the compiled path is not used.
    """
    print(f"slewbench: {message}", file=sys.stderr)
