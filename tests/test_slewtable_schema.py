"""The slew-table file's keys: what ``slewbench table`` reads against what the schema reference lists.

Oracles independent of the declarations: a hand-written table file that gives every key once, the
YAML paths the table parser actually reads (recorded at ``Node.get``), the flags of the
``slewbench table`` parser as argparse holds them, hand-picked bad values, and the parser's verdict
on a file with a key left out against the same file with the key set to its documented default.
Also ``slewbench table``'s exit status: 1 under ``--strict`` when entries failed.
"""
from __future__ import annotations

import argparse
import copy
import dataclasses
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from scenarios.cli.commands import build_parser, main
from scenarios.errors import ScenarioError
from scenarios.schema.node import Node
from scenarios.schema.read import parse_yaml_text
from scenarios.schema.reference import Entry, reference_parts, schema_text
from scenarios.schema.table import TABLE_FLAGS
from scenarios.slewtable.refine import RefineOptions
from scenarios.slewtable.spec import parse_table_spec

UNIT_BOX = {
    "name": "bilimoria-wie",
    "spacecraft": {"inertia": [1.0, 1.0, 1.0], "wheels": None, "torquers": {"max_torque": 1.0}},
    "maneuver": {"duration": 10.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0, 1, 0, 0], "omega": [0, 0, 0]}},
    "planners": [{"name": "collocation"}],
    "controller": {"name": "augmented_quaternion_feedback"},
}

MAXIMAL_TABLE = """
table:
  scenario: box.yaml
  axes: [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]]
  grid: fibonacci
  angles_deg: [45, 90, 180]
  objective: min_time
  duration: null
  held_out: 4
  planner_options: {intervals: 20, multistart: 0}
  execution: {workers: 2, scheduler: "tcp://127.0.0.1:8786", case_timeout_s: 300}
  refine: {tolerance: 0.02, check_angles_deg: [90, 180], max_axes: 400, max_rounds: 3}
"""

MINIMAL_TABLE = """
table:
  scenario: box.yaml
"""


def table_entries() -> list[Entry]:
    return [entry for part in reference_parts() if part.group == "Slew-table file" for entry in part.entries]


def mapping_paths(data: Any, prefix: str = "") -> set[str]:
    """Every YAML path of the mappings in ``data`` (not into lists: ``axes`` is a value)."""
    paths = set()
    if isinstance(data, dict):
        for key, value in data.items():
            path = f"{prefix}.{key}" if prefix else str(key)
            paths.add(path)
            paths |= mapping_paths(value, path)
    return paths


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    (tmp_path / "box.yaml").write_text(yaml.safe_dump(UNIT_BOX))
    return tmp_path


def write_table(folder: Path, data: dict, name: str = "table.yaml") -> Path:
    path = folder / name
    path.write_text(yaml.safe_dump(data))
    return path


@pytest.fixture
def keys_read(monkeypatch):
    """The YAML path of every key the table parser reads (``Node.get``, through which every key
    reader goes and which ``Node.finish`` compares the file against)."""
    read: list[str] = []
    original = Node.get

    def get(self, key, *args, **kwargs):
        read.append(self._child_path(key))
        return original(self, key, *args, **kwargs)

    monkeypatch.setattr(Node, "get", get)
    return read


# --- every key read is documented, every documented key read ---------------------------------------

def test_the_maximal_table_uses_every_documented_key_and_the_parser_reads_no_other(folder, keys_read):
    data = parse_yaml_text(MAXIMAL_TABLE)
    spec = parse_table_spec(write_table(folder, data))
    assert spec.held_out == 4 and spec.refine is not None and spec.refine.max_rounds == 3  # every key taken
    assert spec.scheduler == "tcp://127.0.0.1:8786" and spec.case_timeout_s == 300.0 and spec.workers == 2
    read = {path for path in keys_read if path == "table" or path.startswith("table.")}
    written = mapping_paths(data)
    written -= {path for path in written if path.startswith("table.planner_options.")}  # collocation's options
    documented = {entry.path for entry in table_entries()}
    assert read - documented == set(), sorted(read - documented)
    assert documented - read == set(), sorted(documented - read)
    assert written == documented, sorted(written ^ documented)


