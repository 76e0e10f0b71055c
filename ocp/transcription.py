"""Transcriptions of optimal-control problems into NLPs: the registry.

The interface and the shared stage-wise assembly live in :mod:`ocp.transcription_base`; one
module per method (:mod:`ocp.radau`, :mod:`ocp.shooting`). ``TRANSCRIPTIONS`` maps the
``transcription`` option to the class; planners construct one with ``from_options``.
"""
from __future__ import annotations

from ocp.radau import RadauCollocation, lagrange, radau_weights
from ocp.shooting import MultipleShooting
from ocp.transcription_base import (
           NLP,
           Cone,
           Interval,
           OptimalControlProblem,
           Transcription,
)

TRANSCRIPTIONS: dict[str, type[Transcription]] = {cls.name: cls for cls in (RadauCollocation, MultipleShooting)}

__all__ = [
           "NLP",
           "TRANSCRIPTIONS",
           "Cone",
           "Interval",
           "MultipleShooting",
           "OptimalControlProblem",
           "RadauCollocation",
           "Transcription",
           "lagrange",
           "radau_weights",
]
