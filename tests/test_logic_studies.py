"""Trade studies against oracles worked out here (issue 33): the random stream of each case
(``SeedSequence(seed).spawn``, drawn again independently), ``offset`` against ``scale``, what the
store key depends on, the summary statistics of a small table worked out by hand, and a case
stored twice."""
import copy
import csv

import numpy as np
import pytest
from scipy.stats import norm

import scenarios
from scenarios.study import SweepStore
from tests.test_sweep import InlineExecutor

BASE = {
    "name": "tiny",
    "spacecraft": {"inertia": [2.0, 3.0, 4.0], "wheels": {"max_torque": 0.05}},
    "maneuver": {"duration": 30.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.9238795, 0.3826834, 0, 0], "omega": [0, 0, 0]}},
    "planners": [{"name": "eigenaxis", "label": "smooth"}],
    "controller": {"name": "augmented_quaternion_feedback", "options": {"kp": 0.2, "kd": 0.6}},
    "simulation": {"sample_time": 1.0, "duration": 35.0},
}


def study_data(**parts):
    return {"study": "logic", "scenario": copy.deepcopy(BASE), **parts}




def row(value, status="ok"):
    return {"label": "smooth", "planner": "eigenaxis", "controller": "augmented_quaternion_feedback",
            "status": status, "message": "", "plan_time_s": 0.1, "reference": None,
            "closed_loop": None if value is None else {"int_u": value}}


def fake_task(values_by_key, calls):
    def task(payload):
        calls.append(payload["key"])
        value, status = values_by_key[payload["key"]]
        return {"key": payload["key"], "status": "ok", "rows": [row(value, status)], "elapsed_s": 0.0,
                "cpu_s": 0.0, "worker_cpu_s": 0.0, "worker": "here:0", "cache_builds": 0}
    return task


DISPERSIONS = {"controller.options.kd": {"offset": {"uniform": [0.05, 0.15]}},
               "controller.options.kp": {"scale": {"normal": {"mean": 1.0, "std": 0.1}}}}


