"""Attitudes in mission terms, the geometry (``ocp.geometry.targets``) and ``ocp.quat.from_euler``.

Oracles: SciPy's ``Rotation`` (Euler sequences, axis-angle, the two-vector alignment with an exact
primary), hand-worked WGS-84 values and ERFA's own geodetic conversion, and an Earth orientation
written by hand from the IAU 1976 precession (Lieske 1977) and the IAU 1982 sidereal time; the LVLH
and RTN axes are checked against their definitions from the orbit's position and velocity.
"""
from __future__ import annotations

import datetime

import erfa
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from ocp import CircularOrbit, quat
from ocp.errors import ModelError
from ocp.geometry.directions import Geometry
from ocp.geometry.targets import (
    ATTITUDE_FRAMES,
    MIN_SEPARATION,
    WGS84_A,
    geodetic_to_ecef,
    ground_point,
    itrs_to_gcrf,
    two_vector_attitude,
)

SEQUENCES = ["321", "123", "132", "213", "231", "312", "313", "121", "131", "212", "232", "323"]
ARCSEC = np.deg2rad(1.0 / 3600.0)


def angle(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.arctan2(np.linalg.norm(np.cross(a, b)), a @ b))


def same_attitude(q, p, tolerance=1e-12):
    assert quat.error_angle(q, p) < tolerance, (q, p)


# --- Euler angles and axis-angle against SciPy ------------------------------------------------------

@pytest.mark.parametrize("sequence", SEQUENCES)
def test_from_euler_matches_scipy_intrinsic_rotations(sequence):
    rng = np.random.default_rng(int(sequence))
    angles = rng.uniform(-np.pi, np.pi, size=(20, 3))
    letters = "".join("XYZ"[int(axis) - 1] for axis in sequence)  # upper case: intrinsic (body) axes
    expected = Rotation.from_euler(letters, angles).as_quat(scalar_first=True)
    q = quat.from_euler(angles, sequence)
    assert np.all(q[:, 0] >= 0.0)
    for mine, theirs in zip(q, expected):
        same_attitude(mine, theirs)
    np.testing.assert_allclose(quat.rotation_matrix(q), Rotation.from_euler(letters, angles).as_matrix(), atol=1e-14)


def test_from_euler_letters_and_inverse_of_to_euler():
    angles = np.array([0.3, -0.4, 1.2])
    same_attitude(quat.from_euler(angles, "zyx"), quat.from_euler(angles, "321"))
    np.testing.assert_allclose(quat.to_euler(quat.from_euler(angles, "321"), "321"), angles, atol=1e-13)
    with pytest.raises(ValueError, match="sequence"):
        quat.from_euler(angles, "331")
    with pytest.raises(ValueError, match="3 components"):
        quat.from_euler([0.1, 0.2], "321")


def test_axis_angle_conversion_matches_scipy_rotation_vector():
    from scenarios.schema.targets import axis_angle_quaternion
    rng = np.random.default_rng(7)
    for _ in range(20):
        axis, angle_deg = rng.normal(size=3) * 5.0, rng.uniform(-360.0, 360.0)
        expected = Rotation.from_rotvec(axis / np.linalg.norm(axis) * np.deg2rad(angle_deg)).as_quat(scalar_first=True)
        same_attitude(axis_angle_quaternion(axis, angle_deg), expected)


# --- the two-vector attitude ------------------------------------------------------------------------

def test_two_vector_attitude_points_the_boresight_and_puts_the_secondary_in_the_plane():
    rng = np.random.default_rng(3)
    for _ in range(200):
        b, t, s, d = (rng.normal(size=3) * rng.uniform(0.1, 10.0) for _ in range(4))
        q = two_vector_attitude(b, t, s, d)
        assert abs(np.linalg.norm(q) - 1.0) < 1e-14 and q[0] >= 0.0
        assert angle(quat.rotate(q, b), t) < 1e-9
        s_inertial = quat.rotate(q, s / np.linalg.norm(s))
        t_unit, d_unit = t / np.linalg.norm(t), d / np.linalg.norm(d)
        normal = np.cross(t_unit, d_unit) / np.linalg.norm(np.cross(t_unit, d_unit))
        assert abs(s_inertial @ normal) < 1e-12  # in the plane of the target and the direction
        across = d_unit - (d_unit @ t_unit) * t_unit
        assert s_inertial @ across > 0.0  # on the direction's side of the target
        # SciPy's alignment with an exact primary (infinite weight) is the same attitude
        oracle, _ = Rotation.align_vectors([t, d], [b, s], weights=[np.inf, 1.0])
        same_attitude(q, oracle.as_quat(scalar_first=True), 1e-9)


def test_two_vector_attitude_with_perpendicular_pairs_puts_each_axis_on_its_direction():
    q = two_vector_attitude([0, 0, 1], [1, 0, 0], [1, 0, 0], [0, 1, 0])
    # columns: body x -> inertial y, body y = z × x -> x × y = z, body z -> inertial x
    np.testing.assert_allclose(quat.rotation_matrix(q), [[0, 0, 1], [1, 0, 0], [0, 1, 0]], atol=1e-15)
    q = two_vector_attitude([0, 0, 1], [1, 0, 0], [1, 0, 0], [0, -1, 0])
    np.testing.assert_allclose(quat.rotate(q, [1, 0, 0]), [0, -1, 0], atol=1e-15)


