"""Closed-loop simulation: zero-order hold, actuator saturation, sensor noise, scored time series.

What lives here: the :class:`Simulator` and what it takes and gives
(:mod:`~ocp.simulation.simulator`), the whole closed loop as one CasADi function
(:mod:`~ocp.simulation.closed_loop`) and its compilation to C with an on-disk cache
(:mod:`~ocp.simulation.compiled`).

May import: :mod:`ocp.dynamics`, :mod:`ocp.estimation` and the top-level modules of :mod:`ocp`; never
:mod:`ocp.transcription` or :mod:`ocp.nlp`.
"""
from ocp.simulation.closed_loop import ClosedLoop
from ocp.simulation.compiled import compile_function
from ocp.simulation.simulator import (
           GridSampledReference,
           SensorNoise,
           SimulationResult,
           Simulator,
)

__all__ = ["ClosedLoop", "GridSampledReference", "SensorNoise", "SimulationResult", "Simulator", "compile_function"]


def __dir__() -> list[str]:
    """What ``dir()`` lists: the public names (``__all__``) and the module's dunder attributes."""
    return sorted({*__all__, *(name for name in globals() if name.startswith("__") and name.endswith("__"))})
