"""Bad scenario input: every file that used to hang, crash or give a meaningless "ok" row (issue 11,
section 2) is now an exit-2 error naming the YAML path, fast; a mutation property test covers the rest."""
import contextlib
import copy
import io
import json
import math
import signal
import textwrap
import time
from pathlib import Path

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from scenarios.cli.commands import main

BASE = {
    "name": "base",
    "spacecraft": {"inertia": [2.0, 3.0, 4.0], "wheels": {"max_torque": 0.05}},
    "maneuver": {"duration": 20.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.9659258, 0.2588190, 0, 0], "omega": [0, 0, 0]}, "max_rate": 0.05},
    "planners": [{"name": "eigenaxis", "label": "smooth", "options": {"profile": "smooth", "torque_fraction": 1.0}},
                 {"name": "shape_polynomial", "label": "shape", "options": {"duration": "scenario", "max_terms": 2}},
                 {"name": "natural_motion", "label": "natural", "options": {"stop_time": 5.0, "starts": 2}}],
    "controller": {"name": "augmented_quaternion_feedback", "options": {"kp": 0.2, "kd": 0.6}},
    "simulation": {"sample_time": 0.5, "max_step": 0.05, "max_samples": 2000,
                   "sensor_noise": {"attitude_deg": 0.0, "rate": 0.0, "seed": 0}},
}


def with_planner(planner: dict, **scenario_changes) -> dict:
    data = copy.deepcopy(BASE)
    data["planners"] = [planner]
    data.update(scenario_changes)
    return data


def set_path(data: dict, path: tuple, value) -> dict:
    data = copy.deepcopy(data)
    node = data
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    return data


def run_cli(tmp_path: Path, text: str, command: str = "validate") -> tuple[int, str, float]:
    path = tmp_path / "case.yaml"
    path.write_text(text)
    stderr = io.StringIO()
    start = time.perf_counter()
    with contextlib.redirect_stderr(stderr), contextlib.redirect_stdout(io.StringIO()):
        status = main([command, str(path)] + (["--out", str(tmp_path / "out"), "--no-plots"] if command == "run" else []))
    return status, stderr.getvalue(), time.perf_counter() - start


