"""What the default seeds cost (issue 30, part 5), side by side in one process, alternating.

``collocation`` with default options (``seed_planners: auto``: the eigenaxis warm start and the
spin extremal's reference) against the warm start alone (``seed_planners: []``), after the NLP
builds (the first plan of each, timed apart):

* the spin paper's minimum energy: the default reaches the best known optimum 0.018548 (the warm
  start alone stops at 0.093244); target: the plan within 100 ms after the build;
* Bilimoria & Wie's minimum time (3.2431) and the full-inertia one (7.6826 s): the same optima;
  the ratio of the times is the seeds' price (the full inertia has no spin extremal: 1.0).

Run: ``python -m pytest tests/benchmarks/test_bench_seeds.py -o addopts="" -s``.
"""
from __future__ import annotations

import time

import numpy as np
import pytest
from test_bench_min_time import bilimoria_wie, full_inertia, spin_paper_case

from ocp.cache import SolverCache
from planners import PLANNERS

PAIRS = 9
"""Alternating pairs of plans timed per case (medians quoted)."""

CASES = {
    "spin_min_energy": (spin_paper_case, {}, 0.018548, 0.093244),
    "bilimoria_wie_min_time": (bilimoria_wie, {"objective": "min_time"}, 3.2431, 3.2431),
    "full_inertia_min_time": (full_inertia, {"objective": "min_time"}, 7.6826, 7.6826),
}


def timed(planner, problem):
    start = time.perf_counter()
    reference = planner.plan(problem)
    return time.perf_counter() - start, reference


@pytest.mark.parametrize("case", sorted(CASES))
def test_default_seeds_side_by_side(case):
    make, options, best, alone_best = CASES[case]
    problem = make()
    default = PLANNERS["collocation"](options, cache=SolverCache())
    alone = PLANNERS["collocation"]({**options, "seed_planners": []}, cache=SolverCache())
    build_default, first = timed(default, problem)
    build_alone, _ = timed(alone, problem)
    times: dict[str, list[float]] = {"default": [], "alone": []}
    for k in range(PAIRS):
        order = (("default", default), ("alone", alone)) if k % 2 == 0 else (("alone", alone), ("default", default))
        for name, planner in order:
            elapsed, reference = timed(planner, problem)
            times[name].append(elapsed)
            value = reference.duration if options.get("objective") == "min_time" else reference.stats["objective"]
            assert round(value, 4 if options else 6) == (best if name == "default" else alone_best), reference.message
    median = {name: float(np.median(values)) for name, values in times.items()}
    ratio = float(np.median(np.divide(times["default"], times["alone"])))
    print(f"\n{case}: default {1e3 * median['default']:.1f} ms [{1e3 * min(times['default']):.1f}, "
          f"{1e3 * max(times['default']):.1f}], alone {1e3 * median['alone']:.1f} ms "
          f"[{1e3 * min(times['alone']):.1f}, {1e3 * max(times['alone']):.1f}], ratio {ratio:.2f}; first plans "
          f"(with the builds) {1e3 * build_default:.0f} and {1e3 * build_alone:.0f} ms; seeds {first.stats['seeds']}"
          + ("; target 100 ms" if case == "spin_min_energy" else ""))
