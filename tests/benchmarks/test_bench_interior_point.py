"""The compiled interior point (ocp.nlp.interior_point) against IPOPT on the coarse minimum-time starts,
side by side in one run (issue 30).

For each case, the coarse (8-interval) multistart's starts as ``collocation`` (default options,
``objective: min_time``) gives them to its solver are solved alternately by IPOPT (the NLP's own
``nlpsol``, with ``COARSE_MIN_TIME_OPTIONS``: what solved them before) and by the interior point
(``COARSE_INTERIOR_POINT``, the same options), ROUNDS pairs a start; the test prints per start the
iterations, objectives, median wall times with their spread (min..max) and the median of the pairwise
ratios, and asserts the same optimum (objectives within 1e-7 relative: IPOPT relaxes its bounds by
1e-8, the interior point does not) and iterations within 3 of IPOPT's.

Run: ``python -m pytest tests/benchmarks/test_bench_interior_point.py -o addopts="" -s``.

Measured 2026-12-05 (quiet host, load 0.7, 9 rounds; wall, median [min..max]):

=========================  =====================  =========  =========  =================
case, start                iterations IPOPT / ip   IPOPT      ip         ip / IPOPT
=========================  =====================  =========  =========  =================
Bilimoria & Wie, 0         22 / 23                 15.5 ms    5.3 ms     0.34 [0.29..0.36]
Bilimoria & Wie, 1         24 / 24                 16.0 ms    5.2 ms     0.32 [0.28..0.35]
full inertia, 0            14 / 15                 9.7 ms     3.8 ms     0.39 [0.36..0.40]
XTE, 0                     32 / 33                 30.4 ms    8.3 ms     0.28 [0.26..0.28]
XTE, 1                     38 / 38                 30.4 ms    8.7 ms     0.29 [0.28..0.57]
=========================  =====================  =========  =========  =================

``test_first_plans_of_new_problems_against_ipopt``: 190 ms [145..481] against 192 ms [162..529] (the
interior point's build, 4 ms, is lost in the NLPs' builds).
"""
import os
import time

import numpy as np
import pytest

from ocp.fast_call import buffered
from ocp.nlp.sparse_ldl import available
from planners import PLANNERS
from tests.benchmarks.test_bench_min_time import bilimoria_wie, full_inertia, xte
from tests.test_interior_point import coarse_starts

ROUNDS = int(os.environ.get("SLEWBENCH_ROUNDS", "9"))
CASES = {"bilimoria_wie": bilimoria_wie, "full_inertia": full_inertia, "xte": xte}




def _ipopt(solver, arguments):
    """IPOPT's solve of the same start, through the buffers as ``solve_multistart`` calls it."""
    function = buffered(solver.nlpsol)
    names = [solver.nlpsol.name_in(i) for i in range(solver.nlpsol.n_in())]
    for target, name, default in zip(function.inputs, names, (solver.nlpsol.default_in(i) for i in range(len(names)))):
        value = arguments.get(name)
        target[:] = default if value is None else np.asarray(value, dtype=float).ravel()
    function.evaluate()
    stats = function.stats()
    return float(function.outputs[1][0]), int(stats["iter_count"]), function.outputs[0].copy()


def _spread(values):
    values = np.asarray(values) * 1e3
    return f"{np.median(values):6.2f} ms [{values.min():.2f}..{values.max():.2f}]"


@pytest.mark.skipif(not available()[0], reason=available()[1])
@pytest.mark.parametrize("case", sorted(CASES))
def test_side_by_side_ipopt(case):
    _, starts = coarse_starts(CASES[case]())
    assert starts, "no coarse start reached the interior point"
    for index, (solver, arguments) in enumerate(starts):
        ours, theirs = [], []
        for _ in range(ROUNDS):
            tic = time.perf_counter()
            f_ipopt, it_ipopt, x_ipopt = _ipopt(solver, arguments)
            theirs.append(time.perf_counter() - tic)
            tic = time.perf_counter()
            result = solver(**arguments)
            ours.append(time.perf_counter() - tic)
        stats = solver.stats()
        ratio = np.asarray(ours) / np.asarray(theirs)
        print(f"\n{case} start {index}: IPOPT {it_ipopt} iterations f = {f_ipopt:.9f} {_spread(theirs)}; "
              f"{stats['solver']} {stats['iter_count']} iterations f = {float(result['f'][0]):.9f} {_spread(ours)}; "
              f"ip/IPOPT {np.median(ratio):.2f} [{ratio.min():.2f}..{ratio.max():.2f}]; "
              f"load {os.getloadavg()[0]:.2f}")
        assert stats["solver"] == "interior_point"
        assert float(result["f"][0]) == pytest.approx(f_ipopt, rel=1e-7)
        assert abs(stats["iter_count"] - it_ipopt) <= 3


def _fresh_problems(count, seed=11):
    """``count`` random rest-to-rest minimum-time slews (principal moments 8-15 kg m², 1 N m
    torquers, 30-170° about random axes): each a new model, so each plan builds its NLPs anew."""
    from ocp import Spacecraft, Torquers, quat
    from planners import ManeuverProblem

    rng = np.random.default_rng(seed)
    return [ManeuverProblem(Spacecraft(np.diag(rng.uniform(8.0, 15.0, 3)), torquers=Torquers(1.0)), quat.IDENTITY,
                            np.zeros(3), quat.from_axis_angle(rng.normal(size=3), np.deg2rad(rng.uniform(30, 170))),
                            30.0, omegaf=np.zeros(3)) for _ in range(count)]


@pytest.mark.skipif(not available()[0], reason=available()[1])
def test_first_plans_of_new_problems_against_ipopt(monkeypatch):
    """The cost a user meets: the first plan of a new problem, every build included (a solver cache
    of its own: the NLPs, the interior point's functions), with the interior point and with IPOPT for
    the coarse starts (the stand-in withheld), alternating; CPU time per plan, the same durations."""
    import planners.collocation.planner as planner_module
    from ocp import SolverCache

    with_ip, without, durations = [], [], []
    for index, problem in enumerate(_fresh_problems(ROUNDS)):
        for use in ((True, False) if index % 2 == 0 else (False, True)):  # either first in turn
            if not use:
                monkeypatch.setattr(planner_module, "for_nlpsol", lambda *arguments, **keywords: None)
            tic = time.process_time()
            reference = PLANNERS["collocation"]({"objective": "min_time"}, cache=SolverCache()).plan(problem)
            (with_ip if use else without).append(time.process_time() - tic)
            durations.append(reference.duration)
            monkeypatch.undo()
    ratio = np.asarray(with_ip) / np.asarray(without)
    print(f"\nfirst plans: interior point {_spread(with_ip)}, IPOPT {_spread(without)}; "
          f"ratio {np.median(ratio):.2f} [{ratio.min():.2f}..{ratio.max():.2f}]; load {os.getloadavg()[0]:.2f}")
    assert np.allclose(durations[0::2], durations[1::2], rtol=1e-6)
