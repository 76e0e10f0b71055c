"""The star tracker's exclusions as the user gives them: NumPy numbers taken as numbers, a single
exclusion where a tuple is due refused in words, the order of ``exclusion_deg`` as written (the
exclusions, their messages and the validate summary), and the ``blinded`` time-series column
absent without a star tracker and documented with the others.

Oracles: the values and the YAML order the tests write, not the code under test.
"""
from __future__ import annotations

import copy
import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import yaml

from ocp.estimation import Exclusion, Gyro, Magnetometer, StarTracker
from scenarios.cli.commands import main
from scenarios.errors import ScenarioError
from scenarios.output.writer import write_timeseries
from scenarios.schema.loader import parse_scenario

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "scenarios" / "spin_repoint_estimator.yaml"
EPOCH = "2025-06-21T00:00:00Z"
PATH = "simulation.sensors.star_tracker.exclusion_deg"
SUN = np.array([0.0, 1.0, 0.0])


def scenario_data(exclusion: dict, epoch: str | None = EPOCH) -> dict:
    data = yaml.safe_load(EXAMPLE.read_text())
    if epoch is not None:
        data["epoch"] = epoch
    data["simulation"]["sensors"]["star_tracker"]["exclusion_deg"] = exclusion
    return data


# --- numbers -------------------------------------------------------------------------------------

@pytest.mark.parametrize("value", [np.int64(1), np.int32(0), np.float32(0.5), np.float64(0.25), 2, 0.75, math.pi])
def test_an_exclusion_takes_any_real_number_as_a_float(value):
    exclusion = Exclusion("sun", value, SUN)
    assert type(exclusion.half_angle) is float and exclusion.half_angle == float(value)


@pytest.mark.parametrize("value", [True, np.bool_(False), "0.5", None, [0.5]])
def test_an_exclusion_refuses_what_is_not_a_number_saying_so(value):
    with pytest.raises(ValueError, match=r"half-angle must be a number of rad in \[0, pi\], got") as raised:
        Exclusion("sun", value, SUN)
    assert type(value).__name__ in str(raised.value)


@pytest.mark.parametrize("value", [np.float32(4.0), np.int64(-1), -0.1, math.inf, math.nan])
def test_an_exclusion_refuses_a_number_out_of_range(value):
    with pytest.raises(ValueError, match=r"the sun exclusion half-angle must be in \[0, pi\] rad, got"):
        Exclusion("sun", value, SUN)


def test_the_other_sensor_numbers_take_numpy_numbers_and_refuse_bools():
    gyro = Gyro(arw=np.float32(0.5), rrw=np.int64(0))
    assert (type(gyro.arw), gyro.arw, type(gyro.rrw), gyro.rrw) == (float, 0.5, float, 0.0)
    assert Magnetometer(noise=np.float32(0.25)).noise == 0.25
    tracker = StarTracker(noise=[1e-5] * 3, rate=np.int64(2))
    assert type(tracker.rate) is float and tracker.rate == 2.0
    np.testing.assert_array_equal(tracker.available(np.arange(0.0, 2.0, 0.25)), [1, 0, 1, 0, 1, 0, 1, 0])
    with pytest.raises(ValueError, match="rate must be a finite positive number of Hz or None, got True"):
        StarTracker(noise=[1e-5] * 3, rate=True)
    with pytest.raises(ValueError, match="arw must be a finite non-negative number"):
        Gyro(arw=np.bool_(True))


# --- a single exclusion --------------------------------------------------------------------------

def test_a_single_exclusion_where_a_tuple_is_due_is_refused_in_words():
    exclusion = Exclusion("sun", 0.5, SUN)
    with pytest.raises(ValueError, match=r"exclusions must be a tuple of Exclusion, got a single one \('sun'\); "
                                         r"write exclusions=\(Exclusion\(\.\.\.\),\)"):
        StarTracker(noise=[1e-5] * 3, exclusions=exclusion)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="exclusions must be a tuple of Exclusion, got 5"):
        StarTracker(noise=[1e-5] * 3, exclusions=5)  # type: ignore[arg-type]
    moon = Exclusion("moon", 0.2, [1.0, 0.0, 0.0])
    tracker = StarTracker(noise=[1e-5] * 3, exclusions=[exclusion, moon])  # type: ignore[arg-type]
    assert tracker.exclusions == (exclusion, moon)


# --- the order written ---------------------------------------------------------------------------

@pytest.mark.parametrize("written", [{"moon": 20, "sun": 30}, {"sun": 30, "moon": 20}])
def test_the_exclusions_follow_the_order_written(written):
    tracker = parse_scenario(scenario_data(dict(written))).simulation.sensors.star_tracker
    assert [item.name for item in tracker.exclusions] == list(written)
    assert [round(math.degrees(item.half_angle), 9) for item in tracker.exclusions] == list(written.values())


@pytest.mark.parametrize("written, epoch, first", [
    ({"moon": 190, "sun": -5}, EPOCH, "moon"),
    ({"sun": -5, "moon": 190}, EPOCH, "sun"),
    ({"moon": 20, "sun": 30}, None, "moon"),  # both need the epoch: the first written is named
    ({"sun": 30, "moon": 20}, None, "sun"),
])
def test_the_first_bad_exclusion_written_is_the_one_named(written, epoch, first):
    with pytest.raises(ScenarioError) as raised:
        parse_scenario(copy.deepcopy(scenario_data(written, epoch)))
    assert f"{PATH}.{first}" in str(raised.value)


@pytest.mark.parametrize("written, words", [
    ({"moon": 12.5, "sun": 30}, "blinded within 12.5 deg of the moon, 30 deg of the sun"),
    ({"sun": 30, "moon": 12.5}, "blinded within 30 deg of the sun, 12.5 deg of the moon"),
])
def test_the_validate_summary_lists_the_exclusions_as_written(written, words, tmp_path, capsys):
    path = tmp_path / "blinded.yaml"
    path.write_text(yaml.safe_dump(scenario_data(written), sort_keys=False))
    assert main(["validate", str(path)]) == 0
    lines = [line for line in capsys.readouterr().out.splitlines() if "sensors:" in line]
    assert lines == [f"  sensors: gyro, star tracker (outages 50-60 s; {words}); estimator: MEKF"]


# --- the time-series column ----------------------------------------------------------------------

def test_without_a_star_tracker_there_is_no_blinded_column(tmp_path):
    t = np.arange(3.0)
    sim = SimpleNamespace(t=t, x=np.hstack([np.tile([1.0, 0, 0, 0], (3, 1)), np.zeros((3, 3))]),
                          q=np.tile([1.0, 0, 0, 0], (3, 1)), wheel_momentum=np.zeros((3, 0)),
                          applied_torque=np.zeros((2, 3)), sensors=None, sensor_state=None, blinded=None)
    path = tmp_path / "row.csv"
    write_timeseries(SimpleNamespace(label="r", simulation=sim, reference=None), path)  # type: ignore[arg-type]
    assert "blinded" not in path.read_text().splitlines()[0].split(",")


def test_the_outputs_page_documents_the_blinded_column():
    page = (ROOT / "docs" / "outputs.rst").read_text()
    section = page[page.index("``timeseries/<row>.csv``"):page.index("PNG figures")]
    assert "``blinded``" in section and "bit ``i``" in section
