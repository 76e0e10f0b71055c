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
from scenarios.errors import ScenarioError
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


def run_cli(tmp_path: Path, data: dict | str, command: str = "validate", name: str = "case.yaml") -> tuple[int, str]:
    """``slewbench <command> FILE`` on ``data`` written to a file; (exit status, stderr)."""
    path = tmp_path / name
    path.write_text(data if isinstance(data, str) else yaml.safe_dump(data, sort_keys=False))
    extra = {"validate": [], "run": ["--out", str(tmp_path / "out"), "--no-plots"],
             "sweep": ["--out", str(tmp_path / "out"), "--no-plots", "--workers", "1"]}[command]
    stderr = io.StringIO()
    with contextlib.redirect_stderr(stderr), contextlib.redirect_stdout(io.StringIO()):
        status = main([command, str(path), *extra])
    return status, stderr.getvalue()


def study(summary: list[str] | None = None, **grid) -> dict:
    """A study of the 12U case (eigenaxis only) over ``grid`` (paths with '__' for '.')."""
    scenario = base()
    scenario["planners"] = [{"name": "eigenaxis"}]
    data = {"study": "hostile", "scenario": scenario,
            "grid": {path.replace("__", "."): values for path, values in grid.items()}
            or {"requirements.pointing.st_sun.angle_deg": [20, 30]}}
    if summary is not None:
        data["summary"] = summary
    return data


@pytest.mark.parametrize(("column", "words"), [
    ("ref.req.st_moon.min_margin_deg", ["'st_moon'", "ref.req.st_sun.min_margin_deg"]),
    ("ref.req.st_sun.min_margin", ["'min_margin'", "min_margin_deg"]),
    ("cl.req.actuators.wheels_torque", ["'wheels_torque'", "cl.req.actuators.wheels_momentum"]),
    ("ref.req.actuators.wheel_torque", ["'wheel_torque'", "wheels_torque"]),
    ("ref.req.rate.peak_rate", ["'rate'"]),
])
def test_a_summary_naming_a_requirement_column_the_study_lacks_is_refused(tmp_path, column, words):
    """A typo in a summary's requirement column ran the whole study and summarised nothing (empty
    statistics, no word said): it is refused before anything runs, naming the entry and the columns
    there are."""
    status, error = run_cli(tmp_path, study(summary=["cl.final_error_deg", column]), command="sweep")
    assert status == 2, error
    assert "summary[1]" in error and column in error, error
    for word in words:
        assert word in error, (word, error)
    assert "Traceback" not in error and not (tmp_path / "out").exists()


def test_a_summary_of_requirement_columns_the_cases_have_is_accepted():
    from scenarios.study.spec import parse_study

    columns = ["ref.req.st_sun.min_margin_deg", "cl.req.st_sun.time_in_violation_s",
               "ref.req.actuators.wheels_momentum", "ref.req.actuators.wheels_torque_time_s"]
    parsed = parse_study(study(summary=columns))
    assert parsed.summary == columns
    # a requirement only some cases have (added by the grid) is a column of the study
    data = study(summary=["cl.req.rate.peak_rate"], requirements__rate=[None, {"max": 0.1}])
    assert parse_study(data).summary == ["cl.req.rate.peak_rate"]


def test_the_fields_a_study_checks_its_summary_against_are_those_a_run_gives():
    """score_fields (what a summary may name) against the scores of a run with every kind of
    requirement: the same names and fields, scope by scope."""
    import scenarios
    from scenarios.requirements.scoring import score_fields

    data = base()
    data["planners"] = [{"name": "eigenaxis"}]
    data["requirements"]["rate"] = {"max": 0.1}
    data["requirements"]["final"] = {"after_s": 5.0, "error_deg": 1.0, "rate": 0.01}
    scenario = parse_scenario(data)
    row = scenarios.run(scenario).rows[0]
    fields = score_fields(scenario.requirements, scenario.problem.spacecraft)
    assert row.requirements is not None
    for scope in ("reference", "closed_loop"):
        given = {name: tuple(values) for name, values in row.requirements[scope].items()}
        assert given == fields[scope], scope  # each score starts with its verdict, "met"


