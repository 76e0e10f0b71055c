"""Environment: gravity-gradient torque, geomagnetic field models, and what acts on the spacecraft.

Frames: the inertial frame is Earth-centred (ECI, z along the Earth's spin axis); the Earth-fixed
frame turns about z at ``earth_rate``. The expression builders take CasADi symbols (or numbers)
and return CasADi expressions; :class:`ocp.dynamics.model.AttitudeModel` assembles them. The orbit
they follow is an :class:`~ocp.dynamics.orbits.Orbit` (:mod:`ocp.dynamics.orbits`).

A geomagnetic field is anything with the :class:`MagneticField` interface. The models a scenario
names (``environment.magnetic_field.model``) are registered in :data:`MAGNETIC_FIELDS`, each a
:class:`FieldModel`: :class:`TiltedDipole` (``tilted_dipole``) and
:class:`~ocp.dynamics.igrf.IGRFField` (``igrf``, registered by its module).
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from typing import Annotated, Any, ClassVar, Protocol, runtime_checkable

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ocp import quat_casadi as qc
from ocp.dynamics.orbits import MU_EARTH, Orbit
from ocp.errors import ModelError
from ocp.options import Range, real_array
from ocp.quat_casadi import Expr

EARTH_RATE = 7.2921159e-5      # rad/s, sidereal rotation rate
DIPOLE_STRENGTH = 7.96e15      # T m³, Wertz (1978) dipole moment of the Earth's field


@runtime_checkable
class MagneticField(Protocol):
    """The geomagnetic field as the model and the simulator use it.

    :meth:`field_inertial` is all the model evaluates (the magnetorquer torque, the magnetometer,
    the field rate of ``bdot``'s exact derivative). Optional attributes, read when present:

    * ``valid_until`` (float [s]): the field is known on ``[0, valid_until]`` only (a table); the
      simulator refuses a longer run.
    * ``orbit`` (:class:`~ocp.dynamics.orbits.Orbit`): the orbit the field is tabulated along; it must be the
      environment's.

    The model's fingerprint (:attr:`~ocp.dynamics.model.AttitudeModel.fingerprint`, which keys the
    solver and simulator caches) describes a dataclass field by field: write a field model as a
    frozen dataclass of plain numbers and text.
    """

    def field_inertial(self, position: Expr, t: Expr) -> Expr:
        """Field vector at a point and time.

        Parameters
        ----------
        position : (3, 1) casadi.SX, MX, DM or array_like
            Position from the Earth's centre [m], inertial frame.
        t : float or scalar casadi.SX / MX
            Time since t = 0 [s].

        Returns
        -------
        (3, 1) casadi.DM, SX or MX
            Field ``B`` [T], inertial frame, built of CasADi operations (symbolic in ``t`` and
            ``position``).
        """
        ...


class FieldModel(ABC):
    """Base of the field models a scenario names: a :class:`MagneticField` class registered in
    :data:`MAGNETIC_FIELDS` under :attr:`name`.

    ``Options`` is a frozen dataclass of the YAML keys next to ``model:`` in
    ``environment.magnetic_field``, in the units written there (``_deg``, ``_s``), each typed with
    its :class:`~ocp.options.Range` and a default, and documented in an ``Attributes`` section:
    the scenario schema reads them and the schema reference lists them. A model whose extent
    depends on the closed-loop window may also define ``for_window(window) -> MagneticField``,
    which the scenario loader calls with the window [s] once it is known. Write a model as a
    frozen dataclass (see :class:`MagneticField`).

    Attributes
    ----------
    name : str
        The registry name (``environment.magnetic_field.model``).
    """

    name: ClassVar[str]

    @dataclass(frozen=True)
    class Options:
        """The model's options: subclasses replace this empty dataclass by their own."""

    @classmethod
    @abstractmethod
    def from_options(cls, options: Any, orbit: Orbit | None) -> FieldModel:
        """The field of validated options along the environment's orbit.

        Parameters
        ----------
        options : Options
            The options (an instance of the class's ``Options``).
        orbit : Orbit or None
            The scenario's orbit (``None``: none given).

        Returns
        -------
        FieldModel
            The field.

        Raises
        ------
        ModelError
            Naming the option (its ``field``; empty for the whole entry) and what was expected.
        """

    @abstractmethod
    def field_inertial(self, position: Expr, t: Expr) -> Expr:
        """Field vector at a point and time (see :meth:`MagneticField.field_inertial`).

        Parameters
        ----------
        position : (3, 1) casadi.SX, MX, DM or array_like
            Position from the Earth's centre [m], inertial frame.
        t : float or scalar casadi.SX / MX
            Time since t = 0 [s].

        Returns
        -------
        (3, 1) casadi.DM, SX or MX
            Field ``B`` [T], inertial frame.
        """


