"""The slew-table fit where the table has no time: entries not ok, angles past the table, start
attitudes the table does not hold; and the table's messages about them.

Oracles: the eigenaxis bang-bang time ``T = 2 √(θ max_i |e_i|)`` of a unit-inertia body with
``|u_i| <= 1`` N m per body axis (on a principal axis ``2 √θ``), tabulated exactly, so the fit
reproduces it wherever every entry it uses is ok (``g = T / √(θ s(e)) = 2``); the keep-out geometry
(the camera's boresight turned by the slew, by :mod:`ocp.quat`) for which entries are impossible;
quaternion products from :mod:`ocp.quat` for the start attitudes.
"""
from __future__ import annotations

import json
import math
import warnings
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest
import yaml

from ocp import quat
from scenarios.cli.commands import main
from scenarios.slewtable.compute import SlewTable, TablePart, compute_table, fit_entries
from scenarios.slewtable.files import write_plot
from scenarios.slewtable.fit import IDENTITY_TOLERANCE, SlewTimeFit, load_fit
from scenarios.slewtable.spec import parse_table_spec

BODY_AXES = np.array([[0, 0, 1], [0, 0, -1], [1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0]], dtype=float)
ANGLES_DEG = [30.0, 90.0, 120.0, 180.0]
I = (1.0, 0.0, 0.0, 0.0)


def bang_bang(axis, angle: float) -> float:
    """Eigenaxis bang-bang time [s] of a unit-inertia body, |u_i| <= 1 N m, about ``axis`` by ``angle`` [rad]."""
    e = np.asarray(axis, dtype=float)
    return 2.0 * math.sqrt(angle * float(np.max(np.abs(e / np.linalg.norm(e)))))


def _part(statuses: dict[tuple[int, int], str], axes: np.ndarray = BODY_AXES,
          angles_deg: list[float] = ANGLES_DEG) -> TablePart:
    part = TablePart.empty(axes, angles_deg)
    for i, axis in enumerate(axes):
        for k, angle in enumerate(angles_deg):
            part.status[i][k] = statuses.get((i, k), "ok")
            part.slew_time_s[i, k] = bang_bang(axis, math.radians(angle)) if part.status[i][k] == "ok" else math.nan
    return part


def _fit(statuses: dict[tuple[int, int], str], meta: dict | None = None, **kwargs) -> SlewTimeFit:
    fit, _ = fit_entries(_part(statuses, **kwargs), np.eye(3), np.eye(3), meta)
    assert fit is not None
    return fit


def _both(fit: SlewTimeFit, axis, angle_deg: float, q0=I) -> tuple[float, float]:
    """The scalar and the vectorised call, for the slew from ``q0`` about body ``axis``."""
    qf = quat.product(np.asarray(q0, dtype=float), quat.from_axis_angle(axis, math.radians(angle_deg)))
    scalar = fit(list(q0), qf.tolist())
    many = float(fit.slew_time_many(np.array([q0], dtype=float), qf.reshape(1, 4))[0])
    return scalar, many


# --- entries that are not ok ----------------------------------------------------------------------

@pytest.mark.parametrize("status", ["failed", "crashed", "violated"])
def test_the_fit_has_no_time_around_an_entry_that_is_not_ok(status):
    """The user's keep-out table: +z at 90 deg not ok; the fit gave 2.4274 s there and 2.2985 s /
    2.5469 s at 80 / 100 deg (filled along the axis)."""
    fit = _fit({(0, 1): status})
    near_z = [0.1, 0.2, 0.97]
    for axis, angle in (([0, 0, 1], 90.0), ([0, 0, 1], 80.0), ([0, 0, 1], 100.0), ([0, 0, 1], 60.0),
                        (near_z, 95.0), (near_z, 40.0)):
        scalar, many = _both(fit, axis, angle)
        assert math.isnan(scalar) and math.isnan(many), (axis, angle, scalar, many)
    # cells without that entry: the table's time (the closed form it holds), scalar and vectorised alike
    for axis, angle in (([0, 0, 1], 30.0), ([0, 0, 1], 20.0), ([0, 0, 1], 120.0), ([0, 0, 1], 150.0),
                        ([0, 0, 1], 180.0), ([0, 0, -1], 90.0), ([1, -1, -1], 60.0), ([1, 2, -3], 100.0),
                        ([1, 0, 0], 60.0), ([1, 0, 0], 90.0), ([0.6, 0.8, 0.0], 75.0), (near_z, 150.0)):
        expected = bang_bang(axis, math.radians(angle))
        scalar, many = _both(fit, axis, angle)
        assert scalar == pytest.approx(expected, rel=1e-9), (axis, angle)
        assert many == pytest.approx(expected, rel=1e-9), (axis, angle)


