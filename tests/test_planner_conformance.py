"""Every registered planner against the planner contract (as scipy tests every METHODS entry).

For each entry of ``PLANNERS`` and each of its ``example_options``, every standard problem the
planner accepts (``problem_error`` is ``None``) is planned once and checked by every check of
:data:`planners.conformance.CHECKS`: boundary conditions (respecting ``free_boundary``),
``q̇ = ½ q ⊗ [0, ω]``, ``ω̇`` and the feed-forward torque against finite differences, vectorised =
point-wise, and torque-free continuation after T. The first accepted problem of each option set
runs in the default suite, the others with ``pytest -m slow``.
"""
from __future__ import annotations

from collections.abc import Callable
from functools import cache
from typing import Any

import numpy as np
import pytest

from ocp import metrics_from_reference, quat
from planners import (
    PLANNERS,
    ManeuverProblem,
    Reference,
    ReferenceSample,
    inverse_dynamics_torque,
)
from planners.conformance import CHECKS, check_reference, standard_problems
from planners.errors import ConformanceError

PROBLEMS = standard_problems()
VARIANTS = [(name, index) for name, cls in PLANNERS.items() for index in range(len(cls.example_options))]


def _variant_id(name: str, index: int) -> str:
    options = PLANNERS[name].example_options[index]
    return name + ("[" + ",".join(f"{k}={v}" for k, v in options.items()) + "]" if options else "")


def _accepted(name: str, index: int) -> list[str]:
    planner = PLANNERS[name](PLANNERS[name].example_options[index])
    return [key for key, problem in PROBLEMS.items() if planner.problem_error(problem) is None]


CASES = []
for _name, _index in VARIANTS:
    for _position, _key in enumerate(_accepted(_name, _index)):
        marks = [pytest.mark.slow] if _position > 0 else []
        CASES.append(pytest.param(_name, _index, _key, marks=marks, id=f"{_variant_id(_name, _index)}-{_key}"))


@cache
def planned(name: str, index: int, key: str) -> Reference:
    """Each (planner, options, problem) is planned once for all checks."""
    return PLANNERS[name](PLANNERS[name].example_options[index]).plan(PROBLEMS[key])


@pytest.mark.parametrize("name,index", VARIANTS, ids=[_variant_id(*v) for v in VARIANTS])
def test_every_option_set_accepts_a_standard_problem(name, index):
    assert _accepted(name, index), f"{_variant_id(name, index)} declines every standard problem"


@pytest.mark.parametrize("check", CHECKS)
@pytest.mark.parametrize("name,index,key", CASES)
def test_conformance(name, index, key, check):
    reference = planned(name, index, key)
    if key == _accepted(name, index)[0]:
        assert reference.ok, f"{reference.status}: {reference.message}"  # the problem of the default suite
    elif not reference.ok:
        pytest.skip(f"numerical failure, reported as a row: {reference.message}")
    # the planner with its options: the checks of its declarations (deterministic plans with them)
    CHECKS[check](PROBLEMS[key], reference, PLANNERS[name](PLANNERS[name].example_options[index]))


@pytest.mark.parametrize("name,index", VARIANTS, ids=[_variant_id(*v) for v in VARIANTS])
def test_a_non_finite_time_is_refused_not_answered_with_nan(name, index):
    # Before: sample(nan) returned NaN quantities silently and sample(inf) raised an IndexError
    # from the torque-free continuation's chunk table.
    reference = planned(name, index, _accepted(name, index)[0])
    for bad in (np.nan, np.inf, [0.0, np.nan], [0.5 * reference.duration, -np.inf]):
        with pytest.raises(ValueError, match="reference times must be finite"):
            reference.sample(bad)
    assert np.isfinite(reference.sample([0.0, 2.0 * reference.duration]).q).all()


