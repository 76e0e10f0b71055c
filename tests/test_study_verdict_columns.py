"""A requirement's verdict column (``<scope>.req.<name>.met``, true or false) given where a study asks
for a number (a summary metric, a robustness threshold): one error naming the YAML path, the value
given, what the column is and the number columns of that requirement (the fields documented in
docs/guide/requirements.rst: a pointing requirement's ``min_margin_deg``, the rate's ``peak_rate``,
the final one's ``worst_error_deg``), whatever the threshold's value."""
from __future__ import annotations

import pytest

import scenarios
from scenarios.study.spec import parse_study
from tests.test_requirement_verdicts import scenario


def _error(**extra) -> str:
    with pytest.raises(scenarios.ScenarioError) as raised:
        parse_study({"study": "verdicts", "scenario": scenario([0.0, 0.0, 0.0]), **extra})
    return str(raised.value)


@pytest.mark.parametrize("bound, shown", [(True, "True"), ("true", "'true'"), ({"at_most": 1}, "{'at_most': 1}"),
                                          (0.5, "0.5")])
def test_a_threshold_on_a_verdict_names_the_path_the_value_and_the_numbers(bound, shown):
    # `true` (or any bound) on cl.req.st.met: refused as a verdict before its value is read as a number
    message = _error(robustness={"thresholds": {"cl.req.st.met": bound}})
    assert message.startswith("robustness.thresholds.cl.req.st.met: 'cl.req.st.met' is whether requirement 'st' "
                              "is met in the closed loop"), message
    assert f"(given the bound {shown})" in message and "expected a number column such as" in message
    assert "cl.req.st.min_margin_deg" in message and "ref.req.st.min_margin_deg" not in message
    assert "expected a number, got" not in message


@pytest.mark.parametrize("column, number", [("cl.req.st.met", "cl.req.st.min_margin_deg"),
                                            ("ref.req.rate.met", "ref.req.rate.peak_rate"),
                                            ("cl.req.final.met", "cl.req.final.worst_error_deg")])
def test_a_summary_verdict_names_the_path_and_the_requirements_numbers(column, number):
    message = _error(summary=["cl.rms_error_deg", column])
    assert message.startswith(f"summary[1]: {column!r} is whether requirement"), message
    assert "not a number to summarise" in message and number in message and "given the bound" not in message


@pytest.mark.parametrize("column, kind, scope", [("ref.req.final.met", "final", "reference")])
def test_a_verdict_of_a_scope_that_never_scores_the_requirement_says_so(column, kind, scope):
    # a final requirement is scored in the closed loop only: no number columns to offer in the
    # reference (the message listed none: "such as " and nothing)
    message = _error(robustness={"thresholds": {column: True}})
    assert f"({kind}) is not scored in the {scope}" in message and "(given the bound True)" in message
    assert not message.rstrip().endswith("such as")


def test_the_closed_loops_actuator_verdict_names_its_wheel_momentum():
    # the closed loop's wheels are scored against their momentum limit: its number columns offered
    message = _error(robustness={"thresholds": {"cl.req.actuators.met": True}})
    assert message.startswith("robustness.thresholds.cl.req.actuators.met: 'cl.req.actuators.met' is whether "
                              "requirement 'actuators' is met in the closed loop"), message
    assert "cl.req.actuators.<quantity>" in message and "ref.req.actuators" not in message
