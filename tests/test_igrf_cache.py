"""The IGRF interpolant is built once per field value (ocp.dynamics.igrf): equal fields share it,
its values are those of a table built afresh, different fields get their own, and the cache is
bounded."""
import casadi as ca
import numpy as np
import pytest

pytest.importorskip("ppigrf")

from ocp import CircularOrbit, IGRFField
from ocp.dynamics import igrf

ORBIT = CircularOrbit(600e3, np.deg2rad(97.8), 0.3, 0.2)


def fresh(field):
    """The interpolant built here from the field's nodes and exact values, bypassing any cache."""
    nodes = field.nodes
    return ca.interpolant("fresh", "bspline", [nodes], field.exact(nodes).ravel())


def values(function, times):
    return np.hstack([np.asarray(function(t)) for t in times])


def test_equal_fields_share_one_interpolant_equal_to_a_fresh_build(rng):
    first = IGRFField(ORBIT, span=900.0, epoch="2024-03-01")
    second = IGRFField(CircularOrbit(600e3, np.deg2rad(97.8), 0.3, 0.2), span=900.0, epoch="2024-03-01")
    assert first is not second and first == second
    assert first.interpolant is second.interpolant
    times = rng.uniform(0.0, first.valid_until, 25)
    np.testing.assert_array_equal(values(first.interpolant, times), values(fresh(second), times))


@pytest.mark.parametrize("change", [dict(epoch="2021-06-01"), dict(step=20.0), dict(greenwich_angle=1.0),
                                    dict(earth_rate=7.3e-5), dict(span=1200.0),
                                    dict(orbit=CircularOrbit(600e3, np.deg2rad(97.8), 0.3, 0.2 + 1e-12))])
def test_a_field_differing_in_any_input_gets_its_own_table(change, rng):
    base = dict(orbit=ORBIT, span=900.0, epoch="2024-03-01")
    first, other = IGRFField(**base), IGRFField(**{**base, **change})
    assert other.interpolant is not first.interpolant
    times = rng.uniform(0.0, min(first.valid_until, other.valid_until), 25)
    np.testing.assert_array_equal(values(other.interpolant, times), values(fresh(other), times))


def test_the_cache_is_bounded():
    cache = igrf._INTERPOLANTS
    first = IGRFField(ORBIT, span=120.0, greenwich_angle=0.0)
    built = first.interpolant
    for k in range(1, cache.size + 3):
        _ = IGRFField(ORBIT, span=120.0, greenwich_angle=0.01 * k).interpolant
    assert len(cache._entries) == cache.size
    builds = cache.builds
    again = IGRFField(ORBIT, span=120.0, greenwich_angle=0.0).interpolant
    assert cache.builds == builds + 1 and again is not built  # dropped, then built again
