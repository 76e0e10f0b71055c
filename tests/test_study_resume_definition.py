"""``slewbench sweep --resume`` continues a study only while its definition is the stored one: an
edited grid value, a case added or removed, an edited base scenario file or Monte Carlo entry is
refused before anything runs, naming what changed, with nothing touched; an unchanged study (its
summary, execution and robustness may change) resumes its missing cases only; a store that records
no study is refused, since whether it holds the study's cases cannot be told."""
from __future__ import annotations

import copy
import csv
import hashlib
import re
import shutil
import sqlite3

import pytest
import yaml

from scenarios.cli.commands import main
from scenarios.study.engine import sweep
from scenarios.study.spec import load_study
from scenarios.study.store import SweepStore, claim_sweep_directory, definition_changes
from tests.test_sweep import BASE, InlineExecutor

VALUES = [0.2, 0.3]


def write_study(folder, values=VALUES, base=None, **more):
    """The study ``res`` (a grid of ``controller.options.kp``) over ``base.yaml`` in ``folder``."""
    (folder / "base.yaml").write_text(yaml.safe_dump(base or BASE))
    path = folder / "study.yaml"
    path.write_text(yaml.safe_dump({"study": "res", "scenario": "base.yaml",
                                    "grid": {"controller.options.kp": list(values)}, **more}))
    return path


def snapshot(directory):
    """Every file under ``directory`` and its content's hash."""
    return {p.relative_to(directory).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(directory.rglob("*")) if p.is_file()}


@pytest.fixture(scope="module")
def swept(tmp_path_factory):
    """A finished sweep of the study (2 cases) in ``out``."""
    folder = tmp_path_factory.mktemp("swept")
    path = write_study(folder)
    assert main(["sweep", str(path), "--out", str(folder / "out"), "--workers", "1", "--no-plots"]) == 0
    return folder


@pytest.fixture
def partial(swept, tmp_path):
    """A copy of the sweep with its second case (kp 0.3) not stored, as an interrupted sweep leaves
    it; returns the folder, the study file and the output directory."""
    shutil.copytree(swept, tmp_path, dirs_exist_ok=True)
    out = tmp_path / "out"
    key = next(case.key for case in load_study(tmp_path / "study.yaml").cases
               if case.scenario["controller"]["options"]["kp"] == 0.3)
    with SweepStore(out) as store:
        assert key in store.keys()
    with sqlite3.connect(out / "sweep.sqlite") as db:
        db.execute("DELETE FROM cases WHERE key = ?", (key,))
    return tmp_path, tmp_path / "study.yaml", out


def refused(path, out, capsys):
    """Resume ``path`` into ``out``: it must exit 2 with ``out`` untouched; returns the message."""
    before = snapshot(out)
    capsys.readouterr()
    assert main(["sweep", str(path), "--out", str(out), "--workers", "1", "--no-plots", "--resume"]) == 2
    said = capsys.readouterr()
    assert snapshot(out) == before
    assert said.out == "", said.out  # no case started
    return said.err


def test_an_edited_value_is_refused_naming_the_path_and_what_to_do(partial, capsys):
    folder, _, out = partial
    path = write_study(folder, values=[0.2, 0.35])
    error = refused(path, out, capsys)
    assert ("holds the sweep of study 'res' with another definition (2 cases then, 2 now), changed since: "
            "grid.controller.options.kp[1]: 0.3 -> 0.35.") in error, error
    assert "nothing was run or touched" in error, error
    assert ("Run the edited study into a new directory (another --out), or resume with study.yaml and base.yaml as "
            "they were") in error, error


@pytest.mark.parametrize("values, counts", [([0.2, 0.3, 0.4], "2 cases then, 3 now"), ([0.2], "2 cases then, 1 now")])
def test_a_case_added_or_removed_is_refused(partial, capsys, values, counts):
    """Adding 0.4 keeps both stored cases the study's: the old resume ran only the new one and
    said nothing; removing 0.3 left a stored case out with a note. Both are refused now."""
    folder, _, out = partial
    error = refused(write_study(folder, values=values), out, capsys)
    assert f"({counts}), changed since: grid.controller.options.kp: [0.2, 0.3] -> {values}." in error, error