def test_the_spin_extremal_declares_its_initial_rates_and_the_metrics_report_them():
    # Biggs & Horri: the body spins about roll at rest transversally; the extremal starts with
    # transverse rates of its own (free parameters of the method).
    problem = PROBLEMS["spinning"]
    reference = planned("spin_extremal", 0, "spinning")
    assert {"omega0", "omegaf"} <= reference.free_boundary
    start = reference.omega(0.0)
    mismatch = float(np.linalg.norm(start - problem.omega0))
    assert mismatch > 1e-3  # a real mismatch, not a rounding
    metrics = metrics_from_reference(reference, problem.qf, problem.omegaf, initial_omega=problem.omega0)
    assert metrics["initial_rate_error"] == pytest.approx(np.hypot(start[1], start[2]), rel=1e-12)


def test_the_spin_extremal_family_cannot_match_a_transversally_resting_body():
    # Matching ω(0) = [v, 0, 0] forces r = 0, and then q*(t) is the free spin E1(v t) whatever c and
    # β are: the family keeps no freedom to reach a target (closed form vs the spin about roll).
    from ocp.dynamics.spin_closed_form import extremal_quaternion

    t = np.linspace(0.0, 50.0, 11)
    for c, beta in ((0.3, 0.0), (-1.2, 2.0)):
        q = np.stack(extremal_quaternion(t, 0.2, 1e-14, c, beta), axis=-1)
        np.testing.assert_allclose(q, quat.from_axis_angle(np.array([1.0, 0.0, 0.0]), 0.2 * t), atol=1e-12)


# --- a deliberately broken planner must fail -------------------------------------------------------

class Mutated(Reference):
    """A registered planner's reference with one quantity changed."""

    def __init__(self, inner: Reference, change: Callable[[Any], Any]) -> None:
        super().__init__(inner.planner, inner.duration, inner.inertia, free_boundary=inner.free_boundary,
                         breakpoints=inner.breakpoints, enforced_times=inner.enforced_times)
        self.inner, self.change = inner, change

    def _evaluate(self, t):
        return self.change(self.inner._evaluate(t))


class HoldAfterEnd(Mutated):
    """The old continuation: q held at q(T) while ω = ω(T), torque ω × I ω."""

    def sample(self, t):
        times = np.atleast_1d(np.asarray(t, dtype=float))
        inside = self.inner.sample(np.minimum(times, self.duration))
        q, w, w_dot, u = (np.array(a) for a in inside)
        after = times > self.duration
        w_dot[after], u[after] = 0.0, np.cross(w[after], w[after] @ self.inertia.T)
        return type(inside)(q, w, w_dot, u) if np.ndim(t) else type(inside)(q[0], w[0], w_dot[0], u[0])


def _flip_torque(s):
    return s._replace(torque=-s.torque)


def _flip_acceleration(s):  # the shape polynomials' ω̇ sign flip, torque recomputed from it
    return s._replace(omega_dot=-s.omega_dot, torque=inverse_dynamics_torque(INERTIA, s.omega, -s.omega_dot))


INERTIA = PROBLEMS["spinning"].spacecraft.inertia


@pytest.mark.parametrize("name,index,key,mutation,failing", [
    ("shape_polynomial", 1, "spinning", _flip_torque, "dynamics"),
    ("shape_polynomial", 1, "spinning", _flip_acceleration, "dynamics"),
    ("spin_extremal", 0, "spinning", _flip_torque, "dynamics"),
    ("eigenaxis", 0, "rest_to_rest", lambda s: s._replace(omega=-s.omega), "kinematics"),
])
def test_a_mutated_reference_fails(name, index, key, mutation, failing):
    reference = Mutated(planned(name, index, key), mutation)
    with pytest.raises(ConformanceError):
        CHECKS[failing](PROBLEMS[key], reference)


def test_the_old_hold_after_the_end_fails():
    reference = HoldAfterEnd(planned("spin_extremal", 0, "spinning"), lambda s: s)
    with pytest.raises(ConformanceError, match="torque-free"):
        CHECKS["after_end"](PROBLEMS["spinning"], reference)


class IgnoresFinalRate(PLANNERS["eigenaxis"]):  # type: ignore[misc, valid-type]
    """A registered planner that plans for a final rate other than the problem's."""

    def _plan(self, problem: ManeuverProblem) -> Reference:
        axis = quat.to_rotation_vector(quat.error(problem.qf, problem.q0))
        skewed = ManeuverProblem(problem.spacecraft, problem.q0, problem.omega0, problem.qf, problem.duration,
                                 omegaf=0.01 * axis / np.linalg.norm(axis))
        return super()._plan(skewed)


