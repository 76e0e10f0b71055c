"""Trade studies at scale (issue 32), side by side in one run:

* 1000 cheap cases (the eigenaxis demo's first row, the sensor-noise seed varied, no plots): two
  local workers give at least 1.8x the throughput of one; the parent's CPU time is at most 0.3 ms per
  case (checking the cases, keys, store, collection, progress); the sweep's time per case over an
  in-process loop with a worker's caches is at most 1 ms;
* a 100,000-case Monte Carlo (the shipped one, scaled) is checked and started within 10 s;
* on a local Dask cluster of 2 worker processes, the same 1000 cases within 1.2x of the local pool;
* a 2000-case dry run (check and findings of every case) within 2 ms of CPU a case.

CPU times hardly depend on the machine's load; wall times do. On a shared machine the wall-time
targets are reported with the load average and asserted only when the machine was quiet (load
average below 0.5 per core when the benchmark started); the CPU targets are always asserted, and
the speed-up two workers can give is also bounded from CPU times (Amdahl, from the parent's share).
"""
import contextlib
import copy
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml

import scenarios
from ocp import SolverCache
from ocp.cache import RecentCache
from scenarios.schema.read import read_yaml
from scenarios.study.engine import start_forkserver, sweep
from scenarios.study.spec import load_study
from scenarios.study.store import SweepStore, claim_sweep_directory

ROOT = Path(__file__).resolve().parents[2]
CASES = 1000
CORES = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)


def quiet() -> bool:
    return os.getloadavg()[0] < 0.5 * CORES


def cheap_study(folder: Path, offset: int = 0, cases: int = CASES) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    base = read_yaml(ROOT / "scenarios" / "eigenaxis_demo.yaml")
    base["planners"] = base["planners"][:1]
    path = folder / f"cheap_{offset}_{cases}.yaml"
    path.write_text(yaml.safe_dump({"study": "cheap", "scenario": base,
                                    "grid": {"simulation.sensor_noise.seed": list(range(offset, offset + cases))}}))
    return path


def timed_sweep(path: Path, out: Path, **kwargs) -> tuple[float, float, dict]:
    """Wall time [s] and the parent's CPU time [s] of checking and running the study into a store
    (the report's tables are not part of it), and the results."""
    start, cpu = time.perf_counter(), time.process_time()
    study = load_study(path)
    directory = claim_sweep_directory(out)
    with SweepStore(directory) as store:
        results = sweep(study, store=store, **kwargs)
    return time.perf_counter() - start, time.process_time() - cpu, results


def in_process(path: Path) -> tuple[float, float]:
    """Wall and CPU time [s] of ``scenarios.run`` on each case in a loop, with a worker's caches."""
    cases = [case.scenario for case in load_study(path).cases]
    cache, simulators = SolverCache(), RecentCache()
    start, cpu = time.perf_counter(), time.process_time()
    for case in cases:
        scenarios.run(scenarios.parse_scenario(copy.deepcopy(case)), cache=cache, simulators=simulators)
    return time.perf_counter() - start, time.process_time() - cpu


