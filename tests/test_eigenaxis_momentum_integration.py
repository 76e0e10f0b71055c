"""The eigenaxis wheel budget's integration of the wheels' momentum
(:meth:`planners.eigenaxis.WheelBudget.integrated_ratios`): its Runge-Kutta steps as affine maps,
composed by a scan, are the classical Runge-Kutta stepped one step at a time (written out here), and a
plan that measures its profile by it costs a fraction of a second (it cost 7-8 s of CPU a plan when
each step was a handful of NumPy calls on 3-vectors)."""
from __future__ import annotations

import time

import numpy as np
import pytest

from ocp import ReactionWheels, Spacecraft, Torquers, quat
from planners import PLANNERS, ManeuverProblem
from planners.eigenaxis import _affine_orbit, _cross_matrix, _runge_kutta_maps


def stepped(projector, axis, push, spin, rate0, accel, dt, steps, h0):
    """The classical Runge-Kutta of dh/dt = -P (p + r^2 s + r axis x h), r = rate0 + accel t, one
    step at a time."""
    def f(rate, h):
        return -projector @ (push + rate**2 * spin + rate * np.cross(axis, h))

    h, out = np.array(h0, float), [np.array(h0, float)]
    for k in range(steps):
        r0 = rate0 + accel * k * dt
        k1 = f(r0, h)
        k2 = f(r0 + 0.5 * accel * dt, h + 0.5 * dt * k1)
        k3 = f(r0 + 0.5 * accel * dt, h + 0.5 * dt * k2)
        k4 = f(r0 + accel * dt, h + dt * k3)
        h = h + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        out.append(h)
    return np.array(out)


@pytest.mark.parametrize("steps", [1, 2, 3, 8, 37, 1000])
def test_the_composed_maps_are_the_stepped_runge_kutta(steps):
    rng = np.random.default_rng(steps)
    for _ in range(5):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        basis = rng.normal(size=(3, 2))
        projector = basis @ np.linalg.pinv(basis)  # onto two wheels' span
        push, spin, h0 = rng.normal(size=3), rng.normal(size=3), rng.normal(size=3)
        # as the planner steps: the body turns at most step_angle (0.002 rad; 0.05 here) a step
        rate0, accel = rng.uniform(-0.05, 0.05), rng.uniform(-1e-3, 1e-3)
        peak = max(abs(rate0), abs(rate0 + accel * steps * 1.0), 1e-3)
        dt = rng.uniform(0.2, 1.0) * 0.05 / peak
        rates = rate0 + accel * np.arange(steps) * dt
        phi, gamma = _runge_kutta_maps(projector, _cross_matrix(axis), push, spin, rates, accel, dt)
        expected = stepped(projector, axis, push, spin, rate0, accel, dt, steps, h0)
        scale = np.max(np.abs(expected))
        assert np.max(np.abs(_affine_orbit(phi, gamma, h0) - expected)) <= 1e-12 * scale


def test_cross_matrix_is_the_cross_product():
    rng = np.random.default_rng(1)
    a, w = rng.normal(size=(2, 3))
    assert _cross_matrix(a) @ w == pytest.approx(np.cross(a, w), abs=1e-15)


def test_a_measured_two_wheel_plan_takes_a_fraction_of_a_second():
    """Wheels 1 and 3 of a 54.7° pyramid failed, torquers beside, stored momentum: the profile is
    measured by integration about 30 times per plan (7.4-8.3 s of CPU a plan before, 0.11-0.19 s
    after, 2026-12-04); the bound leaves a factor of about 10 for a loaded host."""
    s, c = np.sin(np.radians(54.7356)), np.cos(np.radians(54.7356))
    axes = np.array([[s, 0, c], [0, s, c], [-s, 0, c], [0, -s, c]]).T  # each 54.7° from body z
    wheels = ReactionWheels(axes, max_torque=0.01, max_momentum=0.05, failed=[1, 3])
    spacecraft = Spacecraft(np.diag([2.0, 2.5, 3.0]), wheels=wheels, torquers=Torquers(0.002))
    axis = np.array([0.9518, 0.1937, -0.238])
    problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3),
                              quat.from_axis_angle(axis / np.linalg.norm(axis), np.radians(81.47)), 400.0,
                              omegaf=np.zeros(3), wheel_momentum0=np.array([0.0265, 0.0469, 0.0019, -0.0095]))
    planner = PLANNERS["eigenaxis"]({"profile": "min_time"})
    begin = time.process_time()
    reference = planner.plan(problem)
    spent = time.process_time() - begin
    assert reference.status == "ok", reference.message
    assert "verified by integration" in reference.message
    assert spent < 2.0, f"{spent:.2f} s of CPU"
