"""The exceptions of :mod:`controllers`, derived from :class:`ocp.errors.SlewbenchError`.

A law that cannot run somewhere says why through ``environment_error``, ``sample_time_error`` or
``planner_error`` (the scenario loader reports it); bad options raise
:class:`~ocp.errors.OptionsError`. These are for contract breaches. Imports only :mod:`ocp.errors`.
"""
from __future__ import annotations

from ocp.errors import SlewbenchError

__all__ = ["ConformanceError"]


class ConformanceError(SlewbenchError, AssertionError):
    """A controller breaks the controller contract (:func:`controllers.conformance.check_controller`);
    the message says what to fix.

    A planner's reference that breaks the planner contract raises
    :class:`planners.ConformanceError` instead, a class of its own (each package's errors import
    only :mod:`ocp.errors`); catch both as ``AssertionError`` or :class:`~ocp.errors.SlewbenchError`.
    """
