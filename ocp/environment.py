"""Environment: circular orbit, gravity-gradient torque, tilted-dipole geomagnetic field.

Frames: the inertial frame is Earth-centred (ECI, z along the Earth's spin axis); the Earth-fixed
frame turns about z at ``earth_rate``. The expression builders take CasADi symbols (or numbers)
and return CasADi expressions; :class:`ocp.model.AttitudeModel` assembles them.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ocp import quat_casadi as qc
from ocp.spacecraft import ModelError

MU_EARTH = 3.986004418e14      # m³/s², EGM96 / WGS-84
R_EARTH = 6378.137e3           # m, WGS-84 equatorial radius
EARTH_RATE = 7.2921159e-5      # rad/s, sidereal rotation rate
DIPOLE_STRENGTH = 7.96e15      # T m³, Wertz (1978) dipole moment of the Earth's field


@dataclass(frozen=True)
class CircularOrbit:
    """Circular Keplerian orbit.

    Parameters
    ----------
    altitude : m, above ``R_EARTH``.
    inclination, raan, arg_latitude : rad; ``arg_latitude`` is the argument of latitude at t = 0.
    mu : m³/s², gravitational parameter.
    """

    altitude: float
    inclination: float = 0.0
    raan: float = 0.0
    arg_latitude: float = 0.0
    mu: float = MU_EARTH

    def __post_init__(self) -> None:
        if not self.altitude > -R_EARTH * 0.99:
            raise ModelError("altitude", f"the orbit radius must be positive, got altitude {self.altitude} m")

    @property
    def radius(self) -> float:
        """Orbit radius (m)."""
        return R_EARTH + self.altitude

    @property
    def mean_motion(self) -> float:
        """Mean motion n (rad/s)."""
        return float(np.sqrt(self.mu / self.radius**3))

    def position(self, t):
        """Inertial position (m) at time ``t`` (s)."""
        u = self.arg_latitude + self.mean_motion * t
        ci, si = np.cos(self.inclination), np.sin(self.inclination)
        cO, sO = np.cos(self.raan), np.sin(self.raan)
        return self.radius * ca.vertcat(
            ca.cos(u) * cO - ca.sin(u) * ci * sO,
            ca.cos(u) * sO + ca.sin(u) * ci * cO,
            ca.sin(u) * si,
        )

    def velocity(self, t):
        """Inertial velocity (m/s) at ``t``."""
        u = self.arg_latitude + self.mean_motion * t
        ci, si = np.cos(self.inclination), np.sin(self.inclination)
        cO, sO = np.cos(self.raan), np.sin(self.raan)
        return self.radius * self.mean_motion * ca.vertcat(
            -ca.sin(u) * cO - ca.cos(u) * ci * sO,
            -ca.sin(u) * sO + ca.cos(u) * ci * cO,
            ca.cos(u) * si,
        )

    def nadir(self, t):
        """Unit vector from the spacecraft to the Earth's centre, inertial axes."""
        r = self.position(t)
        return -r / ca.norm_2(r)

    def function(self) -> ca.Function:
        """``casadi.Function`` ``(t) -> (position, velocity, nadir)`` in inertial axes (m, m/s, unit)."""
        t = ca.SX.sym("t")
        return ca.Function("orbit", [t], [self.position(t), self.velocity(t), self.nadir(t)], ["t"],
                           ["position", "velocity", "nadir"])

    def lvlh_matrix(self, t):
        """Columns: LVLH axes in inertial axes (x along-track, y = −orbit normal, z nadir)."""
        z = self.nadir(t)
        v = self.velocity(t)
        y = ca.cross(z, v)
        y = y / ca.norm_2(y)
        return ca.horzcat(ca.cross(y, z), y, z)