@dataclass(frozen=True)
class TiltedDipole(FieldModel):
    """Tilted dipole geomagnetic field rotating with the Earth (nano-spacecraft paper, eq. 6).

    ``B = μ_m / r³ [3 (m̂·r̂) r̂ − m̂]`` where ``m̂`` is the dipole direction, which points to the
    southern geomagnetic pole. In geomagnetic latitude λ and longitude η this is exactly eq. 6:
    ``b = −μ_m/r³ [3 sinλ cosλ cosη, 3 sinλ cosλ sinη, 3 sin²λ − 1]``.

    Parameters
    ----------
    strength : float, optional
        Dipole strength ``μ_m`` [T m^3] (default ``DIPOLE_STRENGTH``, 7.96e15: about 30 µT at the
        equator on the ground).
    tilt : float, optional
        Angle between the geomagnetic and geographic north poles [rad] (default 11.5°).
    pole_longitude : float, optional
        East longitude of the northern geomagnetic pole [rad] (default −70°).
    greenwich_angle : float, optional
        Angle of the Earth-fixed x axis from the inertial x axis at t = 0 [rad] (default 0).
    earth_rate : float, optional
        Rotation rate of the Earth-fixed frame about the inertial z axis [rad/s] (default
        ``EARTH_RATE``, sidereal).
    """

    name: ClassVar[str] = "tilted_dipole"

    strength: float = DIPOLE_STRENGTH
    tilt: float = np.deg2rad(11.5)
    pole_longitude: float = np.deg2rad(-70.0)
    greenwich_angle: float = 0.0
    earth_rate: float = EARTH_RATE

    @dataclass(frozen=True)
    class Options:
        """Options of ``tilted_dipole`` (YAML keys of ``environment.magnetic_field``).

        Attributes
        ----------
        strength : float
            Dipole strength μ_m [T m^3] (default 7.96e15, Wertz 1978: about 30 µT at the equator
            on the ground).
        tilt_deg : float
            Angle between the geomagnetic and the geographic north pole [deg].
        pole_longitude_deg : float
            East longitude of the northern geomagnetic pole [deg].
        greenwich_angle_deg : float
            Angle of the Earth-fixed x axis from the inertial x axis at t = 0 [deg].
        """

        strength: Annotated[float, Range(gt=0.0)] = DIPOLE_STRENGTH
        tilt_deg: Annotated[float, Range()] = 11.5
        pole_longitude_deg: Annotated[float, Range()] = -70.0
        greenwich_angle_deg: Annotated[float, Range()] = 0.0

    @classmethod
    def from_options(cls, options: Any, orbit: Orbit | None) -> TiltedDipole:
        """The dipole of ``options`` (degrees converted to radians).

        Parameters
        ----------
        options : TiltedDipole.Options
            The YAML options.
        orbit : Orbit or None
            Not used (the dipole is defined everywhere); the :class:`FieldModel` interface.

        Returns
        -------
        TiltedDipole
            The field.
        """
        return cls(strength=options.strength, tilt=float(np.deg2rad(options.tilt_deg)),
                   pole_longitude=float(np.deg2rad(options.pole_longitude_deg)),
                   greenwich_angle=float(np.deg2rad(options.greenwich_angle_deg)))

    def dipole_direction(self, t: Expr) -> Expr:
        """Unit dipole direction ``m̂`` (towards the southern geomagnetic pole).

        Parameters
        ----------
        t : float or scalar casadi.SX / MX
            Time since t = 0 [s].

        Returns
        -------
        (3, 1) casadi.DM, SX or MX
            Unit vector, inertial frame.
        """
        angle = self.greenwich_angle + self.earth_rate * t + self.pole_longitude
        st = np.sin(self.tilt)
        return -ca.vertcat(st * ca.cos(angle), st * ca.sin(angle), np.cos(self.tilt))

    def function(self) -> ca.Function:
        """The field as a CasADi function.

        Returns
        -------
        casadi.Function
            ``dipole_field(position, t) -> b``: ``position`` (3,) [m] and ``b`` (3, 1) [T], both
            inertial frame; ``t`` [s].
        """
        position, t = ca.SX.sym("position", 3), ca.SX.sym("t")
        return ca.Function("dipole_field", [position, t], [self.field_inertial(position, t)], ["position", "t"], ["b"])

    def field_inertial(self, position: Expr, t: Expr) -> Expr:
        """Geomagnetic field vector at a point and time.

        Parameters
        ----------
        position : (3, 1) casadi.SX, MX, DM or array_like
            Position from the Earth's centre [m], inertial frame (non-zero).
        t : float or scalar casadi.SX / MX
            Time since t = 0 [s].

        Returns
        -------
        (3, 1) casadi.DM, SX or MX
            Field ``B`` [T], inertial frame.
        """
        r = ca.norm_2(position)
        r_hat = position / r
        m_hat = self.dipole_direction(t)
        return self.strength / r**3 * (3 * ca.dot(m_hat, r_hat) * r_hat - m_hat)


