"""The shipped ``eo_microsat_pyramid_keep_outs.yaml``: it validates without a plausibility warning,
runs, and its numbers hold against hand geometry and closed forms.

* The eigenaxis slew turns the star tracker about body z through the Sun: the boresight is at
  23.40 deg elevation (0.3971 / |b|), the Sun at the epoch at 23.43 deg (its declination, within the
  Sun's 0.39 deg per day drift of the solstice), so the path passes within a few hundredths of a
  degree of it and the margin to the 35 deg cone is about -35 deg: violated.
* Its quintic profile peaks at 1.875 theta / T = 1.875 (2 pi / 3) / 90 s = 0.043633 rad/s, 0.8727
  of the 0.05 rad/s bound.
* Collocation plans the Sun's cone 1 deg wider (cone_margin_deg), so its reference clears it by
  1 deg; the closed loop meets every requirement (ok), and the magnetorquers beside the pyramid,
  which span three axes, are asked nothing.
"""
from __future__ import annotations

import json
import math
import warnings
from pathlib import Path

import scenarios
from scenarios.schema.plausibility import plausibility_warnings

PATH = Path(__file__).resolve().parents[1] / "scenarios" / "eo_microsat_pyramid_keep_outs.yaml"


def test_the_eo_microsatellite_scenario_runs_and_its_numbers_hold():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        scenario = scenarios.load(PATH)
    assert plausibility_warnings(scenario) == []
    rows = {row["label"]: row for row in json.loads(scenarios.run(scenario).to_json())["rows"]}
    assert {label: row["status"] for label, row in rows.items()} == {"collocation": "ok", "eigenaxis": "violated"}

    eigenaxis = rows["eigenaxis"]["requirements"]
    assert not eigenaxis["reference"]["st_sun"]["met"]
    assert -35.0 < eigenaxis["reference"]["st_sun"]["min_margin_deg"] < -34.9
    assert math.isclose(eigenaxis["reference"]["rate"]["ratio"], 1.875 * (2 * math.pi / 3) / 90.0 / 0.05, rel_tol=1e-3)

    collocation = rows["collocation"]["requirements"]
    assert math.isclose(collocation["reference"]["st_sun"]["min_margin_deg"], 1.0, abs_tol=0.01)
    assert collocation["closed_loop"]["st_sun"]["min_margin_deg"] > 0.5
    assert collocation["reference"]["actuators"]["magnetorquers_dipole"] == 0.0
    assert collocation["reference"]["actuators"]["wheels_momentum"] <= 0.9
    assert collocation["closed_loop"]["final"]["met"]