COLLOCATION = {"name": "collocation", "options": {"intervals": 10}}
CASES = {
    "negative shape max_rate": (with_planner({"name": "shape_polynomial", "options": {"max_rate": -0.1}}),
                                "planners[0].options.max_rate"),
    "negative energy weight": (with_planner({"name": "collocation", "options": {"objective": "weighted", "energy_weight": -1}}),
                               "planners[0].options.energy_weight"),
    "all weights zero": (with_planner({"name": "collocation", "options": {"objective": "weighted", "energy_weight": 0}}),
                         "planners[0].options.objective"),
    "negative keep-out angle": (with_planner({"name": "collocation", "options": {"keep_out": [
        {"boresight": [1, 0, 0], "direction": [0, 1, 0], "angle_deg": -30}]}}), "planners[0].options.keep_out[0].angle_deg"),
    "keep-out angle as a word": (with_planner({"name": "collocation", "options": {"keep_out": [
        {"boresight": [1, 0, 0], "direction": [0, 1, 0], "angle_deg": "thirty"}]}}), "planners[0].options.keep_out[0].angle_deg"),
    "boresight as a mapping": (with_planner({"name": "collocation", "options": {"keep_out": [
        {"boresight": {"x": 1}, "direction": [0, 1, 0], "angle_deg": 30}]}}), "planners[0].options.keep_out[0].boresight"),
    # 200 intervals of 100 RK4 steps each: the NLP build (every step expanded) ran > 120 s; 10 x 100
    # took 21 s, 50 x 20 took 20 s.
    "too many RK4 steps": (with_planner({"name": "collocation", "options": {
        "transcription": "multiple_shooting", "intervals": 200, "substeps": 100}}), "planners[0].options.substeps"),
    "duplicate seed planner": (with_planner({"name": "collocation", "options": {
        "seed_planners": ["eigenaxis", "natural_motion", "eigenaxis"]}}), "planners[0].options.seed_planners[2]"),
    # r = c = 0: K = sqrt(r^2 + c^2) = 0 divides the closed form (0/0): an "ok" row whose
    # reference was NaN, then an internal error in the simulation; 1e200 overflowed r^2.
    "spin parameters r = c = 0": (with_planner({"name": "spin_extremal", "options": {"parameters": [0, 0, 0.5]}}),
                                  "planners[0].options.parameters"),
    "huge spin parameters": (with_planner({"name": "spin_extremal", "options": {"parameters": [1e200, 1e200, 0]}}),
                             "planners[0].options.parameters[0]"),
    "negative multistart": (with_planner({"name": "collocation", "options": {"multistart": -1}}), "planners[0].options.multistart"),
    "negative starts": (with_planner({"name": "spin_extremal", "options": {"starts": -1}}), "planners[0].options.starts"),
    "zero max_terms": (with_planner({"name": "shape_polynomial", "options": {"max_terms": 0}}), "planners[0].options.max_terms"),
    "huge intervals": (with_planner({"name": "collocation", "options": {"intervals": 1000000000}}), "planners[0].options.intervals"),
    "float intervals": (with_planner({"name": "collocation", "options": {"intervals": 1e9}}), "planners[0].options.intervals"),
    "2x2 kp": (set_path(BASE, ("controller", "options", "kp"), [[1, 0], [0, 1]]), "controller.options.kp"),
    "negative kp": (set_path(BASE, ("controller", "options", "kp"), -0.2), "controller.options.kp"),
    "negative seed": (set_path(BASE, ("simulation", "sensor_noise", "seed"), -1), "simulation.sensor_noise.seed"),
    "tiny max_step": (set_path(BASE, ("simulation", "max_step"), 1e-9), "simulation.max_step"),
    "long window": (set_path(set_path(BASE, ("simulation", "duration"), 1e7), ("simulation", "sample_time"), 0.01),
                    "simulation.duration"),
    "huge duration": (set_path(BASE, ("maneuver", "duration"), 1e9), "maneuver.duration"),
    "tiny sample time": (set_path(BASE, ("simulation", "sample_time"), 1e-7), "maneuver.duration"),
    # one sample (or none) for the whole window: ran, violated, with no word on the sample time
    "sample time longer than the manoeuvre": (set_path(set_path(BASE, ("simulation", "sample_time"), 30.0),
                                                       ("simulation", "max_step"), 1.0), "simulation.sample_time"),
    "sample time longer than the window": (set_path(set_path(BASE, ("simulation", "sample_time"), 5.0),
                                                    ("simulation", "duration"), 1.0), "simulation.sample_time"),
    "zero quaternion": (set_path(BASE, ("maneuver", "initial", "q"), [0, 0, 0, 0]), "maneuver.initial.q"),
    "empty name": (set_path(BASE, ("name",), ""), "name"),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_bad_values_are_exit_2_naming_the_path(case, tmp_path):
    data, path = CASES[case]
    status, error, seconds = run_cli(tmp_path, yaml.safe_dump(data))
    assert status == 2, error
    assert f"error in scenario: {tmp_path / 'case.yaml'}: {path}:" in error, error
    assert "Traceback" not in error and seconds < 10


@pytest.mark.parametrize("text, path", [
    ("natural_motion_nan", "planners[0].options.stop_time"),
    ("costate_ridge_nan", "controller.options.ridge"),
])
def test_nan_options_are_refused(text, path, tmp_path):
    planner = {"natural_motion_nan": "{name: natural_motion, options: {stop_time: .nan}}",
               "costate_ridge_nan": "{name: costate_tpbvp}"}[text]
    controller = ("{name: costate_feedback, options: {ridge: .nan}}" if text == "costate_ridge_nan"
                  else "{name: augmented_quaternion_feedback}")
    document = yaml.safe_dump({k: v for k, v in BASE.items() if k not in ("planners", "controller")})
    document += f"planners: [{planner}]\ncontroller: {controller}\n"
    status, error, _ = run_cli(tmp_path, document)
    assert status == 2 and f"{path}: expected a finite number" in error, error


def test_duplicate_keys_name_both_places(tmp_path):
    text = textwrap.dedent("""\
        name: dup
        spacecraft: {inertia: [2, 3, 4]}
        maneuver:
          duration: 20.0
          duration: 30.0
          initial: {q: [1, 0, 0, 0]}
          final: {q: [1, 0, 0, 0]}
        planners: []
        controller: {name: none}
        """)
    status, error, _ = run_cli(tmp_path, text)
    assert status == 2 and "maneuver.duration: duplicate key (lines 4 and 5); " in error, error


@pytest.mark.parametrize("written, line, words", [
    # a zero-padded duration and angle: ran as 32 s and a 37 deg slew, no word
    ("maneuver: {duration: 040, initial: {q: [1, 0, 0, 0]}, final: {q: {axis_angle: {axis: [0, 0, 1], "
     "angle_deg: 90}}}}", 3, "maneuver.duration: 040 (line 3) is read by YAML 1.1 as the octal number 32, not 40; "
     "write 40 (without the leading zero)"),
    ("maneuver: {duration: 20, initial: {q: [1, 0, 0, 0]}, final: {q: {axis_angle: {axis: [0, 0, 1], "
     "angle_deg: 045}}}}", 3, "maneuver.final.q.axis_angle.angle_deg: 045 (line 3) is read by YAML 1.1 as the "
     "octal number 37, not 45"),
    # minutes:seconds: ran as 80 s
    ("maneuver: {duration: 1:20, initial: {q: [1, 0, 0, 0]}, final: {q: [1, 0, 0, 0]}}", 3,
     "maneuver.duration: 1:20 (line 3) is read by YAML 1.1 as the base-60 number 80; write 80 if that is meant"),
])
def test_a_number_yaml_reads_as_another_value_is_refused(written, line, words, tmp_path):
    text = f"name: padded\nspacecraft: {{inertia: [2, 3, 4]}}\n{written}\nplanners: []\ncontroller: {{name: none}}\n"
    status, error, _ = run_cli(tmp_path, text)
    assert status == 2 and words in error and "Traceback" not in error, error
    padded = text.replace("040", "07").replace("045", "07").replace("1:20", "20")  # 07 is 7 either way
    status, error, _ = run_cli(tmp_path, padded)
    assert status == 0, error


def test_an_alias_bomb_fails_fast_with_a_short_message(tmp_path):
    lines = ['a0: &a0 ["x", "x", "x", "x", "x", "x", "x", "x", "x", "x"]']
    lines += [f"a{i}: &a{i} [*a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}, "
              f"*a{i - 1}, *a{i - 1}]" for i in range(1, 9)]
    text = "\n".join(lines) + "\nname: *a8\n"
    status, error, seconds = run_cli(tmp_path, text)
    assert status == 2 and "alias" in error and len(error) < 1000 and seconds < 5, (seconds, error[:300])


def test_a_huge_file_is_refused_before_it_is_parsed(tmp_path):
    text = yaml.safe_dump(BASE) + "# " + "x" * (3 * 1024 * 1024) + "\n"
    status, error, seconds = run_cli(tmp_path, text)
    assert status == 2 and "bytes" in error and seconds < 2


def test_error_messages_show_a_bounded_excerpt(tmp_path):
    data = set_path(BASE, ("controller", "options", "kp"), "k" * 100000)
    status, error, _ = run_cli(tmp_path, yaml.safe_dump(data))
    assert status == 2 and "controller.options.kp" in error and len(error) < 600


# ----- property: mutations of a valid scenario --------------------------------------------------

def leaf_paths(node, prefix=()):
    if isinstance(node, dict):
        for key, value in node.items():
            yield prefix + (key,)
            yield from leaf_paths(value, prefix + (key,))
    elif isinstance(node, list):
        for index, value in enumerate(node):
            yield prefix + (index,)
            yield from leaf_paths(value, prefix + (index,))


PATHS = sorted(leaf_paths(BASE), key=repr)
VALUES = st.one_of(
    st.none(), st.booleans(), st.integers(-10**12, 10**12),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0, -1, 1e-9, 1e9, 0.5, 3, "none", "", "..", "x" * 300]),
    st.text(max_size=8), st.lists(st.floats(-10, 10), max_size=4), st.lists(st.integers(-3, 3), max_size=5),
    st.dictionaries(st.text(max_size=4), st.integers(), max_size=2),
)
MUTATIONS = st.one_of(
    st.tuples(st.just("set"), st.sampled_from(PATHS), VALUES),
    st.tuples(st.just("delete"), st.sampled_from(PATHS), st.none()),
    st.tuples(st.just("add"), st.sampled_from(PATHS), st.text(min_size=1, max_size=6)),
)


