"""The sign-off record at the top of a run's ``report.html`` (:mod:`scenarios.output.report.record`).

A reader signing off a slew must read, outside the plots: slewbench's version, the date and the
seed; that the closed loop integrates a truth model and in which keys it differs from the design;
the sensors and the estimator; and per requirement the bound and, per row, the value achieved and
the verdict. The oracles are the scenario's own numbers (written here), the installed version, and
the simulated rates (the peak ‖ω‖ computed here by NumPy).
"""
from __future__ import annotations

import json
import re

import numpy as np
import pytest

import scenarios
from scenarios.output.provenance import package_version
from scenarios.output.report.run import run_report

SEED = 4242
SCENARIO = {
    "name": "record <test> & co",
    "spacecraft": {"inertia": [10.0, 9.0, 6.0], "wheels": {"max_torque": 0.05, "max_momentum": 1.0}},
    "maneuver": {"duration": 60.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.70710678, 0, 0, 0.70710678], "omega": [0, 0, 0]}},  # 90 deg about z
    "planners": [{"name": "eigenaxis", "label": "smooth", "options": {"profile": "smooth"}}],
    "controller": {"name": "augmented_quaternion_feedback"},
    "environment": {"disturbance_torque": [1e-6, 0.0, 0.0]},
    "truth": {"spacecraft": {"inertia": [10.5, 8.7, 6.2]}, "wheels": {"max_torque": 0.045, "torque_noise": 1e-5},
              "disturbance": {"constant": [2e-6, 0.0, 0.0]}},
    "simulation": {"sample_time": 0.2, "duration": 70.0, "sensor_noise": {"seed": SEED},
                   "sensors": {"gyro": {"arw_deg_per_sqrt_h": 0.02},
                               "star_tracker": {"noise_arcsec": [6, 6, 40]}},
                   "estimator": {"type": "mekf", "initial_attitude_sigma_deg": 0.05,
                                 "initial_bias_sigma_deg_per_h": 3.0}},
    # the rate bound is met (a 90 deg slew in 60 s peaks near 0.05 rad/s); the final error bound of
    # 1e-9 deg is not, with sensor noise and a truth model
    "requirements": {"actuators": {"margin": 0.2}, "rate": {"max": 0.09},
                     "final": {"after_s": 5.0, "error_deg": 1e-9}},
}


def embedded(html: str) -> dict:
    match = re.search(r'<script type="application/json" id="slewbench-data">(.*?)</script>', html, re.DOTALL)
    assert match, "the page embeds no data"
    return json.loads(match.group(1))


def table(data: dict, key: str) -> list[dict]:
    """A table of the page as one dict per row, by column name."""
    spec = data["tables"][key]
    names = [c["key"] for c in spec["columns"]]
    return [dict(zip(names, row)) for row in spec["rows"]]


@pytest.fixture(scope="module")
def results():
    return scenarios.run(scenarios.parse_scenario(SCENARIO))


@pytest.fixture(scope="module")
def page(results):
    return run_report(results)


def test_the_record_comes_before_the_rows(page):
    headings = re.findall(r'<h2 id="[^"]*">([^<]*)</h2>', page)
    assert headings[:5] == ["Provenance", "Plant", "Sensors and estimator", "Requirements", "Rows"]
    assert "record &lt;test&gt; &amp; co" in page and "record <test>" not in page  # escaped


def test_the_provenance_names_the_version_the_date_and_the_seed(results, page):
    entries = {row["entry"]: row["value"] for row in table(embedded(page), "provenance")}
    assert entries["slewbench"] == package_version()
    assert entries["seeds.simulation.sensor_noise.seed"] == str(SEED)
    assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", entries["date_utc"])
    assert "scenario" not in entries


def test_the_plant_shows_each_truth_key_beside_the_design(page):
    rows = {row["truth key"]: (row["design model"], row["truth model"]) for row in table(embedded(page), "plant")}
    assert rows == {"truth.spacecraft.inertia": ("[10.0, 9.0, 6.0]", "[10.5, 8.7, 6.2]"),
                    "truth.wheels.max_torque": ("0.05", "0.045"),
                    "truth.wheels.torque_noise": ("-", "1e-05"),  # the design model has no torque noise
                    "truth.disturbance.constant": ("[1e-06, 0.0, 0.0]", "[2e-06, 0.0, 0.0]")}
    assert "truth model that differs from the design model" in page


def test_the_sensors_and_the_estimator_are_named(page):
    assert "In the loop: gyro (Gyro), star tracker (StarTracker), estimator (Mekf)." in page
    settings = {row["setting"]: row["value"] for row in table(embedded(page), "sensors")}
    assert settings["simulation.sensors.star_tracker.noise_arcsec"] == "[6, 6, 40]"
    assert settings["simulation.estimator.type"] == "mekf"


def test_each_bound_is_shown_with_the_value_achieved_and_the_verdict(results, page):
    data = embedded(page)
    words = {row["requirement"]: row["bound"] for row in table(data, "requirements")}
    assert "0.09 rad/s" in words["rate"] and "1e-09 deg" in words["final"] and "80 %" in words["actuators"]
    lines = {(row["scope"], row["requirement"], row["quantity"]): row for row in table(data, "requirement-scores")}
    simulation = results.rows[0].simulation
    rate = lines[("closed loop", "rate", "peak_rate")]
    assert (rate["required"], rate["unit"], rate["this quantity within its bound"],
            rate["requirement (all its quantities)"]) == ("≤ 0.09", "rad/s", "yes", "met")
    assert rate["achieved"] == pytest.approx(np.max(np.linalg.norm(simulation.omega, axis=1)), rel=1e-12)
    final = lines[("closed loop", "final", "worst_error_deg")]
    assert (final["required"], final["unit"], final["this quantity within its bound"],
            final["requirement (all its quantities)"]) == ("≤ 1e-09", "deg", "no", "broken")
    assert final["achieved"] > 1e-9
    torque = lines[("reference", "actuators", "wheels_torque")]
    assert (torque["required"], torque["unit"], torque["requirement (all its quantities)"]) == ("≤ 0.8", "–", "met")
    assert results.rows[0].status == "violated"


def test_a_run_on_the_design_model_says_so():
    plain = {key: value for key, value in SCENARIO.items() if key not in ("truth", "environment")}
    plain["simulation"] = {"sample_time": 0.5, "duration": 60.0}
    plain["requirements"] = {}
    page = run_report(scenarios.run(scenarios.parse_scenario(plain)))
    assert "The closed loop integrates the design model (the scenario has no truth section)." in page
    assert "No sensor models and no estimator" in page
    words = {row["requirement"]: row["bound"] for row in table(embedded(page), "requirements")}
    assert list(words) == ["actuators"]  # the one every scenario carries, unstated
    assert words["actuators"].endswith("(not stated: margin 0)") and "100 %" in words["actuators"]


def test_the_record_reads_the_scoring_bounds():
    """The record may not import the scoring (it loads the model): its copy must be the scoring's.
    (Its verdicts are the scores' own ``met``: ``tests/test_requirement_verdicts.py``.)"""
    from scenarios.output.report.record import UNREALISED_SHARE
    from scenarios.requirements.scoring import SCOPE_WORDS, UNREALISED_TOLERANCE

    for scope, words in SCOPE_WORDS.items():
        assert words == scope.replace("_", " ")  # the record's scope words
    assert UNREALISED_SHARE == UNREALISED_TOLERANCE
