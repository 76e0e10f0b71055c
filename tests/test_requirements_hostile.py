"""A hostile new user's input and the defects a review of the requirements found.

Bad input through the command line (exit 2, the message naming the YAML path, the value and what
was expected, never a traceback) for the cases the schema tests do not already hold; and one test
per defect found in review, each failing before its fix.
"""
from __future__ import annotations

import contextlib
import copy
import io
from pathlib import Path

import numpy as np
import pytest
import yaml

from scenarios.cli.commands import main
from scenarios.requirements.scoring import endpoint_violations
from scenarios.schema.loader import parse_scenario

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "cubesat_12u_sun_keep_out.yaml"


def base() -> dict:
    """The 12U CubeSat Sun keep-out scenario as data (the epoch as text, as a user writes it)."""
    data = yaml.safe_load(SCENARIO.read_text())
    data["epoch"] = "2027-03-20T12:00:00Z"
    return data


def limb_scenario() -> dict:
    """The 12U case with a 10 deg keep-out about the Earth's limb. The orbit (RAAN 90 deg, argument
    of latitude 0) starts on the inertial y axis, so nadir is -y; the star tracker's boresight
    [0.5, -0.866, 0] at the initial attitude (identity) lies 30 deg from it."""
    data = base()
    data["requirements"]["pointing"] = {"st_earth": {"sensor": "star_tracker", "keep_out": "earth_limb",
                                                     "angle_deg": 10}}
    return data


def test_an_end_point_inside_a_grown_cone_names_the_cone_it_breaks():
    """The Earth's disc from 500 km subtends asin(R / (R + h)) = 68.02 deg: a 10 deg keep-out about
    the limb is a 78.02 deg cone about nadir. A boresight 30 deg from nadir breaks it by 48.02 deg,
    and the message must name the 78 deg cone, not a '10 deg keep-out cone' that 30 deg would meet."""
    scenario = parse_scenario(limb_scenario())
    radius = 6378.137e3
    disc = np.rad2deg(np.arcsin(radius / (radius + 500e3)))
    assert disc == pytest.approx(68.0187, abs=1e-4)
    messages = endpoint_violations(scenario.problem)
    assert len(messages) == 1, messages
    message = messages[0]
    assert "initial attitude" in message and "st_earth" in message
    assert f"{30.0 - 10.0 - disc:.3g} deg" in message, message       # the margin, -48.0 deg
    assert f"{10.0 + disc:.4g} deg keep-out cone" in message, message  # 78.02 deg, the cone broken
    assert "10 deg about earth_limb" in message, message               # what the user wrote
    assert "the 10 deg keep-out cone" not in message, message
