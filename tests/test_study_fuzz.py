"""Property: any mutation of a valid study file (a key set to any value, deleted, or added) ends in
``slewbench sweep`` exiting 0, or exiting 2 with a message naming the path, within a time limit,
never with a traceback, and writing nothing outside its output directory (issue 32). A few
examples run in the default suite, 500 in the slow one."""
import contextlib
import copy
import io
import signal

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from scenarios.cli.commands import main
from tests.test_sweep import BASE

STUDY = {
    "study": "fuzz",
    "scenario": {**copy.deepcopy(BASE), "simulation": {"sample_time": 1.0, "duration": 32.0}},
    "grid": {"maneuver.duration": [30.0, 31.0]},
    "zip": {"planners[label=fast].options.torque_fraction": [0.8]},
    "monte_carlo": {"samples": 2, "method": "random", "seed": 1, "dispersions": {
        "simulation.initial_attitude_error_deg": {"normal": {"mean": [0, 0, 0], "std": [0.5, 0.5, 0.5]}},
        "simulation.sensor_noise.seed": "case_seed"}},
    "summary": ["cl.final_error_deg", "ref.int_u"],
    "execution": {"workers": 1, "case_timeout_s": 60.0, "retries": 1},
}
LIMIT_S = 120
"""Per example: an accepted study runs its four cases, a refused one answers at once."""


def paths(node, prefix=()):
    if isinstance(node, dict):
        for key, value in node.items():
            yield prefix + (key,)
            yield from paths(value, prefix + (key,))
    elif isinstance(node, list):
        for index, value in enumerate(node):
            yield prefix + (index,)
            yield from paths(value, prefix + (index,))


PATHS = sorted(paths(STUDY), key=repr)
VALUES = st.one_of(
    st.none(), st.booleans(), st.integers(-10**12, 10**12), st.integers(2**62, 2**130),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0, -1, 1e-9, 1e9, 1e300, 0.5, 3, 100001, "none", "", "..", "auto", "case_seed", "x" * 300,
                     "tcp://", "tcp://127.0.0.1:1", "latin_hypercube", "maneuver.duration", "planners[9].x",
                     "planners[label=nope].options.x"]),
    st.text(max_size=8), st.lists(st.floats(-1e3, 1e3), max_size=4), st.lists(st.integers(-3, 3), max_size=5),
    st.dictionaries(st.text(max_size=6), st.integers(), max_size=2),
    st.sampled_from([{"linspace": [0, 1, 3]}, {"linspace": [1, 2, 10**6]}, {"geomspace": [-1, 1, 3]},
                     {"axis_angle": {"axis": [0, 0, 0], "angle_deg": [1]}}, {"normal": {"mean": 0, "std": -1}},
                     {"uniform": [2, 1]}, {"scale": {"uniform": [0.9, 1.1]}}, {"offset": {"normal": {"mean": [0],
                                                                                                  "std": [1]}}},
                     {"nope": 1}, [[1, 2], [3]], [{"seed": 1}], {"samples": 3}]),
)
MUTATIONS = st.one_of(
    st.tuples(st.just("set"), st.sampled_from(PATHS), VALUES),
    st.tuples(st.just("delete"), st.sampled_from(PATHS), st.none()),
    st.tuples(st.just("add"), st.sampled_from([()] + PATHS), st.one_of(
        st.text(min_size=1, max_size=6), st.sampled_from(["simulation.sample_time", "maneuver.duration",
                                                          "spacecraft.inertia", "simulation.sensor_noise.seed",
                                                          "planners[0].options.profile", "controller.options.kp"]))),
)


def mutate(data: dict, mutation) -> dict:
    kind, path, value = mutation
    data = copy.deepcopy(data)
    if kind == "add":
        node = data
        for key in path:
            node = node[key]
        if isinstance(node, dict):
            node[value] = [1.0] if path and path[0] in ("grid", "zip") else {"normal": {"mean": 1, "std": 0.1}} \
                if path[-1:] == ("dispersions",) else 1
        return data
    node = data
    for key in path[:-1]:
        node = node[key]
    if kind == "set":
        node[path[-1]] = value
    else:
        del node[path[-1]]
    return data


class ExampleTimeout(Exception):
    pass


def check(mutation, folder):
    data = mutate(STUDY, mutation)
    path = folder / "study.yaml"
    path.write_text(yaml.safe_dump(data, allow_unicode=True))
    out = folder / "out"
    stderr = io.StringIO()

    def expire(signum, frame):
        raise ExampleTimeout

    previous = signal.signal(signal.SIGALRM, expire)
    signal.alarm(LIMIT_S)
    try:
        with contextlib.redirect_stderr(stderr), contextlib.redirect_stdout(io.StringIO()):
            status = main(["sweep", str(path), "--out", str(out), "--no-plots"])
    except ExampleTimeout:
        pytest.fail(f"mutation {mutation!r} ran for more than {LIMIT_S} s")
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    error = stderr.getvalue()
    assert "Traceback" not in error, (mutation, error)
    assert status in (0, 2), (mutation, status, error)
    assert sorted(p.name for p in folder.iterdir()) in (["study.yaml"], ["out", "study.yaml"]), mutation
    if status == 2:
        assert error.startswith(("slewbench: error in study file: ", "slewbench: output error: ")), (mutation, error)
        named = error.split(": ", 2)[-1]
        assert ": " in named or "study file" in named or "given a study" in named, (mutation, error)
        assert len(error) < 3000 and not out.exists(), (mutation, error)
    else:
        assert (out / "cases.csv").is_file() and (out / "sweep.sqlite").is_file(), mutation


# Derandomised: the default run draws the same 6 mutations every time (a random draw such as
# maneuver.final.omega = [-33994, 0, 0] runs both its cases to the 60 s case timeout, past LIMIT_S:
# a CI run must not pass or fail by the draw); the slow test below draws 500 at random.
@settings(max_examples=6, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(mutation=MUTATIONS)
def test_mutated_studies_exit_0_or_2_naming_a_path(mutation, tmp_path_factory):
    check(mutation, tmp_path_factory.mktemp("study"))


@pytest.mark.slow  # 500 examples: about 10 to 20 minutes on the shared 2-core machine
@settings(max_examples=500, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture,
                                                                   HealthCheck.too_slow])
@given(mutation=MUTATIONS)
def test_mutated_studies_exit_0_or_2_naming_a_path_500_examples(mutation, tmp_path_factory):
    check(mutation, tmp_path_factory.mktemp("study"))
