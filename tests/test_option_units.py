"""The unit an option's description gives (``[rad/s]``) is a unit, never an index the text quotes.

A reviewer saw ``slewbench list --options collocation`` give ``switch_refinement`` the unit
``"switch_refinement"``: its description mentions ``stats["switch_refinement"]`` before any unit.
The oracle: a unit never holds a quote.
"""
from __future__ import annotations

import pytest

from controllers import CONTROLLERS
from planners import PLANNERS
from scenarios.schema.keys import _unit, option_entries

REGISTERED = [*(("planner", name, PLANNERS[name]) for name in PLANNERS),
              *(("controller", name, CONTROLLERS[name]) for name in CONTROLLERS)]


@pytest.mark.parametrize(("kind", "name", "entry"), REGISTERED, ids=[f"{k}-{n}" for k, n, _ in REGISTERED])
def test_no_option_unit_is_a_quoted_index(kind, name, entry):
    for option in option_entries(entry.Options):
        assert '"' not in option.unit and "'" not in option.unit, (kind, name, option.name, option.unit)


def test_an_index_before_the_unit_is_skipped_and_the_unit_found():
    assert _unit('recorded in stats["time_error"]; the bound [rad/s]') == "rad/s"
    assert _unit("stats['x'] only") == ""
    assert _unit("a torque [N m]") == "N m"
