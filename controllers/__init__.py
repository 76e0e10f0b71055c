"""Feedback controllers. ``CONTROLLERS`` maps registry names to controller classes."""
from controllers.augmented_quaternion_feedback import AugmentedQuaternionFeedback
from controllers.base import Controller, gain_matrix
from controllers.costate_feedback import CostateFeedback
from controllers.eigenaxis_pd import EigenaxisPD
from controllers.none import NoControl

CONTROLLERS: dict[str, type[Controller]] = {
    cls.name: cls for cls in (AugmentedQuaternionFeedback, CostateFeedback, EigenaxisPD, NoControl)
}

__all__ = ["AugmentedQuaternionFeedback", "CONTROLLERS", "Controller", "CostateFeedback", "EigenaxisPD", "NoControl", "gain_matrix"]
