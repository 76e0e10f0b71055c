"""Directions seen from the spacecraft and their tables (:mod:`ocp.geometry.directions`).

Oracles: the circular orbit written out here from its elements (rotation matrices, not
``CircularOrbit``); the Earth's apparent radius in closed form; the Moon's and the Sun's geocentric
positions (tested against ERFA in ``test_ephemeris``) minus that orbit; the table interpolated by
:class:`~ocp.geometry.pointing.PointingConstraint` against those exact directions between rows.
"""
from __future__ import annotations

import datetime
import time

import numpy as np
import pytest

from ocp.dynamics.ephemeris import moon_position, sun_position
from ocp.dynamics.orbits import MU_EARTH, CircularOrbit
from ocp.errors import ModelError
from ocp.geometry import (
    DIRECTIONS,
    INTERPOLATION_TOLERANCE,
    DirectionKind,
    Geometry,
    PointingConstraint,
    direction_kind,
    direction_table,
)

R_EARTH = 6378137.0  # m, WGS-84 equatorial radius, written here
EPOCH = datetime.datetime(2025, 6, 1, 3, 0)


def orbit_by_hand(radius: float, inclination: float, raan: float, arg_latitude: float,
                  t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Position [m] and velocity [m/s] on a circular orbit: R3(-Ω) R1(-i) [cos u, sin u, 0]."""
    n = np.sqrt(MU_EARTH / radius**3)
    u = arg_latitude + n * np.asarray(t, dtype=float)
    c, s = np.cos, np.sin
    rz = np.array([[c(raan), -s(raan), 0.0], [s(raan), c(raan), 0.0], [0.0, 0.0, 1.0]])
    rx = np.array([[1.0, 0.0, 0.0], [0.0, c(inclination), -s(inclination)], [0.0, s(inclination), c(inclination)]])
    in_plane = np.stack([c(u), s(u), np.zeros_like(u)], axis=-1)
    in_plane_rate = np.stack([-s(u), c(u), np.zeros_like(u)], axis=-1)
    m = rz @ rx
    return radius * in_plane @ m.T, radius * n * in_plane_rate @ m.T


def unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def angle_deg(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    a, b = np.atleast_2d(a), np.atleast_2d(b)
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.einsum("ij,ij->i", a, b)))


ORBITS = {  # name: (altitude [m], inclination, RAAN, argument of latitude at t = 0) [rad]
    "sun-synchronous 500 km": (500e3, np.radians(97.4), np.radians(30.0), np.radians(-40.0)),
    "equatorial 500 km": (500e3, 0.0, 0.0, 0.0),
    "ISS-like 420 km": (420e3, np.radians(51.6), np.radians(200.0), np.radians(123.0)),
}


def exact(kind: str, elements: tuple[float, float, float, float], epoch: datetime.datetime,
          t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The exact direction of a kind and its growth, from the hand-written orbit and the ephemeris."""
    altitude, inclination, raan, u0 = elements
    radius = R_EARTH + altitude
    position, velocity = orbit_by_hand(radius, inclination, raan, u0, t)
    zero = np.zeros(len(t))
    return {"sun": lambda: (unit(sun_position(epoch, t) - position), zero),
            "moon": lambda: (unit(moon_position(epoch, t) - position), zero),
            "earth": lambda: (unit(-position), zero),
            "earth_limb": lambda: (unit(-position), np.full(len(t), np.arcsin(R_EARTH / radius))),
            "velocity": lambda: (unit(velocity), zero)}[kind]()


def geometry_of(elements: tuple[float, float, float, float], epoch: datetime.datetime | None = EPOCH) -> Geometry:
    altitude, inclination, raan, u0 = elements
    return Geometry(epoch, CircularOrbit(altitude, inclination, raan, u0))


# --- Geometry -------------------------------------------------------------------------------------

@pytest.mark.parametrize("name", ORBITS)
def test_position_velocity_nadir_and_ram_follow_the_orbit(name):
    elements = ORBITS[name]
    geometry = geometry_of(elements)
    t = np.linspace(0.0, 6000.0, 41)
    position, velocity = orbit_by_hand(R_EARTH + elements[0], *elements[1:], t)
    np.testing.assert_allclose(geometry.position(t), position, rtol=0, atol=1e-6)
    np.testing.assert_allclose(geometry.velocity(t), velocity, rtol=0, atol=1e-9)
    assert geometry.position(12.0).shape == (1, 3)
    nadir, growth = DIRECTIONS["earth"].table(geometry, t)
    np.testing.assert_allclose(nadir, -position / np.linalg.norm(position, axis=1, keepdims=True), atol=1e-15)
    assert not growth.any()
    ram, _ = DIRECTIONS["velocity"].table(geometry, t)
    np.testing.assert_allclose(np.einsum("ij,ij->i", ram, nadir), 0.0, atol=1e-15)   # circular: ram ⟂ nadir
    np.testing.assert_allclose(np.linalg.norm(ram, axis=1), 1.0, atol=1e-15)


@pytest.mark.parametrize("altitude, limb_deg", [(500e3, 68.0), (35786e3, 8.7)])
def test_the_earth_limb_grows_the_cone_by_the_earths_apparent_radius(altitude, limb_deg):
    geometry = Geometry(None, CircularOrbit(altitude, np.radians(45.0)))
    t = np.linspace(0.0, 3000.0, 7)
    nadir, growth = DIRECTIONS["earth_limb"].table(geometry, t)
    np.testing.assert_allclose(growth, np.arcsin(R_EARTH / (R_EARTH + altitude)), rtol=1e-14)
    assert abs(np.degrees(growth[0]) - limb_deg) < 0.1  # 68.0 deg from 500 km, 8.7 deg from GEO
    np.testing.assert_allclose(nadir, DIRECTIONS["earth"].table(geometry, t)[0], atol=0)
    # a boresight on the limb: at the cone's edge (zero margin) for a keep-out of 0+
    side = unit(np.cross(nadir[0], [0.0, 0.0, 1.0]))
    on_limb = np.cos(growth[0]) * nadir[0] + np.sin(growth[0]) * side
    assert abs(angle_deg(on_limb, nadir[0])[0] - np.degrees(growth[0])) < 1e-9


def test_the_earth_limb_refuses_an_orbit_inside_the_earth():
    with pytest.raises(ModelError, match="above the Earth's surface") as error:
        DIRECTIONS["earth_limb"].table(Geometry(None, CircularOrbit(-1000.0)), np.zeros(1))
    assert error.value.field == "orbit"


def test_the_moon_from_a_7000_km_orbit_carries_a_parallax_of_up_to_a_degree():
    radius = 7000e3
    geometry = Geometry(EPOCH, CircularOrbit(radius - R_EARTH, np.radians(60.0), np.radians(10.0)))
    t = np.linspace(0.0, 86400.0, 2001)
    moon = moon_position(EPOCH, t)
    position, _ = orbit_by_hand(radius, np.radians(60.0), np.radians(10.0), 0.0, t)
    seen = geometry.moon(t)
    np.testing.assert_allclose(seen, unit(moon - position), atol=1e-14)
    parallax = angle_deg(seen, unit(moon))
    bound = np.degrees(np.arcsin(radius / np.linalg.norm(moon, axis=1)))   # r ⟂ the Moon's direction
    assert np.all(parallax <= bound + 1e-9)
    assert 0.9 < parallax.max() < 1.1 and parallax.max() > 0.97 * bound.min()
    # without an orbit: seen from the Earth's centre
    np.testing.assert_allclose(Geometry(EPOCH, None).moon(t), unit(moon), atol=1e-15)


def test_the_sun_from_low_orbit_differs_from_the_geocentric_sun_by_its_tiny_parallax():
    geometry = geometry_of(ORBITS["sun-synchronous 500 km"])
    t = np.linspace(0.0, 6000.0, 101)
    parallax = angle_deg(geometry.sun(t), unit(sun_position(EPOCH, t)))
    assert 0.002 < parallax.max() < np.degrees((R_EARTH + 500e3) / 1.47e11)   # ≈ 0.0027 deg
    np.testing.assert_allclose(Geometry(EPOCH, None).sun(t), unit(sun_position(EPOCH, t)), atol=1e-15)


def test_geometry_says_what_is_missing():
    for call, field in [(lambda: Geometry(EPOCH, None).position(0.0), "orbit"),
                        (lambda: Geometry(EPOCH, None).velocity(0.0), "orbit"),
                        (lambda: Geometry(None, CircularOrbit(500e3)).sun(0.0), "epoch"),
                        (lambda: Geometry(None, None).moon(0.0), "epoch"),
                        (lambda: Geometry(EPOCH, None, frame="EME2000"), "frame"),
                        (lambda: Geometry("1 June", None), "epoch")]:  # type: ignore[arg-type]
        with pytest.raises(ModelError) as error:
            call()
        assert error.value.field == field
    assert "needs an epoch" in str(pytest.raises(ModelError, Geometry(None, None).sun, 0.0).value)
    aware = datetime.datetime(2025, 6, 1, 5, tzinfo=datetime.timezone(datetime.timedelta(hours=2)))
    assert Geometry(aware, None).epoch == EPOCH


# --- the registry ---------------------------------------------------------------------------------

def test_the_registry_holds_the_five_kinds_with_their_needs():
    needs = {name: (kind.needs_epoch, kind.needs_orbit) for name, kind in DIRECTIONS.items()}
    assert needs == {"sun": (True, False), "moon": (True, False), "earth": (False, True),
                     "earth_limb": (False, True), "velocity": (False, True)}
    for name, kind in DIRECTIONS.items():
        assert kind.name == name and kind.meaning and "\n" not in kind.meaning


def test_direction_kind_registers_a_kind_and_refuses_a_clash():
    @direction_kind
    class North(DirectionKind):
        name = "test_north"
        needs_epoch = False
        needs_orbit = False
        meaning = "the inertial z axis"

        def step_s(self, geometry: Geometry) -> float | None:
            return None

        def table(self, geometry, times):
            return np.tile([0.0, 0.0, 1.0], (len(times), 1)), np.zeros(len(times))

    try:
        times, directions, growth = direction_table("test_north", Geometry(None, None), 600.0)
        assert times.tolist() == [0.0] and directions.tolist() == [[0.0, 0.0, 1.0]] and growth.tolist() == [0.0]
        with pytest.raises(ValueError, match="taken"):
            direction_kind(type("Other", (North,), {"name": "test_north"}))
        with pytest.raises(TypeError):
            direction_kind(int)  # type: ignore[type-var]
    finally:
        del DIRECTIONS["test_north"]


# --- tables ---------------------------------------------------------------------------------------

def test_direction_table_refuses_what_a_kind_cannot_be_tabulated_without():
    with pytest.raises(KeyError, match="expected one of.*earth_limb"):
        direction_table("mars", Geometry(EPOCH, None), 10.0)
    with pytest.raises(ModelError, match="needs an epoch") as error:
        direction_table("sun", Geometry(None, CircularOrbit(500e3)), 10.0)
    assert error.value.field == "epoch"
    with pytest.raises(ModelError, match="needs an orbit") as error:
        direction_table("velocity", Geometry(EPOCH, None), 10.0)
    assert error.value.field == "orbit"
    with pytest.raises(ModelError, match="DE421") as error:
        direction_table("moon", Geometry(datetime.datetime(2199, 12, 31, 23), None), 7200.0)
    assert error.value.field == "epoch"
    with pytest.raises(ModelError) as error:
        direction_table("earth", geometry_of(ORBITS["equatorial 500 km"]), -1.0)
    assert error.value.field == "duration"


def test_a_table_spans_the_run_at_the_kinds_step():
    geometry = geometry_of(ORBITS["sun-synchronous 500 km"])
    for name, kind in DIRECTIONS.items():
        times, directions, growth = direction_table(name, geometry, 7200.0)
        step = kind.step_s(geometry)
        assert step is not None and times[0] == 0.0 and times[-1] == 7200.0
        assert np.all(np.diff(times) <= step * (1 + 1e-12)) and len(times) == int(np.ceil(7200.0 / step)) + 1
        assert directions.shape == (len(times), 3) and growth.shape == (len(times),)
        np.testing.assert_allclose(np.linalg.norm(directions, axis=1), 1.0, atol=1e-15)
        assert direction_table(name, geometry, 0.0)[0].tolist() == [0.0]


FRACTIONS = (0.5, (3.0 - np.sqrt(3.0)) / 6.0, 0.1, 0.9)
"""Where between rows the interpolated table is checked: the middle, where a uniform turn's cubic
error peaks, and near the rows."""


@pytest.mark.parametrize("orbit", ORBITS)
@pytest.mark.parametrize("kind", ["sun", "moon", "earth", "earth_limb", "velocity"])
def test_a_table_interpolated_linearly_is_within_1e_4_deg_between_rows(kind, orbit):
    elements = ORBITS[orbit]
    epoch = datetime.datetime(2024, 4, 8, 18)   # near a perigee of the Moon (and the eclipse): fast Moon
    times, directions, growth = direction_table(kind, geometry_of(elements, epoch), 7200.0)
    constraint = PointingConstraint(kind, np.array([1.0, 0.0, 0.0]), True, 0.5, times=times, directions=directions,
                                    growth=growth)
    h = np.diff(times)
    between = np.concatenate([times[:-1] + f * h for f in FRACTIONS])
    direction, limit = exact(kind, elements, epoch, between)
    error = angle_deg(constraint.direction(between), direction)
    assert error.max() < 1e-4, f"{kind}, {orbit}: {error.max():.2e} deg with {len(times)} rows"
    np.testing.assert_allclose(constraint.limit(between), 0.5 + limit, rtol=0, atol=1e-12)
    assert error.max() > 1e-7  # the tolerance binds: the step is not far finer than needed


def test_the_step_is_not_far_finer_than_the_tolerance_needs():
    # doubling the step must break the 1e-4 deg bound somewhere for the orbit-bound kinds
    elements = ORBITS["sun-synchronous 500 km"]
    geometry = geometry_of(elements)
    for name in ("earth", "moon"):
        step = DIRECTIONS[name].step_s(geometry)
        assert step is not None
        times = np.arange(0.0, 7200.0, 3.0 * step)
        table, _ = exact(name, elements, EPOCH, times)
        constraint = PointingConstraint(name, np.array([1.0, 0.0, 0.0]), True, 0.5, times=times, directions=table)
        between = np.concatenate([times[:-1] + f * 3.0 * step for f in FRACTIONS])
        assert angle_deg(constraint.direction(between), exact(name, elements, EPOCH, between)[0]).max() \
            > np.degrees(INTERPOLATION_TOLERANCE)


def test_tabulating_a_two_hour_run_takes_well_under_a_tenth_of_a_second():
    geometry = geometry_of(ORBITS["sun-synchronous 500 km"])
    for name in DIRECTIONS:
        direction_table(name, geometry, 7200.0)  # loads the ephemeris once
    worst = {}
    for name in DIRECTIONS:
        durations = []
        for _ in range(5):
            start = time.perf_counter()
            direction_table(name, geometry, 7200.0)
            durations.append(time.perf_counter() - start)
        worst[name] = min(durations)
    print("\nbest of 5, 2-hour run, 500 km: " + ", ".join(f"{n} {1e3 * s:.1f} ms" for n, s in worst.items()))
    assert max(worst.values()) < 0.05