def test_rate_jumps_are_taken_up_by_the_wheels_as_momentum_conservation_says():
    """A reference that starts at a rate other than the spacecraft's and steps its rate at 20 s (as
    natural motion's spin-up and step stop do): the wheels take each jump's momentum at once. Oracle:
    the total angular momentum is conserved in inertial axes (no external torque),
    ``h(t) = R(q)ᵀ R(q₀)(I ω_actual(0) + h₀) − I ω(t)``, the attitude integrated from the rate
    across the step (SciPy). Before the fix the jumps were ignored: the wheels stayed at h₀."""
    from scipy.integrate import solve_ivp

    from controllers import CONTROLLERS
    from controllers.allocation import reference_demand
    from ocp import AttitudeModel, ReactionWheels, Spacecraft, quat

    inertia = np.diag([0.25, 0.28, 0.12])
    step = np.array([0.004, -0.003, 0.01])

    def rate(t):
        t = np.atleast_1d(t)
        smooth = np.stack([0.02 * np.sin(0.3 * t), 0.015 * np.cos(0.2 * t) - 0.015, 0.01 * t / (1 + 0.1 * t)], -1)
        return smooth + (t[:, None] >= 20.0) * step

    def rate_dot(t):
        return np.stack([0.006 * np.cos(0.3 * t), -0.003 * np.sin(0.2 * t), 0.01 / (1 + 0.1 * t) ** 2], -1)

    def rhs(time, q):
        return 0.5 * quat.product(q, np.concatenate([[0.0], rate(time)[0]]))

    t = np.linspace(0.0, 40.0, 4001)
    first = solve_ivp(rhs, (0.0, 20.0), quat.IDENTITY, t_eval=t[t < 20.0], rtol=1e-12, atol=1e-13,
                      method="DOP853", dense_output=True)
    second = solve_ivp(rhs, (20.0, 40.0), first.sol(20.0), t_eval=t[t >= 20.0], rtol=1e-12, atol=1e-13,
                       method="DOP853")
    q = np.vstack([first.y.T, second.y.T])
    omega = rate(t)
    torque = rate_dot(t) @ inertia.T + np.cross(omega, omega @ inertia.T)
    actual0 = rate(0.0)[0] - np.array([0.01, 0.02, -0.03])  # the spacecraft's rate at 0: the reference jumps from it
    jumps = np.zeros((t.size, 3))
    jumps[0] = rate(0.0)[0] - actual0
    jumps[np.searchsorted(t, 20.0)] = step
    h0 = np.array([0.004, -0.002, 0.001])
    spacecraft = Spacecraft(inertia, wheels=ReactionWheels.from_body_axes(max_torque=0.003, max_momentum=0.05))
    demand = reference_demand(CONTROLLERS["augmented_quaternion_feedback"](), AttitudeModel(spacecraft), t, q, omega,
                              torque, h0, jumps=jumps)
    total = quat.rotate(q[0], inertia @ actual0 + h0)
    expected = quat.rotate_inverse(q, total) - omega @ inertia.T
    values, k = demand["wheels_momentum"].values, int(np.searchsorted(t, 20.0))
    np.testing.assert_allclose(values[:k], expected[:k], atol=2e-8)  # the jump at 0 taken up exactly
    # After the step too: three wheels take the momenta from conservation (no stepping), exact to rounding
    np.testing.assert_allclose(values[k:], expected[k:], atol=1e-12 * np.max(np.abs(expected)))


NATURAL = {
    "name": "natural-motion-momentum",
    "spacecraft": {"inertia": [0.25, 0.28, 0.12], "wheels": {"max_torque": 0.003, "max_momentum": 0.0045}},
    "maneuver": {"duration": 60.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.5, 0, 0, 0.8660254], "omega": [0, 0, 0]}},
    "planners": [{"name": "natural_motion"}, {"name": "eigenaxis", "options": {"profile": "trapezoidal"}}],
    "controller": {"name": "augmented_quaternion_feedback"},
    "simulation": {"sample_time": 0.1, "duration": 70.0},
}


