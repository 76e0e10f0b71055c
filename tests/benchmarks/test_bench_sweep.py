"""Trade-study timings (issue 12). Targets: the sweep machinery adds at most 10 % per case over
calling ``scenarios.run`` in process (eigenaxis_demo.yaml, no plots); two local workers give at
least 1.7x the throughput of one; 100 cases of one collocation structure build the NLP once per
worker.

The sweep side is the command itself, ``slewbench sweep STUDY --out DIR --no-plots --workers N``,
run in this process (``scenarios.cli.commands.main``): it expands and checks the study, claims the
directory, commits every case to the SQLite store and writes the tables. The in-process side is
a loop of ``scenarios.run(scenarios.parse_scenario(case), cache=..., simulators=...)`` over the
same cases, with the caches a worker keeps (a solver cache and a few simulators), so that the
difference is the machinery alone; the loop without the simulators (each case builds its own, as
``scenarios.run`` does by default) is reported beside it. The process that
local pools fork from is started (and imports the workbench) once per session, before timing,
as for a library user who sweeps more than once; every timed sweep starts its own pool. Sides are
interleaved and medians compared, because the reference machine is shared.

Because two workers can only show their throughput on two idle cores, one benchmark also reports
what does not depend on the machine's load: the CPU time per case in the worker, and the serial
fraction of a one-worker sweep (the time no case runs, plus the driver's CPU time while cases
run), from which
Amdahl's law bounds the two-worker speed-up.
"""
import copy
import time
from pathlib import Path

import numpy as np
import yaml

import scenarios
from ocp import SolverCache
from ocp.cache import RecentCache
from scenarios.cli.commands import main
from scenarios.schema.read import read_yaml
from scenarios.study.engine import start_forkserver, sweep
from scenarios.study.spec import load_study, parse_study
from scenarios.study.store import SweepStore, claim_sweep_directory

DEMO = Path(__file__).resolve().parents[2] / "scenarios" / "eigenaxis_demo.yaml"


def demo_study(tmp: Path, cases: int, offset: int = 0) -> Path:
    """A study file of ``cases`` distinct runs of the demo scenario (the sensor-noise seed varies)."""
    tmp.mkdir(parents=True, exist_ok=True)
    path = tmp / f"study_{cases}_{offset}.yaml"
    path.write_text(yaml.safe_dump({"study": "bench", "scenario": str(DEMO),
                                    "grid": {"simulation.sensor_noise.seed": list(range(offset, offset + cases))}}))
    return path


def cli_sweep(study: Path, workers: int, out: Path) -> float:
    """Wall time [s] of ``slewbench sweep STUDY --out OUT --no-plots --workers N``."""
    start = time.perf_counter()
    status = main(["sweep", str(study), "--out", str(out), "--no-plots", "--workers", str(workers)])
    elapsed = time.perf_counter() - start
    assert status == 0
    return elapsed


def in_process(study: Path, reuse: bool = True) -> tuple[float, float]:
    """Wall and CPU time [s] of ``scenarios.run`` called on each case of ``study`` in a loop, with
    the caches a worker keeps (``reuse``: solvers and simulators), or a solver cache alone."""
    cases = [case.scenario for case in load_study(study).cases]
    cache, simulators = SolverCache(), RecentCache() if reuse else None
    start, cpu = time.perf_counter(), time.process_time()
    for case in cases:
        scenarios.run(scenarios.parse_scenario(copy.deepcopy(case)), cache=cache, simulators=simulators)
    return time.perf_counter() - start, time.process_time() - cpu


def warm_up(tmp: Path) -> None:
    """Start the process that local pools fork from, and warm this process's imports and CasADi."""
    start_forkserver()
    cli_sweep(demo_study(tmp, 1, 900), 1, tmp / "warm")
    in_process(demo_study(tmp, 1, 999))


