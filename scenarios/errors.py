"""The exceptions of :mod:`scenarios`, derived from :class:`ocp.errors.SlewbenchError`.

:class:`ScenarioError` is a user's mistake in a scenario or study file (or a library argument), at
its YAML path; :class:`OutputError` an output location slewbench must not or cannot write to, at
that location (it is not a :class:`ScenarioError`: the scenario may be right). Both end the command
line with exit status 2. :class:`SweepInterrupted` is a study stopped before every case finished.
Imports only :mod:`ocp.errors`.
"""
from __future__ import annotations

from pathlib import Path

from ocp.errors import SlewbenchError

__all__ = ["CaseTimeout", "OutputError", "ScenarioError", "SweepInterrupted"]


class ScenarioError(SlewbenchError, ValueError):
    """A scenario file is wrong; ``path`` is where, ``message`` what was expected."""

    def __init__(self, path: str, message: str):
        super().__init__(f"{path}: {message}" if path else message)
        self.path = path
        self.message = message


class OutputError(SlewbenchError):
    """An output location slewbench must not or cannot write to (exit status 2); nothing was written.

    Parameters
    ----------
    path : str or Path
        The output location (a directory, or a file in it).
    message : str
        What is wrong with it and what to do.
    """

    def __init__(self, path: str | Path, message: str):
        super().__init__(f"{path}: {message}")
        self.path = Path(path)
        self.message = message


class CaseTimeout(SlewbenchError):
    """Raised inside a worker when a case exceeds its time limit."""


class SweepInterrupted(SlewbenchError):
    """The sweep was stopped before every case finished; ``missing`` cases are not stored.

    Parameters
    ----------
    missing : int
        Cases not finished (not in the store).
    total : int
        Cases of the study.
    """

    def __init__(self, missing: int, total: int) -> None:
        super().__init__(f"{missing} of {total} cases are missing")
        self.missing, self.total = missing, total
