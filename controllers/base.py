"""Controller contract and the mapping of a body torque onto the actuators.

A controller computes, at each sample, a :class:`~ocp.actuators.Command`. Laws written for the
rigid body ``I ω̇ = −ω × I ω + u`` compute ``u`` and call :meth:`Controller.allocate`, which maps it
to the actuators as ARCHITECTURE.md states: wheels take ``τ_w = u + ω × A h_w`` through
``g = −A⁺ τ_w`` (working wheels only); what the wheels cannot give (fewer than three independent
axes) goes to the torquers if there are any, else to the magnetorquers as
``m = B × τ / |B|²`` (the component of τ perpendicular to B). Without wheels the torquers take
``u``, else the magnetorquers. With ``hold_compensation`` the gyroscopic term is taken at
mid-sample (see :meth:`Controller._gyroscopic_drift`), which removes the first-order lag of the
zero-order hold when the body carries a large momentum (spinning spacecraft, loaded wheels).
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Any, Mapping

import numpy as np
from numpy.typing import NDArray

from ocp import Command, Measurement, Spacecraft
from ocp.options import Configurable, InvalidOption

Array = NDArray[np.float64]


class Controller(Configurable, ABC):
    """Base class of every feedback law.

    Contract
    --------
    * ``name`` is the registry key; ``Options`` a dataclass of the law's options with defaults.
    * ``reset(spacecraft, sample_time, target=None)`` clears any state before a run; ``target``
      is ``(q_f, ω_f or None)``, used in regulation mode and by regulators.
    * ``__call__(t, measurement, reference)`` returns the :class:`Command` for the coming sample;
      ``reference`` is a ``planners.Reference`` or ``None`` (regulation to the target).
    * ``needs_reference``: the law cannot regulate (``reference=None``) and raises ``ValueError``
      there; the scenario loader rejects regulation mode for it.
    * ``planner_error(name, options)`` says why the law cannot track references of that planner
      (``None`` if it can); the scenario loader reports it. Most laws track any reference.
    * ``spacecraft_error(spacecraft)`` says why the law cannot control that spacecraft (``None``
      if it can), e.g. a two-wheel law on three working wheels; the scenario loader reports it.
    * Saturation is the simulator's actuator model's job, not the controller's.

    Capability flags (class attributes) used by :meth:`allocate`: ``hold_compensation``,
    ``gyroscopic_compensation`` and ``wheels_only``.
    """

    hold_compensation: bool = True
    """Correct the held gyroscopic term to mid-sample in :meth:`allocate`."""
    gyroscopic_compensation: bool = True
    """The law's ``u`` is for ``I ω̇ = −ω × I ω + u``: :meth:`allocate` adds the wheels' ``ω × A h_w``.
    ``False``: ``u`` is the wheels' body torque itself (laws written for ``I ω̇ = u`` under zero momentum)."""
    wheels_only: bool = False
    """Pure wheel mode: what the wheels cannot give is dropped, never sent to torquers or magnetorquers."""
    needs_reference: bool = False

    def __init__(self, options: Mapping[str, Any] | Any | None = None, path: str = "options"):
        super().__init__(options, path)
        self.spacecraft: Spacecraft | None = None
        self.sample_time = 0.0
        self.target: tuple[Array, Array | None] | None = None

    def planner_error(self, planner: str, options: Any) -> str | None:
        """Why this law cannot track the references of ``planner`` with ``options``, or ``None``."""
        return None

    def spacecraft_error(self, spacecraft: Spacecraft) -> str | None:
        """Why this law cannot control ``spacecraft``, or ``None`` (most laws control any)."""
        return None

    def reset(self, spacecraft: Spacecraft, sample_time: float, target: Any = None) -> None:
        """Prepare for a run of ``spacecraft`` sampled every ``sample_time`` seconds."""
        self.spacecraft = spacecraft
        self.sample_time = sample_time
        self.target = target
        wheels = spacecraft.wheels
        self._working_axes = None
        if wheels is not None and np.any(wheels.working):
            self._working_axes = wheels.axes * wheels.working
            self._wheel_pinv = np.linalg.pinv(self._working_axes)

    @abstractmethod
    def __call__(self, t: float, measurement: Measurement, reference: Any) -> Command:
        """The command for the sample starting at ``t`` (s)."""

    def _gyroscopic_drift(self, measurement: Measurement) -> Array:
        """Mid-sample correction of the held gyroscopic term ``ω × H`` (``H = I ω + A h_w``, the
        total body momentum): without external torque ``H`` turns in body axes as ``Ḣ = −ω × H``,
        whatever the wheels exchange, so over the hold ``ω × H`` drifts by ``−dt/2 ω × (ω × H)``."""
        omega = measurement.omega
        momentum = self.spacecraft.inertia @ omega + self.spacecraft.wheel_axes @ measurement.wheel_momentum
        return -0.5 * self.sample_time * np.cross(omega, np.cross(omega, momentum))

    def allocate(self, torque: Array, measurement: Measurement) -> Command:
        """Map a rigid-body control torque ``u`` (N m, body axes) to the actuators."""
        spacecraft = self.spacecraft
        command = Command()
        residual = np.asarray(torque, dtype=float)
        if self.hold_compensation:
            residual = residual + self._gyroscopic_drift(measurement)
        if self._working_axes is not None:
            wheel_torque = residual
            if self.gyroscopic_compensation:
                wheel_torque = residual + np.cross(measurement.omega, spacecraft.wheel_axes @ measurement.wheel_momentum)
            command.wheel_torque = -self._wheel_pinv @ wheel_torque
            if self.wheels_only:
                return command
            residual = wheel_torque + self._working_axes @ command.wheel_torque
            if np.linalg.norm(residual) <= 1e-12 * max(np.linalg.norm(wheel_torque), 1e-300):
                return command
        if self.wheels_only:
            return command
        if spacecraft.torquers is not None:
            command.torque = residual
        elif spacecraft.magnetorquers is not None and measurement.field_body is not None:
            field = measurement.field_body
            command.dipole = np.cross(field, residual) / max(float(field @ field), 1e-30)
        return command


def check_gain(option: str, gain: float | list[list[float]]) -> None:
    """Raise :class:`~ocp.options.InvalidOption` unless ``gain`` is a non-negative scalar or a 3x3
    matrix whose symmetric part is positive semi-definite (a gain that pumps energy in is an error).

    Parameters
    ----------
    option : the option's name, for the message.
    gain : the scalar (times the inertia) or the 3x3 matrix.
    """
    if isinstance(gain, (int, float)):
        if gain < 0:
            raise InvalidOption(option, f"expected a non-negative gain, got {gain!r}")
        return
    matrix = np.asarray(gain, dtype=float)
    if np.linalg.eigvalsh(0.5 * (matrix + matrix.T)).min() < -1e-12 * max(1.0, float(np.abs(matrix).max())):
        raise InvalidOption(option, "expected a 3x3 gain matrix with a positive semi-definite symmetric part")


def gain_matrix(gain: float | list[list[float]], inertia: Array) -> Array:
    """A scalar gain times the inertia (the spin paper's choice), or a full 3x3 gain matrix."""
    if isinstance(gain, (int, float)):
        return float(gain) * inertia
    matrix = np.asarray(gain, dtype=float)
    if matrix.shape != (3, 3):
        raise ValueError(f"a gain matrix must be 3x3, got shape {matrix.shape}")
    return matrix
