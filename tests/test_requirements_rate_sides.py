"""The rate requirement on a reference whose peak rate is at a breakpoint between two samples.

A bang-bang slew about the principal z axis that accelerates at ``α₁`` up to ``b`` and decelerates
at ``α₂`` to rest at ``T``: ``ω_z(t) = α₁ t`` before ``b``, ``α₂ (T − t)`` after, its peak
``α₁ b`` at the switch ``b`` only (closed form). With ``b`` between two of the reference's samples
(:func:`~scenarios.requirements.scoring.reference_times`), the samples alone see at most
``α₁ b − α₂ (s − b)`` (``s`` the sample after ``b``); a bound between the two is broken, and only
the reference's sides of its breakpoint (:meth:`planners.Reference.breakpoint_sides`) show it.
The step stop of a rate that is the control (natural motion's) too: ``ω_z`` rises to the
breakpoint and drops to rest there.
"""
from __future__ import annotations

import numpy as np
import pytest

from ocp import Environment, Spacecraft, quat
from planners import ManeuverProblem, Reference, ReferenceSample
from scenarios.requirements.scoring import reference_times, score_reference
from scenarios.requirements.spec import RateRequirement, Requirements

T = 10.0
STEP = T / 2000  # the reference's sample spacing on [0, T]
SWITCH = (600 + 0.4) * STEP  # between the samples at 3.000 s and 3.005 s
ACCELERATION = 0.02  # rad/s^2
PEAK = ACCELERATION * SWITCH  # rad/s, at the switch only
INERTIA = np.diag([2.0, 3.0, 4.0])


class BangBang(Reference):
    """θ(t) about z: ``α₁ t²/2`` up to the switch, then decelerating at ``α₂`` to rest at T; or
    (``step``) turning on at ``α₁`` up to the switch and at rest, its attitude held, after it."""

    def __init__(self, step: bool = False) -> None:
        super().__init__("hand", T, INERTIA, breakpoints=[SWITCH])
        self.step = step

    def _evaluate(self, t: np.ndarray) -> ReferenceSample:
        before = t <= SWITCH
        deceleration = 0.0 if self.step else PEAK / (T - SWITCH)
        after = np.maximum(t - SWITCH, 0.0)
        rate = np.where(before, ACCELERATION * t, 0.0 if self.step else PEAK - deceleration * after)
        angle = np.where(before, 0.5 * ACCELERATION * t ** 2,
                         0.5 * ACCELERATION * SWITCH ** 2 + (0.0 if self.step else PEAK * after
                                                               - 0.5 * deceleration * after ** 2))
        acceleration = np.where(before, ACCELERATION, -deceleration)
        zeros = np.zeros_like(t)
        q = quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), angle[:, None]) if t.size else np.zeros((0, 4))
        omega = np.stack([zeros, zeros, rate], axis=-1)
        omega_dot = np.stack([zeros, zeros, acceleration], axis=-1)
        return ReferenceSample(np.reshape(q, (t.size, 4)), omega, omega_dot, omega_dot @ INERTIA)


def rate_score(reference: Reference, bound: float):
    requirements = Requirements(rate=RateRequirement(bound))
    problem = ManeuverProblem(Spacecraft(INERTIA), quat.IDENTITY, np.zeros(3), None, T, environment=Environment())
    times = reference_times(T, T, 0.1)
    assert not np.any(np.isclose(times, SWITCH, rtol=0.0, atol=0.1 * STEP))  # truly between two samples
    return score_reference(requirements, problem, times, reference.sample(times), None, reference)["rate"], times


@pytest.mark.parametrize("step", [False, True], ids=["bang_bang", "step_stop"])
def test_a_peak_rate_at_a_breakpoint_between_samples_breaks_the_bound(step):
    reference = BangBang(step)
    _, times = rate_score(reference, 1.0)
    sampled = float(np.max(np.linalg.norm(reference.sample(times).omega, axis=1)))
    assert sampled < PEAK * (1 - 1e-4)  # the samples alone fall short of the peak by a bound's breadth
    bound = 0.5 * (sampled + PEAK)  # above every sample, below the peak
    score, _ = rate_score(reference, bound)
    assert not score.met
    assert score.values["peak_rate"] == pytest.approx(PEAK, rel=1e-7)
    assert score.values["peak_time_s"] == pytest.approx(SWITCH, abs=1e-6)
    assert score.values["ratio"] == pytest.approx(PEAK / bound, rel=1e-7)
    assert "peak rate" in score.detail
    # a bound just above the peak is met
    assert rate_score(reference, PEAK * (1 + 1e-6))[0].met
