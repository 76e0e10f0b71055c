"""Feedback controllers. ``CONTROLLERS`` maps registry names to controller classes."""
from controllers.augmented_quaternion_feedback import AugmentedQuaternionFeedback
from controllers.base import Controller, gain_matrix
from controllers.bdot import BDot
from controllers.costate_feedback import CostateFeedback
from controllers.eigenaxis_pd import EigenaxisPD
from controllers.gain_scheduled_min_norm import GainScheduledMinNorm
from controllers.min_norm import MinNorm
from controllers.none import NoControl
from controllers.singular_rate_tracking import SingularRateTracking
from controllers.singular_zero_momentum import SingularZeroMomentum
from controllers.tdfc import TDFC

CONTROLLERS: dict[str, type[Controller]] = {
    cls.name: cls for cls in (AugmentedQuaternionFeedback, BDot, CostateFeedback, EigenaxisPD, NoControl, TDFC,
                              SingularZeroMomentum, SingularRateTracking, MinNorm, GainScheduledMinNorm)
}

__all__ = ["AugmentedQuaternionFeedback", "BDot", "TDFC", "CONTROLLERS", "Controller", "CostateFeedback", "EigenaxisPD",
           "GainScheduledMinNorm", "MinNorm", "NoControl", "SingularRateTracking", "SingularZeroMomentum", "gain_matrix"]
