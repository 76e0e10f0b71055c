"""Time-delayed feedback control (nano-spacecraft paper, eq. 11): ``m = −K_t (B̃_k − B̃_{k−d})``.

``d = τ / T_s`` samples; ``τ`` must be a whole multiple of the sample time. ``m = 0`` until a
reading ``τ`` old exists (the first ``d`` samples). The delay buffer is cleared by ``reset``.

Dissipation: for a body spinning at ``ω`` in a field fixed in inertial space, ``B(t − τ)`` is
``B(t)`` turned back by the angle ``|ω| τ`` about ``ω``, and the power of the law is
``ω·(m × B) = −K_t |ω| sin(|ω| τ) |B_⊥|²`` (``B_⊥``: the part of ``B`` normal to ``ω``). It removes
energy only while ``|ω| τ < π``; for ``π < |ω| τ < 2π`` it pumps energy in. The paper (τ = 2 s,
``|ω0|`` = 0.9 rad/s) does not state this limit: the law needs ``τ < π / |ω|max``.

Symbolic form: state ``z = [B̃_{k−1}, …, B̃_{k−d}, n]`` (3d + 1 numbers), ``n`` the number of
readings stored so far (at most d).
"""
from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from typing import Annotated, Any

import casadi as ca
import numpy as np

from controllers.detumbling.magnetic import MagneticController, field_components
from ocp import Command, Measurement, Spacecraft
from ocp.options import Range

MAX_DELAY_SAMPLES = 100_000
"""Upper bound on ``τ / T_s`` (buffer length)."""
MAX_SYMBOLIC_DELAY = 32
"""Longest delay buffer (samples) of the symbolic law; longer delays run in the Python loop."""


def delay_samples(delay: float, sample_time: float) -> int:
    """The delay in samples, ``d = τ / T_s``, if it is a whole number (to 1e-9 relative).

    Parameters
    ----------
    delay : float
        τ [s].
    sample_time : float
        T_s [s].

    Returns
    -------
    int
        d, at least 1 and at most :data:`MAX_DELAY_SAMPLES`.

    Raises
    ------
    ValueError
        ``τ / T_s`` is not a whole number >= 1, or exceeds :data:`MAX_DELAY_SAMPLES`.
    """
    ratio = delay / sample_time
    samples = round(ratio)
    if samples < 1 or abs(ratio - samples) > 1e-9 * max(1.0, ratio):
        raise ValueError(f"the delay {delay:g} s must be a whole multiple (>= 1) of the sample time "
                         f"{sample_time:g} s (got {ratio:.6g} samples)")
    if samples > MAX_DELAY_SAMPLES:
        raise ValueError(f"the delay is {samples} samples; at most {MAX_DELAY_SAMPLES}")
    return samples


class TDFC(MagneticController):
    """Time-delayed feedback: dipole against the change of the field over the delay (eq. 11)."""

    name = "tdfc"

    @dataclass(frozen=True)
    class Options:
        """Options of ``tdfc`` (the YAML keys under the controller's ``options``).

        Parameters
        ----------
        gain : float, >= 0
            K_t [A m²/T]: dipole per unit change of the body-frame field over the delay. The paper
            gives no value; the default is the one of ``scenarios/nano_detumble.yaml``.
        delay : float, > 0 and <= 1e5
            τ [s], a whole multiple of ``simulation.sample_time`` and shorter than the run
            (``simulation.duration``, else in regulation ``maneuver.duration``; else an error at
            ``options.delay``). Default 2 s, the paper's. The law removes energy only while
            ``|ω| τ < π`` (module docstring).
        """

        gain: Annotated[float, Range(ge=0.0)] = 1.0e4
        delay: Annotated[float, Range(gt=0.0, le=1.0e5)] = 2.0

    def sample_time_error(self, sample_time: float) -> tuple[str, str] | None:
        """Refuse a sample time of which the delay is not a whole multiple.

        Parameters
        ----------
        sample_time : float
            T_s [s].

        Returns
        -------
        tuple of 2 str or None
            ``("delay", message)``, or ``None`` when ``τ / T_s`` is a whole number of samples.
        """
        try:
            delay_samples(self.options.delay, sample_time)
        except ValueError as error:
            return "delay", str(error)
        return None

    def run_length_error(self, duration: float) -> tuple[str, str] | None:
        """Refuse a delay not shorter than the run: ``m = 0`` until a reading ``τ`` old exists, so the
        law would never act.

        Parameters
        ----------
        duration : float
            Length of the closed-loop run [s].

        Returns
        -------
        tuple of 2 str or None
            ``("delay", message)``, or ``None`` when ``τ`` is shorter than the run.
        """
        if self.options.delay >= duration:
            return "delay", (f"the delay {self.options.delay:g} s is not shorter than the run ({duration:g} s): "
                             f"the dipole is zero until a field reading that old exists, so the law never acts")
        return None

    def reset(self, spacecraft: Spacecraft, sample_time: float, target: Any = None) -> None:
        super().reset(spacecraft, sample_time, target)
        self._delay = delay_samples(self.options.delay, sample_time)
        self._buffer: deque[tuple[float, float, float]] = deque(maxlen=self._delay + 1)

    def __call__(self, t: float, measurement: Measurement, reference: Any) -> Command:
        reading = field_components(measurement.field_body)
        buffer = self._buffer
        buffer.append(reading)
        if len(buffer) <= self._delay:
            return self.dipole(0.0, 0.0, 0.0)
        old, k = buffer[0], self.options.gain
        return self.dipole(-k * (reading[0] - old[0]), -k * (reading[1] - old[1]), -k * (reading[2] - old[2]))

    def symbolic_error(self) -> str | None:
        """Why the law has no symbolic form: a delay buffer longer than :data:`MAX_SYMBOLIC_DELAY`
        samples is kept in the Python loop (in one CasADi graph every sample would copy the whole
        buffer, memory growing with N d).

        Returns
        -------
        str or None
            The reason, or ``None`` when the symbolic law exists.
        """
        if getattr(self, "_delay", 0) > MAX_SYMBOLIC_DELAY:
            return (f"the delay of {self._delay} samples is more than the {MAX_SYMBOLIC_DELAY} that the "
                    "symbolic closed loop holds; it runs in the Python loop")
        return super().symbolic_error()

    def state_vector(self) -> np.ndarray:
        d = self._delay
        stored = list(self._buffer)[::-1][:d]          # newest first: B̃_{k}, B̃_{k−1}, ...
        z = np.zeros(3 * d + 1)
        if stored:
            z[:3 * len(stored)] = np.ravel(stored)
        z[-1] = len(stored)
        return z

    def _law(self, t: ca.SX, y: ca.SX, z: ca.SX, r: ca.SX) -> tuple[ca.SX, ca.SX]:
        d = self._delay
        b = self.symbolic_field(y)
        count = z[3 * d]
        oldest = z[3 * (d - 1):3 * d]
        gain = self.constant("gain", float(self.options.gain))  # the delay (in samples) fixes the state's size
        dipole = ca.if_else(count >= d, -gain * (b - oldest), ca.DM.zeros(3))
        z_next = ca.vertcat(b, z[0:3 * (d - 1)], ca.fmin(count + 1, d))
        return self.symbolic_dipole(dipole), z_next