def test_a_reference_that_jumps_its_rate_is_never_ok():
    """Natural motion (stop_time 10 s) turns 120 deg about z on a torque-free arc of 50 s at
    ω = (2π/3)/50 = 0.041888 rad/s, reached at once from rest and left at once at 50 s. The start is
    the free initial rate natural motion declares (an initial tracking error, ``ref.initial_rate_error``,
    left to the closed loop); the stop at 50 s, inside the reference, no finite torque gives: the
    wheels take I_zz ω = 0.0050265 N m s, 1.117 x their 0.0045 N m s. The row was ``ok`` (demand 0:
    the jump was not seen) while its closed loop saturated and ended 27 deg off. The trapezoidal
    eigenaxis (ω continuous, ω̇ jumps at its switches) has no rate jump. The wheels hold 0.0045 N m s
    (1.117 x for natural motion's stop): the eigenaxis trapezoid over 60 s coasts at 0.0356 rad/s,
    I_zz ω = 0.00427 N m s (at 0.004 N m s its coast is capped at 0.0333 rad/s and 60 s is too short:
    the eigenaxis planner honours the wheels' momentum since 2026-12-02)."""
    import scenarios

    results = scenarios.run(parse_scenario(copy.deepcopy(NATURAL)))
    natural, eigenaxis = results.rows
    assert natural.requirements is not None and eigenaxis.requirements is not None
    arc_rate = (2.0 * np.pi / 3.0) / 50.0
    score = natural.requirements["reference"]["actuators"]
    assert natural.status == "violated", natural.message
    assert score["rate_jump"] == pytest.approx(arc_rate, rel=1e-6)
    assert score["rate_jump_time_s"] == 50.0  # the step stop (a breakpoint); the declared free start is not one
    assert score["wheels_momentum"] == pytest.approx(0.12 * arc_rate / 0.0045, rel=1e-4)
    assert f"rate jumps by {arc_rate:.3g} rad/s at 50 s" in natural.message, natural.message
    assert "jumps" not in natural.message.split("rate jumps by")[1].split(";")[0]  # one jump only
    assert eigenaxis.requirements["reference"]["actuators"]["rate_jump"] == 0.0
    assert eigenaxis.requirements["reference"]["actuators"]["rate_jump_time_s"] is None
    assert "rate jump" not in eigenaxis.message


def test_an_epoch_outside_the_ephemeris_names_the_run_as_written():
    """The 12U case runs 70 s (simulation.duration); its directions are tabulated over 180 s (twice
    the manoeuvre plus a minute, room for a longer reference). The message said 'the run ... for
    180 s', a run the user never wrote; an epoch before the ephemeris is refused whatever the run,
    and the message says which limit it is."""
    data = base()
    data["epoch"] = "1900-01-01T00:00:00Z"
    with pytest.raises(ScenarioError) as raised:
        parse_scenario(data)
    error = str(raised.value)
    assert "epoch" in error and "1900-01-01T00:00:00" in error and "1960-01-01" in error and "2200-01-01" in error
    assert "simulation.duration = 70 s" in error and "before its start" in error, error
    assert "180 s" not in error, error


def test_a_collocation_failure_names_what_the_requirements_ask():
    """An actuator margin of 0.99 leaves 1 % of each limit: the 120 deg slew in 60 s cannot be made,
    and IPOPT says so. The hint named cones ('a larger cone_margin_deg', which would make it harder)
    for a problem without any; it must point at the margin (and the duration)."""
    from planners import PLANNERS

    data = base()
    data["requirements"] = {"actuators": {"margin": 0.99}}
    problem = parse_scenario(data).problem
    reference = PLANNERS["collocation"]({"intervals": 10}).plan(problem)
    assert not reference.ok
    assert "requirements.actuators.margin" in reference.message and "0.99" in reference.message, reference.message
    assert "cone_margin_deg" not in reference.message, reference.message
    # with a rate bound too slow for the slew, the hint names it
    data["requirements"] = {"rate": {"max": 0.01}, "actuators": None}
    reference = PLANNERS["collocation"]({"intervals": 10}).plan(parse_scenario(data).problem)
    assert not reference.ok
    assert "requirements.rate.max" in reference.message and "0.01" in reference.message, reference.message
    assert "cone_margin_deg" not in reference.message, reference.message


def _edit(**paths) -> dict:
    """The 12U case with ``a__b=value`` set (``DELETE`` removes the key)."""
    data = base()
    for path, value in paths.items():
        keys = path.split("__")
        node = data
        for key in keys[:-1]:
            node = node.setdefault(key, {})
        if value is DELETE:
            node.pop(keys[-1], None)
        else:
            node[keys[-1]] = value
    return data


