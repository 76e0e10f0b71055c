"""The exceptions of :mod:`controllers`, derived from :class:`ocp.errors.SlewbenchError`.

A law that cannot run somewhere says why through ``environment_error``, ``sample_time_error`` or
``planner_error`` (the scenario loader reports it); bad options raise
:class:`~ocp.errors.OptionsError`. These are for contract breaches. Imports only :mod:`ocp.errors`.
"""
from __future__ import annotations

from ocp.errors import SlewbenchError

__all__ = ["ConformanceError"]


class ConformanceError(SlewbenchError, AssertionError):
    """A controller breaks the controller contract; the message says what to fix."""
