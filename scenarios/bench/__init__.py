"""The benchmark suite: attitude planning problems with stated data, sources and best known
optima (:mod:`~scenarios.bench.suite`, the versioned index ``suite.yaml`` beside the scenario
files in ``problems/``), the leaderboard that ``slewbench bench`` writes from running them
(:mod:`~scenarios.bench.leaderboard`), and the peers run beside slewbench's planners
(:mod:`scenarios.bench.peers`).

May import: :mod:`ocp`, :mod:`planners`, :mod:`scenarios.errors`, :mod:`scenarios.schema`,
:mod:`scenarios.output`, :mod:`scenarios.requirements` (a plan's own status), :mod:`scenarios.runner` and
:mod:`scenarios.bench` itself. Its names
are imported on first use.
"""
from __future__ import annotations

from scenarios._faces import lazy_face

_HOMES = {"BenchProblem": "scenarios.bench.suite",
          "SUITE_FILE": "scenarios.bench.suite",
          "Suite": "scenarios.bench.suite",
          "load_suite": "scenarios.bench.suite"}

__all__ = ["SUITE_FILE", "BenchProblem", "Suite", "load_suite"]

__getattr__, __dir__ = lazy_face(__name__, _HOMES)
