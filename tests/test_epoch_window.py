"""The epoch against the ephemeris: one check, at ``epoch``, whichever section reads the ephemeris
first (an attitude target toward the Sun, a requirement's direction), naming the run as written and
the limit it crosses; a run that fits near the ephemeris' end is accepted (the tabulation window,
longer than the run, is clipped to the ephemeris).

The limits are DE421's span as the docs state it (1960-01-01 to 2200-01-01 UTC), written here by
hand, not read from the code.
"""
from __future__ import annotations

import copy

import numpy as np
import pytest

from scenarios.errors import ScenarioError
from scenarios.schema.loader import parse_scenario

BASE = {
    "name": "eo12u",
    "epoch": "2027-06-21T10:30:00Z",
    "spacecraft": {
        "inertia": [0.25, 0.28, 0.12],
        "wheels": {"axes": [[0.8164966, 0, 0.5773503], [0, 0.8164966, 0.5773503],
                            [-0.8164966, 0, 0.5773503], [0, -0.8164966, 0.5773503]],
                   "max_torque": 0.003, "max_momentum": 0.02, "spin_inertia": 2.0e-5},
        "sensors": {"camera": {"boresight": [0, 0, 1]}, "solar_panel": {"boresight": [0, 1, 0]},
                    "star_tracker": {"boresight": [0.5, 0.0, -0.8660254]}},
    },
    "orbit": {"altitude_km": 500, "inclination_deg": 97.4, "raan_deg": 78.5, "arg_latitude_deg": 38.13},
    "maneuver": {
        "duration": 90.0,
        "initial": {"q": {"quaternion": [1, 0, 0, 0], "frame": "lvlh"}, "omega": [0, 0, 0]},
        "final": {"q": {"point": {"sensor": "camera", "at": {"ground": {"lat_deg": 43.6, "lon_deg": 1.44}},
                                  "secondary": {"sensor": "solar_panel", "toward": "sun"}}},
                  "omega": [0, 0, 0]},
    },
    "planners": [{"name": "eigenaxis"}],
    "controller": {"name": "augmented_quaternion_feedback"},
    "simulation": {"sample_time": 1.0, "duration": 110.0},
    "requirements": {"pointing": {"st_sun": {"sensor": "star_tracker", "keep_out": "sun", "angle_deg": 30}}},
}


def scenario(epoch: str, target_toward_sun: bool = True) -> dict:
    data = copy.deepcopy(BASE)
    data["epoch"] = epoch
    if not target_toward_sun:  # the requirement's Sun direction is then the first consumer
        data["maneuver"]["final"]["q"] = {"quaternion": [0.0, 0.0, 0.0, 1.0], "frame": "lvlh"}
    return data


def refusal(data: dict) -> ScenarioError:
    with pytest.raises(ScenarioError) as raised:
        parse_scenario(data)
    return raised.value


@pytest.mark.parametrize("toward_sun", [True, False])
def test_an_epoch_after_the_ephemeris_is_reported_at_epoch_with_the_run_as_written(toward_sun):
    """The Sun-pointing target read the ephemeris first and was reported at
    maneuver.final.q.point.secondary.toward, 'for 90 s' (maneuver.duration; the run is 110 s)."""
    error = refusal(scenario("2250-01-01T00:00:00Z", toward_sun))
    assert error.path == "epoch", error
    text = str(error)
    assert "2250-01-01T00:00:00" in text and "2200-01-01" in text and "after its end" in text, text
    assert "simulation.duration = 110 s" in text and "90 s" not in text, text


@pytest.mark.parametrize("toward_sun", [True, False])
def test_a_run_crossing_the_ephemeris_end_names_its_end_and_the_latest_epoch(toward_sun):
    """23:59:00 + 110 s = 00:00:50 the next day, past 2200-01-01; the latest start is 23:58:10."""
    error = refusal(scenario("2199-12-31T23:59:00Z", toward_sun))
    assert error.path == "epoch", error
    text = str(error)
    assert "ends at 2200-01-01T00:00:50Z" in text and "2199-12-31T23:58:10Z or earlier" in text, text
    assert "simulation.duration = 110 s" in text, text


def test_an_epoch_before_the_ephemeris_says_before_its_start():
    error = refusal(scenario("1959-12-31T23:59:59Z"))
    assert error.path == "epoch" and "before its start, 1960-01-01" in str(error), error


def test_a_run_that_fits_near_the_ephemeris_end_is_accepted():
    """23:57:00 + 110 s ends at 23:58:50, inside DE421. The directions were tabulated over twice the
    manoeuvre plus a minute (240 s) and the scenario was refused; the window is now clipped to the
    ephemeris' end (180 s from the epoch), never below the run."""
    loaded = parse_scenario(scenario("2199-12-31T23:57:00Z"))
    (constraint,) = loaded.problem.pointing
    assert constraint.times[-1] == pytest.approx(180.0)
    assert constraint.times[-1] >= 110.0
    # the latest epoch the run fits: the window is the run itself
    latest = parse_scenario(scenario("2199-12-31T23:58:10Z"))
    assert latest.problem.pointing[0].times[-1] == pytest.approx(110.0)
    # far from the end, the window is unchanged: twice the manoeuvre plus a minute
    assert parse_scenario(scenario("2027-06-21T10:30:00Z")).problem.pointing[0].times[-1] == pytest.approx(240.0)
    assert np.all(np.isfinite(constraint.directions))
