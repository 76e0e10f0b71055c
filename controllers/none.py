"""No actuation: free motion under the environment (how the model is checked against others)."""
from __future__ import annotations

from typing import Any

import casadi as ca

from controllers.base import Controller
from ocp import Command, Measurement


class NoControl(Controller):
    """Commands nothing."""

    name = "none"
    needs_target_attitude = False

    def __call__(self, t: float, measurement: Measurement, reference: Any) -> Command:
        return Command()

    def _law(self, t: ca.SX, y: ca.SX, z: ca.SX, r: ca.SX) -> tuple[ca.SX, ca.SX]:
        return ca.SX.zeros(self._nu), z
