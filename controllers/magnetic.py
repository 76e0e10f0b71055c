"""Shared pieces of the magnetometer-only detumbling laws (``bdot``, ``tdfc``).

Both laws command the magnetorquer dipole from the magnetometer reading alone; they need
magnetorquers and a field model, and regulate the rate only, so the final attitude may be free.
Per-sample code works on Python floats (three components), not NumPy arrays: a detumbling run has
10⁵–10⁶ samples and NumPy's per-call overhead would dominate it.
"""
from __future__ import annotations

from typing import Any

import casadi as ca
import numpy as np

from controllers.base import Controller
from ocp import Command
from ocp.layout import split_measurement

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

    def dipole(self, mx: float, my: float, mz: float) -> Command:
        """The command for a dipole (A m², body axes); nothing without magnetorquers."""
        if "dipole" not in self._slices:
            return Command()
        return Command(dipole=np.array((mx, my, mz)))

    def symbolic_dipole(self, dipole: ca.SX) -> ca.SX:
        """The control vector ``u`` (the model's layout) holding ``dipole``, zeros elsewhere."""
        u = ca.SX.zeros(self._nu)
        if "dipole" in self._slices:
            u[self._slices["dipole"]] = dipole
        return u

    def symbolic_field(self, y: ca.SX) -> ca.SX:
        """The magnetometer reading (T, body axes) in the measurement vector ``y``."""
        return split_measurement(y, self.spacecraft.n_wheels)[3]


def field_components(field: Any) -> Vector:
    """The magnetometer reading as three floats (T); zeros without a reading (no field model),
    as the symbolic form's measurement vector holds it."""
    if field is None:
        return 0.0, 0.0, 0.0
    return float(field[0]), float(field[1]), float(field[2])
