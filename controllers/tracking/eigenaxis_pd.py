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

from controllers.base import check_gain
from controllers.tracking.augmented_quaternion_feedback import (
    AugmentedQuaternionFeedback,
)
from ocp.options import Range


class EigenaxisPD(AugmentedQuaternionFeedback):
    """Regulates to the target; a reference, if any, is ignored."""

    name = "eigenaxis_pd"
    tracks_reference = False

    @dataclass(frozen=True)
    class Options:
        """Options of ``eigenaxis_pd`` (the YAML keys under the controller's ``options``).

        Parameters
        ----------
        kp : float >= 0 or (3, 3) list of lists
            Attitude gain: a scalar k [1/s²] gives ``K = k J`` (the inertia times k), which keeps a
            rest-to-rest slew on the eigenaxis; a 3x3 matrix is K itself [N m per unit of the
            error quaternion's vector part], with a positive semi-definite symmetric part.
        kd : float >= 0 or (3, 3) list of lists
            Rate gain: a scalar c [1/s] gives ``C = c J``; a 3x3 matrix is C itself [N m s/rad],
            with a positive semi-definite symmetric part.
        feedforward : bool
            The ``J ω̇*`` term of the parent law. Eq. 39 has none (default ``False``); the target
            has no acceleration, so it adds nothing here. Kept so the parent's law is reused as is.
        hold_compensation : bool
            Default ``True``: the gyroscopic term ``ω × J ω`` (and the wheels' ``ω × A h_w``) is
            taken at the rate and wheel momentum predicted to mid-sample, so the held torque is
            right to O(T²); ``False`` samples the continuous law at ``t_k``.
        """

        kp: Annotated[float | list[list[float]], Range(shape=(3, 3))] = 0.06
        kd: Annotated[float | list[list[float]], Range(shape=(3, 3))] = 0.48
        feedforward: bool = False
        hold_compensation: bool = True

        def __post_init__(self) -> None:
            check_gain("kp", self.kp)
            check_gain("kd", self.kd)
