"""Requirement scores that the mutation check found unguarded, each against a hand computation.

* A declared free start carries momentum into the wheels: no external torque acts, so the total
  angular momentum ``I ω₀ + h₀`` (inertial) is conserved; along a reference at rest at its start
  the wheels hold all of it, with its sign (an initial wheel momentum along the spin adds to it).
* The final error is compared in degrees with its bound in degrees.
* The work limit's caveat is said where the final error's search reached it, and only there.
* An end point is checked when its window covers it: the target, held after ``T``, at the window's
  start when that opens after ``T``.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from ocp import quat
from ocp.geometry import pointing
from scenarios.requirements.scoring import endpoint_violations, score_closed_loop
from scenarios.requirements.spec import (
    Direction,
    FinalRequirement,
    PointingRequirement,
    Requirements,
)
from tests.test_requirements_actuators import SPINNING
from tests.test_requirements_scoring import X_AXIS, problem_with
from tests.test_user_limits import spin


@pytest.mark.parametrize("momentum0", [0.4, -0.4])
def test_a_free_start_adds_the_spins_momentum_to_the_wheels_own_with_its_sign(tmp_path, momentum0):
    """The eigenaxis slew of ``SPINNING`` (a 10 kg m² sphere spinning at 0.05 rad/s about x, a
    declared free start, at rest at both ends of a 90° turn about z) with the x wheel holding
    ``momentum0`` [N m s] at the start. The total momentum ``10 × 0.05 + momentum0`` along inertial
    x is conserved, all of it in the wheels while the body rests: on x at the start, on −y at the
    end (body axes after 90° about z), at most that on x and y between. The z wheel holds only the
    slew's own momentum, at most 10 × 1.875 × (π/2) / 200 = 0.147 N m s (the quintic's peak rate).
    The largest wheel momentum over the 1 N m s limit is then 0.9 for 0.4 (0.5 + 0.4), and the
    slew's 0.147 for −0.4 (0.5 − 0.4 = 0.1 is less): a spin counted against the wheels' own
    momentum, or left out, reads 0.147 or 0.4 for the first and 0.9 or 0.4 for the second."""
    from scenarios.runner import run
    from scenarios.schema.loader import load

    text = SPINNING.replace("SPIN", "0.05").replace(
        "omega: [0.05, 0, 0]}", f"omega: [0.05, 0, 0], wheel_momentum: [{momentum0}, 0, 0]}}")
    assert "wheel_momentum" in text
    path = tmp_path / "spinning.yaml"
    path.write_text(text)
    row = run(load(path)).rows[0]
    slew = 10.0 * 1.875 * (math.pi / 2.0) / 200.0
    expected = max(abs(10.0 * 0.05 + momentum0), slew)
    assert row.requirements["reference"]["actuators"]["wheels_momentum"] == pytest.approx(expected, rel=1e-6)


def _held_error(error_deg: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Samples at 0..14 s at rest: 10° off the target before 12 s, ``error_deg`` off it from then on
    (about body x). The rates are zero, so the attitude between samples from 12 s on is the held one:
    the worst error from 12 s is ``error_deg`` exactly."""
    qf = quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), 1.0)
    t = np.arange(15.0)
    errors = np.where(t < 12, 10.0, error_deg)
    q = np.stack([quat.product(qf, quat.from_axis_angle(np.array([1.0, 0.0, 0.0]), np.deg2rad(e))) for e in errors])
    return t, q, np.zeros((t.size, 3)), qf


@pytest.mark.parametrize("bound_deg, met", [(0.5, False), (0.7, True)])
def test_a_final_error_over_its_bound_in_degrees_breaks_it(bound_deg, met):
    """0.6° held from T + 2 s: over a 0.5° bound (broken, said in degrees), under 0.7° (met)."""
    t, q, omega, qf = _held_error(0.6)
    final = FinalRequirement(after_s=2.0, error_deg=bound_deg)
    score = score_closed_loop(Requirements(final=final), problem_with(Requirements(final=final), qf=qf),
                              t, q, omega, 10.0)["final"]
    assert score.values["worst_error_deg"] == pytest.approx(0.6, rel=1e-9)
    assert score.met == met
    assert ("error 0.6 deg at 12.0 s over 0.5 deg" in score.detail) == (not met), score.detail


def test_the_final_errors_search_says_it_reached_its_work_limit_and_only_then(monkeypatch):
    """A 50 rad/s spin about z sampled every 10 ms for 10 s (``tests.test_user_limits.spin``): the
    error to the identity sweeps 0 to 180° each turn, so every interval may cross a 0.1° bound and
    is cut at FINE_STEP: 0.5 rad a sample over 8.7e-4 rad, 5.7e5 points. Under the module's limit
    (2e6) it is searched in full and nothing is said; under a limit of 2e4 the score says that an
    error over the bound shorter than its step may have been missed."""
    t, q, omega = spin(10.0, 0.01)
    final = FinalRequirement(after_s=0.0, error_deg=0.1)
    problem = problem_with(Requirements(final=final), qf=quat.IDENTITY)
    full = score_closed_loop(Requirements(final=final), problem, t, q, omega, 0.0)["final"]
    assert not full.met and full.values["worst_error_deg"] == pytest.approx(180.0, abs=1e-3)
    assert "work limit" not in full.detail, full.detail
    monkeypatch.setattr(pointing, "MAX_SUB_GRID", 20_000)
    limited = score_closed_loop(Requirements(final=final), problem, t, q, omega, 0.0)["final"]
    assert not limited.met
    assert "the error's search between samples reached its work limit" in limited.detail, limited.detail
    assert "may be missed" in limited.detail


