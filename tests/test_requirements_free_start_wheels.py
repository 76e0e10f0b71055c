"""A wheel's momentum broken by a declared free start's momentum is said to be the free start's.

The sphere of ``test_requirements_free_start`` (I = 10 kg m^2, spinning at 0.05 rad/s about body x;
an eigenaxis quintic from rest, 90° about z in 200 s) on wheels along y and z (x failed) with a
0.005 N m torquer on every axis: the torquers remove the start's 0.5 N m s, asked as 0.5 / 200 N m
along inertial x, and as the body turns about z the y wheel takes what turns into its span, by
hand ``h_y(T) = (J / T) ∫ sin θ dt`` (θ the quintic's angle), 0.29 N m s, its peak at T. With 0.2
N m s wheels that breaks their limit, while the slew's own momentum (the z wheel, I times the
quintic's peak rate 1.875 (π/2) / 200 s, 0.1473 N m s) keeps 0.736 of it: the message names the
free start, and what the wheel at the peak would hold without it.
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

from scenarios.runner import run
from scenarios.schema.loader import load

SPHERE = """
name: free-start-wheels
spacecraft:
  inertia: [10.0, 10.0, 10.0]
  wheels: {axes: [[1, 0, 0], [0, 1, 0], [0, 0, 1]], failed: [0], max_torque: 0.1, max_momentum: MOMENTUM}
  torquers: {max_torque: 0.005}
maneuver:
  duration: 200.0
  initial: {q: [1, 0, 0, 0], omega: [SPIN, 0, 0]}
  final: {q: [0.7071068, 0, 0, 0.7071068], omega: [0, 0, 0]}
planners:
  - {name: eigenaxis, label: smooth, options: {profile: smooth}}
controller: {name: augmented_quaternion_feedback, options: {kp: 0.5, kd: 3.0}}
simulation: {sample_time: 0.5, duration: 260.0}
"""
QUINTIC_SINE = quad(lambda s: np.sin(np.pi / 2 * (10 * s**3 - 15 * s**4 + 6 * s**5)), 0.0, 1.0, epsabs=1e-14)[0]
SLEW_MOMENTUM = 10 * 1.875 * (np.pi / 2) / 200.0  # N m s, the z wheel's peak


def _row(tmp_path, momentum: float, spin: float = 0.05):
    path = tmp_path / "free_start_wheels.yaml"
    path.write_text(SPHERE.replace("MOMENTUM", f"{momentum}").replace("SPIN", f"{spin}"))
    return run(load(path)).rows[0]


def test_a_wheel_momentum_the_free_start_breaks_names_the_free_start(tmp_path):
    row = _row(tmp_path, 0.2)
    score = row.requirements["reference"]["actuators"]
    assert score["wheels_momentum"] == pytest.approx(0.5 * QUINTIC_SINE / 0.2, rel=1e-6)
    assert score["wheels_momentum"] > 1.0 > SLEW_MOMENTUM / 0.2
    assert score["wheels_momentum_time_s"] == 200.0
    assert score["torquers_torque"] == pytest.approx(0.5 / 200.0 / 0.005, rel=1e-9)  # within: the torquers remove it
    assert row.status == "violated"
    wheels = row.message[row.message.index("wheels_momentum "):]
    # the y wheel, at the peak, holds nothing without the free start
    assert "(the free start's momentum, 0.5 N m s, takes it there: 0 x without it)" in wheels, row.message


def test_the_wheel_the_free_start_breaks_is_named_even_where_the_slew_breaks_another(tmp_path):
    # 0.1 N m s wheels: the slew's own 0.1473 N m s breaks the z wheel, but the peak is the y wheel's,
    # 0.29 N m s from the free start alone (nothing without it)
    row = _row(tmp_path, 0.1)
    assert row.requirements["reference"]["actuators"]["wheels_momentum"] == pytest.approx(0.5 * QUINTIC_SINE / 0.1,
                                                                                          rel=1e-6)
    assert "(the free start's momentum, 0.5 N m s, takes it there: 0 x without it)" in row.message, row.message


def test_a_wheel_momentum_the_slew_breaks_alone_does_not_name_it(tmp_path):
    # spinning at 0.01 rad/s: the y wheel takes 0.1 x 0.58 N m s, the z wheel's 0.1473 N m s, the
    # slew's own, is the peak and breaks 0.1 N m s wheels without the free start
    row = _row(tmp_path, 0.1, spin=0.01)
    assert row.requirements["reference"]["actuators"]["wheels_momentum"] == pytest.approx(SLEW_MOMENTUM / 0.1, rel=1e-6)
    assert row.status == "violated"
    assert "takes it there" not in row.message, row.message
