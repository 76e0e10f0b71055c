"""A closed loop that turns more than TURN_PER_SAMPLE_RAD between two samples has its pointing
requirements, where met, say that the margin between samples is interpolated (the row's caveat):
the coarse nutating case of tests/test_check_h6_held_torque_between_samples.py is scored met there
while its held-torque motion enters the cone."""
from __future__ import annotations

import copy

import numpy as np
import pytest
import yaml

import scenarios
from scenarios.requirements.scoring import TURN_PER_SAMPLE_RAD, coarse_samples
from scenarios.schema.loader import load
from tests.test_check_h6_held_torque_between_samples import SCENARIO


def test_the_turn_per_sample_is_the_larger_end_rate_times_the_interval():
    t = np.array([0.0, 1.0, 3.0])
    omega = np.array([[0.1, 0.0, 0.0], [0.0, 0.2, 0.0], [0.0, 0.0, 0.2]])  # turns 0.2 and 0.4 rad
    assert coarse_samples(t, omega, limit=0.41) == ""
    words = coarse_samples(t, omega, limit=0.39)
    assert "0.4 rad" in words and "(1.0 to 3.0 s)" in words


@pytest.mark.filterwarnings("ignore::scenarios.errors.PlausibilityWarning")  # the coarse, fast case is deliberate
@pytest.mark.parametrize("sample_time, caveat", [(2.0, True), (0.25, False)])
def test_a_met_pointing_requirement_between_coarse_samples_carries_the_caveat(tmp_path, sample_time, caveat):
    spec = copy.deepcopy(SCENARIO)
    spec["simulation"]["sample_time"] = sample_time
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(spec, sort_keys=False))
    row = scenarios.run(load(tmp_path / "s.yaml")).rows[0]
    scored = row.requirements["closed_loop"]["thin"]
    assert scored["met"] or not caveat  # the coarse case is (wrongly) met: the caveat is its warning
    # the turn from the loop's own rates: the largest body rate times the sample time
    turn = sample_time * np.max(np.linalg.norm(row.simulation.omega, axis=1))
    assert (turn > TURN_PER_SAMPLE_RAD) == caveat
    assert ("thin (closed loop) met, but the closed loop turns up to" in row.message) == caveat, row.message
