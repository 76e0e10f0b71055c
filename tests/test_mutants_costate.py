"""The co-state planner's time budget across its two cold starts, with the solver replaced by a
recorder (an injected failure): the deadline is the wall clock at the plan's start plus
``options.time_limit``, the other cold start gets the same deadline, and is not tried once it has
passed."""
from __future__ import annotations

import time

from planners import PLANNERS
from planners.costate import tpbvp
from tests.test_costate_time_limit import fast_spin

FAILED = "solve_bvp failed at continuation fraction 0.125: injected"


def recorded(monkeypatch, out_of_time: bool) -> list[float | None]:
    """Replace the solver by one that fails at once, recording each call's deadline; the clock
    reads past every deadline when ``out_of_time``."""
    deadlines: list[float | None] = []

    def solve(system, nodes, steps, tolerance, max_nodes, guess=None, min_step=1e-3, deadline=None):
        deadlines.append(deadline)
        return None, None, 1, FAILED

    monkeypatch.setattr(tpbvp, "solve", solve)
    if out_of_time:
        monkeypatch.setattr(tpbvp, "_out_of_time", lambda deadline: deadline is not None)
    return deadlines


def test_the_deadline_is_the_clock_at_the_start_plus_the_time_limit_for_both_cold_starts(monkeypatch):
    """A spin at 1 rad/s: the eigenaxis cold start fails (injected), then the coast start is tried
    with the same deadline, ``time.monotonic()`` at the plan plus 30 s."""
    deadlines = recorded(monkeypatch, out_of_time=False)
    before = time.monotonic()
    reference = PLANNERS["costate_tpbvp"]({"time_limit": 30.0}).plan(fast_spin(1.0))
    after = time.monotonic()
    assert reference.status == "failed" and FAILED in reference.message
    assert len(deadlines) == 2 and deadlines[0] is not None
    assert before + 30.0 <= deadlines[0] <= after + 30.0
    assert deadlines[1] == deadlines[0]


def test_no_second_cold_start_after_the_deadline(monkeypatch):
    """The first cold start fails and the clock has passed the deadline: the coast start is not
    tried, and the message says so and names the option."""
    deadlines = recorded(monkeypatch, out_of_time=True)
    reference = PLANNERS["costate_tpbvp"]({"time_limit": 30.0}).plan(fast_spin(1.0))
    assert len(deadlines) == 1
    assert reference.status == "failed"
    assert "was not tried (time limit reached)" in reference.message
    assert "options.time_limit = 30 s" in reference.message


def test_without_a_time_limit_there_is_no_deadline(monkeypatch):
    deadlines = recorded(monkeypatch, out_of_time=False)
    PLANNERS["costate_tpbvp"]({"time_limit": None}).plan(fast_spin(1.0))
    assert deadlines == [None, None]