DELETE = object()
ST = "requirements__pointing__st_sun"


def _st(**entry) -> dict:
    values = {"sensor": "star_tracker", "keep_out": "sun", "angle_deg": 30, **entry}
    return {key: value for key, value in values.items() if value is not None}


_TEXT = SCENARIO.read_text()
HOSTILE: dict[str, tuple[dict | str, str, list[str]]] = {  # case: (scenario data or YAML text, the path named, words the message holds)
    "boresight of strings": (_edit(spacecraft__sensors={"star_tracker": {"boresight": ["a", "b", "c"]}}),
                             "spacecraft.sensors.star_tracker.boresight", ["list of 3 numbers", "'a'"]),
    "boresight of two": (_edit(spacecraft__sensors={"star_tracker": {"boresight": [1, 0]}}),
                         "spacecraft.sensors.star_tracker.boresight", ["3 numbers", "2"]),
    "boresight NaN": (_edit(spacecraft__sensors={"star_tracker": {"boresight": [float("nan"), 0, 1]}}),
                      "spacecraft.sensors.star_tracker.boresight", ["finite"]),
    "sensors a list": (_edit(spacecraft__sensors=[]), "spacecraft.sensors", ["mapping", "[]"]),
    "sensor without boresight": (_edit(spacecraft__sensors={"star_tracker": {}}),
                                 "spacecraft.sensors.star_tracker.boresight", ["required"]),
    "angle 'abc'": (_edit(**{ST: _st(angle_deg="abc")}), "requirements.pointing.st_sun.angle_deg",
                    ["a number", "'abc'"]),
    "angle true": (_edit(**{ST: _st(angle_deg=True)}), "requirements.pointing.st_sun.angle_deg", ["a number"]),
    "angle inf": (_edit(**{ST: _st(angle_deg=float("inf"))}), "requirements.pointing.st_sun.angle_deg", ["inf"]),
    "angle -5": (_edit(**{ST: _st(angle_deg=-5)}), "requirements.pointing.st_sun.angle_deg", ["(0, 180)", "-5"]),
    "Sun without an epoch": (_edit(epoch=DELETE), "requirements.pointing.st_sun.keep_out", ["'sun'", "epoch"]),
    "epoch 2300": (_edit(epoch="2300-01-01T00:00:00Z"), "epoch", ["2200-01-01", "2300-01-01"]),
    "epoch 1900": (_edit(epoch="1900-01-01"), "epoch", ["1960-01-01", "1900-01-01", "70 s"]),
    "epoch month 13": (_edit(epoch="2027-13-01"), "epoch", ["'2027-13-01'", "2025-01-01"]),
    "epoch 'yesterday'": (_edit(epoch="yesterday"), "epoch", ["'yesterday'"]),
    "epoch a number": (_edit(epoch=12345), "epoch", ["12345"]),
    "epoch empty": (_edit(epoch=""), "epoch", ["''"]),
    "epoch a list": (_edit(epoch=[2027, 3, 20]), "epoch", ["[2027, 3, 20]"]),
    "epoch a leap second": (_edit(epoch="2016-12-31T23:59:60Z"), "epoch", ["leap second"]),
    "window empty": (_edit(**{ST: _st(window=[10, 10])}), "requirements.pointing.st_sun.window", ["[10, 10]"]),
    "window reversed": (_edit(**{ST: _st(window=[40, 10])}), "requirements.pointing.st_sun.window", ["[40, 10]"]),
    "window after the run": (_edit(**{ST: _st(window=[80, None])}), "requirements.pointing.st_sun.window",
                             ["80", "70"]),
    "window ends after the run": (_edit(**{ST: _st(window=[0, 100])}), "requirements.pointing.st_sun.window",
                                  ["100", "70", "null"]),
    "window start null": (_edit(**{ST: _st(window=[None, 10])}), "requirements.pointing.st_sun.window[0]",
                          ["a number", "None"]),
    "window a word": (_edit(**{ST: _st(window="all")}), "requirements.pointing.st_sun.window", ["list", "'all'"]),
    "direction 'Sun'": (_edit(**{ST: _st(keep_out="Sun")}), "requirements.pointing.st_sun.keep_out",
                        ["'Sun'", "'sun'"]),
    "direction 'mars'": (_edit(**{ST: _st(keep_out="mars")}), "requirements.pointing.st_sun.keep_out",
                         ["'mars'", "inertial"]),
    "direction a number": (_edit(**{ST: _st(keep_out=42)}), "requirements.pointing.st_sun.keep_out", ["42"]),
    "inertial zero": (_edit(**{ST: _st(keep_out={"inertial": [0, 0, 0]})}),
                      "requirements.pointing.st_sun.keep_out.inertial", ["cannot be zero"]),
    "inertial of two": (_edit(**{ST: _st(keep_out={"inertial": [1, 0]})}),
                        "requirements.pointing.st_sun.keep_out.inertial", ["3 numbers"]),
    "inertial with a frame": (_edit(**{ST: _st(keep_out={"inertial": [1, 0, 0], "frame": "gcrf"})}),
                              "requirements.pointing.st_sun.keep_out.frame", ["unknown key", "inertial"]),
    "inertial misspelt": (_edit(**{ST: _st(keep_out={"inertal": [1, 0, 0]})}),   # said only that it is missing
                          "requirements.pointing.st_sun.keep_out.inertial", ["missing", "'inertal' is given"]),
    "boresight misspelt": (_edit(spacecraft__sensors={"star_tracker": {"boresite": [1, 0, 0]}}),
                           "spacecraft.sensors.star_tracker.boresight", ["'boresite' is given"]),
    "limb without an orbit": (_edit(orbit=DELETE, environment={"gravity_gradient": False},
                                    **{ST: _st(keep_out="earth_limb", angle_deg=10)}),
                              "requirements.pointing.st_sun.keep_out", ["'earth_limb'", "orbit"]),
    "keep_out and keep_in": (_edit(**{ST: _st(keep_in="moon")}), "requirements.pointing.st_sun",
                             ["exactly one of keep_out and keep_in"]),
    "neither": (_edit(**{ST: _st(keep_out=None)}), "requirements.pointing.st_sun", ["exactly one"]),
    "duplicated requirement names": (_TEXT.replace(
        "    st_sun: {sensor: star_tracker, keep_out: sun, angle_deg: 30}",
        "    st_sun: {sensor: star_tracker, keep_out: sun, angle_deg: 30}\n"
        "    st_sun: {sensor: star_tracker, keep_out: moon, angle_deg: 20}"),
        "requirements.pointing.st_sun", ["duplicate key"]),
    "duplicated sensor names": (_TEXT.replace(
        "    star_tracker: {boresight: [0.5, -0.8660254, 0.0]}",
        "    star_tracker: {boresight: [0.5, -0.8660254, 0.0]}\n    star_tracker: {boresight: [0, 0, 1]}"),
        "spacecraft.sensors.star_tracker", ["duplicate key"]),
    "requirements a list": (_edit(requirements=[]), "requirements", ["mapping", "[]"]),
    "requirements a word": (_edit(requirements="yes"), "requirements", ["mapping", "'yes'"]),
    "pointing a list": (_edit(requirements__pointing=[]), "requirements.pointing", ["mapping", "[]"]),
    "a pointing entry null": (_edit(**{ST: None}), "requirements.pointing.st_sun", ["mapping", "None"]),
    "unknown requirement kind": (_edit(requirements__thermal={"max": 1}), "requirements.thermal",
                                 ["unknown key", "pointing"]),
    "name starting with a digit": (_edit(requirements__pointing={"1st": _st()}), "requirements.pointing.1st",
                                   ["letter", "'1st'"]),
    "margin 1.0": (_edit(requirements__actuators={"margin": 1.0}), "requirements.actuators.margin", ["[0, 1)", "1.0"]),
    "margin -0.1": (_edit(requirements__actuators={"margin": -0.1}), "requirements.actuators.margin", ["-0.1"]),
    "margin '10%'": (_edit(requirements__actuators={"margin": "10%"}), "requirements.actuators.margin", ["'10%'"]),
    "rate max 0": (_edit(requirements__rate={"max": 0}), "requirements.rate.max", ["positive", "0"]),
    "rate max -1": (_edit(requirements__rate={"max": -1}), "requirements.rate.max", ["positive", "-1"]),
    "final after the run": (_edit(requirements__final={"after_s": 20, "error_deg": 0.1}),
                            "requirements.final.after_s", ["80", "70"]),
    "final error 0": (_edit(requirements__final={"after_s": 5, "error_deg": 0}), "requirements.final.error_deg",
                      ["positive"]),
    "final with nothing": (_edit(requirements__final={}), "requirements.final", ["error_deg, rate or both"]),
}


