"""Threads sharing one planner and one ``SolverCache``: a CasADi function called from two threads
at once crashes the process (segfault), so the cache keeps one set of entries per thread. The
scenario runs in a subprocess (a crash there fails the test instead of killing pytest) with a short
switch interval, so that the threads interleave inside the solvers."""
import gc
import os
import pickle
import subprocess
import sys
import textwrap
import threading
from pathlib import Path

import pytest

from ocp import SolverCache

ROOT = Path(__file__).resolve().parents[1]

SCENARIO = textwrap.dedent("""
    import sys, warnings
    import numpy as np
    warnings.simplefilter("ignore")
    sys.setswitchinterval(1e-5)
    from concurrent.futures import ThreadPoolExecutor
    from ocp import ReactionWheels, SolverCache, Spacecraft, quat
    from planners import PLANNERS, ManeuverProblem

    name, n = sys.argv[1], 8
    rng = np.random.default_rng(7)
    specs = [(rng.uniform(20, 170), rng.normal(size=3)) for _ in range(n)]
    spacecraft = Spacecraft([19.5, 19.0, 12.6], wheels=ReactionWheels.from_body_axes(max_torque=0.1))
    cache = SolverCache()
    planner = PLANNERS[name]({"duration": "scenario"} if name == "shape_polynomial" else {}, cache=cache)

    def job(i):
        angle, axis = specs[i]
        problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.from_axis_angle(axis, np.deg2rad(angle)),
                                  120.0, omegaf=np.zeros(3))
        reference = planner.plan(problem)
        assert reference.ok, reference.message
        s = reference.sample(np.linspace(0.0, reference.duration, 61))
        return np.hstack([s.q, s.omega, s.omega_dot, s.torque])

    serial = [job(i) for i in range(n)]
    with ThreadPoolExecutor(2) as pool:
        threaded = list(pool.map(job, range(n)))
    print("mismatches", sum(not np.array_equal(a, b) for a, b in zip(serial, threaded)))
""")


@pytest.mark.parametrize("name", ["collocation", "shape_polynomial"])
def test_threads_sharing_a_cache_give_the_single_thread_answers(name, tmp_path):
    script = tmp_path / "threads.py"
    script.write_text(SCENARIO)
    done = subprocess.run([sys.executable, "-X", "faulthandler", str(script), name], cwd=ROOT, capture_output=True,
                          check=False, text=True, timeout=600, env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert done.returncode == 0, done.stderr[-3000:]
    assert done.stdout.strip().splitlines()[-1] == "mismatches 0"


def test_each_thread_has_its_own_entries():
    cache = SolverCache()
    main = cache.get("solver", object)
    assert cache.get("solver", object) is main
    seen = []
    thread = threading.Thread(target=lambda: seen.extend([cache.get("solver", object), cache.get("solver", object)]))
    thread.start()
    thread.join()
    assert seen[0] is seen[1] and seen[0] is not main  # built once in the thread, never the main thread's
    assert (cache.builds, cache.hits) == (2, 2)
    seen.clear()
    del thread
    gc.collect()
    assert len(cache) == 1  # the ended thread's entries went with it
    cache.clear()
    assert len(cache) == 0 and cache.get("solver", object) is not main


def test_a_pickled_cache_is_empty():
    # its entries are built solvers (megabytes each): the other process builds them again
    cache = SolverCache()
    cache.get("k", lambda: [1, 2])
    copy = pickle.loads(pickle.dumps(cache))
    assert len(copy) == 0 and (copy.builds, copy.hits) == (0, 0)
    assert copy.get("k", lambda: [3]) == [3] and copy.builds == 1  # built again on its first look-up
    assert cache.get("k", list) == [1, 2] and len(cache) == 1  # the original keeps its entries
