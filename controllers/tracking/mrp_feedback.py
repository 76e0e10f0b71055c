"""Basilisk's MRP feedback tracking law (``mrpFeedback``, Schaub & Junkins, *Analytical Mechanics of
Space Systems*, example 8.14), without its integral term.

The law of Basilisk's ``mrpFeedback`` flight-software module (``controlLawType`` 0 or 1, integral
gain ``Ki`` < 0, i.e. off, no known external torque), written for slewbench's state::

    L_r = −K σ − P δω + ω_g × (I ω + A h_w) − I (ω × ω_r − ω̇_r)

* ``σ`` the MRPs of the body relative to the reference, ``q_v / (1 + q_0)`` of
  ``q_e = q*⁻¹ ⊗ q`` with ``q_e0 ≥ 0`` (the short set, ``|σ| ≤ 1``, as Basilisk's ``subMRP``);
* ``ω_r = R(q_e)ᵀ ω*`` and ``ω̇_r = R(q_e)ᵀ ω̇*`` the reference rate and acceleration in body axes
  (slewbench's ``ω*``, ``ω̇*`` are in reference axes), ``δω = ω − ω_r``;
* ``A h_w`` the wheels' spin momenta (Basilisk's ``[G_s] h_s``, with
  ``h_s = J_s (ĝ_sᵀ ω + Ω)``, which is slewbench's ``h_w``), every wheel counted (a failed one still
  carries its momentum);
* ``ω_g = ω_r`` (``gyroscopic_rate: reference``, Basilisk's ``controlLawType = 0``, the default)
  or ``ω_g = ω`` (``body``, ``controlLawType = 1``).

``I`` is slewbench's inertia, which excludes the wheels' spin inertia about their axes (Basilisk's
``[I_RW]``; its module reads the inertia from its vehicle configuration message, which is to hold
this matrix for the two laws to be one). The law is sampled at ``t_k`` and held, as Basilisk's task
does: there is no hold compensation. With ``V = ½ δωᵀ I δω + 2K ln(1 + σᵀσ)`` the continuous closed
loop has ``V̇ = −P δωᵀ δω``.

``L_r`` is the torque the actuators are to exert on the body, mapped to the wheels as
``g = −A⁺ L_r``, Basilisk's ``rwMotorTorque`` with control axes the body axes. With
``gyroscopic_rate: body`` the law is a rigid-body law: ``u = L_r − ω × A h_w`` does not depend on the
wheel momenta, and the allocation adds ``ω × A h_w`` back (``gyroscopic_compensation`` true). With
``reference`` (Basilisk's default) it is not: ``L_r − ω × A h_w`` keeps ``−δω × A h_w``, so the
wheels' term stays in the law and ``L_r`` is mapped as it is (``gyroscopic_compensation`` false;
the controller conformance tells the two kinds apart). The scenario's actuator requirement asks
the wheels for ``ω × A h_w`` along the reference with either form
(:func:`controllers.allocation.reference_demand`).
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Annotated, Any, Literal

import casadi as ca
import numpy as np

from controllers.base import Array, Controller
from ocp import Command, Measurement, Spacecraft
from ocp.dynamics.layout import split_measurement
from ocp.options import Range
from ocp.quat import error, rotation_matrix


class MRPFeedback(Controller):
    """Basilisk's MRP feedback (module docstring), tracking a reference or regulating to the target.

    Parameters
    ----------
    options : mapping or Options, optional
        The law's options (:class:`Options`); ``None``: the defaults.
    path : str, optional
        YAML path of the options, for error messages.
    """

    name = "mrp_feedback"
    tracks_reference = True
    gyroscopic_compensation = False
    """Per instance: true with ``gyroscopic_rate: body`` (module docstring)."""

    @dataclass(frozen=True)
    class Options:
        """Options of ``mrp_feedback`` (the YAML keys under the controller's ``options``).

        Parameters
        ----------
        k : float >= 0
            Attitude gain ``K`` [N m per unit MRP] (Basilisk's ``K``).
        p : float >= 0
            Rate gain ``P`` [N m s/rad] (Basilisk's ``P``).
        gyroscopic_rate : {"reference", "body"}
            The rate crossed with the total angular momentum: ``ω_r`` (Basilisk's
            ``controlLawType = 0``, the default) or the body rate ``ω`` (``controlLawType = 1``).
        """

        k: Annotated[float, Range(ge=0.0)] = 2.0
        p: Annotated[float, Range(ge=0.0)] = 8.0
        gyroscopic_rate: Literal["reference", "body"] = "reference"

    def __init__(self, options: Mapping[str, Any] | Any | None = None, path: str = "options"):
        super().__init__(options, path)
        self.gyroscopic_compensation = self.options.gyroscopic_rate == "body"

    def reset(self, spacecraft: Spacecraft, sample_time: float, target: Any = None) -> None:
        super().reset(spacecraft, sample_time, target)
        self._inertia = np.asarray(spacecraft.inertia, dtype=float)
        self._axes = np.asarray(spacecraft.wheel_axes, dtype=float).reshape(3, -1)

    def _rows(self, t: float, reference: Any) -> Array:
        if reference is None and self.target is None:
            raise ValueError(f"controller {self.name} regulates to a target: reset it with one")
        return self.reference_rows(reference, np.array([t]))[0]

    def __call__(self, t: float, measurement: Measurement, reference: Any) -> Command:
        row = self._rows(t, reference)
        q = np.asarray(measurement.q, dtype=float)
        omega = np.asarray(measurement.omega, dtype=float)
        q_e = error(q, row[0:4])
        sigma = q_e[1:] / (1.0 + q_e[0])
        to_body = rotation_matrix(q_e).T
        omega_r, omega_dot_r = to_body @ row[4:7], to_body @ row[7:10]
        momentum = self._inertia @ omega
        if self._axes.shape[1] and not self.gyroscopic_compensation:  # else the allocation adds ω × A h_w
            momentum = momentum + self._axes @ np.asarray(measurement.wheel_momentum, dtype=float)
        spin = omega if self.gyroscopic_compensation else omega_r
        torque = (-self.options.k * sigma - self.options.p * (omega - omega_r) + np.cross(spin, momentum)
                  - self._inertia @ (np.cross(omega, omega_r) - omega_dot_r))
        return self.allocate(torque, measurement)

    def _law(self, t: ca.SX, y: ca.SX, z: ca.SX, r: ca.SX) -> tuple[ca.SX, ca.SX]:
        spacecraft = self._spacecraft()
        q, omega, h, _ = split_measurement(y, spacecraft.n_wheels)
        q_ref, w_ref, a_ref = r[0:4], r[4:7], r[7:10]  # the reference (or the target) at t
        scalar = ca.dot(q_ref, q)
        vector = q_ref[0] * q[1:4] - q[0] * q_ref[1:4] - ca.cross(q_ref[1:4], q[1:4])
        sign = ca.if_else(scalar < 0, -1, 1)
        e0, ev = sign * scalar, sign * vector
        sigma = ev / (1 + e0)

        # R(q_e)ᵀ v = v − 2 e0 (e_v × v) + 2 e_v × (e_v × v)
        def to_body(v: ca.SX) -> ca.SX:
            return v - 2 * e0 * ca.cross(ev, v) + 2 * ca.cross(ev, ca.cross(ev, v))

        omega_r, omega_dot_r = to_body(w_ref), to_body(a_ref)
        inertia = ca.DM(self._inertia)
        momentum = ca.mtimes(inertia, omega)
        if spacecraft.n_wheels and not self.gyroscopic_compensation:  # else the allocation adds ω × A h_w
            momentum = momentum + ca.mtimes(ca.DM(self._axes), h)
        spin = omega if self.gyroscopic_compensation else omega_r
        torque = (-self.options.k * sigma - self.options.p * (omega - omega_r) + ca.cross(spin, momentum)
                  - ca.mtimes(inertia, ca.cross(omega, omega_r) - omega_dot_r))
        return self.allocate_symbolic(torque, y), z