def test_parent_keeps_up_with_two_workers(benchmark, tmp_path):
    was_quiet, load = quiet(), os.getloadavg()
    start_forkserver()
    timed_sweep(cheap_study(tmp_path, 5000, 20), tmp_path / "warm", workers=2)
    rounds = 3
    one, two, parent, loop, serial, cpu_overhead = [], [], [], [], [], []
    for r in range(rounds):  # interleaved, so that the machine's load hits every side
        path = cheap_study(tmp_path, 10_000 * (r + 1))
        wall, cpu, results = timed_sweep(path, tmp_path / f"one{r}", workers=1)
        assert results.missing == 0
        one.append(wall)
        parent.append(cpu / CASES)
        busy = sum(results.cpu_s.values())
        serial.append(cpu / (cpu + busy))  # the parent's share of the CPU work
        swept_cpu = cpu + sum(results.worker_cpu_s.values())  # the workers' CPU from their start
        wall, cpu, results = timed_sweep(path, tmp_path / f"two{r}", workers=2)
        two.append(wall)
        parent.append(cpu / CASES)
        loop_wall, loop_cpu = in_process(path)
        loop.append(loop_wall)
        cpu_overhead.append((swept_cpu - loop_cpu) / CASES)
    ratio = float(np.median(one) / np.median(two))
    cpu_per_case = float(np.median(parent))
    overhead = float((np.median(one) - np.median(loop)) / CASES)
    s = float(np.median(serial))
    amdahl = 1.0 / (s + (1.0 - s) / 2.0)
    benchmark.extra_info.update(one_worker_s=one, two_workers_s=two, throughput_ratio=ratio, parent_cpu_per_case_s=parent,
                                in_process_loop_s=loop, overhead_per_case_s=overhead, parent_share=serial,
                                cpu_overhead_per_case_s=cpu_overhead,
                                amdahl_two_workers=amdahl, load_average=load)
    benchmark.pedantic(lambda: None, rounds=1)
    print(f"\n{CASES} cheap cases (load average {load[0]:.1f} on {CORES} cores): 1 worker {np.median(one):.2f} s "
          f"{np.round(one, 2)}, 2 workers {np.median(two):.2f} s {np.round(two, 2)}: throughput ratio {ratio:.2f}; "
          f"parent CPU {cpu_per_case * 1e3:.3f} ms/case {np.round(np.array(parent) * 1e3, 3)}; in-process loop "
          f"{np.median(loop):.2f} s {np.round(loop, 2)}: sweep overhead {overhead * 1e3:+.2f} ms/case of wall time, "
          f"{np.median(cpu_overhead) * 1e3:+.2f} ms/case of CPU time {np.round(np.array(cpu_overhead) * 1e3, 2)} "
          f"(parent and worker, worker start-up included); parent's share "
          f"of the CPU {s:.4f}: two workers on two idle cores give at most {amdahl:.2f}x")
    assert cpu_per_case <= 0.3e-3 and amdahl >= 1.8 and float(np.median(cpu_overhead)) <= 1e-3
    if was_quiet:
        assert ratio >= 1.8 and overhead <= 1e-3