def test_a_key_not_documented_is_refused_at_its_yaml_path(folder):
    for where, data in (("table.bogus", {"table": {"scenario": "box.yaml", "bogus": 1}}),
                        ("table.execution.retries", {"table": {"scenario": "box.yaml", "execution": {"retries": 1}}}),
                        ("table.refine.rounds", {"table": {"scenario": "box.yaml", "refine": {"rounds": 2}}}),
                        ("study", {"table": {"scenario": "box.yaml"}, "study": "x"})):
        with pytest.raises(ScenarioError) as error:
            parse_table_spec(write_table(folder, data))
        assert error.value.path == where and "unknown key" in error.value.message, error.value


def table_flags() -> dict[str, argparse.Action]:
    parser = build_parser()
    sub = next(action for action in parser._actions if action.dest == "command")
    table = sub.choices["table"]
    return {option: action for action in table._actions for option in action.option_strings}


def test_every_flag_of_slewbench_table_sets_a_documented_key_and_the_reference_names_it():
    # how the command runs, not what the table is: --max-entries is a guard of this command line,
    # as --strict is (a table file states its grid, and the guard is for a mistyped flag)
    flags = set(table_flags()) - {"-h", "--help", "--out", "--no-plots", "--strict", "--max-entries"}
    assert flags == set(TABLE_FLAGS.values()), sorted(flags ^ set(TABLE_FLAGS.values()))
    documented = {entry.path: entry for entry in table_entries()}
    for name, flag in TABLE_FLAGS.items():
        entry = documented[f"table.{name}"]
        assert entry.type != "mapping" and f"``{flag}``" in entry.meaning, entry
    assert sum("Flag: ``" in entry.meaning for entry in table_entries()) == len(TABLE_FLAGS)


# a bad value of each flagged key: as the flag gives it (text where argparse gives text), in YAML, and
# what of it the message shows
BAD = {
    "axes": (0, 0, "0"),
    "grid": ("icosahedral", "icosahedral", "icosahedral"),
    "angles_deg": ("10,200", [10, 200], "200"),
    "objective": ("fastest", "fastest", "fastest"),
    "duration": (-1.0, -1.0, "-1"),
    "held_out": (-1, -1, "-1"),
    "execution.workers": (0, 0, "0"),
    "execution.scheduler": ("nowhere", "nowhere", "nowhere"),
    "execution.case_timeout_s": (-1.0, -1.0, "-1"),
    "refine.tolerance": (1.5, 1.5, "1.5"),
    "refine.check_angles_deg": ("ninety", "ninety", "ninety"),
    "refine.max_axes": (0, 0, "0"),
    "refine.max_rounds": (0, 0, "0"),
}


def nested(name: str, value: Any) -> dict:
    head, _, tail = name.partition(".")
    return {head: nested(tail, value) if tail else value}


@pytest.mark.parametrize("name", sorted(TABLE_FLAGS))
def test_a_bad_value_is_refused_at_its_flag_and_at_its_yaml_path_alike(folder, name):
    assert set(BAD) == set(TABLE_FLAGS)
    flag_value, yaml_value, shown = BAD[name]
    flag = TABLE_FLAGS[name]
    with pytest.raises(ScenarioError) as by_flag:
        parse_table_spec(folder / "box.yaml", {flag[2:]: flag_value})
    assert by_flag.value.path == flag, by_flag.value
    assert shown in by_flag.value.message.split(", got")[-1], by_flag.value
    data = {"table": {"scenario": "box.yaml", **nested(name, yaml_value)}}
    with pytest.raises(ScenarioError) as by_file:
        parse_table_spec(write_table(folder, data))
    assert by_file.value.path == f"table.{name}", by_file.value
    assert shown in by_file.value.message.split(", got")[-1], by_file.value
    # what was expected, in the same words
    assert by_flag.value.message.split(", got")[0] == by_file.value.message.split(", got")[0], \
        (by_flag.value, by_file.value)


