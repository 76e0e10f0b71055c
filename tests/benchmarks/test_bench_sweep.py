"""Trade-study timings (issue 12). Targets: the sweep machinery adds at most 10 % per case over
calling ``scenarios.run`` in process (eigenaxis_demo.yaml, no plots); two local workers give at
least 1.7x the throughput of one; 100 cases of one collocation structure build the NLP once per
worker. The process that local pools fork from (it imports the workbench once per session) is
started before timing; each timed sweep then starts its own pool and writes its files. Sides are
interleaved and medians compared, because the reference machine is shared."""
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


def warm_forkserver(tmp: Path) -> None:
    """Start the process that local pools fork from (it imports the workbench once per session)."""
    timed_sweep(demo_study(1, 900), 1, tmp)


def test_sweep_overhead_per_case(benchmark, tmp_path):
    n, rounds = 40, 3  # enough cases that a fresh worker's first-case builds are spread out
    warm_forkserver(tmp_path / "warm")
    in_process(demo_study(1, 999))  # warm CasADi in this process
    direct, swept = [], []
    for r in range(rounds):  # interleaved, so that a change of the machine's load hits both sides
        direct.append(in_process(demo_study(n, 10 * r)) / n)
        swept.append(timed_sweep(demo_study(n, 10 * r), 1, tmp_path / f"s{r}") / n)
    overhead = float(np.median(swept) / np.median(direct) - 1)
    benchmark.extra_info.update(direct_per_case_s=direct, sweep_per_case_s=swept, overhead=overhead)
    benchmark.pedantic(lambda: None, rounds=1)
    print(f"\nin process {np.median(direct):.3f} s/case {np.round(direct, 3)}, sweep with 1 worker (new pool, "
          f"files, no plots) {np.median(swept):.3f} s/case {np.round(swept, 3)}: overhead {overhead:+.1%}")
    assert overhead <= 0.10


def test_two_workers_throughput(benchmark, tmp_path):
    n, rounds = 40, 3
    warm_forkserver(tmp_path / "warm")
    one, two = [], []
    for r in range(rounds):
        one.append(timed_sweep(demo_study(n, 10 * r), 1, tmp_path / f"one{r}"))
        two.append(timed_sweep(demo_study(n, 10 * r), 2, tmp_path / f"two{r}"))
    ratio = float(np.median(one) / np.median(two))
    benchmark.extra_info.update(one_worker_s=one, two_workers_s=two, throughput_ratio=ratio)
    benchmark.pedantic(lambda: None, rounds=1)
    print(f"\n{n} cases: 1 worker {np.median(one):.2f} s {np.round(one, 2)}, 2 workers {np.median(two):.2f} s "
          f"{np.round(two, 2)}: throughput ratio {ratio:.2f}")
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
