"""Runner timings (issue 3). Targets: the demo scenario end to end (CLI, files and plots) under
10 s; the runner adds under 20 % to the plan plus simulation time it orchestrates."""
import time
from pathlib import Path

import numpy as np

import scenarios
from controllers import CONTROLLERS
from ocp import Simulator, metrics_from_reference, metrics_from_simulation
from planners import PLANNERS
from scenarios.cli.commands import main

DEMO = Path(__file__).resolve().parents[2] / "scenarios" / "eigenaxis_demo.yaml"


def test_demo_end_to_end(benchmark, tmp_path):
    code = benchmark.pedantic(main, args=(["run", str(DEMO), "--out", str(tmp_path / "out")],), rounds=3, iterations=1)
    assert code == 0


def bare_plan_and_simulate(scenario):
    """What the runner orchestrates, written directly: build, plan, simulate, score."""
    problem, spec = scenario.problem, scenario.simulation
    simulator = Simulator(problem.model, spec.sample_time, spec.integrator, max_step=spec.max_step)
    for planner_spec in scenario.planners:
        reference = PLANNERS[planner_spec.name](planner_spec.options).plan(problem)
        metrics_from_reference(reference, problem.qf, problem.omegaf)
        duration = spec.duration or max(problem.duration, reference.duration)
        result = simulator.run(CONTROLLERS[scenario.controller.name](scenario.controller.options),
                               scenario.true_initial_state, duration, reference=reference,
                               target=(problem.qf, problem.omegaf), noise=spec.noise)
        metrics_from_simulation(result, problem.qf, problem.omegaf, reference=reference)


def test_runner_overhead(benchmark):
    scenario = scenarios.load(DEMO)
    scenarios.run(scenario)  # warm caches (CasADi builds) for both sides alike
    bare = []
    for _ in range(5):
        start = time.perf_counter()
        bare_plan_and_simulate(scenario)
        bare.append(time.perf_counter() - start)
    benchmark.pedantic(scenarios.run, args=(scenario,), rounds=5, iterations=1)
    overhead = benchmark.stats.stats.median / float(np.median(bare)) - 1
    benchmark.extra_info["bare_median_s"] = float(np.median(bare))
    benchmark.extra_info["overhead"] = overhead
    print(f"\nrunner median {benchmark.stats.stats.median:.3f} s, bare {np.median(bare):.3f} s, overhead {overhead:.1%}")
    assert overhead < 0.20
