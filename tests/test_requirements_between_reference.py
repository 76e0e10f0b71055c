"""Scores between the samples: a reference's pointing scored as a closed loop's is, a window's edges
evaluated where they fall, and the final error angle between a closed loop's samples.

Oracles, none of them the code under test:

* a body turning uniformly about the inertial z axis points its body x axis at azimuth ``ω t``: its
  angle to a fixed direction in the xy-plane is ``|ω t − φ|`` at any time (closed form);
* the eigenaxis quintic about z, ``θ(t) = Θ (10 s³ − 15 s⁴ + 6 s⁵)`` with ``s = t / T``, the same
  with ``θ(t)``, its crossing times found by ``scipy.optimize.brentq``;
* a body rocking about z, ``θ(t) = A sin(2π (t − t₀) / P)``, whose error angle to the inertial
  attitude is ``|θ(t)|``;
* a closed loop's held torques integrated between its samples by ``scipy.integrate.solve_ivp``
  (rigid body and wheels, the integration checked against the next sample first).
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import scenarios
from ocp import Environment, Spacecraft, quat
from ocp.geometry.directions import Geometry
from planners import ManeuverProblem, Reference, ReferenceSample
from scenarios.requirements.scoring import (
    reference_times,
    score_closed_loop,
    score_reference,
)
from scenarios.requirements.spec import (
    Direction,
    FinalRequirement,
    PointingRequirement,
    Requirements,
    Sensor,
)

ROOT = Path(__file__).resolve().parents[1]
T = 10.0
RATE = math.pi / T  # rad/s: body x sweeps 18 deg of azimuth a second
DEG_PER_S = math.degrees(RATE)
STEP = T / 2000  # the reference's sample spacing on [0, T] (2001 points): 0.09 deg of turn
BETWEEN = (700 + 0.5) * STEP  # half-way between two of the reference's samples
X_AXIS = Sensor("x_axis", [1.0, 0.0, 0.0])
INERTIA = np.diag([2.0, 3.0, 4.0])


def turning(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    half = 0.5 * RATE * t
    q = np.stack([np.cos(half), np.zeros_like(t), np.zeros_like(t), np.sin(half)], axis=-1)
    return q, np.tile([0.0, 0.0, RATE], (t.size, 1))


class UniformTurn(Reference):
    """q(t) = rotation by RATE t about z, from the inertial attitude."""

    def __init__(self) -> None:
        super().__init__("hand", T, INERTIA)

    def _evaluate(self, t: np.ndarray) -> ReferenceSample:
        q, omega = turning(t)
        zeros = np.zeros((t.size, 3))
        return ReferenceSample(q, omega, zeros, zeros)


def azimuth(degrees: float) -> Direction:
    return Direction(None, [math.cos(math.radians(degrees)), math.sin(math.radians(degrees)), 0.0])


def problem_with(requirements: Requirements) -> ManeuverProblem:
    constraints = tuple(r.constraint(Geometry(None, None), T + 60.0) for r in requirements.pointing)
    qf = quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), RATE * T)
    return ManeuverProblem(Spacecraft(INERTIA), quat.IDENTITY, np.zeros(3), qf, T, omegaf=np.zeros(3),
                           environment=Environment(), pointing=constraints)


def reference_score(requirement: PointingRequirement) -> dict:
    requirements = Requirements((requirement,))
    reference = UniformTurn()
    times = reference_times(T, T, 0.1)
    assert not np.any(np.isclose(times, BETWEEN, rtol=0.0, atol=0.1 * STEP))  # truly between two samples
    scores = score_reference(requirements, problem_with(requirements), times, reference.sample(times), None,
                             reference)
    return scores[requirement.name].values


def test_a_reference_crossing_a_narrow_cone_between_its_samples_is_violated():
    """A 0.02 deg keep-out centred half-way between two reference samples (0.045 deg of turn from
    each, both clear): margin ``|18 t − φ| − 0.02`` deg, -0.02 at ``BETWEEN``, inside for
    ``2 × 0.02 / 18`` s. Scored on the samples alone it read +0.025 deg, met."""
    requirement = PointingRequirement("tiny", X_AXIS, True, math.radians(0.02), azimuth(DEG_PER_S * BETWEEN))
    score = reference_score(requirement)
    assert score["min_margin_deg"] == pytest.approx(-0.02, abs=1e-7)
    assert score["min_margin_time_s"] == pytest.approx(BETWEEN, abs=1e-7)
    assert score["first_violation_s"] == pytest.approx(BETWEEN - 0.02 / DEG_PER_S, abs=1e-7)
    assert score["time_in_violation_s"] == pytest.approx(2 * 0.02 / DEG_PER_S, abs=1e-7)


def test_a_window_ending_between_reference_samples_is_scored_at_its_end():
    """Keep-out 30 deg about azimuth ``18 t_e + 30 − 0.01`` deg over ``[0, t_e]``, ``t_e`` between two
    samples: the boresight enters the cone 0.01/18 s before the window closes; margin -0.01 deg at
    ``t_e``. The last sample inside the window read +0.035 deg."""
    end = BETWEEN
    requirement = PointingRequirement("edge", X_AXIS, True, math.radians(30.0),
                                      azimuth(DEG_PER_S * end + 30.0 - 0.01), (0.0, end))
    score = reference_score(requirement)
    assert score["min_margin_deg"] == pytest.approx(-0.01, abs=1e-9)
    assert score["min_margin_time_s"] == pytest.approx(end, abs=1e-12)
    assert score["first_violation_s"] == pytest.approx(end - 0.01 / DEG_PER_S, abs=1e-8)
    assert score["time_in_violation_s"] == pytest.approx(0.01 / DEG_PER_S, abs=1e-8)


def test_a_window_opening_between_reference_samples_is_scored_from_its_start():
    """Keep-out 30 deg about azimuth ``18 t_s − 30.5`` deg (behind the boresight) from ``t_s``: margin
    ``0.5 + 18 (t − t_s)`` deg, least at the window's start. The first sample inside read 0.545."""
    start = BETWEEN
    requirement = PointingRequirement("edge", X_AXIS, True, math.radians(30.0),
                                      azimuth(DEG_PER_S * start - 30.5), (start, T + 60.0))
    score = reference_score(requirement)
    assert score["min_margin_deg"] == pytest.approx(0.5, abs=1e-9)
    assert score["min_margin_time_s"] == pytest.approx(start, abs=1e-12)
    assert score["first_violation_s"] is None and score["time_in_violation_s"] == 0.0


