"""The benchmark suite: attitude planning problems with stated data, sources and best known
optima (:mod:`~scenarios.bench.suite`, the versioned index ``suite.yaml`` beside the scenario
files in ``problems/``), the leaderboard that ``slewbench bench`` writes from running them
(:mod:`~scenarios.bench.leaderboard`), and the peers run beside slewbench's planners
(:mod:`scenarios.bench.peers`).

May import: :mod:`ocp`, :mod:`planners`, :mod:`scenarios.errors`, :mod:`scenarios.schema`,
:mod:`scenarios.output`, :mod:`scenarios.runner` and :mod:`scenarios.bench` itself.
"""
from __future__ import annotations

from scenarios.bench.suite import SUITE_FILE, BenchProblem, Suite, load_suite

__all__ = ["SUITE_FILE", "BenchProblem", "Suite", "load_suite"]
