"""The slew table's grids against what they are by construction: the held-out angles are the table's
angles and the midpoints of each pair of neighbours (hand-worked), and the Fibonacci lattice's points at the
middle heights of n bands of equal area (Archimedes' hat-box theorem: equal heights are equal areas
on the sphere; González 2010, Math. Geosci. 42, 49), none at a pole, mirror-symmetric in z."""
import numpy as np
import pytest

from scenarios.slewtable.grid import GOLDEN_ANGLE, fibonacci_axes, held_out_angles


def test_held_out_angles_are_the_table_angles_and_their_midpoints():
    # the table's angles themselves (the largest, 180, most of all) are held-out angles: a held-out
    # axis there measures the fit between axes, which the midpoints alone never isolate
    assert held_out_angles([10.0, 30.0, 60.0, 90.0, 180.0]) == [10.0, 20.0, 30.0, 45.0, 60.0, 75.0, 90.0, 135.0, 180.0]
    assert held_out_angles([45.0, 90.0]) == [45.0, 67.5, 90.0]
    assert held_out_angles([90.0]) == [90.0]


@pytest.mark.parametrize("n", [1, 2, 7, 50])
def test_fibonacci_axes_are_the_middles_of_equal_area_bands(n):
    axes = fibonacci_axes(n)
    np.testing.assert_allclose(np.linalg.norm(axes, axis=1), 1.0, rtol=0, atol=1e-15)
    # band i spans z from 1 - 2 i / n to 1 - 2 (i + 1) / n; the point is at its middle height
    np.testing.assert_allclose(axes[:, 2], 1.0 - (2.0 * np.arange(n) + 1.0) / n, rtol=0, atol=1e-15)
    np.testing.assert_allclose(np.sort(axes[:, 2]), -np.sort(axes[:, 2])[::-1], rtol=0, atol=1e-15)
    assert np.all(np.abs(axes[:, 2]) < 1.0)  # no pole
    if n > 1:  # successive points turn by the golden angle about z
        turns = np.diff(np.unwrap(np.arctan2(axes[:, 1], axes[:, 0])))
        np.testing.assert_allclose(np.mod(turns, 2 * np.pi), GOLDEN_ANGLE, rtol=0, atol=1e-12)


def test_the_fit_along_a_table_axis_is_scipys_pchip_of_the_scaled_times():
    """On a table axis (one vertex of its triangle, weight 1) the fit is the PCHIP interpolant of
    that axis's t / sqrt(angle) over the angles, times sqrt(angle) (no generators: shape 1); the
    times curve in the angle, so the two end slopes of each Hermite segment differ."""
    from scipy.interpolate import PchipInterpolator

    from scenarios.slewtable.fit import SlewTimeFit

    angles = np.deg2rad([10.0, 30.0, 60.0, 90.0, 120.0, 150.0, 180.0])
    axes = fibonacci_axes(40)
    times = np.array([(3.0 + axis[0]) * np.sqrt(angles) * (1.0 + 0.3 * angles**2 + 0.1 * axis[2] * angles)
                      for axis in axes])
    fit = SlewTimeFit(angles, axes, times)
    between = np.deg2rad([12.0, 25.0, 47.0, 80.0, 111.0, 163.0, 177.0])
    for row in (0, 17, 39):
        expected = PchipInterpolator(angles, times[row] / np.sqrt(angles))(between) * np.sqrt(between)
        axis = fit.axes[row]
        scalar = [fit.axis_angle(*axis.tolist(), float(a)) for a in between]
        np.testing.assert_allclose(scalar, expected, rtol=1e-12)
        np.testing.assert_allclose(fit.many_axis_angle(np.tile(axis, (len(between), 1)), between), expected, rtol=1e-12)


def test_a_failed_wheel_gives_the_grid_no_torque_generator():
    """Documented: the grid's shape is the *working* actuators' torque generators. Four pyramid wheels
    of 0.02, 0.03, 0.04, 0.05 N m with the second failed, plus torquers of [0.001, 0.002, 0.003] N m:
    the generators are three wheel axes times their bounds and the torquer axes, by hand."""
    from scenarios.slewtable.spec import torque_generators
    pyramid = np.array([[1, 1, 1], [-1, 1, 1], [-1, -1, 1], [1, -1, 1]]) / np.sqrt(3.0)
    scenario = {"name": "failed", "spacecraft": {
        "inertia": [1.0, 2.0, 3.0],
        "wheels": {"axes": pyramid.tolist(), "max_torque": [0.02, 0.03, 0.04, 0.05], "max_momentum": 1.0,
                   "failed": [1]},
        "torquers": {"max_torque": [0.001, 0.002, 0.003]}},
        "maneuver": {"duration": 60.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                     "final": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]}},
        "planners": [], "controller": {"name": "none"}}
    inertia, generators = torque_generators(scenario)
    np.testing.assert_allclose(inertia, np.diag([1.0, 2.0, 3.0]))
    expected = [pyramid[0] * 0.02, pyramid[2] * 0.04, pyramid[3] * 0.05, [0.001, 0, 0], [0, 0.002, 0], [0, 0, 0.003]]
    np.testing.assert_allclose(generators, expected, rtol=1e-12, atol=1e-15)
