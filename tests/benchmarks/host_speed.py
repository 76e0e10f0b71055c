"""Is it the code or the host? The spin paper's minimum-energy plan (the 60 ms target of issue 16)
timed alternately with a fixed CPU-bound reference workload, in one process.

On the shared 2-core VM the host's speed moves by 1.5x within a minute with nothing else running
in the VM: three runs 20 s apart gave reference medians 21.7, 28.8 and 36.2 ms and plan medians
52.7, 63.7 and 80.1 ms, while plan/reference stayed at 2.2-2.4 (with the IPOPT coarse seed; 1.8-2.1
with the FATROP seed, stop 24). Quote a plan time with the reference time of the same run.

Run: ``python tests/benchmarks/host_speed.py [pairs]`` (default 60); one line: medians and 10th/90th
percentiles of the plan, of the reference and of their ratio, and their correlation.
"""
from __future__ import annotations

import pathlib
import sys
import time

import numpy as np

sys.path[:0] = [str(pathlib.Path(__file__).parents[2]), str(pathlib.Path(__file__).parent)]

from test_bench_min_time import spin_paper_case

from planners import PLANNERS


def reference_workload() -> int:
    """A fixed pure-Python loop (about 22 ms on the VM at its fast speed)."""
    total = 0
    for i in range(400_000):
        total += i * i
    return total


def main() -> None:
    pairs = int(sys.argv[1]) if len(sys.argv) > 1 else 60
    problem = spin_paper_case()
    planner = PLANNERS["collocation"]({"intervals": 50, "warm_start": "spin_extremal"})
    planner.plan(problem)  # the build
    plan, reference = np.empty(pairs), np.empty(pairs)
    for k in range(pairs):
        tic = time.perf_counter()
        planner.plan(problem)
        plan[k] = time.perf_counter() - tic
        tic = time.perf_counter()
        reference_workload()
        reference[k] = time.perf_counter() - tic
    plan, reference = 1e3 * plan, 1e3 * reference
    ratio = plan / reference
    def spread(values: np.ndarray, digits: int) -> str:
        p10, p50, p90 = np.percentile(values, [10, 50, 90])
        return f"median {p50:.{digits}f} (p10 {p10:.{digits}f}, p90 {p90:.{digits}f})"

    print(f"plan {spread(plan, 1)} ms; reference {spread(reference, 1)} ms; plan/reference {spread(ratio, 2)}; "
          f"correlation {np.corrcoef(plan, reference)[0, 1]:.2f}")


if __name__ == "__main__":
    main()
