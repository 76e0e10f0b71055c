"""``cl.settling_time_s``'s band follows ``requirements.final.error_deg`` when
``simulation.settling_tolerance_deg`` is unset: a row missing a 0.05 deg requirement read
'settled at 89 s' against the 0.5 deg default. A value the user gives is kept."""
from __future__ import annotations

import copy
from pathlib import Path

import pytest
import yaml

from scenarios.schema.loader import parse_scenario

ROOT = Path(__file__).resolve().parents[1]
KEEP_OUT = yaml.safe_load((ROOT / "scenarios" / "cubesat_12u_sun_keep_out.yaml").read_text())


def band(final: dict | None, **simulation) -> float:
    data = copy.deepcopy(KEEP_OUT)
    data.setdefault("simulation", {}).pop("settling_tolerance_deg", None)
    data["simulation"].update(simulation)
    data.setdefault("requirements", {}).pop("final", None)
    if final is not None:
        data["simulation"]["duration"] = data["maneuver"]["duration"] + 20.0
        data["requirements"]["final"] = final
    return parse_scenario(data).simulation.settling_tolerance_deg


def test_the_band_defaults_to_the_final_requirements_error():
    assert band({"after_s": 5, "error_deg": 0.05}) == pytest.approx(0.05)
    assert band({"after_s": 5, "error_deg": 0.05}, settling_tolerance_deg=None) == pytest.approx(0.05)


def test_an_explicit_band_is_kept_and_without_the_requirement_it_is_half_a_degree():
    assert band({"after_s": 5, "error_deg": 0.05}, settling_tolerance_deg=0.5) == pytest.approx(0.5)
    assert band({"after_s": 5, "error_deg": 0.05}, settling_tolerance_deg=1.0) == pytest.approx(1.0)
    assert band(None) == pytest.approx(0.5)
    assert band({"after_s": 5, "rate": 1e-4}) == pytest.approx(0.5)  # a final requirement on the rate only
