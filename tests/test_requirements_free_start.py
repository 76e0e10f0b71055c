"""A declared free start's momentum that the working wheels cannot take (``start_torque``), against
hand computations.

A sphere (I = 10 kg m^2) spins at 0.05 rad/s about body x; an eigenaxis reference (a declared free
start: it starts at rest) turns it 90° about z in 200 s. The body must lose I ω₀ = 0.5 N m s along
inertial x. Wheels along the three body axes take it at once (the case of
``test_requirements_actuators``, unchanged); wheels on y and z only cannot, at t = 0, take any of it:

* without torquers it is a torque impulse no working actuator gives: asked as the least constant
  torque that removes it by T, 0.5 / 200 = 2.5e-3 N m about body x at t = 0 (inertial x, which the
  body turns away from as it slews, the wheels taking what turns into their span: the y wheel's
  momentum, integrated by hand), unrealised there: the requirement is broken;
* a torquer on x takes it: 2.5e-3 N m at t = 0, 1.25 x a 2e-3 N m limit, 0.5 x a 5e-3 N m one.
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

from ocp import ReactionWheels, Spacecraft, Torquers
from scenarios.requirements.scoring import start_torque

SPHERE = """
name: free-start
spacecraft:
  inertia: [10.0, 10.0, 10.0]
  wheels: {axes: [[1, 0, 0], [0, 1, 0], [0, 0, 1]], failed: [FAILED], max_torque: 0.1, max_momentum: 1.0}
  TORQUERS
maneuver:
  duration: 200.0
  initial: {q: [1, 0, 0, 0], omega: [SPIN]}
  final: {q: [0.7071068, 0, 0, 0.7071068], omega: [0, 0, 0]}
planners:
  - {name: eigenaxis, label: smooth, options: {profile: smooth}}
