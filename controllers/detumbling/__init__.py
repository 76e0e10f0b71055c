"""Magnetometer-only detumbling laws: B-dot and time-delayed feedback (nano-spacecraft paper, eq. 11-12).

What lives here: the pieces both laws share (:mod:`~controllers.detumbling.magnetic`),
:mod:`~controllers.detumbling.bdot` and :mod:`~controllers.detumbling.tdfc`.

May import: :mod:`ocp` and :mod:`controllers.base`.
"""
from controllers.detumbling.bdot import BDot
from controllers.detumbling.magnetic import MagneticController
from controllers.detumbling.tdfc import TDFC

__all__ = ["BDot", "MagneticController", "TDFC"]


def __dir__() -> list[str]:
    """What ``dir()`` lists: the public names (``__all__``) and the module's dunder attributes."""
    return sorted({*__all__, *(name for name in globals() if name.startswith("__") and name.endswith("__"))})