def test_an_infeasible_entry_is_inf_at_itself_and_nan_around_it():
    fit = _fit({(0, 1): "infeasible"})
    assert _both(fit, [0, 0, 1], 90.0) == (math.inf, math.inf)
    for angle in (80.0, 100.0):
        assert all(math.isnan(v) for v in _both(fit, [0, 0, 1], angle))
    # an infeasible entry beside a failed one: unknown there, not proven impossible
    mixed = _fit({(0, 1): "infeasible", (2, 1): "failed"})
    assert _both(mixed, [0, 0, 1], 90.0) == (math.inf, math.inf)
    assert all(math.isnan(v) for v in _both(mixed, [1, 0, 1], 90.0))


def test_a_fit_with_gaps_round_trips_through_fit_json(tmp_path):
    fit = _fit({(0, 1): "infeasible", (3, 2): "failed"})
    fit.save(tmp_path / "fit.json")
    data = json.loads((tmp_path / "fit.json").read_text())
    assert data["status"][0][1] == "infeasible" and data["times_s"][0][1] is None
    loaded = load_fit(tmp_path)
    for axis, angle in (([0, 0, 1], 90.0), ([0, 0, 1], 80.0), ([-1, 0, 0], 150.0), ([1, 2, 3], 100.0)):
        np.testing.assert_array_equal(_both(loaded, axis, angle), _both(fit, axis, angle))


@pytest.mark.parametrize("note", ["1 entries not ok filled along their axis",
                                  "1 of 6 axes left out (fewer than 2 ok angles)"])
def test_a_fit_json_that_filled_entries_is_refused(tmp_path, note):
    """fit.json written before the gaps: its times hold fills the table did not find."""
    data = _fit({}).to_dict()
    del data["status"]
    data["meta"]["note"] = note
    (tmp_path / "fit.json").write_text(json.dumps(data))
    with pytest.raises(ValueError, match="filled the entries that are not ok"):
        load_fit(tmp_path / "fit.json")


def test_fit_entries_keeps_every_axis_and_says_how_many_entries_are_not_ok():
    """An axis left out of the fit (fewer than 2 ok angles) was covered by its neighbours' times."""
    part = _part({(0, k): "failed" for k in range(4)} | {(2, 1): "infeasible"})
    fit, note = fit_entries(part, np.eye(3), np.eye(3))
    assert fit is not None and len(fit.axes) == 6
    assert "5 entries not ok (1 infeasible)" in note
    assert all(math.isnan(v) for v in _both(fit, [0.1, 0.1, 1.0], 150.0))  # about the failed axis
    one, note = fit_entries(_part({(2, 1): "failed"}), np.eye(3), np.eye(3))
    assert one is not None and note.startswith("1 entry not ok (0 infeasible)")
    none, note = fit_entries(_part({}, axes=BODY_AXES[:1]), np.eye(3), np.eye(3))
    assert none is None and "1 axis (4 or more" in note