def test_a_window_ending_between_closed_loop_samples_is_scored_at_its_end():
    """The closed loop's edges, by the same machinery: the turn sampled every 0.1 s (its attitude and
    rate exact at the samples), the window's end 0.0525 s past a sample; its attitude there is
    interpolated (error ~ (ω h)⁴ / 384, 2e-9 rad). (Already so before the reference was scored
    between its samples: a check that both scopes agree with the closed form.)"""
    end = 3.5525
    requirement = PointingRequirement("edge", X_AXIS, True, math.radians(30.0),
                                      azimuth(DEG_PER_S * end + 30.0 - 0.01), (0.0, end))
    requirements = Requirements((requirement,))
    t = np.arange(0.0, T + 1e-9, 0.1)
    q, omega = turning(t)
    score = score_closed_loop(requirements, problem_with(requirements), t, q, omega, T)["edge"].values
    assert score["min_margin_deg"] == pytest.approx(-0.01, abs=1e-6)
    assert score["min_margin_time_s"] == pytest.approx(end, abs=1e-12)
    assert score["time_in_violation_s"] == pytest.approx(0.01 / DEG_PER_S, abs=1e-6)


def quintic_time(theta: float, total: float, duration: float) -> float:
    """When the rest-to-rest quintic ``Θ (10 s³ − 15 s⁴ + 6 s⁵)`` reaches ``theta``."""
    return brentq(lambda t: total * (10 * (t / duration) ** 3 - 15 * (t / duration) ** 4 + 6 * (t / duration) ** 5)
                  - theta, 0.0, duration, xtol=1e-14)


def test_the_shipped_keep_out_scenario_scores_every_row_against_its_cone():
    """``collocation_keep_out.yaml``: the tracker (body x) must stay 30 deg off inertial y. The
    eigenaxis slew of 162 deg about z turns body x through azimuth θ(t) (the quintic): it passes
    through the direction at θ = 90 deg (margin -30 deg) and is inside for θ in (60, 120) deg; the
    collocation row imposes the cone and is ok."""
    rows = {row.label: row for row in scenarios.run(scenarios.load(ROOT / "scenarios" / "collocation_keep_out.yaml")).rows}
    duration, total = 60.0, 162.0
    eigenaxis = rows["eigenaxis"]
    score = eigenaxis.requirements["reference"]["tracker_sun"]
    assert score["min_margin_deg"] == pytest.approx(-30.0, abs=1e-6)
    assert score["min_margin_time_s"] == pytest.approx(quintic_time(90.0, total, duration), abs=1e-5)
    assert score["first_violation_s"] == pytest.approx(quintic_time(60.0, total, duration), abs=1e-5)
    enter, leave = quintic_time(60.0, total, duration), quintic_time(120.0, total, duration)
    assert score["time_in_violation_s"] == pytest.approx(leave - enter, abs=1e-5)
    assert eigenaxis.requirements["closed_loop"]["tracker_sun"]["min_margin_deg"] < -29.0
    assert eigenaxis.status == "violated" and "tracker_sun (reference): min margin -30 deg" in eigenaxis.message
    collocation = rows["keep-out"]
    assert collocation.status == "ok"
    assert collocation.requirements["reference"]["tracker_sun"]["min_margin_deg"] >= 0.0


