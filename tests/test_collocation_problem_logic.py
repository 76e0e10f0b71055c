"""The problem side and the search bookkeeping of ``collocation``, checked against their documented
rules worked by hand: a keep-out cone is widened by ``cone_margin_deg`` and a keep-in cone narrowed
(``planners.collocation.problem.parse_cone``); ``stats["seeds"]`` counts and labels starts as
:func:`planners.collocation.strategy.seed_record` documents; a fallback's result counts the failed
solve's starts first (:func:`planners.collocation.strategy.merged`)."""
from __future__ import annotations

import numpy as np
import pytest

from ocp.errors import InvalidOption
from ocp.nlp.solve import NLPResult, StartResult
from planners.collocation.problem import parse_cone
from planners.collocation.strategy import merged, seed_record

CONE = {"boresight": [0, 0, 1], "direction": [1, 0, 0]}
MARGIN = float(np.deg2rad(1.0))


@pytest.mark.parametrize("keep_out, angle_deg, refused", [
    (True, 179.5, True),    # widened by 1 deg: past 180, no cone left
    (True, 0.5, False),     # widened to 1.5 deg: a cone
    (False, 0.5, True),     # narrowed by 1 deg: below 0
    (False, 179.5, False),  # narrowed to 178.5 deg
])
def test_the_margin_widens_a_keep_out_cone_and_narrows_a_keep_in_one(keep_out, angle_deg, refused):
    spec = {**CONE, "angle_deg": angle_deg}
    if refused:
        with pytest.raises(InvalidOption) as error:
            parse_cone(spec, keep_out, MARGIN, where="keep_out[0]")
        assert error.value.option == "keep_out[0].angle_deg" and "tightened" in error.value.message
    else:
        cone = parse_cone(spec, keep_out, MARGIN, where="keep_out[0]")
        assert cone.angle == pytest.approx(np.deg2rad(angle_deg))  # stored as given, not tightened


def _start(f: float, converged: bool, iterations: int = 5) -> StartResult:
    return StartResult("Solve_Succeeded" if converged else "Infeasible_Problem_Detected", f, iterations, 0.1,
                       0.0 if converged else 1.0, converged)


def _result(starts: list, best: int | None) -> NLPResult:
    f = starts[best].f if best is not None else np.inf
    return NLPResult(None, f, None, best is not None, "ok" if best is not None else "failed", "",
                     sum(s.iterations for s in starts), 0.1 * len(starts), best, starts)


def test_agreed_starts_are_converged_ones_whose_objective_matches_the_best():
    """A failed start stopped at the best objective's value does not agree (its point is infeasible):
    of [1.0 ok, 1.0 failed, 1.0 + 1e-9 ok, 1.5 ok], 2 agree (the documented relative 1e-6)."""
    result = _result([_start(1.0, True), _start(1.0, False), _start(1.0 + 1e-9, True), _start(1.5, True)], 0)
    assert seed_record(result, 4, ["a", "b", "c", "d"]) == {"tried": 4, "agreed": 2, "best_from": "a"}


def test_fallbacks_are_tried_only_while_no_start_has_converged():
    """Two starts and one fallback label: the third solve is the fallback when both starts failed, and a
    restart from the best point when one converged (seed_record's documented order)."""
    failed = _result([_start(2.0, False), _start(2.0, False), _start(1.0, True)], 2)
    assert seed_record(failed, 2, ["eigenaxis", "spin", "fallback"])["best_from"] == "fallback"
    converged = _result([_start(2.0, True), _start(2.0, False), _start(1.0, True)], 2)
    assert seed_record(converged, 2, ["eigenaxis", "spin", "fallback"])["best_from"] == "restart 1"


def test_a_merged_result_counts_the_failed_solves_starts_first():
    """The fallback's best start, index 1 of its own, is index 3 after the failed solve's two."""
    first = _result([_start(3.0, False, 7), _start(3.0, False, 8)], None)
    second = _result([_start(2.0, True, 4), _start(1.0, True, 6)], 1)
    both = merged(first, second)
    assert both.best_start == 3 and both.starts[both.best_start].f == 1.0
    assert both.iterations == 25 and len(both.starts) == 4
