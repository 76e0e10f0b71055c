"""Transcriptions of optimal-control problems into NLPs, and their registry.

What lives here: what an optimal-control problem asks for (:mod:`~ocp.transcription.problem`), the
:class:`Transcription` interface (:mod:`~ocp.transcription.base`) and the stage-wise NLP every
transcription shares (:mod:`~ocp.transcription.stagewise`), one module per method
(:mod:`~ocp.transcription.radau`, :mod:`~ocp.transcription.shooting`), and the transfer of
multipliers between meshes (:mod:`~ocp.transcription.mesh_transfer`). ``TRANSCRIPTIONS`` maps the
``transcription`` option to the class; planners construct one with ``from_options``.

May import: :mod:`ocp.dynamics`, :mod:`ocp.geometry` (the pointing constraints a problem imposes) and
the top-level modules of :mod:`ocp`; never
:mod:`ocp.simulation` or :mod:`ocp.nlp` (a transcription builds an NLP; it does not solve it).
"""
from __future__ import annotations

from ocp.transcription.base import Transcription
from ocp.transcription.mesh_transfer import transfer_multipliers
from ocp.transcription.problem import NLP, Interval, OptimalControlProblem
from ocp.transcription.radau import RadauCollocation, lagrange, radau_weights
from ocp.transcription.shooting import MultipleShooting

TRANSCRIPTIONS: dict[str, type[Transcription]] = {cls.name: cls for cls in (RadauCollocation, MultipleShooting)}

__all__ = [
           "NLP",
           "TRANSCRIPTIONS",
           "Interval",
           "MultipleShooting",
           "OptimalControlProblem",
           "RadauCollocation",
           "Transcription",
           "lagrange",
           "radau_weights",
           "transfer_multipliers",
]


def __dir__() -> list[str]:
    """What ``dir()`` lists: the public names (``__all__``) and the module's dunder attributes."""
    return sorted({*__all__, *(name for name in globals() if name.startswith("__") and name.endswith("__"))})
