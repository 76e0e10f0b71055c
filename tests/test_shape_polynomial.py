"""Shape-based quaternion polynomials: exact boundary conditions, unit norm, rate limit."""
import numpy as np
import pytest

from ocp import Spacecraft, Torquers, quat
from planners import PLANNERS, ManeuverProblem

# Vepa, section 8, final example: qd = [0.2068, 0.2518, 0.1682, 0.9303] scalar last, |ω| <= 0.001 rad/s.
VEPA_TARGET = quat.from_scalar_last([0.2068, 0.2518, 0.1682, 0.9303])


def attitude_problem(rng=None, omega0=(0, 0, 0), omegaf=(0, 0, 0)):
    spacecraft = Spacecraft([2.27293, 3.27331, 1.5], torquers=Torquers(1.0))
    q0 = quat.IDENTITY if rng is None else quat.random_unit(rng)
    qf = VEPA_TARGET if rng is None else quat.random_unit(rng)
    return ManeuverProblem(spacecraft, q0, np.array(omega0, float), qf, 1000.0, omegaf=np.array(omegaf, float),
                           max_rate=0.001)


@pytest.mark.parametrize("terms", range(1, 7))
def test_boundary_conditions_are_exact_and_the_quaternion_stays_unit(terms, rng):
    problem = attitude_problem(rng, omega0=rng.normal(0, 2e-4, 3), omegaf=rng.normal(0, 2e-4, 3))
    reference = PLANNERS["shape_polynomial"]({"terms": terms, "duration": "scenario"}).plan(problem)
    assert reference.status == "ok", reference.message
    start, end = reference.sample(0.0), reference.sample(reference.duration)
    assert quat.error_angle(start.q, problem.q0) < 1e-12 and quat.error_angle(end.q, problem.qf) < 1e-12
    np.testing.assert_allclose(start.omega, problem.omega0, atol=1e-12)
    np.testing.assert_allclose(end.omega, problem.omegaf, atol=1e-12)
    q = reference.q(np.linspace(0, reference.duration, 3001))
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-14)


def test_rate_limited_duration_respects_the_limit_and_the_physical_bound():
    problem = attitude_problem()
    reference = PLANNERS["shape_polynomial"]().plan(problem)
    assert reference.status == "ok", reference.message
    t = np.linspace(0, reference.duration, 4001)
    assert np.max(np.linalg.norm(reference.omega(t), axis=1)) == pytest.approx(0.001, rel=1e-6)
    # No rest-to-rest path with |ω| <= ω_max turns θ in less than θ/ω_max (751 s here); the paper's
    # 733.3 s for N = 1 is below that bound (see scenarios/REPRODUCTION.md).
    assert reference.duration > quat.error_angle(VEPA_TARGET, quat.IDENTITY) / 0.001
    assert 1 <= reference.stats["terms"] <= 6