def test_each_case_draws_from_its_own_spawned_stream():
    """Case i of a random Monte Carlo takes its seed and unit samples from
    ``SeedSequence(seed).spawn(n_cases + n_points)[i]``; ``offset`` adds the draw to the base value,
    ``scale`` multiplies it (base kd = 0.6, kp = 0.2: the two forms give different numbers)."""
    seed, samples, points = 7, 3, 2
    study = scenarios.parse_study(study_data(
        grid={"maneuver.duration": [30.0, 31.0]},
        monte_carlo={"samples": samples, "seed": seed, "dispersions": DISPERSIONS}))
    n = points * samples
    children = np.random.SeedSequence(seed).spawn(n + points)
    assert len(study.cases) == n
    for i, case in enumerate(study.cases):
        assert case.index == i and case.point == i // samples
        assert case.seed == int(children[i].generate_state(1)[0])
        u = np.random.default_rng(children[i]).random((1, 2))[0]
        options = case.scenario["controller"]["options"]
        assert options["kd"] == pytest.approx(0.6 + 0.05 + 0.1 * u[0], rel=1e-12)
        assert options["kp"] == pytest.approx(0.2 * (1.0 + 0.1 * norm.ppf(u[1])), rel=1e-12)
        assert case.scenario["maneuver"]["duration"] == [30.0, 31.0][i // samples]
    kds = [c.scenario["controller"]["options"]["kd"] for c in study.cases]
    assert len(set(kds)) == n  # every case has its own stream


def test_a_latin_hypercube_per_grid_point_from_the_streams_after_the_cases():
    """``latin_hypercube``: grid point p's design is ``qmc.LatinHypercube(d, seed=default_rng(child))``
    with child ``n_cases + p`` of the spawn; sample s of the point takes row s of it, and the case
    seed is still child ``p × samples + s``. Each column of a design is stratified: one value in
    each of ``samples`` equal bins."""
    from scipy.stats import qmc
    seed, samples, points = 11, 4, 2
    study = scenarios.parse_study(study_data(
        grid={"maneuver.duration": [30.0, 31.0]},
        monte_carlo={"samples": samples, "seed": seed, "method": "latin_hypercube", "dispersions": DISPERSIONS}))
    n = points * samples
    children = np.random.SeedSequence(seed).spawn(n + points)
    for point in range(points):
        design = qmc.LatinHypercube(d=2, seed=np.random.default_rng(children[n + point])).random(samples)
        assert sorted(np.floor(design[:, 0] * samples)) == list(range(samples))
        for sample in range(samples):
            case = study.cases[point * samples + sample]
            assert case.seed == int(children[point * samples + sample].generate_state(1)[0])
            options = case.scenario["controller"]["options"]
            assert options["kd"] == pytest.approx(0.6 + 0.05 + 0.1 * design[sample, 0], rel=1e-12)
            assert options["kp"] == pytest.approx(0.2 * (1.0 + 0.1 * norm.ppf(design[sample, 1])), rel=1e-12)


def test_the_study_seed_reaches_the_case_seeds_and_keys():
    """Two studies that differ only in ``monte_carlo.seed`` give different case seeds and keys."""
    one = scenarios.parse_study(study_data(monte_carlo={"samples": 2, "seed": 1, "dispersions": DISPERSIONS}))
    two = scenarios.parse_study(study_data(monte_carlo={"samples": 2, "seed": 2, "dispersions": DISPERSIONS}))
    assert [c.seed for c in one.cases] != [c.seed for c in two.cases]
    assert [c.key for c in one.cases] != [c.key for c in two.cases]


def test_the_store_key_depends_on_the_whole_resolved_case_and_the_version():
    data = study_data(grid={"controller.options.kp": [0.2, 0.3], "simulation.sample_time": [1.0, 0.5],
                            "spacecraft.wheels.max_torque": [0.05, 0.06]})
    study = scenarios.parse_study(copy.deepcopy(data))
    keys = [case.key for case in study.cases]
    assert len(set(keys)) == len(keys) == 8  # any varied section changes the key
    again = scenarios.parse_study(copy.deepcopy(data))
    assert [case.key for case in again.cases] == keys  # and nothing else does
    other = scenarios.parse_study(copy.deepcopy(data), version="999.0")
    assert not {case.key for case in other.cases} & set(keys)  # another version: other keys


def test_resume_reuses_only_cases_of_the_same_version(tmp_path):
    data = study_data(grid={"maneuver.duration": [30.0, 31.0, 32.0]})
    study = scenarios.parse_study(copy.deepcopy(data))
    values = {case.key: (1.0, "ok") for case in study.cases}
    calls = []
    (tmp_path / "store").mkdir()
    with SweepStore(tmp_path / "store") as store:
        scenarios.sweep(study, InlineExecutor(), workers=1, store=store, task=fake_task(values, calls))
    assert len(calls) == 3
    calls.clear()
    with SweepStore(tmp_path / "store") as store:
        results = scenarios.sweep(scenarios.parse_study(copy.deepcopy(data)), InlineExecutor(), workers=1,
                                  store=store, task=fake_task(values, calls))
    assert calls == [] and results.missing == 0  # everything was stored
    newer = scenarios.parse_study(copy.deepcopy(data), version="999.0")
    values.update({case.key: (2.0, "ok") for case in newer.cases})
    with SweepStore(tmp_path / "store") as store:
        results = scenarios.sweep(newer, InlineExecutor(), workers=1, store=store, task=fake_task(values, calls))
    assert len(calls) == 3  # a result of another version is not reused
    assert [results.records[c.key]["rows"][0]["closed_loop"]["int_u"] for c in newer.cases] == [2.0] * 3


def test_summary_statistics_per_grid_point_against_hand_worked_values(tmp_path):
    """Two grid points, four Monte Carlo samples each; the values of ``cl.int_u`` are given, one row
    failed without a value. Hand-worked (sample std, linear percentiles):
    point 1 [1, 2, 4, 10]: mean 4.25, std sqrt(48.75/3), median 3, p5 1.15, p95 9.1;
    point 2 [3, -, 5, 6]:  count 3 (rows with a value), no_value 1, not_ok 1, mean 14/3, std sqrt(14/3/2),
    median 5, p5 3.2, p95 5.9."""
    study = scenarios.parse_study(study_data(
        grid={"maneuver.duration": [30.0, 40.0]}, summary=["cl.int_u"],
        monte_carlo={"samples": 4, "seed": 3, "dispersions": {"controller.options.kd": {"uniform": [0.5, 0.7]}}}))
    given = [(1.0, "ok"), (2.0, "ok"), (4.0, "ok"), (10.0, "ok"), (3.0, "ok"), (None, "failed"), (5.0, "ok"), (6.0, "ok")]
    values = {case.key: given[case.index] for case in study.cases}
    results = scenarios.sweep(study, InlineExecutor(), workers=1, task=fake_task(values, []))
    results.write(tmp_path / "out", plots=False)
    with open(tmp_path / "out" / "summary.csv", newline="") as handle:
        lines = list(csv.DictReader(handle))
    assert len(lines) == 2
    by_point = {float(line["maneuver.duration"]): line for line in lines}
    expected = {30.0: {"count": 4, "not_ok": 0, "mean": 4.25, "std": np.sqrt(48.75 / 3), "median": 3.0,
                       "p5": 1.15, "p95": 9.1, "min": 1.0, "max": 10.0},
                40.0: {"count": 3, "no_value": 1, "not_ok": 1, "mean": 14 / 3, "std": np.sqrt(14 / 3 / 2),
                       "median": 5.0, "p5": 3.2, "p95": 5.9, "min": 3.0, "max": 6.0}}
    for duration, stats in expected.items():
        line = by_point[duration]
        assert line["label"] == "smooth" and line["metric"] == "cl.int_u"
        for name, value in stats.items():
            assert float(line[name]) == pytest.approx(value, rel=1e-9), (duration, name)


def test_a_case_stored_twice_is_one_record_the_last(tmp_path):
    (tmp_path / "s").mkdir()
    with SweepStore(tmp_path / "s") as store:
        store.put("k1", "crashed", [row(None, "crashed")], None, 1)
        store.put("k2", "ok", [row(5.0)], 0.5, 1)
        store.put("k1", "ok", [row(3.0)], 1.5, 2)
        assert len(store) == 2 and store.keys() == {"k1", "k2"}
    with SweepStore(tmp_path / "s", create=False) as store:
        records = store.records()
    assert len(records) == 2
    assert records["k1"]["status"] == "ok" and records["k1"]["attempts"] == 2 and records["k1"]["elapsed_s"] == 1.5
    assert records["k1"]["rows"][0]["closed_loop"]["int_u"] == 3.0
    assert records["k2"]["rows"][0]["closed_loop"]["int_u"] == 5.0
