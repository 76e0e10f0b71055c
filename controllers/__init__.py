"""Feedback controllers. ``CONTROLLERS`` maps registry names to controller classes.

The contract is :mod:`controllers.base` (:class:`Controller`: a numeric law, its symbolic form,
options and capabilities) with the torque-to-actuator map of :mod:`controllers.allocation`;
:mod:`controllers.conformance` checks it for any law (``check_controller``), and
:mod:`controllers.errors` holds the package's exceptions. The laws: :mod:`controllers.none`,
:mod:`controllers.tracking`, :mod:`controllers.detumbling` and :mod:`controllers.two_wheel`.

May import: :mod:`ocp` and :mod:`planners`; never :mod:`scenarios`.
"""
from controllers.base import Controller, gain_matrix
from controllers.detumbling.bdot import BDot
from controllers.detumbling.tdfc import TDFC
from controllers.errors import ConformanceError
from controllers.none import NoControl
from controllers.tracking.augmented_quaternion_feedback import (
    AugmentedQuaternionFeedback,
)
from controllers.tracking.costate_feedback import CostateFeedback
from controllers.tracking.eigenaxis_pd import EigenaxisPD
from controllers.tracking.mrp_feedback import MRPFeedback
from controllers.two_wheel.gain_scheduled_min_norm import GainScheduledMinNorm
from controllers.two_wheel.min_norm import MinNorm
from controllers.two_wheel.singular_rate_tracking import SingularRateTracking
from controllers.two_wheel.singular_zero_momentum import SingularZeroMomentum
from planners.registry import Registry

CONTROLLERS: Registry[type[Controller]] = Registry("controller", {
    cls.name: cls for cls in (AugmentedQuaternionFeedback, BDot, CostateFeedback, EigenaxisPD, MRPFeedback, NoControl, TDFC,
                              SingularZeroMomentum, SingularRateTracking, MinNorm, GainScheduledMinNorm)
})

__all__ = ["CONTROLLERS", "TDFC", "AugmentedQuaternionFeedback", "BDot", "ConformanceError", "Controller", "CostateFeedback",
           "EigenaxisPD",
           "GainScheduledMinNorm", "MRPFeedback", "MinNorm", "NoControl", "SingularRateTracking", "SingularZeroMomentum", "gain_matrix"]


def __dir__() -> list[str]:
    """What ``dir()`` lists: the public names (``__all__``) and the module's dunder attributes."""
    return sorted({*__all__, *(name for name in globals() if name.startswith("__") and name.endswith("__"))})