@pytest.mark.parametrize("case", sorted(HOSTILE))
def test_hostile_input_is_exit_2_naming_the_path_and_the_value(case, tmp_path):
    data, path, words = HOSTILE[case]
    status, error = run_cli(tmp_path, data)
    assert status == 2, error
    # a file that cannot be read (a duplicate key) is named by its path: validate cannot yet tell its kind
    file = tmp_path / "case.yaml"
    kind = file if "duplicate key" in words else f"scenario: {file}"  # a scenario's names its file after its kind
    assert f"error in {kind}: {path}:" in error, error
    for word in words:
        assert word in error, (word, error)
    assert "Traceback" not in error


@pytest.mark.parametrize(("grid", "path", "words"), [
    ({"requirements.pointing.st_sun.angle_deg": [20, 200]}, "requirements.pointing.st_sun.angle_deg",
     ["case 1", "200", "(0, 180)"]),
    ({"epoch": ["2027-03-20T12:00:00Z", "1900-01-01"]}, "epoch", ["case 1", "1900-01-01", "1960-01-01"]),
    ({"epoch": ["2027-03-20T12:00:00Z", "yesterday"]}, "epoch", ["case 1", "'yesterday'"]),
])
def test_a_study_sweeping_a_requirement_or_the_epoch_refuses_a_bad_case(tmp_path, grid, path, words):
    status, error = run_cli(tmp_path, study(**{key.replace(".", "__"): values for key, values in grid.items()}),
                            command="sweep")
    assert status == 2, error
    assert f"{path} (set by {path})" in error, error
    for word in words:
        assert word in error, (word, error)
    assert "Traceback" not in error and not (tmp_path / "out").exists()