def test_sweep_overhead_per_case(benchmark, tmp_path):
    n, rounds = 40, 5  # enough cases that a fresh worker's first case is spread out
    warm_up(tmp_path)
    direct, plain, swept = [], [], []
    for r in range(rounds):  # interleaved (and alternated), so that the machine's load hits every side
        study = demo_study(tmp_path, n, 100 * r)
        if r % 2:
            swept.append(cli_sweep(study, 1, tmp_path / f"s{r}") / n)
        direct.append(in_process(study)[0] / n)
        plain.append(in_process(study, reuse=False)[0] / n)
        if not r % 2:
            swept.append(cli_sweep(study, 1, tmp_path / f"s{r}") / n)
    ratios = np.array(swept) / np.array(direct)
    overhead = float(np.median(ratios) - 1)
    speedup = float(np.median(np.array(plain) / np.array(swept)))
    benchmark.extra_info.update(direct_per_case_s=direct, plain_run_per_case_s=plain, sweep_per_case_s=swept,
                                overhead=overhead, sweep_speedup_over_plain_run=speedup)
    benchmark.pedantic(lambda: None, rounds=1)
    print(f"\nin process with a worker's caches {np.median(direct):.4f} s/case {np.round(direct, 4)}, "
          f"slewbench sweep --workers 1 --no-plots {np.median(swept):.4f} s/case {np.round(swept, 4)}: overhead "
          f"(median of the rounds' ratios) {overhead:+.1%} {np.round(ratios - 1, 3)}; scenarios.run with a "
          f"solver cache only {np.median(plain):.4f} s/case {np.round(plain, 4)} ({speedup:.2f}x the sweep's time)")
    assert overhead <= 0.10


def test_cpu_per_case_and_serial_fraction(benchmark, tmp_path):
    """What the command does with one worker, timed from inside, in terms the machine's load hardly
    changes: CPU time per case in process and in the sweep (the driver's CPU time, parsing, store
    and tables included, plus the worker's since it started), and the serial fraction s (no case
    running, plus the driver's CPU time while cases run, as if it took it from the workers).
    Amdahl: two workers on two idle cores give at most 1 / (s + (1 - s) / 2)."""
    n, rounds = 40, 5
    warm_up(tmp_path)
    direct, plain, case_cpu, swept, serial = [], [], [], [], []
    for r in range(rounds):
        path = demo_study(tmp_path, n, 100 * r)
        direct.append(in_process(path)[1] / n)
        plain.append(in_process(path, reuse=False)[1] / n)
        start, driver = time.perf_counter(), time.process_time()
        study = load_study(path)
        out = claim_sweep_directory(tmp_path / f"c{r}")
        with SweepStore(out) as store:
            during = time.process_time()
            results = sweep(study, workers=1, store=store)
            during = time.process_time() - during
        results.write(out, plots=False)
        total, driver = time.perf_counter() - start, time.process_time() - driver
        busy = sum(record["elapsed_s"] for record in results.records.values())
        assert results.missing == 0 and len(results.cpu_s) == n and len(results.worker_cpu_s) == 1
        case_cpu.append(float(np.median(list(results.cpu_s.values()))))
        swept.append((driver + sum(results.worker_cpu_s.values())) / n)
        serial.append((total - busy + during) / total)
    cpu_overhead = float(np.median(np.array(swept) / np.array(direct)) - 1)
    s = float(np.median(serial))
    bound = 1.0 / (s + (1.0 - s) / 2.0)
    benchmark.extra_info.update(direct_cpu_per_case_s=direct, plain_run_cpu_per_case_s=plain, case_cpu_s=case_cpu,
                                sweep_cpu_per_case_s=swept,
                                cpu_overhead=cpu_overhead, serial_fraction=serial, amdahl_two_workers=bound)
    benchmark.pedantic(lambda: None, rounds=1)
    print(f"\nCPU per case: in process with a worker's caches {np.median(direct):.4f} s {np.round(direct, 4)} "
          f"(solver cache only {np.median(plain):.4f} s); sweep (driver + "
          f"worker) {np.median(swept):.4f} s {np.round(swept, 4)}: {cpu_overhead:+.1%}; median case in the "
          f"worker {np.median(case_cpu):.4f} s. Serial fraction {s:.3f} {np.round(serial, 3)}: two workers on "
          f"two idle cores give at most {bound:.2f}x")
    assert cpu_overhead <= 0.10 and bound >= 1.7


def test_two_workers_throughput(benchmark, tmp_path):
    n, rounds = 40, 3
    warm_up(tmp_path)
    one, two = [], []
    for r in range(rounds):
        study = demo_study(tmp_path, n, 100 * r)
        one.append(cli_sweep(study, 1, tmp_path / f"one{r}"))
        two.append(cli_sweep(study, 2, tmp_path / f"two{r}"))
    ratio = float(np.median(one) / np.median(two))
    benchmark.extra_info.update(one_worker_s=one, two_workers_s=two, throughput_ratio=ratio)
    benchmark.pedantic(lambda: None, rounds=1)
    print(f"\n{n} cases: 1 worker {np.median(one):.2f} s {np.round(one, 2)}, 2 workers {np.median(two):.2f} s "
          f"{np.round(two, 2)}: throughput ratio {ratio:.2f} (needs two idle cores)")
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