def mutate(data: dict, mutation) -> dict:
    kind, path, value = mutation
    data = copy.deepcopy(data)
    node = data
    for key in path[:-1]:
        node = node[key]
    if kind == "set":
        node[path[-1]] = value
    elif kind == "delete":
        del node[path[-1]]
    elif isinstance(node[path[-1]], dict):
        node[path[-1]][value] = 1
    return data


class CaseTimeout(Exception):
    pass


def physical(metrics: dict) -> bool:
    """Finite and non-negative, fractions at most one: what every metric must be (an independent
    restatement of the metric table's units, not the runner's own check)."""
    for key, value in (metrics or {}).items():
        for item in (value if isinstance(value, list) else [value]):
            if item is None:
                continue
            if not math.isfinite(item) or item < 0 or (key == "saturation_fraction" and item > 1):
                return False
    return True


FUZZ = settings(deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])


@pytest.mark.slow
@settings(FUZZ, max_examples=40)
@given(mutation=MUTATIONS)
def test_mutated_scenarios_exit_0_with_physical_metrics_or_2_naming_a_path(mutation, tmp_path_factory):
    check_mutated_scenario(mutation, tmp_path_factory)


@settings(FUZZ, max_examples=12)
@given(mutation=MUTATIONS)
def test_mutated_scenarios_exit_0_with_physical_metrics_or_2_naming_a_path_default_run(mutation, tmp_path_factory):
    """The default run's twin of the 40-example property above: the same mutations, checks and
    per-case 60 s bound on 12 random examples a run (each accepted one runs three planners and a
    closed loop, about 1 s); the slow one adds 28 more examples a run, not a different check."""
    check_mutated_scenario(mutation, tmp_path_factory)


