"""The co-state planner's time budget (``options.time_limit``): a fast initial spin, whose
continuation crawls for minutes before failing (1 rad/s for 200 s: 101-192 s, 2 rad/s: 534 s,
measured 2026-12-03), now fails within its budget with a message naming the option; the budget
stops the solver between ``solve_bvp`` calls, before the continuation and before the refinement."""
import time

import numpy as np
import pytest

from ocp import Spacecraft, Torquers, quat
from ocp.errors import OptionsError
from planners import PLANNERS, ManeuverProblem
from planners.costate import tpbvp
from planners.costate.systems import MinimumEnergySystem
from planners.costate.tpbvp import OUT_OF_TIME, solve

XTE_INERTIA, XTE_ANGLE, XTE_T = np.diag([5621.0, 4547.0, 2364.0]), np.deg2rad(150.0), 60.0


def xte_system():
    """Rest to rest, 150 deg about the principal axis x in 60 s: solved in well under a second."""
    case = ManeuverProblem(Spacecraft(XTE_INERTIA, torquers=Torquers(50.0)), q0=quat.IDENTITY, omega0=np.zeros(3),
                           qf=quat.from_rotation_vector(np.array([XTE_ANGLE, 0.0, 0.0])), duration=XTE_T,
                           omegaf=np.zeros(3))
    return MinimumEnergySystem(case, XTE_T)


def fast_spin(rate):
    """The spin re-pointing problem of the benchmark (0.2 rad/s, solved) at a faster spin about x."""
    return ManeuverProblem(Spacecraft([19.5, 19.0, 12.6], torquers=Torquers(0.1)), [1, 0, 0, 0], [rate, 0, 0],
                           [0, 0, 1, 0], 200.0)


def test_a_spent_deadline_starts_no_solve_bvp_call():
    system = xte_system()
    solution, t_f, stages, failure = solve(system, 60, 3, 1e-8, 5000)
    assert failure is None and solution is not None and stages > 0  # the control: it solves
    solution, t_f, stages, failure = solve(system, 60, 3, 1e-8, 5000, deadline=time.monotonic() - 1.0)
    assert solution is None and t_f is None and stages == 0
    assert failure is not None and failure.startswith(OUT_OF_TIME) and "fraction 0.000" in failure


def test_a_deadline_spent_in_the_continuation_skips_the_refinement(monkeypatch):
    # The loose solve makes one check per continuation stage; a clock that runs out right after
    # them stops the solver before the refinement to 1e-8, which is never started.
    system = xte_system()
    _, _, continuation, failure = solve(system, 60, 3, 1e-5, 5000)
    assert failure is None
    checks = []
    monkeypatch.setattr(tpbvp, "_out_of_time", lambda deadline: checks.append(deadline) or len(checks) > continuation)
    solution, t_f, stages, failure = solve(system, 60, 3, 1e-8, 5000, deadline=0.0)
    assert solution is None and t_f is None and stages == continuation
    assert failure is not None and failure.startswith(f"{OUT_OF_TIME} before refining") and "1e-08" in failure


def test_a_fast_spin_fails_within_its_time_limit():
    # 1 rad/s for 200 s (32 turns): both cold starts fail after 101-192 s without a budget. With 2 s
    # the plan stops after the solve_bvp call under way at 2 s: an eigenaxis stage (under 1 s) or
    # the first torque-free-coast stage (4-8 s measured).
    reference = PLANNERS["costate_tpbvp"]({"time_limit": 2.0}).plan(fast_spin(1.0))
    assert reference.status == "failed"
    assert reference.plan_time_s < 20.0, f"{reference.plan_time_s:.1f} s"
    assert OUT_OF_TIME in reference.message and "options.time_limit = 2 s" in reference.message


def test_the_time_limit_is_in_its_range_or_null():
    assert PLANNERS["costate_tpbvp"]({"time_limit": None}).options.time_limit is None
    assert PLANNERS["costate_tpbvp"]().options.time_limit == 120.0
    with pytest.raises(OptionsError, match=r"options.time_limit: expected a finite number > 0 and <= 86400, got 0"):
        PLANNERS["costate_tpbvp"]({"time_limit": 0})
    with pytest.raises(OptionsError, match=r"options.time_limit: expected a finite number > 0 and <= 86400, got 1000000"):
        PLANNERS["costate_tpbvp"]({"time_limit": 1e6})
