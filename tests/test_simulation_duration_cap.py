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