@dataclass(frozen=True)
class TiltedDipole:
    """Tilted dipole geomagnetic field rotating with the Earth (nano-spacecraft paper, eq. 6).

    ``B = μ_m / r³ [3 (m̂·r̂) r̂ − m̂]`` where ``m̂`` is the dipole direction, which points to the
    southern geomagnetic pole. In geomagnetic latitude λ and longitude η this is exactly eq. 6:
    ``b = −μ_m/r³ [3 sinλ cosλ cosη, 3 sinλ cosλ sinη, 3 sin²λ − 1]``.

    Parameters
    ----------
    strength : T m³, μ_m.
    tilt : rad, angle between the geomagnetic and geographic north poles.
    pole_longitude : rad, east longitude of the northern geomagnetic pole.
    greenwich_angle : rad, angle of the Earth-fixed x axis from the inertial x axis at t = 0.
    earth_rate : rad/s.
    """

    strength: float = DIPOLE_STRENGTH
    tilt: float = np.deg2rad(11.5)
    pole_longitude: float = np.deg2rad(-70.0)
    greenwich_angle: float = 0.0
    earth_rate: float = EARTH_RATE

    def dipole_direction(self, t):
        """Unit dipole direction ``m̂`` in inertial axes at ``t``."""
        angle = self.greenwich_angle + self.earth_rate * t + self.pole_longitude
        st = np.sin(self.tilt)
        return -ca.vertcat(st * ca.cos(angle), st * ca.sin(angle), np.cos(self.tilt))

    def function(self) -> ca.Function:
        """``casadi.Function`` ``(position, t) -> b``: the field (T) in inertial axes."""
        position, t = ca.SX.sym("position", 3), ca.SX.sym("t")
        return ca.Function("dipole_field", [position, t], [self.field_inertial(position, t)], ["position", "t"], ["b"])

    def field_inertial(self, position, t):
        """Field vector (T) in inertial axes at inertial ``position`` (m) and time ``t``."""
        r = ca.norm_2(position)
        r_hat = position / r
        m_hat = self.dipole_direction(t)
        return self.strength / r**3 * (3 * ca.dot(m_hat, r_hat) * r_hat - m_hat)


def gravity_gradient_torque(q, position, inertia: NDArray, mu: float = MU_EARTH):
    """Gravity-gradient torque (N m, body axes): ``3 μ / |r|⁵ · r_B × (I r_B)``."""
    r_body = ca.mtimes(qc.rotation_matrix(q).T, position)
    r = ca.norm_2(position)
    return 3 * mu / r**5 * ca.cross(r_body, ca.mtimes(ca.DM(inertia), r_body))


@dataclass(frozen=True)
class Environment:
    """What acts on the spacecraft besides its actuators.

    Parameters
    ----------
    orbit : circular orbit, required by gravity gradient and the magnetic field.
    gravity_gradient : include the gravity-gradient torque.
    magnetic_field : geomagnetic model (:class:`TiltedDipole`, or :class:`~ocp.igrf.IGRFField`
        tabulated along ``orbit``), or ``None``.
    disturbance_torque : (3,) N m, constant, body axes.
    """

    orbit: CircularOrbit | None = None
    gravity_gradient: bool = False
    magnetic_field: TiltedDipole | Any | None = None
    disturbance_torque: NDArray = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self) -> None:
        disturbance = np.asarray(self.disturbance_torque, dtype=float)
        if disturbance.shape != (3,):
            raise ModelError("disturbance_torque", f"expected 3 values, got shape {disturbance.shape}")
        object.__setattr__(self, "disturbance_torque", disturbance)
        if self.orbit is None and self.gravity_gradient:
            raise ModelError("gravity_gradient", "gravity gradient needs an orbit")
        if self.orbit is None and self.magnetic_field is not None:
            raise ModelError("magnetic_field", "a magnetic field model needs an orbit")
        tabulated_along = getattr(self.magnetic_field, "orbit", None)
        if tabulated_along is not None and tabulated_along != self.orbit:
            raise ModelError("magnetic_field", "the field is tabulated along another orbit than the environment's")

