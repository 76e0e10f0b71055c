"""Feedback controllers. ``CONTROLLERS`` maps registry names to controller classes."""
from controllers.augmented_quaternion_feedback import AugmentedQuaternionFeedback
from controllers.base import Controller, gain_matrix
from controllers.bdot import BDot
from controllers.costate_feedback import CostateFeedback
from controllers.eigenaxis_pd import EigenaxisPD
from controllers.none import NoControl
from controllers.tdfc import TDFC

CONTROLLERS: dict[str, type[Controller]] = {
    cls.name: cls for cls in (AugmentedQuaternionFeedback, BDot, CostateFeedback, EigenaxisPD, NoControl, TDFC)
}

__all__ = ["AugmentedQuaternionFeedback", "BDot", "TDFC", "CONTROLLERS", "Controller", "CostateFeedback", "EigenaxisPD", "NoControl", "gain_matrix"]
