"""Magnetometer-only detumbling laws: B-dot and time-delayed feedback (nano-spacecraft paper, eq. 11-12).

What lives here: the pieces both laws share (:mod:`~controllers.detumbling.magnetic`),
:mod:`~controllers.detumbling.bdot` and :mod:`~controllers.detumbling.tdfc`.

May import: :mod:`ocp` and :mod:`controllers.base`.
"""
from controllers.detumbling.bdot import BDot
from controllers.detumbling.magnetic import MagneticController
from controllers.detumbling.tdfc import TDFC

__all__ = ["BDot", "MagneticController", "TDFC"]
