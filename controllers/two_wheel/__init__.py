"""Two-wheel (underactuated) laws of Horri & Palmer: singular and min-norm, with gain scheduling.

What lives here: the control frame and base class of the laws
(:mod:`~controllers.two_wheel.underactuated`), the desired-rate mathematics they share
(:mod:`~controllers.two_wheel.singular_rates`), and one module per law.

May import: :mod:`ocp` and :mod:`controllers.base`.
"""
from controllers.two_wheel.gain_scheduled_min_norm import GainScheduledMinNorm
from controllers.two_wheel.min_norm import MinNorm
from controllers.two_wheel.singular_rate_tracking import SingularRateTracking
from controllers.two_wheel.singular_rates import SingularGains
from controllers.two_wheel.singular_zero_momentum import SingularZeroMomentum
from controllers.two_wheel.underactuated import TwoWheelLaw, control_frame

__all__ = ["GainScheduledMinNorm", "MinNorm", "SingularGains", "SingularRateTracking", "SingularZeroMomentum",
           "TwoWheelLaw", "control_frame"]


def __dir__() -> list[str]:
    """What ``dir()`` lists: the public names (``__all__``) and the module's dunder attributes."""
    return sorted({*__all__, *(name for name in globals() if name.startswith("__") and name.endswith("__"))})
