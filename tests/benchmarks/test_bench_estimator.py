"""What the MEKF in the loop costs the compiled closed loop (issue 28), side by side. Run:
``python -m pytest tests/benchmarks/test_bench_estimator.py -o addopts="" -s``

The spin paper's re-pointing (``scenarios/spin_repoint_estimator.yaml``: torquers, augmented law,
1 s samples, 20 RK4 sub-steps) over 2000 s, compiled, with the true state plus noise
(``sensor_noise``) and with the gyro, star tracker and MEKF; the two runs alternate, so that the
machine's load falls on both alike. Target: the ratio of the medians per sample at most 2.
"""
import time
from pathlib import Path

import numpy as np

from controllers import CONTROLLERS
from ocp import SensorNoise, Simulator
from planners import PLANNERS
from scenarios.schema.loader import load

ROOT = Path(__file__).resolve().parents[2]
SAMPLES = 2000
ROUNDS = 25


def test_the_estimator_costs_at_most_twice_the_compiled_closed_loop():
    scenario = load(ROOT / "scenarios" / "spin_repoint_estimator.yaml")
    problem, spec = scenario.problem, scenario.simulation
    reference = PLANNERS[scenario.planners[0].name](scenario.planners[0].options).plan(problem)
    simulator = Simulator(problem.model, spec.sample_time, max_step=spec.max_step, compile=True)
    controller = CONTROLLERS[scenario.controller.name](scenario.controller.options)
    cases = {"true state + noise": (SensorNoise(attitude_std=2.4e-5, rate_std=1e-6, seed=3), None),
             "gyro + star tracker + MEKF": (spec.noise, spec.sensors)}

    def run(case):
        noise, sensors = cases[case]
        return simulator.run(controller, scenario.true_initial_state, SAMPLES * spec.sample_time,
                             reference=reference, target=(problem.qf, problem.omegaf), noise=noise, sensors=sensors)

    for case in cases:  # build and compile (or load the cached build) outside the timing
        assert run(case).path == "compiled"
    times = {case: [] for case in cases}
    for _ in range(ROUNDS):
        for case in cases:
            start = time.perf_counter()
            run(case)
            times[case].append((time.perf_counter() - start) / SAMPLES * 1e6)
    medians = {case: float(np.median(values)) for case, values in times.items()}
    for case, values in times.items():
        q1, q3 = np.percentile(values, [25, 75])
        print(f"{case}: median {medians[case]:.2f} us per sample, interquartile {q1:.2f} to {q3:.2f} us "
              f"({ROUNDS} rounds of {SAMPLES} samples)")
    ratio = medians["gyro + star tracker + MEKF"] / medians["true state + noise"]
    print(f"ratio of the medians: {ratio:.2f}")
    assert ratio <= 2.0