controller: {name: augmented_quaternion_feedback, options: {kp: 0.5, kd: 3.0}}
simulation: {sample_time: 0.5, duration: 260.0}
"""


def _row(tmp_path, failed: str = "0", torquers: str = "", spin: str = "0.05, 0, 0", max_momentum: str = "1.0"):
    from scenarios.runner import run
    from scenarios.schema.loader import load

    path = tmp_path / "free_start.yaml"
    path.write_text(SPHERE.replace("FAILED", failed).replace("TORQUERS", torquers).replace("SPIN", spin)
                    .replace("max_momentum: 1.0", f"max_momentum: {max_momentum}"))
    return run(load(path)).rows[0]


def test_a_spin_no_actuator_can_remove_is_unrealised(tmp_path):
    row = _row(tmp_path)
    score = row.requirements["reference"]["actuators"]
    assert score["unrealised_torque"] == pytest.approx(10 * 0.05 / 200.0, rel=1e-9)
    assert score["unrealised_torque_time_s"] == 0.0
    assert score["rate_jump"] == 0.0  # a declared free start: no impulse of the reference's own
    # the y wheel takes the start torque's y part, −(J / T) sin θ(t) in body axes (J = −0.5 N m s
    # along inertial x, θ the quintic's angle about z): h_y(T) = (J / T) ∫ sin θ dt, its peak
    quintic = quad(lambda s: np.sin(np.pi / 2 * (10 * s**3 - 15 * s**4 + 6 * s**5)), 0.0, 1.0, epsabs=1e-14)[0]
    assert score["wheels_momentum"] == pytest.approx(0.5 * quintic, rel=1e-9)
    assert score["wheels_momentum_time_s"] == 200.0
    assert row.status == "violated"
    assert "given by no working actuator" in row.message
    assert "the free start's momentum the wheels cannot take, 0.5 N m s" in row.message


@pytest.mark.parametrize("limit, ratio", [(0.002, 1.25), (0.005, 0.5)])
def test_a_torquer_on_the_spin_axis_is_counted_for_it(tmp_path, limit, ratio):
    row = _row(tmp_path, torquers=f"torquers: {{max_torque: {limit}}}")
    score = row.requirements["reference"]["actuators"]
    assert score["torquers_torque"] == pytest.approx(ratio, rel=1e-9)
    assert score["torquers_torque_time_s"] == 0.0
    assert score["unrealised_torque"] < 1e-15
    assert (row.status == "ok") == (ratio <= 1.0), row.message


FREE = "(with the free start's momentum the wheels cannot take"


def test_the_free_start_is_named_by_the_unrealised_torque_it_asks_not_by_the_slews_wheel_momentum(tmp_path):
    """A slower spin (0.01 rad/s: 0.1 N m s, 0.1 / 200 = 5e-4 N m unrealised at t = 0) and 0.1 N m s
    wheels: the z wheel's momentum, the slew's own (I times the quintic's peak rate, 10 x 1.875
    (π/2) / 200 = 0.1473 N m s at 100 s, 1.47 x its limit; the y wheel's share of the start, at
    most 0.1 x 0.5 of the first test's, stays below), is broken without the free start's part in it."""
    row = _row(tmp_path, spin="0.01, 0, 0", max_momentum="0.1")
    score = row.requirements["reference"]["actuators"]
    assert score["unrealised_torque"] == pytest.approx(10 * 0.01 / 200.0, rel=1e-9)
    assert score["wheels_momentum"] == pytest.approx(10 * 1.875 * (np.pi / 2) / 200.0 / 0.1, rel=1e-6)
    assert score["wheels_momentum_time_s"] == pytest.approx(100.0)
    assert row.status == "violated"
    unrealised, wheels = row.message.split(", wheels_momentum ")
    assert unrealised.endswith(f"is given by no working actuator {FREE}, 0.1 N m s, removed at 0.0005 N m over the "
                               "200 s manoeuvre)"), row.message
    assert FREE not in wheels and row.message.count(FREE) == 1, row.message


def test_the_free_start_is_named_by_the_torquers_demand_it_asks(tmp_path):
    row = _row(tmp_path, torquers="torquers: {max_torque: 0.002}")
    assert row.status == "violated"
    assert (f"torquers_torque 1.25 x its limit at 0.0 s {FREE}, 0.5 N m s, removed at 0.0025 N m over the 200 s "
            "manoeuvre) (allowed 1 x)") in row.message, row.message
    assert row.message.count(FREE) == 1, row.message


def test_a_spin_within_the_wheels_span_goes_to_the_wheels_at_once(tmp_path):
    """About y the y wheel takes the whole 0.5 N m s at t = 0: no start torque is asked. As the body
    turns about z that stored momentum asks the gyroscopic ω × A h = (−ω_z h_y, 0, 0), about x,
    which no wheel gives: unrealised, at most at the quintic's peak rate 1.875 (π/2) / 200 s at
    100 s, 0.5 x 0.014726 = 7.363e-3 N m (nothing at t = 0, where a start torque would be)."""
    row = _row(tmp_path, spin="0, 0.05, 0")
    score = row.requirements["reference"]["actuators"]
    assert score["unrealised_torque"] == pytest.approx(0.5 * 1.875 * (np.pi / 2) / 200.0, rel=1e-6)
    assert score["unrealised_torque_time_s"] == pytest.approx(100.0)
    assert score["wheels_momentum"] == pytest.approx(0.5, rel=1e-9)
    assert "the free start's momentum" not in row.message


def test_the_start_torque_by_hand():
    """Torquers alone (no wheel span): J = I (ω_ref(0) − ω₀), asked as R(q(t))ᵀ R(q(0)) J / T up
    to T (the sample at T included) and zero after; three working wheels: nothing, exact zeros."""
    inertia = np.diag([2.0, 3.0, 4.0])
    spacecraft = Spacecraft(inertia, torquers=Torquers(0.1))
    t = np.array([0.0, 5.0, 10.0, 12.0])
    angles = np.array([0.0, 0.3, 0.5, 0.5])  # about body z
    q = np.stack([np.cos(angles / 2), 0 * angles, 0 * angles, np.sin(angles / 2)], axis=1)
    step = np.array([-0.1, 0.2, 0.0])  # ω_ref(0) − ω₀
    torque, impulse = start_torque(spacecraft, t, q, step, 10.0)
    assert impulse == pytest.approx([-0.2, 0.6, 0.0], abs=1e-15)
    for k, angle in enumerate(angles[:3]):  # inertial (-0.02, 0.06, 0) in the body turned by angle about z
        c, s = np.cos(angle), np.sin(angle)
        assert torque[k] == pytest.approx([c * -0.02 + s * 0.06, -s * -0.02 + c * 0.06, 0.0], abs=1e-15)
    assert np.all(torque[3] == 0.0)
    wheels = Spacecraft(inertia, wheels=ReactionWheels.from_body_axes(max_torque=0.1))
    torque, impulse = start_torque(wheels, t, q, step, 10.0)
    assert np.all(torque == 0.0) and np.all(impulse == 0.0)


def test_the_spin_papers_eigenaxis_slew_on_torquers_asks_them_to_despin(tmp_path):
    """The spin paper's body (I = [19.5, 19, 12.6] kg m^2) spinning at 0.2 rad/s about x, an eigenaxis
    slew from rest (180° about y in 200 s) on 0.1 N m torquers (the guide's example): they must
    remove 19.5 x 0.2 = 3.9 N m s, asked as 3.9 / 200 = 0.0195 N m about x at t = 0, 0.195 of their
    limit (above the slew's own peak, 0.086)."""
    from scenarios.runner import run
    from scenarios.schema.loader import load

    path = tmp_path / "despin.yaml"
    path.write_text(SPHERE.replace("[10.0, 10.0, 10.0]", "[19.5, 19.0, 12.6]")
                    .replace("  wheels: {axes: [[1, 0, 0], [0, 1, 0], [0, 0, 1]], failed: [FAILED], max_torque: 0.1, "
                             "max_momentum: 1.0}\n", "  wheels: none\n")
                    .replace("TORQUERS", "torquers: {max_torque: 0.1}").replace("SPIN", "0.2, 0, 0")
                    .replace("[0.7071068, 0, 0, 0.7071068]", "[0, 0, 1, 0]"))
    assert "wheels: none" in path.read_text() and "[0, 0, 1, 0]" in path.read_text()
    row = run(load(path)).rows[0]
    score = row.requirements["reference"]["actuators"]
    assert score["torquers_torque"] == pytest.approx(19.5 * 0.2 / 200.0 / 0.1, rel=1e-9)
    assert score["torquers_torque_time_s"] == 0.0
    assert row.status == "ok", row.message
