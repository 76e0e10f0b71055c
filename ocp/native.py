"""Native builds: the system C compiler and the cache of the shared libraries built with it.

:func:`build_library` compiles C source into a shared library with the system C compiler (``$CC``,
else ``cc`` or ``gcc``), cached in the user's cache directory (``$XDG_CACHE_HOME/slewbench`` or
``~/.cache/slewbench``) under a name keyed by the SHA-256 of the source, the compiler, its flags and
CasADi's version: an unchanged source is loaded without compiling, a changed one is a new build.
A build is written in a temporary directory beside the cache's files and renamed into place, so a
concurrent build of the same source is harmless and no half-written library is ever loaded.
Nothing is written anywhere else. :func:`load_library` builds a C file shipped with the package and
loads it with ``ctypes``. Their users: the compiled closed loop
(:func:`ocp.simulation.compiled.compile_function`) and the C kernels of the interior point
(:mod:`ocp.nlp.sparse_ldl`, :mod:`ocp.nlp.interior_point`).
"""
from __future__ import annotations

import ctypes
import hashlib
import os
import shutil
import signal
import subprocess
import tempfile
from collections.abc import Sequence
from pathlib import Path

import casadi as ca

from ocp.errors import CompilerUnavailable


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


def build_library(source: str, name: str, flags: Sequence[str], directory: Path | None = None) -> Path:
    """The shared library built from C ``source``, from the cache when it was built before.

    Parameters
    ----------
    source : str
        The C source (one translation unit).
    name : str
        The library's name, before the hash (``{name}_{hash}.so``).
    flags : sequence of str
        The compiler's flags (``-shared`` and ``-fPIC`` among them).
    directory : pathlib.Path or None, optional
        Cache directory, created if needed; ``None`` (default): :func:`cache_directory`.

    Returns
    -------
    pathlib.Path
        The library (complete: written under a temporary name and renamed).

    Raises
    ------
    CompilerUnavailable
        No compiler found, the build failed or the cache cannot be written (its message says why).
    KeyboardInterrupt
        Ctrl-C stopped the compiler (it takes Ctrl-C's default action, also where the caller ignores
        Ctrl-C: a trade study's worker).
    """
    compiler = find_compiler()
    if compiler is None:
        raise CompilerUnavailable("no C compiler found ($CC, cc or gcc)")
    version = ca.__version__  # type: ignore[attr-defined]  # set at import; absent from CasADi's stubs
    digest = hashlib.sha256("\n".join([source, compiler, *flags, version]).encode()).hexdigest()[:32]
    directory = Path(directory) if directory is not None else cache_directory()
    library = directory / f"{name}_{digest}.so"
    try:
        if not library.exists():
            directory.mkdir(parents=True, exist_ok=True)
            with tempfile.TemporaryDirectory(prefix=".build-", dir=directory) as build:
                c_file = Path(build) / f"{name}.c"
                c_file.write_text(source)
                partial = Path(build) / library.name
                completed = subprocess.run([compiler, *flags, str(c_file), "-o", str(partial), "-lm"],
                                           capture_output=True, text=True, check=False)
                if completed.returncode == -signal.SIGINT:  # Ctrl-C stopped the compiler: stop the caller too
                    raise KeyboardInterrupt
                if completed.returncode != 0:
                    raise CompilerUnavailable(f"{Path(compiler).name} failed: {completed.stderr.strip()[:300]}")
                os.replace(partial, library)  # atomic: a concurrent build of the same code is harmless
    except OSError as error:  # an unusable cache directory (a file, read-only, full): build nothing
        raise CompilerUnavailable(f"cannot build in the cache {directory}: {error.strerror or error}") from None
    return library


def load_library(source: Path, flags: Sequence[str]) -> ctypes.CDLL:
    """The shared library of the C file ``source`` (a file shipped with the package), built once
    (:func:`build_library`, named after the file) and loaded with ``ctypes``.

    Parameters
    ----------
    source : pathlib.Path
        The C file.
    flags : sequence of str
        The compiler's flags.

    Returns
    -------
    ctypes.CDLL
        The loaded library (its functions' ``argtypes`` are the caller's to declare).

    Raises
    ------
    CompilerUnavailable
        The build failed or the library does not load (the message says why).
    KeyboardInterrupt
        Ctrl-C stopped the compiler.
    """
    path = build_library(Path(source).read_text(), Path(source).stem, flags)
    try:
        return ctypes.CDLL(str(path))
    except OSError as error:
        raise CompilerUnavailable(f"cannot load {path}: {error}") from None