def test_held_out_errors_compare_only_where_the_fit_has_a_time(tmp_path):
    """A NaN from a gap made the held-out maximum NaN (and fit.json unwritable)."""
    from scenarios.slewtable.compute import held_out_errors
    fit = _fit({(0, 1): "failed"})
    held = TablePart.empty(np.array([[0.1, 0.2, 0.97], [1.0, -1.0, -1.0] / np.sqrt(3.0)]), [60.0, 150.0])
    for i, axis in enumerate(held.axes):
        for k, angle in enumerate(held.angles_deg):
            held.status[i][k] = "ok"
            held.slew_time_s[i, k] = 1.01 * bang_bang(axis, math.radians(angle))  # 1 % off the table
    quality = held_out_errors(fit, held)
    assert quality["points"] == 3 and quality["no_value"] == 1  # near +z at 60 deg: the gap
    assert quality["max_rel_error"] == pytest.approx(1.0 - 1.0 / 1.01, rel=1e-9)
    fit.meta["held_out"] = quality
    fit.save(tmp_path / "fit.json")


# --- past the largest angle --------------------------------------------------------------------

def test_no_time_past_the_tables_largest_angle_unless_it_is_180_deg():
    """A fit from 30 and 90 deg gave +1.1 % at 150 deg and +1.5 % at 180 deg against direct solves
    (continued linearly, never measured)."""
    short = _fit({}, angles_deg=[30.0, 90.0])
    for angle in (90.5, 150.0, 180.0):
        assert all(math.isnan(v) for v in _both(short, [1, 2, 3], angle)), angle
    assert _both(short, [1, 2, 3], 90.0)[0] == pytest.approx(bang_bang([1, 2, 3], math.pi / 2), rel=1e-9)
    full = _fit({}, angles_deg=[30.0, 180.0])
    for axis in ([1, 0, 0], [1, 2, 3]):
        expected = bang_bang(axis, math.pi)
        assert _both(full, axis, 180.0) == pytest.approx((expected, expected), rel=1e-9)


# --- start attitudes a table of slews from the identity does not hold --------------------------

def test_a_table_from_the_identity_only_refuses_another_start():
    """q0 = 60 deg about z gave 2.0069 s where a direct solve with the keep-out takes 2.2003 s."""
    fit = _fit({}, meta={"from_identity_only": True})
    q0 = quat.from_axis_angle([0, 0, 1], math.radians(60.0))
    qf = quat.product(q0, quat.from_axis_angle([0, 0, 1], math.radians(60.0)))
    with pytest.raises(ValueError, match=r"q0 must be the identity .*meta\.from_identity_only.*1\.0472 rad"):
        fit(q0.tolist(), qf.tolist())
    with pytest.raises(ValueError, match=r"q0\[1\] must be the identity .*from_identity_only"):
        fit.slew_time_many(np.array([I, q0]), np.array([qf, qf]))
    # the identity (either sign), and a start within the tolerance, are read
    expected = bang_bang([0, 0, 1], math.radians(60.0))
    qz = quat.from_axis_angle([0, 0, 1], math.radians(60.0))
    near = quat.from_axis_angle([1, 0, 0], 0.5 * IDENTITY_TOLERANCE)
    for start in (np.array(I), -np.array(I), near):
        assert fit(start.tolist(), quat.product(start, qz).tolist()) == pytest.approx(expected, rel=1e-6)
        assert fit.slew_time_many(start, quat.product(start, qz))[0] == pytest.approx(expected, rel=1e-6)
    with pytest.raises(ValueError, match="from_identity_only"):
        fit(quat.from_axis_angle([1, 0, 0], 2.0 * IDENTITY_TOLERANCE).tolist(), qz.tolist())
    # a table whose times depend on the rotation alone reads any start
    free = _fit({})
    assert _both(free, [0, 0, 1], 60.0, q0=tuple(q0.tolist())) == pytest.approx((expected, expected), rel=1e-9)


# --- the keep-out table of the report, end to end ---------------------------------------------

KEEP_OUT = {
    "name": "box-keep-out",
    "spacecraft": {"inertia": [1.0, 1.0, 1.0], "wheels": None, "torquers": {"max_torque": 1.0},
                   "sensors": {"camera": {"boresight": [1, 0, 0]}}},
    "maneuver": {"duration": 20.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.7071068, 0, 0, 0.7071068], "omega": [0, 0, 0]}},
    "planners": [{"name": "collocation"}],
    "controller": {"name": "augmented_quaternion_feedback"},
    "requirements": {"pointing": {"cam_y": {"sensor": "camera", "keep_out": {"inertial": [0, 1, 0]},
                                            "angle_deg": 20}}},
}