def test_a_planner_that_misses_the_final_rate_fails():
    problem = PROBLEMS["rest_to_rest"]
    reference = IgnoresFinalRate({"profile": "smooth"}).plan(problem)
    for check in ("kinematics", "dynamics", "vectorised", "after_end"):
        CHECKS[check](problem, reference)  # a consistent motion ...
    with pytest.raises(ConformanceError, match=r"ω\(T"):
        check_reference(problem, reference)  # ... to the wrong final rate


class PinnedEnds(Reference):
    """A constant body rate ``c`` on ``(0, T)`` (exact kinematics and inverse dynamics inside),
    sampled as ``ω0 = 0`` at the instants 0 and T (``pinned``): the co-state attitude
    acquisition's old rest-to-rest reference, whose steps between 0 and ``c`` hid at 0⁺ and T⁻."""

    RATE = np.array([6e-4, -8e-4, 5e-4])  # rad/s

    def __init__(self, duration: float, pinned: tuple[bool, bool], breakpoints=()) -> None:
        super().__init__("pinned_ends", duration, PROBLEMS["non_principal"].spacecraft.inertia,
                         breakpoints=breakpoints)
        self.pinned = pinned

    def _evaluate(self, t):
        q = quat.product(quat.IDENTITY, quat.from_rotation_vector(np.outer(t, self.RATE)))
        omega = np.tile(self.RATE, (t.size, 1))
        rest = (self.pinned[0] & (t <= 0.0)) | (self.pinned[1] & (t >= self.duration))
        omega[rest] = 0.0
        omega_dot = np.zeros_like(omega)
        return ReferenceSample(q, omega, omega_dot, inverse_dynamics_torque(self.inertia, omega, omega_dot))


def _pinned_problem(duration: float) -> ManeuverProblem:
    qf = quat.from_rotation_vector(duration * PinnedEnds.RATE)
    return ManeuverProblem(PROBLEMS["non_principal"].spacecraft, quat.IDENTITY, np.zeros(3), qf, duration,
                           omegaf=np.zeros(3))


@pytest.mark.parametrize("pinned, breakpoints, where", [
    ((True, True), (), "t = 0"),
    ((False, True), (0.0,), "t = T"),  # the start declared, the stop hidden at T⁻
])
def test_a_rate_step_hidden_at_an_end_fails_only_the_ends_check(pinned, breakpoints, where):
    T = 500.0
    problem, reference = _pinned_problem(T), PinnedEnds(T, pinned, breakpoints)
    step = float(np.linalg.norm(PinnedEnds.RATE))
    assert np.linalg.norm(reference.omega(1e-9 * T) - reference.omega(0.0)) == pytest.approx(step if pinned[0] else 0.0)
    for name, check in CHECKS.items():
        if name != "ends":
            check(problem, reference)  # the motion is consistent inside and meets every boundary value ...
    with pytest.raises(ConformanceError, match=f"ω steps at {where}"):
        CHECKS["ends"](problem, reference)  # ... but the rate steps by |c| = 1.1e-3 rad/s at an end
    with pytest.raises(ConformanceError, match="steps"):
        check_reference(problem, reference)


def test_declared_steps_at_both_ends_pass_and_are_impulses_the_scoring_counts():
    # The honest form: breakpoints at 0 and T, ω(0) the right limit, ω(T) = ωf after the stop.
    from scenarios.requirements.scoring import rate_jumps

    T = 500.0
    problem, reference = _pinned_problem(T), PinnedEnds(T, (False, True), (0.0, T))
    check_reference(problem, reference)
    t = np.concatenate([np.linspace(0.0, T, 2001), [T + 1.0]])  # the scoring samples past T (closed-loop tail)
    jumps = rate_jumps(t, reference.omega(t), problem.omega0, reference)
    assert [time for time, _, _ in jumps] == [0.0, T]
    np.testing.assert_allclose(jumps[0][2], PinnedEnds.RATE, atol=1e-15)
    np.testing.assert_allclose(jumps[1][2], -PinnedEnds.RATE, atol=1e-15)
