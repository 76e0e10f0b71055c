"""Two-wheel laws (Horri & Palmer scenario): a 10000 s closed loop at 1 s samples of the
gain-scheduled min-norm law, as one CasADi function (symbolic law) and in the Python loop (the
reference implementation; per-sample code in scalars, no NumPy on 3-vectors).
Run: pytest tests/benchmarks/test_bench_two_wheel.py -o addopts="" """
from pathlib import Path

import pytest

import scenarios
from controllers import CONTROLLERS
from ocp import Simulator

SCENARIO = Path(__file__).parent.parent.parent / "scenarios" / "horri_palmer_two_wheels.yaml"


@pytest.mark.parametrize("python_loop", [False, True], ids=["symbolic", "python"])
def test_gain_scheduled_min_norm_10000_s(benchmark, python_loop):
    problem = scenarios.load(SCENARIO).problem
    simulator = Simulator(problem.model, 1.0, python_loop=python_loop)
    law = CONTROLLERS["gain_scheduled_min_norm"]()
    run = lambda: simulator.run(law, problem.initial_state, 10000.0, target=(problem.qf, problem.omegaf))
    run()  # first call builds the closed loop
    result = benchmark.pedantic(run, rounds=3, iterations=1)
    assert result.t[-1] == 10000.0