def test_a_100000_case_monte_carlo_is_checked_and_started_within_10_s(benchmark, tmp_path):
    data = yaml.safe_load((ROOT / "scenarios" / "study_spin_monte_carlo.yaml").read_text())
    data["monte_carlo"]["samples"] = 100_000
    path = tmp_path / "mc.yaml"
    path.write_text(yaml.safe_dump(data))
    load = os.getloadavg()
    start = time.perf_counter()
    process = subprocess.Popen([sys.executable, "-m", "scenarios.cli", "sweep", str(path), "--out", str(tmp_path / "out"),
                                "--no-plots"], cwd=ROOT, env=dict(os.environ, PYTHONPATH=str(ROOT)), text=True,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)
    try:
        line = process.stdout.readline()
        started = time.perf_counter() - start
        stat = Path(f"/proc/{process.pid}/stat").read_text()
        fields = stat[stat.rindex(")") + 2:].split()
        cpu = (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    finally:
        os.kill(process.pid, signal.SIGTERM)
        _, error = process.communicate(timeout=60)
    benchmark.extra_info.update(started_s=started, cpu_s=cpu, load_average=load)
    benchmark.pedantic(lambda: None, rounds=1)
    print(f"\n100,000 cases: checked and started in {started:.1f} s wall, {cpu:.1f} s CPU of the command (load average "
          f"{load[0]:.1f}); {line.strip()!r}; stderr: {error.strip()[:300]!r}")
    assert "100000 cases" in line and "checking 100000 cases" in error
    assert cpu <= 10.0
    if quiet():
        assert started <= 10.0


def test_a_dry_run_checks_and_judges_2000_cases_within_2_ms_each(benchmark, tmp_path):
    """``sweep --dry-run`` of 2000 Monte Carlo samples of the eigenaxis demo's noise seed (two
    planners that say their duration by planning the slew): the study's check and ``validate``'s
    findings of every case, parent CPU time per case (imports done before). Before each case was
    parsed twice where the check parsed it and planned its slews again: 2.5 ms a case (5.01 s),
    1.1 ms since (2.19 s), medians of 3 at load 3 on the shared 2-core machine, 2026-12-05."""
    import contextlib
    import io

    from scenarios.cli.commands import main

    path = tmp_path / "demo2000.yaml"
    path.write_text(yaml.safe_dump({"study": "demo2000", "scenario": str(ROOT / "scenarios" / "eigenaxis_demo.yaml"),
                                    "monte_carlo": {"samples": 2000, "seed": 1, "dispersions": {
                                        "simulation.sensor_noise.seed": "case_seed"}}}))
    load = os.getloadavg()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        main(["sweep", str(path), "--dry-run"])  # imports and first builds
    cpu = []
    for _ in range(3):
        start = time.process_time()
        with contextlib.redirect_stdout(io.StringIO()) as out, contextlib.redirect_stderr(io.StringIO()):
            assert main(["sweep", str(path), "--dry-run"]) == 0
        cpu.append((time.process_time() - start) / 2000)
        assert "2000 cases, checked; nothing run, nothing written" in out.getvalue()
    per_case = float(np.median(cpu))
    benchmark.extra_info.update(cpu_per_case_s=cpu, load_average=load)
    benchmark.pedantic(lambda: None, rounds=1)
    print(f"\n2000-case dry run: {per_case * 1e3:.2f} ms of CPU a case {np.round(np.array(cpu) * 1e3, 2)} "
          f"(load average {load[0]:.1f})")
    assert per_case <= 2e-3


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


@contextlib.contextmanager
def dask_cluster(workers: int = 2):
    pytest.importorskip("distributed")
    from distributed import Client
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    commands = [[sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", str(port),
                 "--no-dashboard"]]
    commands += [[sys.executable, "-m", "distributed.cli.dask_worker", address, "--nthreads", "1", "--no-nanny",
                  "--no-dashboard", "--memory-limit", "0", "--host", "127.0.0.1"]] * workers
    started = [subprocess.Popen(command, cwd=ROOT, env=env, start_new_session=True, stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL) for command in commands]
    try:
        with Client(address, timeout="60s") as client:
            client.wait_for_workers(workers, timeout=120)
        yield address
    finally:
        for process in started:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(process.pid, signal.SIGTERM)
        for process in started:
            try:
                process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.killpg(process.pid, signal.SIGKILL)


def test_a_local_dask_cluster_is_within_1_2x_of_the_local_pool(benchmark, tmp_path):
    from scenarios.study.engine import connect_scheduler
    was_quiet, load = quiet(), os.getloadavg()
    start_forkserver()
    pool, dask = [], []
    with dask_cluster(2) as address:
        cluster = connect_scheduler(address)
        try:
            timed_sweep(cheap_study(tmp_path, 5000, 20), tmp_path / "warm", cluster=cluster)
            for r in range(2):
                path = cheap_study(tmp_path, 20_000 * (r + 1))
                pool.append(timed_sweep(path, tmp_path / f"pool{r}", workers=2)[0])
                wall, _, results = timed_sweep(path, tmp_path / f"dask{r}", cluster=cluster)
                assert results.missing == 0
                dask.append(wall)
        finally:
            cluster.close()
    ratio = float(np.median(dask) / np.median(pool))
    benchmark.extra_info.update(local_pool_s=pool, dask_s=dask, ratio=ratio, load_average=load)
    benchmark.pedantic(lambda: None, rounds=1)
    print(f"\n{CASES} cheap cases (load average {load[0]:.1f}): local pool of 2 {np.median(pool):.2f} s "
          f"{np.round(pool, 2)}, Dask cluster of 2 worker processes {np.median(dask):.2f} s {np.round(dask, 2)}: "
          f"{ratio:.2f}x")
    if was_quiet:
        assert ratio <= 1.2
