"""The exceptions of :mod:`scenarios`, derived from :class:`ocp.errors.SlewbenchError`.

:class:`ScenarioError` is a user's mistake in a scenario or study file (or a library argument), at
its YAML path, naming the file where one was read (:func:`in_file`); :class:`OutputError` an output location slewbench must not or cannot write to, at
that location (it is not a :class:`ScenarioError`: the scenario may be right). Both end the command
line with exit status 2. :class:`SweepInterrupted` is a study stopped before every case finished.
:class:`CaseTimeout`, a case out of time in a sweep's worker, is the one exception here not derived
from :class:`~ocp.errors.SlewbenchError` (it derives from :class:`BaseException`).
:class:`PlausibilityWarning` is no error: a warning (:func:`warnings.warn`) on a value that is
valid but almost certainly a unit or layout slip.
Imports only :mod:`ocp.errors`.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from ocp.errors import SlewbenchError

__all__ = ["CaseTimeout", "OutputError", "PlausibilityWarning", "ScenarioError", "SweepInterrupted", "WorkersCannotStart",
           "in_file"]

ANOTHER_DIRECTORY = "choose another directory (the `directory` argument; --out on the command line)"
"""The remedy an :class:`OutputError` names for a directory it refuses: in the library's terms (the
argument of :meth:`~scenarios.output.results.RunResults.write`) and the command line's."""
MAX_PATH_CHARS = 300
"""Characters of a path shown in an error's text (the attribute keeps it whole)."""
MAX_MESSAGE_CHARS = 2000
"""Characters of a message shown in an error's text (the attribute keeps it whole)."""


def _bounded(text: str, limit: int) -> str:
    """``text`` with its middle cut out when longer than ``limit``: head and tail stay."""
    if len(text) <= limit:
        return text
    keep = max(limit - 40, 20)
    return f"{text[:keep * 2 // 3]}...({len(text)} characters)...{text[-(keep - keep * 2 // 3):]}"


class ScenarioError(SlewbenchError, ValueError):
    """A scenario file is wrong; ``path`` is where, ``message`` what was expected.

    The error's text shows at most :data:`MAX_PATH_CHARS` of the path and
    :data:`MAX_MESSAGE_CHARS` of the message, whatever a file holds.

    Parameters
    ----------
    path : str
        The YAML path of the wrong value (``maneuver.duration``), kept as :attr:`path`; empty for
        the file as a whole.
    message : str
        What is wrong and what was expected, kept as :attr:`message`.
    file : str or os.PathLike or None, optional
        The file read, kept as :attr:`file` (a :class:`~pathlib.Path`, or None for data not read
        from a file); the text starts with it (``FILE: path: message``) unless the path or message
        already names it. :func:`in_file` sets it on an error raised while a file is read.
    """

    def __init__(self, path: str, message: str, file: str | os.PathLike[str] | None = None):
        shown = _bounded(message, MAX_MESSAGE_CHARS)
        text = f"{_bounded(path, MAX_PATH_CHARS)}: {shown}" if path else shown
        if file is not None and str(Path(file)) not in f"{path}: {message}":
            text = f"{_bounded(str(Path(file)), MAX_PATH_CHARS)}: {text}"
        super().__init__(text)
        self.path = path
        self.message = message
        self.file = None if file is None else Path(file)


def in_file(error: ScenarioError, file: str | os.PathLike[str], kind: str = "scenario") -> ScenarioError:
    """``error``, raised while ``file`` was read, as the error that names the file.

    The one way :func:`scenarios.load`, :func:`scenarios.load_study` and the other readers of a
    file name it: the result's :attr:`~ScenarioError.file` is ``file`` and its text starts with it
    (once: not where the error already names it); a YAML path equal to the file is dropped (the
    file as a whole), and a missing file is a ``<kind> file not found``.

    Parameters
    ----------
    error : ScenarioError
        The error raised while the file was read and checked.
    file : str or os.PathLike
        The file.
    kind : str, optional
        What the file is (``scenario``, ``study``, ``table``; ``YAML`` where its kind is not known
        yet), named when it is not found.

    Returns
    -------
    ScenarioError
        ``error`` itself when it already has a file (one read inside this one names its own) or is
        a command-line option's (its path starts with ``--``), else a new error with the same path
        and message.
    """
    if error.file is not None or (error.path or "").startswith("--"):
        return error
    named, message = Path(file), error.message
    if not error.path and message == f"scenario file not found: {named}":
        message = f"{kind} file not found: {named}"
    return ScenarioError("" if error.path in (str(file), str(named)) else error.path, message, named)


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
        super().__init__(f"{_bounded(str(path), MAX_PATH_CHARS)}: {_bounded(message, MAX_MESSAGE_CHARS)}")
        self.path = Path(path)
        self.message = message


class PlausibilityWarning(UserWarning):
    """A scenario value the schema accepts that is almost certainly a unit or layout slip (a wheel
    torque in mN m written as N m, wheels whose axes span a plane), issued with :func:`warnings.warn`
    once per finding by :func:`scenarios.load` and :func:`scenarios.parse_scenario`
    (:mod:`scenarios.schema.plausibility` says which checks); ``slewbench validate`` and ``run``
    print the same findings.

    Parameters
    ----------
    path : str
        The YAML path of the value (``spacecraft.wheels.max_torque``), kept as :attr:`path`.
    value : str
        The value as written, with its unit (``4 N m``), kept as :attr:`value`.
    reason : str
        Why it looks wrong and, where one follows, the value probably meant; kept as :attr:`reason`.
    """

    def __init__(self, path: str, value: str, reason: str) -> None:
        super().__init__(f"{path}: {value} {reason}")
        self.path, self.value, self.reason = path, value, reason

    def __reduce__(self) -> tuple[Any, ...]:
        """Pickled as its constructor's arguments (not its text): the same text and attributes after."""
        return type(self), (self.path, self.value, self.reason), self.__dict__


class CaseTimeout(BaseException):
    """Raised inside a worker when a case exceeds its time limit.

    Derived from :class:`BaseException`, like :class:`KeyboardInterrupt`, not from
    :class:`~ocp.errors.SlewbenchError`: a handler of any error (``except Exception``, which turns
    a planner's exception into a failed row) must not catch the end of the case's time, or the case
    would go on and a row would be stored as the planner's failure.
    """


class WorkersCannotStart(SlewbenchError, RuntimeError):
    """The local workers of a sweep died while they started, before any case: a new pool would fail
    the same way, so the sweep stops (usually a script that calls :func:`scenarios.sweep` outside
    ``if __name__ == "__main__":``; the message says)."""


class SweepInterrupted(SlewbenchError):
    """The sweep was stopped before every case finished; ``missing`` cases are not stored.

    Parameters
    ----------
    missing : int
        Cases not finished (not in the store).
    total : int
        Cases of the study.
    reason : str, optional
        Why it stopped, when not by Ctrl-C or SIGTERM (a Dask cluster left without workers).
    """

    def __init__(self, missing: int, total: int, reason: str = "") -> None:
        super().__init__(f"{missing} of {total} cases are missing" + (f" ({reason})" if reason else ""))
        self.missing, self.total, self.reason = missing, total, reason