def test_an_edited_base_scenario_file_is_refused_naming_the_file_and_its_path(partial, capsys):
    folder, _, out = partial
    base = copy.deepcopy(BASE)
    base["maneuver"]["duration"] = 32.0
    base["planners"][1]["options"]["torque_fraction"] = 0.7
    del base["simulation"]["sample_time"]
    path = write_study(folder, base=base)
    assert yaml.safe_load(path.read_text()) == yaml.safe_load((folder / "study.yaml").read_text())  # the study file as it was
    error = refused(path, out, capsys)
    assert ("changed since: base scenario base.yaml: maneuver.duration: 30.0 -> 32.0; base scenario base.yaml: "
            "planners[1].options.torque_fraction: 0.8 -> 0.7; base scenario base.yaml: simulation.sample_time: "
            "removed (was 1.0).") in error, error


def test_a_monte_carlo_entry_added_is_refused(partial, capsys):
    folder, _, out = partial
    mc = {"samples": 2, "seed": 1, "dispersions": {"controller.options.kd": {"uniform": [0.5, 0.7]}}}
    error = refused(write_study(folder, monte_carlo=mc), out, capsys)
    assert "(2 cases then, 4 now), changed since: monte_carlo: added ({'dispersions': {'controller.options.kd'" in error, error


def test_an_unchanged_study_resumes_its_missing_cases_only(partial, capsys):
    """summary, execution and robustness may change: they decide how the cases run and what the
    tables summarise, and the tables are drawn again from the whole store."""
    folder, path, out = partial
    data = yaml.safe_load(path.read_text())
    path.write_text(yaml.safe_dump({**data, "summary": ["cl.final_error_deg"], "execution": {"case_timeout_s": 300},
                                    "robustness": {"worst": 3}}))
    capsys.readouterr()
    assert main(["sweep", str(path), "--out", str(out), "--workers", "1", "--no-plots", "--resume"]) == 0
    said = capsys.readouterr().out
    assert "res: 2 cases, 1 already stored, local process pool\n" in said, said
    assert re.search(r"^1 case run in [0-9.]+ s \(1 already stored, 2 in all\); ", said, re.M), said
    with open(out / "cases.csv", newline="") as handle:
        assert sorted(float(row["controller.options.kp"]) for row in csv.DictReader(handle)) == [0.2, 0.2, 0.3, 0.3]
    with open(out / "summary.csv", newline="") as handle:
        assert {row["metric"] for row in csv.DictReader(handle)} == {"cl.final_error_deg"}  # the summary asked for
    # the store records the study as resumed: a redrawn report is the one the resumed sweep wrote
    written = {name: (out / name).read_text() for name in ("cases.csv", "summary.csv")}
    assert main(["sweep", "--report", str(out), "--no-plots"]) == 0
    assert {name: (out / name).read_text() for name in written} == written


def test_the_same_base_written_inline_resumes(partial, capsys):
    """The base scenario's content is compared, not the way it is given."""
    folder, path, out = partial
    data = yaml.safe_load(path.read_text())
    path.write_text(yaml.safe_dump({**data, "scenario": copy.deepcopy(BASE)}))
    assert main(["sweep", str(path), "--out", str(out), "--workers", "1", "--no-plots", "--resume"]) == 0


def test_a_store_that_records_no_study_is_refused(tmp_path, capsys):
    """A store filled in code (``sweep(study, store=...)``) records no study: whether it holds this
    study's cases, or an edited one's, cannot be told, so it is not resumed."""
    path = write_study(tmp_path)
    out = claim_sweep_directory(tmp_path / "out")
    with SweepStore(out) as store:
        sweep(load_study(path), InlineExecutor(), store=store).write(out, plots=False)
    error = refused(path, out, capsys)
    assert ("sweep.sqlite records no study (it was not written by `slewbench sweep`), so whether it holds this "
            "study's cases cannot be told") in error, error
    assert "Run the study into a new directory (another --out)" in error, error


def test_another_studys_store_is_still_refused_by_name(partial, capsys):
    folder, path, out = partial
    data = yaml.safe_load(path.read_text())
    path.write_text(yaml.safe_dump({**data, "study": "other"}))
    error = refused(path, out, capsys)
    assert "holds the sweep of study 'res', not 'other'" in error, error