def test_a_target_held_until_a_later_window_is_checked_when_the_window_opens():
    """A keep-out behind the target (as in ``test_end_points_that_already_break_a_keep_out_are_named``)
    whose window opens at 20 s, after T = 10 s: the target is held then, so it breaks the cone at
    20 s; a window that closes before T leaves the target unchecked."""
    behind = [-1.0, 0.1, 0.0]
    late = PointingRequirement("late", X_AXIS, True, np.deg2rad(30.0), Direction(None, behind), (20.0, None))
    found = endpoint_violations(problem_with(Requirements((late,))))
    # named as what it is: the window's start, after the manoeuvre's duration T (not the slew's end)
    assert len(found) == 1 and ("the target attitude already breaks it at 20 s, when the window opens after "
                                "maneuver.duration = 10 s (margin") in found[0], found
    early = PointingRequirement("early", X_AXIS, True, np.deg2rad(30.0), Direction(None, behind), (1.0, 5.0))
    assert endpoint_violations(problem_with(Requirements((early,)))) == []


def test_a_counted_start_jump_puts_its_momentum_in_the_wheels_once():
    """A reference turning at a constant 0.1π rad/s about the principal axis z of diag(2, 3, 4) kg m²
    (``UniformTurn``: no free start declared) from a spacecraft at rest, wheels at rest: the jump at
    0 is counted (``rate_jump`` 0.1π rad/s), and the wheels take its momentum once. The total momentum
    is zero (body and wheels at rest), so after the jump the wheels hold ``−I ω = (0, 0, −0.4π)``
    N m s throughout (a spin about a principal axis asks no torque): a peak of 0.4π against 2 N m s."""
    from controllers import CONTROLLERS
    from ocp import ReactionWheels, Spacecraft
    from planners import ManeuverProblem
    from scenarios.requirements.scoring import reference_times, score_reference
    from scenarios.requirements.spec import ActuatorRequirement
    from tests.test_requirements_scoring import INERTIA, RATE, T, UniformTurn

    spacecraft = Spacecraft(INERTIA, wheels=ReactionWheels.from_body_axes(max_torque=1.0, max_momentum=2.0))
    reference = UniformTurn()
    problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), reference.sample(np.array([T])).q[0], T,
                              omegaf=np.array([0.0, 0.0, RATE]))
    requirements = Requirements(actuators=ActuatorRequirement(0.0))
    times = reference_times(T, T, 0.1)
    score = score_reference(requirements, problem, times, reference.sample(times),
                            CONTROLLERS["augmented_quaternion_feedback"](), reference)["actuators"]
    assert score.values["rate_jump"] == pytest.approx(RATE, rel=1e-12) and score.values["rate_jump_time_s"] == 0.0
    assert score.values["wheels_momentum"] == pytest.approx(4.0 * RATE / 2.0, rel=1e-9)


def test_a_reference_is_scored_at_the_closed_loops_spacing_to_the_end_of_the_run():
    """T = 10 s scored at 2001 points, then to the run's end at 12 s every 0.5 s: 10.5, 11, 11.5, 12
    (a tail of 2 s holds 4 steps of 0.5 s); 12.2 s takes 5 steps of 0.44 s (no step longer than the
    closed loop's)."""
    from scenarios.requirements.scoring import reference_times

    times = reference_times(10.0, 12.0, 0.5)
    assert times.size == 2001 + 4
    np.testing.assert_allclose(times[2000:], [10.0, 10.5, 11.0, 11.5, 12.0], rtol=0, atol=1e-12)
    longer = reference_times(10.0, 12.2, 0.5)
    np.testing.assert_allclose(longer[2000:], np.linspace(10.0, 12.2, 6), rtol=0, atol=1e-12)


def test_the_unstated_actuator_requirement_is_not_said_unhonoured():
    """Every scenario carries an actuator requirement, unstated at margin 0: eigenaxis (which honours
    the rate only) is not said to leave it unhonoured; one stated (margin 0.1) it is, beside the
    rate bound it honours."""
    from planners import PLANNERS
    from scenarios.requirements.scoring import unhonoured
    from scenarios.requirements.spec import ActuatorRequirement, RateRequirement

    eigenaxis = PLANNERS["eigenaxis"]()
    implicit = Requirements(actuators=ActuatorRequirement(0.0, stated=False), rate=RateRequirement(1.0))
    assert unhonoured(implicit, eigenaxis) == ""
    stated = Requirements(actuators=ActuatorRequirement(0.1), rate=RateRequirement(1.0))
    assert unhonoured(stated, eigenaxis) == "eigenaxis does not honour the actuators requirement (scored only)"