def _write(folder: Path, name: str, data: dict) -> Path:
    path = folder / name
    path.write_text(yaml.safe_dump(data))
    return path


def test_the_keep_out_table_records_the_impossible_entry_and_the_fit_gives_no_time(tmp_path):
    _write(tmp_path, "keepout.yaml", KEEP_OUT)
    spec = parse_table_spec(_write(tmp_path, "table.yaml", {"table": {
        "scenario": "keepout.yaml", "axes": BODY_AXES.tolist(), "angles_deg": [90, 120],
        "planner_options": {"intervals": 20}}}))
    with ThreadPoolExecutor(2) as executor:
        table = compute_table(spec, executor=executor)
    part = table.parts["table"]
    # the oracle: an entry is impossible when the camera ends within 20 deg of inertial +y
    for i, axis in enumerate(BODY_AXES):
        for k, angle in enumerate(part.angles_deg):
            boresight = quat.rotate(quat.from_axis_angle(axis, math.radians(angle)), [1.0, 0.0, 0.0])
            inside = math.degrees(math.acos(np.clip(boresight[1], -1.0, 1.0))) < 20.0
            assert (part.status[i][k] == "infeasible") == inside, (axis, angle, part.status[i][k], part.message[i][k])
    assert part.status[0][0] == "infeasible" and "no reference can meet it" in part.message[0][0]
    fit = table.fit
    assert fit is not None and fit.meta["from_identity_only"] is True
    # what the times hold for is in the fit: slews from the identity at the epoch, under these requirements
    assert fit.meta["requirements"] == KEEP_OUT["requirements"] and fit.meta["epoch"] is None
    assert "1 entry not ok (1 infeasible)" in table.fit_note
    assert _both(fit, [0, 0, 1], 90.0) == (math.inf, math.inf)
    for angle in (95.0, 100.0, 105.0):  # the camera ends 5-15 deg from +y, inside the cone: no slew
        assert _both(fit, [0, 0, 1], angle) == (math.inf, math.inf)
    for angle in (112.0, 116.0):  # it ends outside, in the cells around the infeasible entry: no time
        assert all(math.isnan(v) for v in _both(fit, [0, 0, 1], angle))
    assert _both(fit, [0, 0, -1], 90.0)[0] == pytest.approx(part.slew_time_s[1, 0], rel=1e-12)


# --- messages -------------------------------------------------------------------------------------

UNIT_BOX = {
    "name": "bilimoria-wie",
    "spacecraft": {"inertia": [1.0, 1.0, 1.0], "wheels": None, "torquers": {"max_torque": 1.0}},
    "maneuver": {"duration": 10.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0, 1, 0, 0], "omega": [0, 0, 0]}},
    "planners": [{"name": "collocation"}],
    "controller": {"name": "augmented_quaternion_feedback"},
}


