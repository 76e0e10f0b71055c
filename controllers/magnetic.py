"""Shared pieces of the magnetometer-only detumbling laws (``bdot``, ``tdfc``).

Both laws command the magnetorquer dipole from the magnetometer reading alone; they need
magnetorquers and a field model, and regulate the rate only, so the final attitude may be free.
Per-sample code works on Python floats (three components), not NumPy arrays: a detumbling run has
10⁵–10⁶ samples and NumPy's per-call overhead would dominate it.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from controllers.base import Controller
from ocp import Command

Vector = tuple[float, float, float]


class MagneticController(Controller):
    """Base of laws that use magnetorquers and the magnetometer only."""

    needs_target_attitude = False
    hold_compensation = False

    def environment_error(self, spacecraft: Any, environment: Any) -> str | None:
        """Why the law cannot run on ``spacecraft`` in ``environment`` (no magnetorquers, no field)."""
        if spacecraft.magnetorquers is None:
            return f"controller {self.name} commands magnetorquers; give spacecraft.magnetorquers"
        if environment.magnetic_field is None:
            return f"controller {self.name} needs a magnetic field; give environment.magnetic_field"
        return None

    @staticmethod
    def dipole(mx: float, my: float, mz: float) -> Command:
        """The command for a dipole (A m², body axes)."""
        return Command(dipole=np.array((mx, my, mz)))


def field_components(field: Any) -> Vector:
    """The magnetometer reading as three floats (T); ``ValueError`` without a reading."""
    if field is None:
        raise ValueError("this law needs the magnetometer: the model has no magnetic field")
    return float(field[0]), float(field[1]), float(field[2])
