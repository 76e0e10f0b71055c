"""Gaps the mutation check found in the requirement fields' declaration
(:func:`scenarios.requirements.fields.field_info`): a bare field name is the declared field of
that name, whatever requirement declares it; only a name no requirement declares is read as an
actuator quantity's. The units are the documented ones, written out here."""
import pytest

from scenarios.requirements.fields import field_info


@pytest.mark.parametrize("field, requirement, unit", [
    ("peak_rate", "rate", "rad/s"), ("ratio", "rate", "–"), ("min_margin_deg", "pointing", "deg"),
    ("worst_error_deg", "final", "deg"), ("worst_rate_error", "final", "rad/s"), ("from_s", "final", "s"),
    ("rate_jump", "actuators", "rad/s"), ("unrealised_torque", "actuators", "N m"),
    ("wheels_torque", "actuators", "–"), ("wheels_torque_time_s", "actuators", "s"),
])
def test_a_bare_field_is_its_declaration(field, requirement, unit):
    info = field_info(field)
    assert (info.field, info.requirement, info.unit) == (field, requirement, unit)