@pytest.mark.parametrize(("table", "where", "words"), [
    ({"axes": [[1, 0, 0], [0, 1, 0], [2, 0, 0]]}, "table.axes[2]", "repeats the direction of table.axes[0]"),
    ({"axes": [[1, 0, 0]], "held_out": 2}, "table.held_out", "1 axis gives no fit"),
    ({"axes": [[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]], "held_out": 2}, "table.held_out", "no fit over the sphere"),
    ({"objective": "min_energy", "duration": 5.0, "held_out": 2}, "table.held_out", "min_time tables"),
])
def test_a_table_that_wastes_entries_exits_2_naming_the_yaml_path(tmp_path, capsys, table, where, words):
    """Duplicate axes were solved twice; a held-out grid was solved for a table that can have no fit."""
    _write(tmp_path, "box.yaml", UNIT_BOX)
    spec = _write(tmp_path, "table.yaml", {"table": {"scenario": "box.yaml", "angles_deg": [90, 180], **table}})
    assert main(["table", str(spec), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert where in err and words in err, err
    assert not (tmp_path / "out").exists()


def test_validate_says_the_held_out_grid_and_the_refinement(tmp_path, capsys):
    _write(tmp_path, "box.yaml", UNIT_BOX)
    plain = _write(tmp_path, "plain.yaml", {"table": {"scenario": "box.yaml", "axes": [[1, 0, 0]],
                                                       "angles_deg": [90, 180]}})
    assert main(["validate", str(plain)]) == 0
    said = capsys.readouterr().out
    assert "1 axis x 2 angles, no held-out grid" in said and "no refinement" in said, said
    full = _write(tmp_path, "full.yaml", {"table": {"scenario": "box.yaml", "axes": 6, "grid": "fibonacci",
                                                     "angles_deg": [90, 180], "held_out": 3,
                                                     "refine": {"tolerance": 0.02, "max_rounds": 2}}})
    assert main(["validate", str(full)]) == 0
    said = capsys.readouterr().out
    assert "6 axes x 2 angles + a held-out grid of 3 axes x 3 angles" in said, said
    assert "refined to a tolerance of 0.02 (at most 2000 axes, 2 rounds)" in said, said


def test_the_plot_of_a_table_without_an_ok_entry_warns_nothing(tmp_path):
    spec = parse_table_spec(_write(tmp_path, "box.yaml", UNIT_BOX), {"axes": [[1, 0, 0]], "angles": "90,180"})
    part = _part({(0, 0): "failed", (0, 1): "failed"}, axes=spec.axes, angles_deg=spec.angles_deg)
    table = SlewTable(spec, {"table": part, "held_out": TablePart.empty(np.zeros((0, 3)), [])})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        write_plot(table, tmp_path / "agility_envelope.png")
    assert (tmp_path / "agility_envelope.png").stat().st_size > 0


def test_the_tables_own_angles_have_a_time_whatever_the_rounding():
    """A table angle recovered from quaternions lands a few ulps off it: just above 30 deg the cell
    [30, 90] holds the failed +z entry at 90 deg with a Hermite weight of 1e-16 (NaN on 25 of 400
    axes near +z), and just above 120 deg the last cell; scalar and vectorised calls disagreed.
    Every entry at 30 and 120 deg is ok: a time, the same from both calls."""
    fit = _fit({(0, 1): "failed"})
    rng = np.random.default_rng(5)
    axes = np.array([0.0, 0.0, 1.0]) + rng.normal(0.0, 0.3, (200, 3))
    for angle in (30.0, 120.0):
        for axis in axes:
            scalar, many = _both(fit, axis, angle)
            expected = bang_bang(axis, math.radians(angle))
            assert scalar == pytest.approx(expected, rel=0.05) and many == pytest.approx(scalar, rel=1e-9), \
                (axis, angle, scalar, many)
    top = _fit({}, angles_deg=[30.0, 90.0])  # at the largest angle (not 180): a time, not "past it"
    for axis in axes[:50]:
        assert all(math.isfinite(v) for v in _both(top, axis, 90.0)), axis


def test_sequences_of_numpy_scalars_give_the_floats_answer_and_text_is_refused():
    """Tuples of NumPy scalars took the pure-Python path with NumPy arithmetic (twice the cost);
    they are converted to floats first: the same answer, bit for bit, as floats; text is not a number."""
    fit = _fit({})
    qf = quat.from_axis_angle([0.3, -0.5, 0.8], 1.2)
    expected = fit(I, tuple(qf.tolist()))
    assert expected == pytest.approx(bang_bang([0.3, -0.5, 0.8], 1.2), rel=1e-12)
    assert fit(tuple(np.array(I)), tuple(qf)) == expected  # tuples of numpy.float64
    assert fit((1, 0, 0, 0), list(qf.astype(np.float32).astype(float))) == pytest.approx(expected, rel=1e-7)
    with pytest.raises(TypeError, match="4 numbers"):
        fit(("1", "0", "0", "0"), tuple(qf.tolist()))