AMPLITUDE = 20.0  # deg
PERIOD = 60.0  # s


def rocking(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """θ(t) = A sin(2π (t − 2.5) / P) about z: peaks |θ| = A at t = 17.5 + 30 k s, half-way between
    samples 5 s apart (which see A cos(2π 2.5 / 60) = 0.966 A = 19.32 deg)."""
    phase = 2 * math.pi * (t - 2.5) / PERIOD
    theta = math.radians(AMPLITUDE) * np.sin(phase)
    rate = math.radians(AMPLITUDE) * 2 * math.pi / PERIOD * np.cos(phase)
    q = np.stack([np.cos(theta / 2), np.zeros_like(t), np.zeros_like(t), np.sin(theta / 2)], axis=-1)
    return q, np.stack([np.zeros_like(t), np.zeros_like(t), rate], axis=-1)


@pytest.mark.parametrize(("bound", "met"), [(19.9, False), (20.01, True)])
def test_the_final_error_between_closed_loop_samples_by_closed_form(bound, met):
    """The error angle to the inertial attitude is |θ(t)|, largest (20 deg) between the samples.
    The interpolation's error over 5 s: h⁴/384 max|θ''''| = 0.004 deg; 0.01 deg allowed."""
    t = np.arange(0.0, 120.0 + 1e-9, 5.0)
    q, omega = rocking(t)
    assert np.rad2deg(np.max(quat.error_angle(q, quat.IDENTITY))) < 19.4  # the samples alone miss it
    requirements = Requirements(final=FinalRequirement(0.0, bound, None))
    problem = ManeuverProblem(Spacecraft(INERTIA), quat.IDENTITY, np.zeros(3), quat.IDENTITY, 1.0,
                              omegaf=np.zeros(3), environment=Environment())
    score = score_closed_loop(requirements, problem, t, q, omega, 0.0)["final"]
    assert score.values["worst_error_deg"] == pytest.approx(AMPLITUDE, abs=0.01)
    assert score.met is met
    if not met:
        assert score.detail.startswith("error 20 deg at") and "over 19.9 deg" in score.detail


COARSE = """
name: final-between-samples
spacecraft:
  inertia: [0.25, 0.28, 0.12]
  wheels: {max_torque: 0.003, max_momentum: 0.02}
maneuver:
  duration: 1200.0
  initial: {q: [1, 0, 0, 0], omega: [0, 0, 0]}
  final: {q: [0.5, 0, 0, 0.8660254], omega: [0, 0, 0]}
planners: [{name: eigenaxis}]
controller: {name: augmented_quaternion_feedback}
simulation: {sample_time: 5.0, duration: 1400.0}
requirements:
  final: {after_s: 0, error_deg: 10}
"""


def test_a_coarsely_sampled_loop_breaking_its_final_bound_between_samples_against_solve_ivp():
    """A loop sampled every 5 s, still swinging after T = 1200 s: 9.5 deg off the target at its
    samples, about 14 deg between them. The oracle integrates the body and its wheels under each
    held torque (``I ω̇ = −ω × (I ω + h) + τ``, ``ḣ = −τ``), first checked against the next sample."""
    row = scenarios.run(scenarios.parse_scenario(yaml.safe_load(COARSE))).rows[0]
    result = row.simulation
    inertia = np.diag([0.25, 0.28, 0.12])
    target = np.array([0.5, 0.0, 0.0, 0.8660254])
    target /= np.linalg.norm(target)
    worst, on_samples = 0.0, 0.0
    for k in np.flatnonzero(result.t[:-1] >= 1200.0 - 1e-9):
        torque = result.applied_torque[k]

        def motion(_: float, x: np.ndarray, torque: np.ndarray = torque) -> np.ndarray:
            q, w, h = x[:4], x[4:7], x[7:10]
            dq = 0.5 * np.array([-q[1:] @ w, *(q[0] * w + np.cross(q[1:], w))])
            return np.concatenate([dq, np.linalg.solve(inertia, -np.cross(w, inertia @ w + h) + torque), -torque])

        solution = solve_ivp(motion, (result.t[k], result.t[k + 1]), result.x[k, :10], rtol=1e-11, atol=1e-13,
                             dense_output=True)
        assert solution.y[:7, -1] == pytest.approx(result.x[k + 1, :7], abs=1e-6)  # the oracle's model is the run's
        states = solution.sol(np.linspace(result.t[k], result.t[k + 1], 401))
        worst = max(worst, float(np.max(np.rad2deg(quat.error_angle(states[:4].T, target)))))
        on_samples = max(on_samples, float(np.rad2deg(quat.error_angle(result.x[k, :4], target))))
    assert on_samples < 10.0 < worst  # the samples alone keep the bound, the motion breaks it
    final = row.requirements["closed_loop"]["final"]
    assert final["worst_error_deg"] == pytest.approx(worst, abs=0.02)
    assert row.status == "violated" and "final (closed loop): error" in row.message
