"""The exceptions of :mod:`scenarios`, derived from :class:`ocp.errors.SlewbenchError`.

:class:`ScenarioError` is a user's mistake in a scenario or study file (or a library argument), at
its YAML path; :class:`OutputError` an output location slewbench must not or cannot write to, at
that location (it is not a :class:`ScenarioError`: the scenario may be right). Both end the command
line with exit status 2. :class:`SweepInterrupted` is a study stopped before every case finished.
:class:`CaseTimeout`, a case out of time in a sweep's worker, is the one exception here not derived
from :class:`~ocp.errors.SlewbenchError` (it derives from :class:`BaseException`).
:class:`PlausibilityWarning` is no error: a warning (:func:`warnings.warn`) on a value that is
valid but almost certainly a unit or layout slip.
Imports only :mod:`ocp.errors`.
"""
from __future__ import annotations

from pathlib import Path

from ocp.errors import SlewbenchError

__all__ = ["CaseTimeout", "OutputError", "PlausibilityWarning", "ScenarioError", "SweepInterrupted", "WorkersCannotStart"]

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
    """

    def __init__(self, path: str, message: str):
        shown = _bounded(message, MAX_MESSAGE_CHARS)
        super().__init__(f"{_bounded(path, MAX_PATH_CHARS)}: {shown}" if path else shown)
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
