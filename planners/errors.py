"""The exceptions of :mod:`planners`, derived from :class:`ocp.errors.SlewbenchError`.

A planner that cannot plan returns a :class:`~planners.reference.FailedReference` (a failed row
with its message), it does not raise: these are for contract breaches. Imports only
:mod:`ocp.errors`.
"""
from __future__ import annotations

from ocp.errors import SlewbenchError

__all__ = ["ConformanceError"]


class ConformanceError(SlewbenchError, AssertionError):
    """A reference breaks the planner contract; the message says what to fix."""