def check_mutated_scenario(mutation, tmp_path_factory) -> None:
    folder = tmp_path_factory.mktemp("case")
    data = mutate(BASE, mutation)
    path = folder / "case.yaml"
    path.write_text(yaml.safe_dump(data, allow_unicode=True))
    out = folder / "out"
    stderr = io.StringIO()

    def expire(signum, frame):
        raise CaseTimeout

    previous = signal.signal(signal.SIGALRM, expire)
    signal.alarm(60)  # per-case bound: an accepted scenario must never hang
    try:
        with contextlib.redirect_stderr(stderr), contextlib.redirect_stdout(io.StringIO()):
            status = main(["run", str(path), "--out", str(out), "--no-plots"])
    except CaseTimeout:
        pytest.fail(f"mutation {mutation!r} ran for more than 60 s")
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    error = stderr.getvalue()
    assert "Traceback" not in error, (mutation, error)
    assert status in (0, 2), (mutation, error)
    assert sorted(p.name for p in folder.iterdir()) in (["case.yaml"], ["case.yaml", "out"]), mutation
    if status == 2:
        assert error.startswith("slewbench: error in scenario: "), (mutation, error)
        assert not out.exists()
        return
    results = json.loads((out / "results.json").read_text())
    for row in results["rows"]:
        assert row["status"] in ("ok", "violated", "failed", "infeasible"), row
        if row["status"] in ("ok", "violated"):  # a violated row is a result: its metrics are physical too
            assert physical(row["reference"]) and physical(row["closed_loop"]), (mutation, row)


# ----- found by a user trial after the second wave landed ------------------------------------------

SCENARIOS = Path(__file__).resolve().parents[1] / "scenarios"


@pytest.mark.parametrize("text", ["a: &a {b: *a}\n", "name: &a [*a]\n",
                                  "planners:\n  - name: collocation\n    options: &a {warm_start: collocation, "
                                  "warm_start_options: *a}\n"])
def test_a_recursive_alias_is_refused_with_a_short_message(text, tmp_path):
    status, error, seconds = run_cli(tmp_path, text)
    assert status == 2 and "nests deeper than" in error and len(error) < 400 and seconds < 5, error[:300]


def test_a_file_without_a_size_is_read_only_up_to_the_limit(capsys):
    start = time.perf_counter()
    assert main(["validate", "/dev/zero"]) == 2
    assert "more than" in capsys.readouterr().err and time.perf_counter() - start < 5


@pytest.mark.parametrize("epoch, words", [("2025-02-30", "expected a date like 2025-01-01"),
                                          ("1800-01-01", "IGRF-14 covers")])
def test_an_impossible_epoch_names_its_path(epoch, words, tmp_path):
    text = (SCENARIOS / "nano_detumble.yaml").read_text().replace(
        "magnetic_field: tilted_dipole}", f"magnetic_field: {{model: igrf, epoch: {epoch}}}}}")
    status, error, _ = run_cli(tmp_path, text)
    assert status == 2 and f"environment.magnetic_field.epoch: {words}" in error, error