def test_a_study_sweeping_the_angle_and_the_epoch_runs_and_reports_each_case(tmp_path):
    """Two angles at two epochs (March and June 2027): in June the Sun lies 23 deg off the equator, the
    target then 37 deg from it, inside a 40 deg cone (every row infeasible, before planning), outside a
    20 deg one; in March the eigenaxis path crosses the Sun (violated)."""
    import csv

    status, error = run_cli(tmp_path, study(summary=["ref.req.st_sun.min_margin_deg"],
                                            requirements__pointing__st_sun__angle_deg=[20, 40],
                                            epoch=["2027-03-20T12:00:00Z", "2027-06-21T12:00:00Z"]),
                            command="sweep")
    assert status == 0, error
    rows = list(csv.DictReader((tmp_path / "out" / "cases.csv").open()))
    by_case = {(row["epoch"], row["requirements.pointing.st_sun.angle_deg"]): row for row in rows}
    assert by_case[("2027-03-20T12:00:00Z", "20")]["status"] == "violated"
    assert by_case[("2027-06-21T12:00:00Z", "20")]["status"] == "ok"
    june_40 = by_case[("2027-06-21T12:00:00Z", "40")]
    # the time it is checked at named as what it is, the manoeuvre's duration (no planner's end of slew)
    assert june_40["status"] == "infeasible", june_40
    assert "target attitude already breaks it at 60 s, maneuver.duration (margin" in june_40["message"], june_40
    assert float(by_case[("2027-03-20T12:00:00Z", "20")]["ref.req.st_sun.min_margin_deg"]) < -19.0
    summary = (tmp_path / "out" / "requirements.csv").read_text().splitlines()
    assert by_case[("2027-03-20T12:00:00Z", "40")]["status"] == "violated"
    assert summary[0] == ("label,criterion,completed,excluded,scored,not_scored,no_verdict,met,fraction_met,"
                          "wilson_low,wilson_high")
    # the failed June row is completed (it does not meet every requirement) and left out of the verdicts
    assert summary[1].startswith("eigenaxis,every requirement,4,1,4,0,0,1,0.25,")
