"""The spin extremal's parameters by Newton steps (``NewtonFirst``) against IPOPT and the closed form.

IPOPT (``build_solver``) is the oracle for the point: from every start the Newton path takes, it must
end where IPOPT ends from the same start, within IPOPT's own tolerance; and the closed form
(``extremal_quaternion``, evaluated here in NumPy) at the parameters found must reach the target.
"""
import numpy as np
import pytest

from ocp import quat
from ocp.dynamics.spin_closed_form import extremal_quaternion
from planners import PLANNERS
from planners.spin_extremal import (
    NewtonFirst,
    SpinExtremalPlanner,
    build_derivatives,
    build_solver,
)
from tests.benchmarks.test_bench_min_time import bilimoria_wie


class NoIpopt:
    """Stands for IPOPT where the Newton path must be taken: fails the test when called."""

    def __call__(self, **arguments):
        raise AssertionError("the start was handed to IPOPT")


def reached(params, v, T, target):
    """``min(‖q(T) − q_f‖², ‖q(T) + q_f‖²)`` of the closed form, in NumPy."""
    q_end = np.array(extremal_quaternion(T, v, *params))
    return min(np.sum((q_end - target) ** 2), np.sum((q_end + target) ** 2))


@pytest.fixture(scope="module")
def functions():
    return build_derivatives(), build_solver()


def test_bilimoria_wie_start_is_solved_by_newton_steps_where_ipopt_perturbs_a_singular_hessian(functions):
    derivatives, ipopt = functions
    problem = bilimoria_wie()
    target = quat.product(quat.conjugate(problem.q0), problem.qf)
    v, T, moments = 0.0, problem.duration, np.ones(3)
    parameters = np.r_[v, T, moments, target, 0.0]
    newton = NewtonFirst(derivatives, NoIpopt())
    for seed in SpinExtremalPlanner({})._seeds(v, T, moments, target):
        found = newton(x0=seed, p=parameters)
        expected = ipopt(x0=seed, p=parameters)
        x, x_ipopt = found["x"].full().ravel(), expected["x"].full().ravel()
        assert np.max(np.abs(x - x_ipopt) / (1.0 + np.abs(x_ipopt))) < 1e-12
        # IPOPT's own record: 4 iterations, each with its inertia correction 1e-4, then a third of the last
        assert newton.stats() == {"return_status": "Solve_Succeeded", "success": True,
                                  "iter_count": ipopt.stats()["iter_count"]}
        assert reached(x, v, T, target) < 1e-28


def test_newton_steps_end_where_ipopt_ends_from_every_start(functions, rng):
    derivatives, ipopt = functions
    newton = NewtonFirst(derivatives, ipopt)
    taken = 0
    for case in range(60):
        moments, T = rng.uniform(1.0, 20.0, 3), rng.uniform(5.0, 300.0)
        v = 0.0 if case % 2 else rng.uniform(-0.5, 0.5)
        weight = 0.0 if case % 3 else 0.1
        target = quat.normalize(rng.normal(size=4))
        parameters = np.r_[v, T, moments, target, weight]
        for seed in SpinExtremalPlanner({"weight": weight})._seeds(v, T, moments, target):
            found = newton(x0=seed, p=parameters)
            if "iter_count" in newton.stats() and len(newton.stats()) == 3:  # the Newton path
                taken += 1
                expected = ipopt(x0=seed, p=parameters)
                x, x_ipopt = found["x"].full().ravel(), expected["x"].full().ravel()
                assert np.max(np.abs(x - x_ipopt) / (1.0 + np.abs(x_ipopt))) < 1e-10, (case, x, x_ipopt)
                assert float(found["f"]) == pytest.approx(float(expected["f"]), abs=1e-12, rel=1e-9)
                if weight == 0.0 and float(expected["f"]) < 1e-20:  # IPOPT reached the target: so must we
                    assert reached(x, v, T, target) < 1e-20
    assert taken > 100  # most starts take the Newton path


def test_planner_reaches_the_paper_target_through_the_newton_path():
    from ocp import Spacecraft
    from planners import ManeuverProblem
    from tests.test_spin_extremal import MOMENTS

    problem = ManeuverProblem(Spacecraft(MOMENTS), [1, 0, 0, 0], [0.2, 0, 0], [0, 0, 1, 0], 200.0)
    reference = PLANNERS["spin_extremal"]({}).plan(problem)
    assert reference.ok, reference.message
    params = (reference.stats["r"], reference.stats["c"], reference.stats["beta"])
    assert reached(params, 0.2, 200.0, np.array([0.0, 0.0, 1.0, 0.0])) < 1e-20