def test_a_date_where_text_is_expected_is_just_text(tmp_path):
    data = copy.deepcopy(BASE)
    text = yaml.safe_dump(data).replace("name: base", "name: 2025-02-30")
    status, error, _ = run_cli(tmp_path, text)
    assert status == 0, error


def test_a_coarse_igrf_table_is_refused(tmp_path):
    """A 1000 s node spacing interpolates the field 42 % wrong along a 600 km orbit."""
    text = (SCENARIOS / "nano_detumble.yaml").read_text().replace(
        "magnetic_field: tilted_dipole}", "magnetic_field: {model: igrf, step_s: 1000}}")
    status, error, _ = run_cli(tmp_path, text)
    assert status == 2 and "environment.magnetic_field.step_s: expected a number <= 120" in error, error


@pytest.mark.parametrize("change, path", [("omega: [0, 0, 0]}", "maneuver.initial.omega"),
                                          ("FINAL", "maneuver.final.omega")])
def test_two_wheel_laws_need_zero_momentum_and_end_at_rest(change, path, tmp_path):
    data = yaml.safe_load((SCENARIOS / "horri_palmer_two_wheels.yaml").read_text())
    if change == "FINAL":
        data["maneuver"]["final"]["omega"] = [0.0, 0.0, 0.05]
    else:
        data["maneuver"]["initial"]["omega"] = [0.01, 0.0, 0.02]
    status, error, _ = run_cli(tmp_path, yaml.safe_dump(data))
    assert status == 2 and f"error in scenario: {tmp_path / 'case.yaml'}: {path}:" in error, error


def test_combined_row_labels_must_differ(tmp_path):
    data = copy.deepcopy(BASE)
    data["planners"] = [{"name": "eigenaxis", "label": "a / b"}, {"name": "eigenaxis", "label": "a"}]
    data.pop("controller")
    data["controllers"] = [{"name": "augmented_quaternion_feedback", "label": "c"},
                           {"name": "eigenaxis_pd", "label": "b / c"}]
    status, error, _ = run_cli(tmp_path, yaml.safe_dump(data))
    assert status == 2 and "controllers[1].label: row label 'a / b / c' is made twice" in error, error


def test_a_long_tdfc_delay_runs_in_the_python_loop_instead_of_exhausting_memory(tmp_path):
    text = textwrap.dedent("""\
        name: long-delay
        spacecraft: {inertia: [0.0109, 0.05, 0.05], wheels: none, magnetorquers: {max_dipole: 0.1}}
        orbit: {altitude_km: 600, inclination_deg: 97.79}
        environment: {magnetic_field: tilted_dipole}
        maneuver: {duration: 12.0, initial: {q: [1, 0, 0, 0], omega: [0.1, 0.1, 0.1]}, final: {q: null, omega: [0, 0, 0]}}
        planners: []
        controllers: [{name: tdfc, options: {gain: 1.0e4, delay: 10.0}}]
        simulation: {sample_time: 0.01, max_step: 0.01}
        """)
    status, error, seconds = run_cli(tmp_path, text, "run")
    assert status == 0 and seconds < 30, error
    rows = json.loads((tmp_path / "out" / "results.json").read_text())["rows"]
    assert rows[0]["status"] == "ok" and rows[0]["closed_loop"]["final_rate"] > 0


@pytest.mark.parametrize("end", ["initial", "final"])
def test_a_body_rate_beyond_any_spacecraft_is_refused_at_its_path(end, tmp_path, capsys):
    """``maneuver.initial.omega: [1e23, 0, 0]`` only warned; eigenaxis's quintic then returned an
    ``ok`` reference ending at -2e8 rad/s and the run never ended (its torque-free coast). Entries
    beyond MAX_BODY_RATE (1e3 rad/s) are refused; 999 rad/s is accepted (with the warning)."""
    from scenarios.cli.commands import main
    from scenarios.schema.loader import MAX_BODY_RATE
    accepted = [(0.999 * MAX_BODY_RATE, 0)] if end == "initial" else []  # the planners here end at rest
    for value, status in [(1e23, 2), (1.0001 * MAX_BODY_RATE, 2), *accepted]:
        data = copy.deepcopy(BASE)
        data["maneuver"][end]["omega"] = [value, 0.0, 0.0]
        path = tmp_path / f"{end}_{value:g}.yaml"
        path.write_text(yaml.safe_dump(data))
        assert main(["validate", str(path)]) == status, value
        err = capsys.readouterr().err
        if status == 2:
            assert f"maneuver.{end}.omega: expected entries within ±1000, got [{value}" in err, err