@pytest.mark.parametrize("offset_deg, field", [(0.0, "secondary_body"), (180.0, "secondary_body"),
                                               (0.05, "secondary_body"), (0.0, "secondary_direction"),
                                               (179.96, "secondary_direction")])
def test_two_vector_attitude_refuses_an_undetermined_roll(offset_deg, field):
    near = [np.cos(np.deg2rad(offset_deg)), np.sin(np.deg2rad(offset_deg)), 0.0]
    arguments = ([1, 0, 0], [0, 0, 1], near, [0, 1, 0]) if field == "secondary_body" else \
        ([1, 0, 0], [1, 0, 0], [0, 1, 0], near)
    with pytest.raises(ModelError) as error:
        two_vector_attitude(*arguments)
    assert error.value.field == field and "undetermined" in error.value.message


def test_two_vector_attitude_accepts_just_above_the_separation():
    offset = MIN_SEPARATION * 1.01
    q = two_vector_attitude([1, 0, 0], [0, 0, 1], [np.cos(offset), np.sin(offset), 0], [0, 1, 0])
    assert angle(quat.rotate(q, [1, 0, 0]), [0, 0, 1]) < 1e-9
    with pytest.raises(ModelError) as error:
        two_vector_attitude([0, 0, 0], [0, 0, 1], [0, 1, 0], [0, 1, 0])
    assert error.value.field == "primary_body"


# --- the orbit's frames -----------------------------------------------------------------------------

def test_lvlh_and_rtn_axes_follow_their_definitions_from_position_and_velocity():
    orbit = CircularOrbit(600e3, inclination=np.deg2rad(51.6), raan=np.deg2rad(-40.0), arg_latitude=1.1)
    geometry = Geometry(None, orbit)
    for t in (0.0, 1234.5):
        r, v = geometry.position(t)[0], geometry.velocity(t)[0]
        normal = np.cross(r, v) / np.linalg.norm(np.cross(r, v))
        lvlh = ATTITUDE_FRAMES["lvlh"].matrix(geometry, t)
        np.testing.assert_allclose(lvlh[:, 2], -r / np.linalg.norm(r), atol=1e-15)  # z nadir
        np.testing.assert_allclose(lvlh[:, 1], -normal, atol=1e-15)  # y: the negative orbit normal
        np.testing.assert_allclose(lvlh[:, 0], np.cross(lvlh[:, 1], lvlh[:, 2]), atol=1e-15)  # x completes
        np.testing.assert_allclose(lvlh[:, 0], v / np.linalg.norm(v), atol=1e-12)  # along the velocity (circular)
        rtn = ATTITUDE_FRAMES["rtn"].matrix(geometry, t)
        np.testing.assert_allclose(rtn[:, 0], r / np.linalg.norm(r), atol=1e-15)
        np.testing.assert_allclose(rtn[:, 2], normal, atol=1e-15)
        np.testing.assert_allclose(rtn[:, 1], np.cross(rtn[:, 2], rtn[:, 0]), atol=1e-15)
        for matrix in (lvlh, rtn):
            np.testing.assert_allclose(matrix.T @ matrix, np.eye(3), atol=1e-14)
            assert np.linalg.det(matrix) == pytest.approx(1.0, abs=1e-14)
    np.testing.assert_array_equal(ATTITUDE_FRAMES["inertial"].matrix(geometry, 5.0), np.eye(3))
    with pytest.raises(ModelError):
        ATTITUDE_FRAMES["lvlh"].matrix(Geometry(None, None), 0.0)


# --- ground points ----------------------------------------------------------------------------------

def test_geodetic_to_ecef_hand_worked_wgs84_values():
    # 45 deg N on the prime meridian at sea level: N = a / sqrt(1 - e² sin² 45°) with e² = f (2 - f)
    np.testing.assert_allclose(geodetic_to_ecef(np.deg2rad(45.0), 0.0, 0.0), [4517590.87885, 0.0, 4487348.40887],
                               atol=1e-3)
    # the pole: the semi-minor axis b = a (1 - f) = 6356752.3142 m, plus the height
    np.testing.assert_allclose(geodetic_to_ecef(np.pi / 2, 1.0, 100.0), [0.0, 0.0, 6356852.3142], atol=1e-3)
    # on the equator at 90 deg E: a + h along y
    np.testing.assert_allclose(geodetic_to_ecef(0.0, np.pi / 2, 1000.0), [0.0, WGS84_A + 1000.0, 0.0], atol=1e-6)


def test_geodetic_to_ecef_matches_erfa():
    rng = np.random.default_rng(11)
    for _ in range(50):
        lat, lon, height = rng.uniform(-np.pi / 2, np.pi / 2), rng.uniform(-np.pi, np.pi), rng.uniform(-400, 9000)
        np.testing.assert_allclose(geodetic_to_ecef(lat, lon, height), erfa.gd2gc(1, lon, lat, height), atol=1e-6)


