"""Orbit elements at the library are finite real numbers: ``True`` is not 1 m or 1 rad, text and NaN
are refused, each a ModelError naming the element."""
import numpy as np
import pytest

from ocp.dynamics.orbits import CircularOrbit, KeplerianOrbit
from ocp.errors import ModelError


@pytest.mark.parametrize("field, value", [("altitude", True), ("altitude", "500e3"), ("altitude", np.nan),
                                          ("inclination", True), ("raan", np.inf), ("arg_latitude", "0"),
                                          ("mu", 1 + 0j)])
def test_a_circular_orbit_refuses_an_element_that_is_no_real_number(field, value):
    elements = {"altitude": 500e3, field: value}
    with pytest.raises(ModelError) as error:
        CircularOrbit(**elements)
    assert error.value.field == field and type(value).__name__ in str(error.value)


@pytest.mark.parametrize("field, value", [("semi_major_axis", True), ("eccentricity", np.nan), ("inclination", "1"),
                                          ("mean_anomaly", None)])
def test_a_keplerian_orbit_refuses_an_element_that_is_no_real_number(field, value):
    elements = {"semi_major_axis": 7000e3, field: value}
    with pytest.raises(ModelError) as error:
        KeplerianOrbit(**elements)
    assert error.value.field == field


def test_numpy_and_python_numbers_are_accepted():
    orbit = CircularOrbit(np.float64(500e3), inclination=np.deg2rad(51.6), raan=1)
    assert orbit.radius == pytest.approx(6378137.0 + 500e3)
    assert KeplerianOrbit(7000e3, np.float32(0.01), 1).eccentricity == pytest.approx(0.01)