def test_a_flag_wins_over_the_file_and_an_unknown_override_is_refused(folder):
    path = write_table(folder, {"table": {"scenario": "box.yaml", "axes": [[1, 0, 0]], "angles_deg": [30, 90],
                                          "held_out": "many"}})
    spec = parse_table_spec(path, {"angles": "45,90", "held-out": 0})
    assert spec.angles_deg == [45.0, 90.0] and spec.held_out == 0
    with pytest.raises(ValueError, match="planner-options"):
        parse_table_spec(path, {"planner-options": {"intervals": 20}})


# --- documented defaults are the defaults applied ---------------------------------------------------

def plain(value: Any) -> Any:
    """A parsed value as nested tuples of plain numbers (dataclass fields compared for equality)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return (type(value).__name__,) + tuple((f.name, plain(getattr(value, f.name)))
                                               for f in dataclasses.fields(value) if f.compare)
    if isinstance(value, np.ndarray):
        return ("array", value.shape, tuple(float(v) for v in value.ravel()))
    if isinstance(value, (list, tuple)):
        return tuple(plain(v) for v in value)
    if isinstance(value, dict):
        return tuple(sorted((k, plain(v)) for k, v in value.items()))
    if isinstance(value, Path):
        return str(value)
    return value


def verdict(path: Path) -> Any:
    try:
        return plain(parse_table_spec(path))
    except ScenarioError as error:
        return ("error", error.path, error.message)  # the file named aside (the two files' names differ)


def test_documented_table_defaults_are_the_defaults_the_table_parser_applies(folder):
    compared = 0
    literal = [entry for entry in table_entries() if entry.default.startswith("``")]
    assert {entry.path for entry in literal} == {entry.path for entry in table_entries()} - {"table", "table.scenario"}
    for entry in literal:
        for text in (MAXIMAL_TABLE, MINIMAL_TABLE):
            data = parse_yaml_text(text)
            *parents, key = entry.path.split(".")
            parent: Any = data
            for step in parents:
                parent = parent.get(step) if isinstance(parent, dict) else None
            if not isinstance(parent, dict):
                continue
            without, with_default = copy.deepcopy(data), copy.deepcopy(data)
            holder = without
            for step in parents:
                holder = holder[step]
            holder.pop(key, None)
            holder = with_default
            for step in parents:
                holder = holder[step]
            holder[key] = parse_yaml_text(f"value: {entry.default[2:-2]}")["value"]
            assert verdict(write_table(folder, without, "without.yaml")) == \
                verdict(write_table(folder, with_default, "with.yaml")), (entry.path, text[:30])
            compared += 1
    top_level = sum(entry.path.count(".") == 1 for entry in literal)
    assert compared == len(literal) + top_level  # every default in the maximal file, the top-level ones in the minimal


def test_the_refinement_options_default_to_the_documented_budget():
    documented = {entry.path: entry.default for entry in table_entries()}
    options = RefineOptions(0.01)
    assert documented["table.refine.max_axes"] == f"``{options.max_axes}``"
    assert documented["table.refine.max_rounds"] == f"``{options.max_rounds}``"


def entry_bounds(name: str) -> str:
    return next(entry.bounds for entry in table_entries() if entry.path == f"table.{name}")


def test_the_help_of_each_flag_states_the_documented_default():
    """The flags' help texts are written by hand (the command line imports nothing of the schema
    until it runs): each default they state is the declared one."""
    documented = {entry.path: entry.default.strip("`") for entry in table_entries()}
    actions = table_flags()
    stated = 0
    for name, flag in TABLE_FLAGS.items():
        text = " ".join(actions[flag].help.split())
        default = documented[f"table.{name}"]
        numbers = re.search(r"default ([0-9][0-9.,]*)", text)
        word = re.search(r"(\w+)'? \(default", text)
        if numbers:
            assert [float(v) for v in numbers.group(1).strip(".,").split(",")] == \
                [float(v) for v in re.findall(r"[0-9.]+", default)], (flag, text, default)
            stated += 1
        elif word and (word.group(1) in entry_bounds(name) or word.group(1) == default):
            assert word.group(1) == default, (flag, text, default)
            stated += 1
    assert stated >= 8


# --- slewbench schema table ---------------------------------------------------------------------------

def test_slewbench_schema_table_prints_every_table_key():
    everything = schema_text("table")
    for entry in table_entries():
        assert entry.path in everything.splitlines(), entry.path
    headings = {line.split(":")[0] for line in everything.splitlines() if re.match(r"^[A-Z][\w -]+: ", line)}
    assert headings == {"Slew-table file"}, headings
    refine = schema_text("table.refine").splitlines()
    assert "table.refine.max_rounds" in refine and "table.axes" not in refine
    assert "integer; default 2000; >= the initial grid's axes and <= 100000" in schema_text("table.refine.max_axes")
    assert "table.axes" not in schema_text("scenario")  # the scenario file's keys, not the table's


# --- the exit status ------------------------------------------------------------------------------------

def test_strict_exits_1_when_the_tables_entries_failed_and_writes_the_files(folder, capsys):
    """One iteration of the solver cannot converge: every entry fails (cheaply). Without
    ``--strict`` the failed entries are results (0); with it the command exits 1, after writing."""
    path = write_table(folder, {"table": {"scenario": "box.yaml", "axes": [[1, 0, 0]], "angles_deg": [90, 180],
                                          "planner_options": {"max_iterations": 1, "multistart": 0}}})
    out = folder / "out"
    assert main(["table", str(path), "--out", str(out), "--no-plots", "--strict"]) == 1
    captured = capsys.readouterr()
    assert "0 of 2 entries ok" in captured.out
    assert "--strict: 2 of 2 table entries (2 failed) not ok" in captured.err, captured.err
    rows = (out / "slew_table.csv").read_text().splitlines()
    assert len(rows) == 3 and all(",failed," in row for row in rows[1:]), rows
    assert main(["table", str(path), "--out", str(out), "--no-plots"]) == 0  # from the store: results, not errors
    assert "(2 entries already stored)" in capsys.readouterr().out


def test_strict_exits_0_when_every_entry_is_ok(folder, capsys):
    path = write_table(folder, {"table": {"scenario": "box.yaml", "axes": [[1, 0, 0]], "angles_deg": [90, 180],
                                          "planner_options": {"multistart": 0}}})
    assert main(["table", str(path), "--out", str(folder / "out"), "--no-plots", "--strict"]) == 0
    captured = capsys.readouterr()
    assert "2 of 2 entries ok" in captured.out and "--strict" not in captured.err


def test_a_study_file_given_to_table_is_named_as_a_study_not_as_a_table(folder, capsys):
    """``table STUDY`` said '... is a study or table file, not a scenario' although ``table`` takes a
    table file: it names what the file is and the command that runs it, as ``run`` does."""
    study = write_table(folder, {"study": "s", "scenario": "box.yaml", "grid": {"maneuver.duration": [5, 10]}},
                        "study.yaml")
    assert main(["table", str(study), "--out", str(folder / "out")]) == 2
    error = capsys.readouterr().err
    assert f"{study} is a study file, not a scenario: run it with `slewbench sweep {study}`" in error, error
    assert "table file, not" not in error and not (folder / "out").exists()
    table = write_table(folder, {"table": {"scenario": "study.yaml"}})
    with pytest.raises(ScenarioError) as error:
        parse_table_spec(table)
    assert error.value.path == "table.scenario" and "study.yaml is a study file, not a scenario" in str(error.value)
