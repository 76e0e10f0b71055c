"""Trade-study timings (issue 12). Targets: the sweep machinery adds at most 10 % per case over
calling ``scenarios.run`` in process (eigenaxis_demo.yaml, no plots); two local workers give at
least 1.7x the throughput of one; 100 cases of one collocation structure build the NLP once per
worker. Per-case figures are marginal (the time of 2N cases minus that of N, over N), so that the
fixed start of the worker processes (one import of the workbench) is reported apart."""
import copy
import time
from pathlib import Path

import numpy as np

import scenarios
from ocp import SolverCache
from scenarios.study import parse_study
from scenarios.sweep_engine import sweep
from scenarios.yaml_node import read_yaml

DEMO = Path(__file__).resolve().parents[2] / "scenarios" / "eigenaxis_demo.yaml"


def demo_study(cases: int, offset: int = 0) -> dict:
    """``cases`` distinct runs of the demo scenario (the sensor-noise seed varies)."""
    return {"study": "bench", "scenario": read_yaml(DEMO),
            "grid": {"simulation.sensor_noise.seed": list(range(offset, offset + cases))}}


def timed_sweep(data: dict, workers: int, tmp: Path) -> float:
    start = time.perf_counter()
    results = sweep(parse_study(data), workers=workers)
    results.write(tmp, plots=False)
    elapsed = time.perf_counter() - start
    assert results.missing == 0
    return elapsed


def in_process(data: dict) -> float:
    study = parse_study(data)
    cache = SolverCache()
    start = time.perf_counter()
    for case in study.cases:
        scenarios.run(scenarios.parse_scenario(copy.deepcopy(case.scenario)), cache=cache)
    return time.perf_counter() - start


def test_sweep_overhead_per_case(benchmark, tmp_path):
    n = 8
    in_process(demo_study(1, 999))  # warm CasADi in this process
    direct = in_process(demo_study(n)) / n
    small = timed_sweep(demo_study(n), 1, tmp_path / "a")
    large = timed_sweep(demo_study(2 * n, 100), 1, tmp_path / "b")
    per_case = (large - small) / n
    startup = small - n * per_case
    benchmark.extra_info.update(direct_per_case_s=direct, sweep_per_case_s=per_case, startup_s=startup)
    benchmark.pedantic(lambda: None, rounds=1)
    overhead = per_case / direct - 1
    print(f"\nin process {direct:.3f} s/case, sweep (1 worker) {per_case:.3f} s/case marginal, "
          f"overhead {overhead:+.1%}; fixed start {startup:.2f} s; {n} cases total {small:.2f} s "
          f"({small / (n * direct) - 1:+.1%} with the start)")
    assert overhead <= 0.10


def test_two_workers_throughput(benchmark, tmp_path):
    n = 8
    one = [timed_sweep(demo_study(k * n, 10 * k), 1, tmp_path / f"one{k}") for k in (1, 2)]
    two = [timed_sweep(demo_study(k * n, 10 * k + 500), 2, tmp_path / f"two{k}") for k in (1, 2)]
    ratio = (one[1] - one[0]) / (two[1] - two[0])
    benchmark.extra_info.update(one_worker_s=one, two_workers_s=two, throughput_ratio=ratio)
    benchmark.pedantic(lambda: None, rounds=1)
    print(f"\n1 worker: {one[0]:.2f} s / {one[1]:.2f} s for {n} / {2 * n} cases; 2 workers: {two[0]:.2f} s / "
          f"{two[1]:.2f} s; marginal throughput ratio {ratio:.2f} (end to end at {2 * n} cases: "
          f"{one[1] / two[1]:.2f})")
    assert ratio >= 1.7


def test_collocation_nlp_built_once_per_worker(benchmark):
    base = read_yaml(DEMO)
    base["planners"] = [{"name": "collocation", "label": "min energy", "options": {"intervals": 20}}]
    base["simulation"] = {"sample_time": 1.0, "duration": 125.0}
    data = {"study": "colloc", "scenario": base, "grid": {
        "maneuver.final.q": {"axis_angle": {"axis": [1, 1, 1], "angle_deg": {"linspace": [10, 180, 100]}}}}}
    study = parse_study(data)
    results = benchmark.pedantic(sweep, args=(study,), kwargs={"workers": 2}, rounds=1, iterations=1)
    ok = sum(r["rows"][0]["status"] == "ok" for r in results.records.values())
    print(f"\n100 collocation cases on 2 workers in {benchmark.stats.stats.median:.1f} s; {ok} solved; "
          f"solver builds per worker: {results.workers}")
    assert len(results.records) == 100 and results.workers and set(results.workers.values()) == {1}
    assert np.isfinite(benchmark.stats.stats.median)
