"""``simulation.duration`` has the manoeuvre's cap: 1e12 s with an epoch was an internal error (an
OverflowError adding it to the epoch; found by a review, 2026-12-03), now a bad scenario naming
the key, the value and the limit."""
from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from scenarios.errors import ScenarioError
from scenarios.schema.loader import load

BASE = Path(__file__).resolve().parents[1] / "scenarios" / "cubesat_12u_sun_keep_out.yaml"


@pytest.mark.parametrize("duration", [1e12, 1e300])
def test_a_huge_simulation_duration_is_refused_at_its_key(tmp_path: Path, duration: float) -> None:
    data = yaml.safe_load(BASE.read_text())
    assert data.get("epoch"), "the case needs an epoch (the overflow was epoch + duration)"
    data.setdefault("simulation", {})["duration"] = duration
    path = tmp_path / "huge.yaml"
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(ScenarioError) as raised:
        load(path)
    assert raised.value.path == "simulation.duration"
    assert "1e+08" in str(raised.value)


def test_validate_notes_a_window_that_ends_before_the_slew(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    """simulation.duration 1 s with maneuver.duration 120 s: run noted the cut per row, validate said
    nothing; a minimum-time row (its slew ends sooner) is not named."""
    from scenarios.cli.commands import main
    data = yaml.safe_load((BASE.parent / "eigenaxis_demo.yaml").read_text())
    data["simulation"]["duration"] = 1.0
    path = tmp_path / "short.yaml"
    path.write_text(yaml.safe_dump(data))
    assert main(["validate", str(path)]) == 0
    said = capsys.readouterr().out
    assert ("  note: simulation.duration (1 s) ends before maneuver.duration (120 s), the slew of smooth, "
            "bang-coast-bang: the closed loop stops while it is under way, and its closed-loop metrics (final error, "
            "settling) are those at 1 s") in said.splitlines(), said
    data["simulation"]["duration"] = 120.0
    path.write_text(yaml.safe_dump(data))
    assert main(["validate", str(path)]) == 0
    assert "note: simulation.duration" not in capsys.readouterr().out