def gravity_gradient_torque(q: Expr, position: Expr, inertia: NDArray, mu: float = MU_EARTH) -> Expr:
    """Gravity-gradient torque on a rigid body, ``3 μ / |r|⁵ · r_B × (I r_B)``.

    Parameters
    ----------
    q : (4, 1) casadi.SX, MX or DM
        Attitude quaternion, scalar first, body to inertial.
    position : (3, 1) casadi.SX, MX, DM or array_like
        Position of the spacecraft from the Earth's centre [m], inertial frame; rotated here to
        ``r_B = R(q)ᵀ r``.
    inertia : (3, 3) ndarray
        Inertia matrix about the centre of mass [kg m^2], body frame.
    mu : float, optional
        Gravitational parameter [m^3/s^2] (default ``MU_EARTH``).

    Returns
    -------
    (3, 1) casadi.SX, MX or DM
        Torque [N m], body frame.
    """
    r_body = ca.mtimes(qc.rotation_matrix(q).T, position)
    r = ca.norm_2(position)
    return 3 * mu / r**5 * ca.cross(r_body, ca.mtimes(ca.DM(inertia), r_body))


MAX_DISTURBANCE = 1.0e6
"""Largest entry [N m] of ``Environment.disturbance_torque`` (and the scenario's
``environment.disturbance_torque``): a million times the largest disturbance torques on any
spacecraft (the ISS's gravity-gradient and aerodynamic torques, of the order of N m; small
satellites' are µN m to mN m). 1e300 N m was accepted without a warning (its norm overflowed
to inf, which the plausibility check reads as unlimited) and printed NumPy's overflow warnings; a
torque merely larger than the actuators give against it warns (``disturbance``)."""


@dataclass(frozen=True)
class Environment:
    """What acts on the spacecraft besides its actuators.

    Parameters
    ----------
    orbit : Orbit or None, optional
        The orbit; required by the gravity gradient and the magnetic field (default none).
    gravity_gradient : bool, optional
        Include the gravity-gradient torque (default False).
    magnetic_field : MagneticField or None, optional
        Geomagnetic model (:class:`TiltedDipole`, :class:`~ocp.dynamics.igrf.IGRFField` tabulated
        along ``orbit``, or any :class:`MagneticField`), needed by magnetorquers; ``None``
        (default): no field.
    disturbance_torque : (3,) array_like, optional
        Constant disturbance torque [N m], body frame (default zero); held as a (3,) ndarray. It
        is the default of the model's parameter ``p``.

    Raises
    ------
    ModelError
        For a mis-sized disturbance, a gravity gradient or field without an orbit, a field that
        is not a :class:`MagneticField`, or a table along another orbit.
    """

    orbit: Orbit | None = None
    gravity_gradient: bool = False
    magnetic_field: MagneticField | None = None
    disturbance_torque: NDArray = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self) -> None:
        try:
            disturbance = real_array(self.disturbance_torque)
        except ValueError as reason:
            raise ModelError("disturbance_torque", f"expected 3 numbers [N m], got {self.disturbance_torque!r:.200}: "
                                                   f"{reason}") from None
        if disturbance.shape != (3,):
            raise ModelError("disturbance_torque", f"expected 3 values, got shape {disturbance.shape}")
        if not np.all(np.abs(disturbance) <= MAX_DISTURBANCE):  # NaN too
            raise ModelError("disturbance_torque", f"expected finite entries within ±{MAX_DISTURBANCE:g} N m, got "
                                                   f"{disturbance.tolist()}")
        object.__setattr__(self, "disturbance_torque", disturbance)
        if self.orbit is None and self.gravity_gradient:
            raise ModelError("gravity_gradient", "gravity gradient needs an orbit")
        if self.magnetic_field is not None and not isinstance(self.magnetic_field, MagneticField):
            raise ModelError("magnetic_field", "expected a field model with field_inertial(position, t), got "
                                               f"{type(self.magnetic_field).__name__}")
        if self.orbit is None and self.magnetic_field is not None:
            raise ModelError("magnetic_field", "a magnetic field model needs an orbit")
        tabulated_along = getattr(self.magnetic_field, "orbit", None)
        if tabulated_along is not None and tabulated_along != self.orbit:
            raise ModelError("magnetic_field", "the field is tabulated along another orbit than the environment's")



MAGNETIC_FIELDS: dict[str, type[FieldModel]] = {TiltedDipole.name: TiltedDipole}
"""The field models a scenario names (``environment.magnetic_field.model``): registry name -> class
(:class:`FieldModel`). :mod:`ocp.dynamics.igrf` adds ``igrf`` (the :mod:`ocp` package imports it);
register a model of your own the same way, by adding its class under its ``name``."""
