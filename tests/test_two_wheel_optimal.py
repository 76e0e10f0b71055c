"""The optimal two-wheel manoeuvre (collocation on the full model with the z wheel failed) and the
lower bound it gives the two-wheel laws' settling times (Horri & Palmer scenario)."""
from dataclasses import asdict
from pathlib import Path

import numpy as np
import pytest

import scenarios
from controllers import CONTROLLERS
from ocp import Simulator, metrics_from_simulation, quat
from planners import PLANNERS

SCENARIO = Path(__file__).parent.parent / "scenarios" / "horri_palmer_two_wheels.yaml"
TWO_WHEEL_LAWS = ("singular_zero_momentum", "singular_rate_tracking", "min_norm", "gain_scheduled_min_norm")


def open_loop(problem, reference, substeps=24):
    """Integrate the reference's optimal actuator control through the model (not the transcription):
    classical RK4, ``substeps`` steps per collocation interval (the control is smooth within one).
    Returns the times and states."""
    model = problem.model
    disturbance = model.default_parameters
    step = reference.duration / (reference.intervals * substeps)
    n = reference.intervals * substeps
    times = np.arange(n + 1) * step
    stage_times = np.concatenate([times[:-1], times[:-1] + step / 2, times[1:] - 1e-12 * step])
    # The control polynomial meets the bounds at the Radau points only; in between (and at the
    # interval starts, extrapolated) a bang-bang arc overshoots: the wheels' limit clips it.
    limit = np.where(problem.spacecraft.wheels.working, problem.spacecraft.wheels.max_torque, 0.0)
    controls = np.clip(reference.control(stage_times), -limit, limit).reshape(3, n, -1)
    x = problem.initial_state.copy()
    states = [x]
    for k in range(n):
        t = times[k]
        f = lambda x_, u, t_: model.rhs(x_, u, t_, disturbance).full().ravel()
        k1 = f(x, controls[0, k], t)
        k2 = f(x + step / 2 * k1, controls[1, k], t + step / 2)
        k3 = f(x + step / 2 * k2, controls[1, k], t + step / 2)
        k4 = f(x + step * k3, controls[2, k], t + step)
        x = x + step / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        states.append(x)
    return times, np.array(states)


def check_two_wheel_solution(problem, reference, angle_deg=0.05, rate=1e-5):
    controls = reference.controls.T  # at the collocation (Radau) points, where the NLP bounds them
    assert np.max(np.abs(controls[:, 2])) == 0.0                       # the failed wheel gives nothing
    assert np.max(np.abs(controls[:, :2])) <= 0.02 * (1 + 1e-6)          # 20 mN m
    _, states = open_loop(problem, reference)
    assert np.max(np.abs(problem.model.inertial_momentum(states))) < 1e-10  # zero momentum throughout
    assert np.max(np.abs(states[:, 6])) < 1e-12                              # so no rate about z
    final = states[-1]
    error = np.rad2deg(quat.error_angle(final[0:4], problem.qf))
    print(f"open loop: final error {error:.3g} deg, rate {np.linalg.norm(final[4:7]):.3g} rad/s")
    assert error < angle_deg                                                  # the plan flies
    assert np.linalg.norm(final[4:7]) < rate
    return states


def test_min_energy_two_wheel_slew_flies_on_the_model():
    problem = scenarios.load(SCENARIO).problem
    reference = PLANNERS["collocation"]({"objective": "min_energy", "intervals": 50}).plan(problem)
    assert reference.ok, reference.message
    assert reference.duration == problem.duration
    states = check_two_wheel_solution(problem, reference)
    assert np.max(np.abs(states[:, 1:4] @ [0, 0, 1])) > 0.2  # it does turn about the unactuated axis


def scenario_minimum_time(**changes):
    """The scenario's minimum-time plan (its own options, updated by ``changes``)."""
    scenario = scenarios.load(SCENARIO)
    spec = scenario.planners[0]
    return scenario.problem, PLANNERS[spec.name]({**asdict(spec.options), **changes}).plan(scenario.problem)


@pytest.mark.slow
def test_minimum_time_is_bang_bang_and_agrees_with_a_second_transcription():
    """The scenario's configured options reach the two-wheel minimum time: the pre-refactor collocation
    (one T variable, no regularisation) found 136.64 s; the merged core without regularisation
    stopped at a poorer point (164.57 s). Checked without trusting either number: the control is
    bang-bang on both working wheels, several perturbed starts of the regularised problem agree,
    and multiple shooting (RK4, piecewise-linear torques) seeded from it finds the same T."""
    problem, reference = scenario_minimum_time(multistart=4, agree=0)
    assert reference.ok, reference.message
    # One optimum from the 4 starts: every start that converged reaches it. Which starts converge
    # depends on the host's rounding: all 4 up to 2026-12-04; on an AVX-512 host that day the second
    # stopped at the iteration limit (500) near it, at 139.33068 with a violation of 6.9e-6, the
    # other three at 139.328701.
    starts = reference.stats["regularized"]["starts"]
    regularized = [s["f"] for s in starts if s["converged"]]
    assert len(regularized) >= 3
    assert max(regularized) - min(regularized) < 1e-6 * min(regularized)
    T = reference.duration
    assert T == pytest.approx(136.64, abs=0.01)
    # Pontryagin with |u_i| <= 20 mN m and no singular arc: the working wheels' torques are at
    # the bound at every collocation point (two switches each).
    working = reference.controls[:2]
    assert np.all(np.abs(working) >= 0.02 * (1 - 1e-4))
    assert list((np.diff(np.sign(working), axis=1) != 0).sum(axis=1)) == [2, 2]
    second = PLANNERS["collocation"]({"objective": "min_time", "intervals": 50, "transcription": "multiple_shooting",
                                      "warm_start": "collocation",
                                      "warm_start_options": asdict(scenarios.load(SCENARIO).planners[0].options)}).plan(problem)
    assert second.ok, second.message
    assert second.duration == pytest.approx(T, rel=1e-3)
    print(f"minimum time: collocation {T:.4f} s, multiple shooting {second.duration:.4f} s")


@pytest.mark.slow
def test_laws_settle_slower_than_the_minimum_time():
    """Every law's settling time to 0.5° exceeds the collocation minimum time to the exact target
    under the same 20 mN m limit (a law that has not settled in the window counts as longer)."""
    scenario = scenarios.load(SCENARIO)
    problem = scenario.problem
    spec = scenario.planners[0]
    reference = PLANNERS[spec.name](spec.options).plan(problem)
    assert reference.ok, reference.message
    # Flown open loop with its bang-bang control saturated at the limit between the collocation points
    # (each interval's impulse kept), the plan ends within the 0.5 deg of the comparison at T (0.006 deg).
    check_two_wheel_solution(problem, reference, angle_deg=0.5, rate=1e-3)
    t_min = reference.duration
    assert t_min == pytest.approx(136.64, abs=0.01)  # the minimum (see the test above)
    simulator = Simulator(problem.model, scenario.simulation.sample_time)
    window = scenario.simulation.duration
    ratios = {}
    for name in TWO_WHEEL_LAWS:
        result = simulator.run(CONTROLLERS[name](), problem.initial_state, window, target=(problem.qf, problem.omegaf))
        settling = metrics_from_simulation(result, problem.qf, problem.omegaf, settling_tolerance_deg=0.5)["settling_time_s"]
        ratios[name] = None if settling is None else settling / t_min
        assert settling is None or settling > t_min
    print(f"minimum time {t_min:.2f} s; settling to 0.5 deg over it: {ratios}")
