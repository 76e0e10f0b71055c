"""B-dot detumbling (nano-spacecraft paper, eq. 12): ``m = −K_b Ḃ``.

``Ḃ`` is the rate of the field in body axes, obtained in one of three ways (option ``derivative``):

* ``backward_difference`` (default): ``(B̃_k − B̃_{k−1}) / T_s`` from the magnetometer readings
  ``B̃``; ``m = 0`` at the first sample. This is TDFC (eq. 11) with ``τ = T_s`` and
  ``K_t = K_b / T_s``.
* ``exact``: ``Ḃ = R(q)ᵀ ḃ_I − ω × B``, the paper's ideal case. It needs the attitude, the rate
  and the inertial field's rate along the orbit (``needs_field_rate``), which a magnetometer-only
  spacecraft does not have; in a field fixed in inertial space and without saturation its power
  ``ω·(m × B)`` is ``−K_b |ω × B|²``.
* ``filtered``: the backward difference through a first-order low-pass filter of time constant
  ``T_f`` (``filter_time_constant``): ``y_k = α y_{k−1} + (1 − α)(B̃_k − B̃_{k−1})/T_s`` with
  ``α = exp(−T_s/T_f)``, the filter at rest (``y = 0``) before the first difference.

The command is the unsaturated ``m``; the actuator model clips it (per axis or scaled).
Symbolic form: state ``z = [B̃_{k−1} (3), started (1)]``, plus ``y_{k−1}`` (3) when filtered;
the exact derivative has none (ḃ_I is not in the measurement vector).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Annotated, Any, Literal

import casadi as ca
import numpy as np

from controllers.detumbling.magnetic import MagneticController, field_components
from ocp import Command, Measurement, Spacecraft
from ocp.options import Range


class BDot(MagneticController):
    """B-dot: dipole against the rate of the body-frame field (eq. 12)."""

    name = "bdot"

    @dataclass(frozen=True)
    class Options:
        """Options of ``bdot`` (the YAML keys under the controller's ``options``).

        Parameters
        ----------
        gain : float, >= 0
            K_b [A m² s/T]: dipole per unit rate of the body-frame field. The paper gives no value;
            the default is the one of ``scenarios/nano_detumble.yaml``.
        derivative : {"backward_difference", "exact", "filtered"}
            How ``Ḃ`` is obtained (module docstring): ``backward_difference`` (default)
            ``(B̃_k − B̃_{k−1}) / T_s`` from the magnetometer, ``m = 0`` at the first sample;
            ``exact`` ``R(q)ᵀ ḃ_I − ω × B``, the paper's ideal case (no symbolic form); ``filtered``
            the backward difference through a first-order low-pass filter.
        filter_time_constant : float, > 0 and <= 1e6
            T_f [s], time constant of the low-pass filter (``derivative: filtered`` only).
        """

        gain: Annotated[float, Range(ge=0.0)] = 2.0e4
        derivative: Literal["backward_difference", "exact", "filtered"] = "backward_difference"
        filter_time_constant: Annotated[float, Range(gt=0.0, le=1.0e6)] = 1.0

    @property
    def needs_field_rate(self) -> bool:  # type: ignore[override]
        return self.options.derivative == "exact"

    def symbolic_error(self) -> str | None:
        if self.options.derivative == "exact":
            return ("bdot with derivative: exact needs the inertial field rate along the orbit, which is not "
                    "part of the measurement vector of the symbolic form")
        return None

    def reset(self, spacecraft: Spacecraft, sample_time: float, target: Any = None) -> None:
        super().reset(spacecraft, sample_time, target)
        self._previous: tuple[float, float, float] | None = None
        self._filtered = (0.0, 0.0, 0.0)
        self._gain_per_sample = self.options.gain / sample_time   # K_b / T_s (A m²/T)
        self._alpha = math.exp(-sample_time / self.options.filter_time_constant)

    def __call__(self, t: float, measurement: Measurement, reference: Any) -> Command:
        bx, by, bz = field_components(measurement.field_body)
        if self.options.derivative == "exact":
            return self._exact(bx, by, bz, measurement)
        previous, self._previous = self._previous, (bx, by, bz)
        if previous is None:
            return self.dipole(0.0, 0.0, 0.0)
        k = self._gain_per_sample
        dx, dy, dz = bx - previous[0], by - previous[1], bz - previous[2]
        if self.options.derivative == "backward_difference":
            return self.dipole(-k * dx, -k * dy, -k * dz)
        a, (fx, fy, fz) = self._alpha, self._filtered
        self._filtered = fx, fy, fz = a * fx + (1 - a) * dx, a * fy + (1 - a) * dy, a * fz + (1 - a) * dz
        return self.dipole(-k * fx, -k * fy, -k * fz)

    def _exact(self, bx: float, by: float, bz: float, measurement: Measurement) -> Command:
        """``m = −K_b (R(q)ᵀ ḃ_I − ω × B)`` written out on floats."""
        w, x, y, z = (float(v) for v in measurement.q)
        ox, oy, oz = (float(v) for v in measurement.omega)
        rate = measurement.field_rate_inertial
        ix, iy, iz = (0.0, 0.0, 0.0) if rate is None else (float(rate[0]), float(rate[1]), float(rate[2]))
        # R(q)ᵀ ḃ_I: the columns of R(q) (body axes in inertial) dotted with ḃ_I
        rx = (1 - 2 * (y * y + z * z)) * ix + 2 * (x * y + w * z) * iy + 2 * (x * z - w * y) * iz
        ry = 2 * (x * y - w * z) * ix + (1 - 2 * (x * x + z * z)) * iy + 2 * (y * z + w * x) * iz
        rz = 2 * (x * z + w * y) * ix + 2 * (y * z - w * x) * iy + (1 - 2 * (x * x + y * y)) * iz
        k = self.options.gain
        return self.dipole(-k * (rx - (oy * bz - oz * by)), -k * (ry - (oz * bx - ox * bz)),
                           -k * (rz - (ox * by - oy * bx)))

    def state_vector(self) -> np.ndarray:
        if self.options.derivative == "exact":
            return np.zeros(0)
        previous = (0.0, 0.0, 0.0) if self._previous is None else self._previous
        state = [*previous, 0.0 if self._previous is None else 1.0]
        if self.options.derivative == "filtered":
            state += list(self._filtered)
        return np.array(state)

    def _law(self, t: ca.SX, y: ca.SX, z: ca.SX, r: ca.SX) -> tuple[ca.SX, ca.SX]:
        b = self.symbolic_field(y)
        previous, started = z[0:3], z[3]
        difference = b - previous
        # K_b / T_s and the filter's factor from the named numbers (inputs of the generated C).
        gain, sample_time = self.constant("gain", float(self.options.gain)), self.constant("sample_time", float(self.sample_time))
        gain_per_sample = self._gain_per_sample if self._constants is None else gain / sample_time
        if self.options.derivative == "filtered":
            time_constant = self.constant("filter_time_constant", float(self.options.filter_time_constant))
            alpha = self._alpha if self._constants is None else ca.exp(-sample_time / time_constant)
            filtered = ca.if_else(started, alpha * z[4:7] + (1 - alpha) * difference, z[4:7])
            rate, extra = filtered, [filtered]
        else:
            rate, extra = difference, []
        dipole = ca.if_else(started, -gain_per_sample * rate, ca.DM.zeros(3))
        return self.symbolic_dipole(dipole), ca.vertcat(b, 1.0, *extra)