def _hand_itrs_to_gcrf(utc: datetime.datetime, tt_minus_utc: float) -> np.ndarray:
    """IAU 1976 precession (Lieske 1977) and IAU 1982 mean sidereal time, UT1 = UTC, nutation
    neglected (under 20″): the Earth's axes in the GCRF (mean of J2000, frame bias 0.02″)."""
    days_ut1 = (utc - datetime.datetime(2000, 1, 1, 12)).total_seconds() / 86400.0
    centuries = (days_ut1 + tt_minus_utc / 86400.0) / 36525.0
    zeta = (2306.2181 * centuries + 0.30188 * centuries**2 + 0.017998 * centuries**3) * ARCSEC
    z = (2306.2181 * centuries + 1.09468 * centuries**2 + 0.018203 * centuries**3) * ARCSEC
    theta = (2004.3109 * centuries - 0.42665 * centuries**2 - 0.041833 * centuries**3) * ARCSEC
    gmst = np.deg2rad(280.46061837 + 360.98564736629 * days_ut1 + 0.000387933 * (days_ut1 / 36525.0) ** 2)

    def r2(a):  # frame rotations (passive), as the precession angles are defined
        return np.array([[np.cos(a), 0, -np.sin(a)], [0, 1, 0], [np.sin(a), 0, np.cos(a)]])

    def r3(a):
        return np.array([[np.cos(a), np.sin(a), 0], [-np.sin(a), np.cos(a), 0], [0, 0, 1]])

    precession = r3(-z) @ r2(theta) @ r3(-zeta)  # J2000 mean equator and equinox -> of date
    return precession.T @ r3(gmst).T  # Earth-fixed -> of date (sidereal rotation) -> J2000


@pytest.mark.parametrize("epoch", ["2000-01-01T11:58:55.816Z", "2027-03-20T12:00:00Z", "1985-07-04T03:15:00Z"])
def test_itrs_to_gcrf_against_hand_precession_and_sidereal_time(epoch):
    utc = datetime.datetime.fromisoformat(epoch.replace("Z", ""))
    tt_minus_utc = 32.184 + {2000: 32.0, 2027: 37.0, 1985: 22.0}[utc.year]
    matrix = itrs_to_gcrf(epoch, 0.0)[0]
    np.testing.assert_allclose(matrix @ matrix.T, np.eye(3), atol=1e-14)
    hand = _hand_itrs_to_gcrf(utc, tt_minus_utc)
    # nutation (up to 17″ in longitude, 9″ in obliquity) is what the hand model leaves out
    for axis in range(3):
        assert angle(matrix[:, axis], hand[:, axis]) < 25 * ARCSEC, (axis, angle(matrix[:, axis], hand[:, axis]))
    if utc.year == 2027:  # the precession since J2000 (0.15 deg of the pole) is in it
        assert angle(matrix[:, 2], [0, 0, 1]) > 400 * ARCSEC


def test_itrs_to_gcrf_turns_at_the_sidereal_rate_about_the_pole():
    start, later = itrs_to_gcrf("2027-03-20T12:00:00Z", [0.0, 3600.0])
    turn = later @ start.T  # GCRF -> GCRF over an hour
    rotvec = Rotation.from_matrix(turn).as_rotvec()
    # the Earth rotation angle's rate, 2π × 1.00273781191135448 per UT1 day (IERS Conventions 2010,
    # eq. 5.15): the rotation relative to the CIO, which does not precess in right ascension
    era_rate = 2.0 * np.pi * 1.00273781191135448 / 86400.0
    assert np.linalg.norm(rotvec) == pytest.approx(era_rate * 3600.0, rel=1e-9)
    assert angle(rotvec, start[:, 2]) < 1e-6


def test_ground_point_below_the_spacecraft_is_along_the_ellipsoid_normal():
    epoch = datetime.datetime(2027, 3, 20, 12)
    orbit = CircularOrbit(550e3, inclination=np.deg2rad(97.5), raan=np.deg2rad(30.0), arg_latitude=0.4)
    geometry = Geometry(epoch, orbit)
    for t in (0.0, 700.0):
        rotation = itrs_to_gcrf(epoch, t)[0]
        position_ecef = rotation.T @ geometry.position(t)[0]
        longitude, latitude, height = erfa.gc2gd(1, position_ecef)  # the sub-satellite point, by ERFA
        direction, elevation = ground_point(geometry, latitude, longitude, 0.0, t)
        up = rotation @ [np.cos(latitude) * np.cos(longitude), np.cos(latitude) * np.sin(longitude), np.sin(latitude)]
        assert angle(direction, -up) < 1e-9
        assert elevation == pytest.approx(np.pi / 2, abs=1e-7)
        assert height == pytest.approx(550e3, abs=25e3)
        # the antipode is below the horizon
        _, below = ground_point(geometry, -latitude, longitude + np.pi, 0.0, t)
        assert below < -np.deg2rad(60.0)
    with pytest.raises(ModelError):
        ground_point(Geometry(None, orbit), 0.0, 0.0, 0.0, 0.0)
