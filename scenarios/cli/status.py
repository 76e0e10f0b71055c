"""The exit statuses of the ``slewbench`` command line, one set for every command, and the check of
the directory arguments every command shares.

May import: nothing of slewbench.
"""
from __future__ import annotations

import argparse

__all__ = ["EXIT_BAD_OUTPUT", "EXIT_BAD_SCENARIO", "EXIT_INTERNAL", "EXIT_INTERRUPTED", "EXIT_NOT_OK", "EXIT_OK",
           "directory_argument"]

EXIT_OK = 0
"""The command completed (a run's failed and violated rows included: they are results), unless
``run --strict`` found a row that is not ok."""
EXIT_INTERNAL = 1
"""An internal error (a bug), or a run interrupted by Ctrl-C or SIGTERM."""
EXIT_NOT_OK = 1
"""``slewbench run --strict``: the run completed and wrote its results, and some row is not ``ok``
(``violated`` or ``failed``): for users' continuous integration."""
EXIT_BAD_SCENARIO = 2
"""A bad scenario or study file (or key of ``slewbench schema``): nothing was written."""
EXIT_BAD_OUTPUT = 2
"""An output location slewbench must not or cannot write to: nothing was touched."""
EXIT_INTERRUPTED = 130
"""A sweep stopped before every case finished (rerun it with ``--resume``)."""


def directory_argument(text: str) -> str:
    """An output directory given on the command line (``argparse`` ``type``): refuses an empty one.

    ``--out ""`` used to fall back to the default ``results/<name>`` without a word.

    Parameters
    ----------
    text : str
        The argument as given.

    Returns
    -------
    str
        ``text``, unchanged.

    Raises
    ------
    argparse.ArgumentTypeError
        For an empty or blank path (argparse exits 2 with the option's name).
    """
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path: give the output directory")
    return text
