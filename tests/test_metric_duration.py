"""``duration_s`` is the reference's manoeuvre time T, in closed loop too, never the simulated
horizon; its description says so (the documentation's metric table is generated from it).

The case: the user's 12U minimum-time slew (``test_honour_environment_and_rate``), whose T the
planner chooses (34.8 s), simulated for 60 s (``simulation.duration``) in a 90 s manoeuvre.
"""
from __future__ import annotations

import copy

import numpy as np

import scenarios
from ocp.metrics import METRIC_INFO
from tests.test_honour_environment_and_rate import SCENARIO


def test_closed_loop_duration_is_the_references_T_not_the_simulated_horizon():
    data = copy.deepcopy(SCENARIO)
    data["environment"]["gravity_gradient"] = False
    row = scenarios.run(scenarios.parse_scenario(data)).rows[0]
    assert row.status == "ok", row.message
    horizon = float(row.simulation.t[-1])
    assert horizon == 60.0 and not np.isclose(row.reference.duration, horizon)
    assert row.closed_loop_metrics["duration_s"] == row.reference.duration
    assert row.reference_metrics["duration_s"] == row.reference.duration


def test_the_description_says_closed_loop_duration_is_the_references_T():
    meaning = METRIC_INFO["duration_s"].meaning
    assert "in closed loop too" in meaning and "not the simulated horizon" in meaning
