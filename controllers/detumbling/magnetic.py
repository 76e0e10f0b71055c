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

from controllers.base import Array, Controller
from ocp import Command, Spacecraft
from ocp.dynamics.layout import split_measurement

Vector = tuple[float, float, float]


class MagneticController(Controller):
    """Base of laws that use magnetorquers and the magnetometer only."""

    needs_target_attitude = False
    hold_compensation = False

    def environment_error(self, spacecraft: Spacecraft, environment: Any) -> str | None:
        """Refuse a spacecraft without magnetorquers or an environment without a magnetic field.

        Parameters
        ----------
        spacecraft : Spacecraft
            The spacecraft (its ``magnetorquers`` are read).
        environment : ocp.Environment
            The environment (its ``magnetic_field`` is read).

        Returns
        -------
        str or None
            What is missing and which YAML key gives it, or ``None`` when the law can run.
        """
        if spacecraft.magnetorquers is None:
            return f"controller {self.name} commands magnetorquers; give spacecraft.magnetorquers"
        if environment.magnetic_field is None:
            return f"controller {self.name} needs a magnetic field; give environment.magnetic_field"
        return None

    def dipole(self, mx: float, my: float, mz: float) -> Command:
        """The command for a magnetic dipole.

        Parameters
        ----------
        mx, my, mz : float
            Commanded dipole [A m²], body frame, before saturation.

        Returns
        -------
        Command
            The dipole command; an empty command when the model has no magnetorquers.
        """
        if "dipole" not in self._slices:
            return Command()
        return Command(dipole=np.array((mx, my, mz)))

    def symbolic_dipole(self, dipole: ca.SX) -> ca.SX:
        """:meth:`dipole` on expressions.

        Parameters
        ----------
        dipole : (3, 1) casadi.SX
            Commanded dipole [A m²], body frame.

        Returns
        -------
        casadi.SX
            The control vector ``u`` in the model's control layout holding ``dipole``, zeros elsewhere.
        """
        u = ca.SX.zeros(self._nu)
        if "dipole" in self._slices:
            u[self._slices["dipole"]] = dipole
        return u

    def symbolic_field(self, y: ca.SX) -> ca.SX:
        """The magnetometer reading in the measurement vector.

        Parameters
        ----------
        y : casadi.SX
            Measurement vector ``[q, ω, h_w, b]`` (layout in :mod:`ocp.dynamics.layout`).

        Returns
        -------
        (3, 1) casadi.SX
            The reading ``b`` [T], body frame (zeros when the model has no field).
        """
        if self.spacecraft is None:
            raise RuntimeError(f"controller {self.name}: call reset(spacecraft, sample_time, target) first")
        return split_measurement(y, self.spacecraft.n_wheels)[3]


def field_components(field: Array | None) -> Vector:
    """The magnetometer reading as three floats.

    Parameters
    ----------
    field : (3,) ndarray or None
        The reading [T], body frame; ``None`` when the model has no field.

    Returns
    -------
    tuple of 3 float
        ``(bx, by, bz)`` [T]; zeros without a reading, as the symbolic form's measurement vector
        holds it.
    """
    if field is None:
        return 0.0, 0.0, 0.0
    return float(field[0]), float(field[1]), float(field[2])
