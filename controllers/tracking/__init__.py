"""Tracking and regulation laws with full three-axis actuation.

What lives here: the augmented quaternion feedback of the spin and nano papers
(:mod:`~controllers.tracking.augmented_quaternion_feedback`), the eigenaxis PD regulator
(:mod:`~controllers.tracking.eigenaxis_pd`), Vepa's co-state feedback
(:mod:`~controllers.tracking.costate_feedback`) and Basilisk's MRP feedback
(:mod:`~controllers.tracking.mrp_feedback`).

May import: :mod:`ocp`, :mod:`controllers.base` and :mod:`controllers.allocation`; the co-state
feedback also the :mod:`planners` contract (it needs an indirect reference's co-states).
"""
from controllers.tracking.augmented_quaternion_feedback import (
    AugmentedQuaternionFeedback,
)
from controllers.tracking.costate_feedback import CostateFeedback
from controllers.tracking.eigenaxis_pd import EigenaxisPD
from controllers.tracking.mrp_feedback import MRPFeedback

__all__ = ["AugmentedQuaternionFeedback", "CostateFeedback", "EigenaxisPD", "MRPFeedback"]


def __dir__() -> list[str]:
    """What ``dir()`` lists: the public names (``__all__``) and the module's dunder attributes."""
    return sorted({*__all__, *(name for name in globals() if name.startswith("__") and name.endswith("__"))})
