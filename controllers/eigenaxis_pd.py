"""Eigenaxis PD regulator (nano paper eq. 39; Wie, Weiss & Arapostathis 1989).

``u = −K q_e − C ω_e + ω × J ω`` towards the manoeuvre's target ``(q_f, ω_f)``, whatever the
reference: the law itself produces the eigenaxis slew. With ``K = k J`` and ``C = c J`` a rest-to-rest
slew stays on the eigenaxis, because ``q_e`` and ``ω`` remain parallel. Under the zero-order hold
the gyroscopic term is taken at the predicted mid-sample rate (``hold_compensation``, see
``augmented_quaternion_feedback``).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated

from controllers.augmented_quaternion_feedback import AugmentedQuaternionFeedback
from controllers.base import check_gain
from ocp.options import Range


class EigenaxisPD(AugmentedQuaternionFeedback):
    """Regulates to the target; a reference, if any, is ignored."""

    name = "eigenaxis_pd"
    tracks_reference = False

    @dataclass(frozen=True)
    class Options:
        kp: Annotated[float | list[list[float]], Range(shape=(3, 3))] = 0.06
        kd: Annotated[float | list[list[float]], Range(shape=(3, 3))] = 0.48
        feedforward: bool = False  # eq. 39 has none; kept so the parent's law is reused as is
        hold_compensation: bool = True

        def __post_init__(self) -> None:
            check_gain("kp", self.kp)
            check_gain("kd", self.kd)