def test_definition_changes_name_each_path_and_the_order_of_the_cases():
    before = {"grid": {"a.b": [1, 2], "c": [3]}, "monte_carlo": {"samples": 2, "dispersions": {"x": 1, "y": 2}},
              "scenario": {"planners": [{"name": "p", "options": {"w": 1}}, {"name": "q"}], "d": 1.0}}
    after = {"grid": {"c": [3], "a.b": [1, 2]}, "monte_carlo": {"samples": 2, "dispersions": {"x": 1, "y": 2}},
             "scenario": {"planners": [{"name": "p", "options": {"w": 2}}, {"name": "q"}], "d": 1, "e": True}}
    assert definition_changes(before["grid"], after["grid"], "grid") == [
        "grid: its keys in another order (a.b, c -> c, a.b), which orders the cases"]
    assert definition_changes(before["monte_carlo"], after["monte_carlo"], "monte_carlo") == []
    reordered = {**after["monte_carlo"], "dispersions": {"y": 2, "x": 1}}
    assert definition_changes(before["monte_carlo"], reordered, "monte_carlo") == [
        "monte_carlo.dispersions: its keys in another order (x, y -> y, x), which orders the cases"]
    assert definition_changes(before["scenario"], after["scenario"]) == [
        "planners[0].options.w: 1 -> 2",
        "d: 1.0 -> 1 (the same value as another type, float -> int: the cases' keys are computed from it as written)",
        "e: added (True)"]
    assert definition_changes({"s": {"k": 1}}, {"s": {"k": 1, "j": 2}, "t": 3}) == ["s.j: added (2)", "t: added (3)"]
    assert definition_changes({"p": [{"a": 1}]}, {"p": [{"a": 1}, {"a": 2}]}) == [
        "p: [{'a': 1}] -> [{'a': 1}, {'a': 2}]"]
    assert definition_changes(before, copy.deepcopy(before)) == []
    assert definition_changes({"kp": [0.2, 0.3]}, {"kp": [0.2, 0.35]}) == ["kp[1]: 0.3 -> 0.35"]
    assert definition_changes({"i": [[1, 0], [0, 1]]}, {"i": [[1, 0], [0, 2]]}) == ["i[1][1]: 1 -> 2"]
    many = [index / 10 for index in range(16)]  # too long to show whole: counted, the values added and removed named
    assert definition_changes({"kp": many}, {"kp": [*many, 0.99]}) == ["kp: 16 values -> 17, added [0.99]"]
    assert definition_changes({"kp": many}, {"kp": many[1:]}) == ["kp: 16 values -> 15, removed [0.0]"]
    assert definition_changes({"kp": many}, {"kp": [5.0, *many[2:]]}) == [
        "kp: 16 values -> 15, added [5.0], removed [0.0, 0.1]"]


def test_a_dry_run_resume_refuses_what_the_resume_would(partial, capsys):
    """``--dry-run --resume`` on an edited study: refused like the resume itself, not "checked"."""
    folder, _, out = partial
    path = write_study(folder, values=[0.2, 0.35])
    before = snapshot(out)
    capsys.readouterr()
    assert main(["sweep", str(path), "--out", str(out), "--workers", "1", "--dry-run", "--resume"]) == 2
    assert "grid.controller.options.kp[1]: 0.3 -> 0.35" in capsys.readouterr().err
    assert snapshot(out) == before
    # unchanged, the dry run lists the cases
    path = write_study(folder)
    assert main(["sweep", str(path), "--out", str(out), "--workers", "1", "--dry-run", "--resume"]) == 0
    assert snapshot(out) == before


def test_a_number_written_as_another_type_is_named_so(partial, capsys):
    """60.0 -> 60: equal numbers, but the cases' keys hash the value as written, so the stored cases
    would not be found; the refusal says that this is all that changed."""
    folder, _, out = partial
    base = copy.deepcopy(BASE)
    assert isinstance(base["maneuver"]["duration"], float) and base["maneuver"]["duration"].is_integer()
    base["maneuver"]["duration"] = int(base["maneuver"]["duration"])
    error = refused(write_study(folder, base=base), out, capsys)
    assert "(the same value as another type, float -> int: the cases' keys are computed from it as written)" in error
