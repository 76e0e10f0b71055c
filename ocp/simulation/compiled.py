"""CasADi functions compiled to C with the system compiler, cached on disk by a hash of their code.

:func:`compile_function` writes the CasADi-generated C of a function, builds a shared library
with the system C compiler (``$CC``, else ``cc`` or ``gcc``) and loads it with ``casadi.external``.
The build is cached in the user's cache directory (``$XDG_CACHE_HOME/slewbench`` or
``~/.cache/slewbench``), keyed by the SHA-256 of the generated source, the compiler and its flags:
the source encodes every number of the model and the law, so a changed model or law is a new
build and an unchanged one is loaded without compiling. Nothing is written anywhere else.
"""
from __future__ import annotations

import hashlib
import os
import shutil
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

import casadi as ca

from ocp.errors import CompilerUnavailable

CFLAGS = ("-O1", "-fPIC", "-shared")
"""-O1: the generated code is long straight-line arithmetic; -O2/-O3 build several times slower
for a few per cent of run time."""


def cache_directory() -> Path:
    """The default directory of the builds, the only place they go.

    Returns
    -------
    pathlib.Path
        ``$XDG_CACHE_HOME/slewbench``, or ``~/.cache/slewbench`` when the variable is unset or
        empty (not created here).
    """
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "slewbench"


def find_compiler() -> str | None:
    """The C compiler to use.

    Returns
    -------
    str or None
        Full path of ``$CC`` if set and found on ``PATH``, else of ``cc``, else of ``gcc``;
        ``None`` when none is found.
    """
    for candidate in (os.environ.get("CC"), "cc", "gcc"):
        if candidate and shutil.which(candidate):
            return shutil.which(candidate)
    return None


def compile_function(function: ca.Function, directory: Path | None = None) -> ca.Function:
    """The compiled twin of ``function`` (same name, inputs and outputs), built or loaded from cache.

    Parameters
    ----------
    function : casadi.Function
        A function that supports code generation (SX, MX, map/mapaccum of those).
    directory : pathlib.Path or None, optional
        Cache directory, created if needed; ``None`` (default): :func:`cache_directory`.

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
    compiler = find_compiler()
    if compiler is None:
        raise CompilerUnavailable("no C compiler found ($CC, cc or gcc)")
    name = function.name()
    source = ca.CodeGenerator(f"{name}.c", {"with_header": False})
    source.add(function)
    text = source.dump()
    version = ca.__version__  # type: ignore[attr-defined]  # set at import; absent from CasADi's stubs
    digest = hashlib.sha256("\n".join([text, compiler, *CFLAGS, version]).encode()).hexdigest()[:32]
    directory = Path(directory) if directory is not None else cache_directory()
    library = directory / f"{name}_{digest}.so"
    try:
        if not library.exists():
            directory.mkdir(parents=True, exist_ok=True)
            with tempfile.TemporaryDirectory(prefix=".build-", dir=directory) as build:
                c_file = Path(build) / f"{name}.c"
                c_file.write_text(text)
                partial = Path(build) / library.name
                completed = subprocess.run([compiler, *CFLAGS, str(c_file), "-o", str(partial), "-lm"],
                                           capture_output=True, text=True, check=False)
                if completed.returncode == -signal.SIGINT:  # Ctrl-C stopped the compiler: stop the caller too
                    raise KeyboardInterrupt
                if completed.returncode != 0:
                    raise CompilerUnavailable(f"{Path(compiler).name} failed: {completed.stderr.strip()[:300]}")
                os.replace(partial, library)  # atomic: a concurrent build of the same code is harmless
    except OSError as error:  # an unusable cache directory (a file, read-only, full): build nothing
        raise CompilerUnavailable(f"cannot build in the cache {directory}: {error.strerror or error}") from None
    return ca.external(name, str(library))


def notice(message: str) -> None:
    """Print one line, prefixed ``slewbench:``, on standard error (the fallback notice).

    Parameters
    ----------
    message : str
        The notice, e.g. why the compiled path is not used.
    """
    print(f"slewbench: {message}", file=sys.stderr)
