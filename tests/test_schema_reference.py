"""The schema reference (scenarios.schema.reference) against the parsers it documents.

The oracles are independent of the reference: hand-written maximal scenario and study files (every
key once), the keys the parsers actually read (recorded at ``Node.get``), the parsers' verdict on a
file with a key left out against the same file with the key set to the documented default, and
the names of the options dataclasses' fields. Also: ``slewbench schema``, the RST page under
``sphinx-build -W``, validation once per planner and controller, and the two extension guides run
as written.
"""
from __future__ import annotations

import copy
import dataclasses
import re
import subprocess
import sys
import textwrap
from collections.abc import Iterable
from html import unescape
from pathlib import Path
from typing import Annotated, Any, ClassVar

import casadi as ca
import numpy as np
import pytest

import ocp.options
import scenarios
from controllers import CONTROLLERS
from ocp import SolverCache, quat
from ocp.dynamics.environment import MAGNETIC_FIELDS, FieldModel
from planners import PLANNERS
from scenarios.cli.commands import main
from scenarios.errors import ScenarioError
from scenarios.schema.node import Node
from scenarios.schema.read import parse_yaml_text
from scenarios.schema.reference import (
    Entry,
    reference_parts,
    schema_rst,
    schema_text,
    summary_line,
)
from scenarios.schema.study import PRINCIPAL, PRINCIPAL_DISPERSION, VALUE_GENERATORS
from scenarios.study.spec import parse_study

ROOT = Path(__file__).resolve().parents[1]

MAXIMAL_A = """
name: maximal-a
epoch: 2027-03-20T12:00:00Z
spacecraft:
  inertia: [[2.0, 0.0, 0.0], [0.0, 3.0, 0.0], [0.0, 0.0, 4.0]]
  wheels: {axes: [[1, 0, 0], [0, 1, 0], [0, 0, 1]], max_torque: 0.05, max_momentum: [1.0, 1.0, 1.0],
           spin_inertia: 0.001, failed: []}
  magnetorquers: {max_dipole: 0.1, saturation: scale}
  torquers: {max_torque: 0.01}
  sensors: {star_tracker: {boresight: [0, 0, 1]}, antenna: {boresight: [1, 0, 0]}}
orbit: {type: circular, altitude_km: 600, inclination_deg: 97.79, raan_deg: 10.0, arg_latitude_deg: 5.0}
environment:
  gravity_gradient: true
  magnetic_field: {model: tilted_dipole, strength: 7.9e15, tilt_deg: 11.0, pole_longitude_deg: -72.0,
                   greenwich_angle_deg: 3.0}
  disturbance_torque: [0.0, 0.0, 1.0e-7]
maneuver:
  quaternion_order: scalar_first
  initial: {q: [1, 0, 0, 0], omega: [0, 0, 0], wheel_momentum: [0.0, 0.0, 0.0]}
  final: {q: [0.9238795, 0.3826834, 0, 0], omega: [0, 0, 0]}
  duration: 40.0
  max_rate: 0.1
planners:
  - {name: eigenaxis, label: smooth, options: {profile: smooth}}
controller: {name: augmented_quaternion_feedback, label: aqf, options: {kp: 0.2, kd: 0.6}}
simulation:
  sample_time: 0.5
  duration: 45.0
  initial_attitude_error_deg: [0.5, 0, 0]
  initial_rate_error: [0, 0, 0]
  sensor_noise: {attitude_deg: 0.01, rate: 1.0e-5, seed: 3, magnetic_field: 1.0e-8}
  integrator: rk4
  max_step: 0.05
  settling_tolerance_deg: 0.5
  fine_settling_tolerance_deg: 0.1
  detumble_tolerance: 0.01
  max_samples: 100000
  compile: false
requirements:
  pointing:
    st_out: {sensor: star_tracker, keep_out: {inertial: [0, 1, 0]}, angle_deg: 20}
    antenna_in: {sensor: antenna, keep_in: {inertial: [1, 0, 0]}, angle_deg: 60, window: [10, null]}
  actuators: {margin: 0.1}
  rate: {max: 0.2}
  final: {after_s: 5, error_deg: 1.0, rate: 0.01}
plots: {euler_sequence: "313"}
truth:
  spacecraft: {inertia: [[2.1, 0.01, 0.0], [0.01, 2.9, 0.0], [0.0, 0.0, 4.1]]}
  wheels:
    misalignment_deg: [[0, 0.5, 0], [0, 0, 0.5], [0.5, 0, 0]]
    max_torque: 0.04
    max_momentum: [0.9, 0.9, 0.9]
    friction: {coulomb: 1.0e-5, viscous: 1.0e-7}
    max_speed_rpm: 6000
    torque_noise: 1.0e-5
  magnetorquers: {scale_error: 0.02}
  residual_dipole: [0.001, 0, 0]
  disturbance:
    constant: [0, 1.0e-7, 0]
    orbit_periodic: [{harmonic: 2, amplitude: [1.0e-7, 0, 0], phase_deg: [0, 0, 0]}]
"""

MAXIMAL_B = """
name: maximal-b
spacecraft: {inertia: [0.0109, 0.05, 0.05], wheels: none, magnetorquers: {max_dipole: 0.1}}
orbit: {altitude_km: 600, inclination_deg: 97.79}
environment:
  magnetic_field: {model: igrf, epoch: 2025-01-01, step_s: 30, span_s: 200, greenwich_angle_deg: 10.0}
maneuver:
  quaternion_order: scalar_last
  duration: 20.0
  initial: {q: [0, 0, 0, 1], omega: [0.1, 0.1, 0.1]}
  final: {q: null, omega: [0, 0, 0]}
planners: []
controller: null
controllers:
  - {name: bdot, label: B-dot, options: {gain: 1.0e4}}
  - {name: tdfc, label: TDFC, options: {gain: 1.0e4, delay: 2.0}}
simulation:
  sample_time: 0.5
  sensors:
    gyro: {arw_deg_per_sqrt_h: 0.01, rrw_deg_per_h_per_sqrt_h: 0.1, bias_deg_per_h: [1.0, 0, 0]}
    star_tracker: {noise_arcsec: [5, 5, 40], rate_hz: 1.0, outages_s: [[5, 8]], boresight: [0, 1, 0],
                   exclusion_deg: {earth_limb: 20}}
    magnetometer: {noise_T: 1.0e-8, bias_T: [1.0e-7, 0, 0]}
  estimator: {type: mekf, initial_attitude_sigma_deg: 0.1, initial_bias_sigma_deg_per_h: 5.0}
"""

MINIMAL = """
name: minimal
spacecraft: {inertia: [2.0, 3.0, 4.0]}
maneuver:
  duration: 30.0
  initial: {q: [1, 0, 0, 0]}
  final: {q: [0.9238795, 0.3826834, 0, 0]}
planners: [{name: eigenaxis}]
controller: {name: augmented_quaternion_feedback}
"""

ATTITUDES = [  # (maneuver.initial.q, maneuver.final.q) set into MAXIMAL_A: every form of an attitude once
    ({"point": {"sensor": "star_tracker", "at": {"ground": {"lat_deg": 6, "lon_deg": 12, "alt_m": 100}},
                "secondary": {"axis": [1, 0, 0], "toward": {"lvlh": [1, 0, 0]}}}, "at_time_s": 0},
     {"axis_angle": {"axis": [0, 0, 1], "angle_deg": 30}, "frame": "initial"}),
    ({"point": {"boresight": [0, 0, 1], "at": {"inertial": [1, 0, 0]},
                "secondary": {"sensor": "antenna", "toward": {"rtn": [0, 0, 1]}}}},
     {"euler": {"angles_deg": [10, 20, 30], "sequence": "313"}, "frame": "lvlh", "at_time_s": 35}),
    ({"quaternion": [1, 0, 0, 0], "frame": "rtn"},
     {"point": {"sensor": "star_tracker", "at": {"lvlh": [0, 0, 1]},
                "secondary": {"axis": [1, 0, 0], "toward": {"ground": {"lat_deg": 10, "lon_deg": 11, "alt_m": 0}}}}}),
    ({"euler": {"angles_deg": [1, 2, 3], "sequence": "321"}},
     {"point": {"boresight": [0, 0, 1], "at": {"rtn": [1, 0, 0]},
                "secondary": {"sensor": "antenna", "toward": {"inertial": [0, 0, 1]}}}, "at_time_s": 20}),
    ({"point": {"sensor": "star_tracker", "at": {"lvlh": [0, 0, 1]},
                "secondary": {"axis": [1, 0, 0], "toward": {"ground": {"lat_deg": 3, "lon_deg": 12, "alt_m": 0}}}}},
     {"point": {"sensor": "star_tracker", "at": {"ground": {"lat_deg": 7, "lon_deg": 12, "alt_m": 50}},
                "secondary": {"axis": [1, 0, 0], "toward": {"lvlh": [1, 0, 0]}}}}),
    ({"point": {"boresight": [0, 0, 1], "at": {"rtn": [-1, 0, 0]},
                "secondary": {"sensor": "antenna", "toward": {"inertial": [0, 0, 1]}}}},
     {"point": {"boresight": [0, 0, 1], "at": {"inertial": [0, 1, 0]},
                "secondary": {"sensor": "antenna", "toward": {"rtn": [0, 0, 1]}}}}),
    ({"axis_angle": {"axis": [1, 0, 0], "angle_deg": 10}}, {"quaternion": [1, 0, 0, 0], "frame": "lvlh"}),
]
"""The attitude forms (``scenarios.schema.targets``), which MAXIMAL_A's plain quaternions do not use."""


def maximal_scenarios() -> list[dict]:
    """MAXIMAL_A, MAXIMAL_B, MAXIMAL_B with an epoch and the star tracker's exclusions that need it,
    and MAXIMAL_A with each pair of :data:`ATTITUDES`."""
    data = [parse_yaml_text(MAXIMAL_A), parse_yaml_text(MAXIMAL_B)]
    with_epoch = copy.deepcopy(data[1])
    with_epoch["epoch"] = "2025-01-01T00:00:00Z"
    with_epoch["simulation"]["sensors"]["star_tracker"]["exclusion_deg"].update(sun=30, moon=10)
    for initial, final in ATTITUDES:
        variant = copy.deepcopy(data[0])
        variant["maneuver"]["initial"]["q"], variant["maneuver"]["final"]["q"] = initial, final
        data.append(variant)
    return data[:2] + [with_epoch] + data[2:]


MAXIMAL_STUDY = """
study: maximal-study
scenario:
  name: base
  spacecraft: {inertia: [2.0, 3.0, 4.0], wheels: {max_torque: 0.05}}
  maneuver:
    duration: 30.0
    initial: {q: [1, 0, 0, 0], omega: [0, 0, 0]}
    final: {q: [0.9238795, 0.3826834, 0, 0], omega: [0, 0, 0]}
  planners: [{name: eigenaxis, label: fast, options: {torque_fraction: 0.9}}]
  controller: {name: augmented_quaternion_feedback}
  simulation: {sample_time: 0.5, initial_attitude_error_deg: [0, 0, 0], initial_rate_error: [0, 0, 0],
               sensor_noise: {seed: 0}}
  truth: {spacecraft: {inertia: [2.0, 3.0, 4.0]}}
grid:
  maneuver.duration: [30.0, 40.0]
  planners[label=fast].options.torque_fraction: {linspace: [0.5, 1.0, 2]}
  simulation.max_step: {geomspace: [0.01, 0.05, 2]}
  maneuver.final.q: {axis_angle: {axis: [0, 0, 1], angle_deg: {linspace: [30, 60, 2]}}}
zip:
  simulation.sample_time: [0.5]
monte_carlo:
  samples: 2
  method: latin_hypercube
  seed: 4
  dispersions:
    simulation.initial_attitude_error_deg: {normal: {mean: [0, 0, 0], std: [1, 1, 1]}}
    simulation.initial_rate_error: {uniform: {low: [0, 0, 0], high: [1.0e-4, 1.0e-4, 1.0e-4]}}
    spacecraft.inertia: {scale: {uniform: [0.9, 1.1]}}
    truth.spacecraft.inertia: {principal: {moments_scale: {uniform: [0.95, 1.05]},
                                           axes_deg: {normal: {mean: [0, 0, 0], std: [1, 1, 1]}}}}
    spacecraft.wheels.max_torque: {offset: {normal: {mean: 0.0, std: 1.0e-4}}}
    simulation.sensor_noise.seed: case_seed
summary: [cl.int_u, ref.final_error_deg]
execution: {workers: 2, scheduler: null, case_timeout_s: 60, retries: 0}
robustness: {thresholds: {cl.final_error_deg: 0.1, cl.int_u: {at_least: 0.01}, cl.max_error_deg: {at_most: 5}}, worst: 3}
resolved: {version: "0"}
"""

MINIMAL_STUDY = """
study: minimal-study
scenario: eigenaxis_demo.yaml
grid:
  maneuver.duration: [60.0]
"""


def entries(group: str | None = None) -> list[Entry]:
    return [entry for part in reference_parts() for entry in part.entries if group in (None, part.group)]


def documented_paths() -> set[str]:
    return {entry.path for entry in entries()}


def yaml_paths(data: Any, prefix: str = "") -> set[str]:
    """Every key path of YAML data: mappings are walked, lists of mappings as ``[i]``."""
    paths = set()
    if isinstance(data, dict):
        for key, value in data.items():
            path = f"{prefix}.{key}" if prefix else str(key)
            paths.add(path)
            paths |= yaml_paths(value, path)
    elif isinstance(data, list) and data and all(isinstance(item, dict) for item in data):
        for item in data:
            paths |= yaml_paths(item, f"{prefix}[i]")
    return paths


def scenario_paths(paths: Iterable[str]) -> set[str]:
    """Scenario paths as the reference writes them: indices as ``[i]``, ``controllers[i]`` as
    ``controller`` (both take the keys of one controller), a user's name under a key of named
    entries (``spacecraft.sensors.st``) as ``<name>``. (The reference is built once for all of
    ``paths``: building it takes a tenth of a second.)"""
    named = {entry.path.split(".<name>")[0] for entry in entries() if ".<name>" in entry.path}
    written = set()
    for path in paths:
        path = re.sub(r"\[\d+\]", "[i]", path).replace("controllers[i]", "controller")
        for prefix in named:
            path = re.sub(rf"^{re.escape(prefix)}\.[^.]+", f"{prefix}.<name>", path)
        written.add(path)
    return written


# --- every key accepted is documented, every documented key accepted ------------------------------

def test_the_maximal_scenarios_use_every_documented_scenario_key_and_only_documented_keys():
    found = set()
    for data in maximal_scenarios():
        scenarios.parse_scenario(copy.deepcopy(data))  # every key in them is accepted
        found |= scenario_paths(yaml_paths(data))
    assert found <= documented_paths(), sorted(found - documented_paths())
    section_keys = {entry.path for entry in entries("Scenario file")}
    assert section_keys - found == set(), sorted(section_keys - found)
    used = {}
    for text in (MAXIMAL_A, MAXIMAL_B):
        field = parse_yaml_text(text)["environment"]["magnetic_field"]
        used[field["model"]] = set(field) - {"model"}
    for name in MAGNETIC_FIELDS:
        assert used[name] == {entry.key.rsplit(".", 1)[-1] for entry in entries("Magnetic field models")
                              if entry.key.startswith(f"environment.magnetic_field.{name}.")}


@pytest.fixture
def keys_read(monkeypatch):
    """The YAML path of every key a parser reads (``Node.get``, which every key reader goes
    through and which ``Node.finish`` compares the file against)."""
    read: list[str] = []
    original = Node.get

    def get(self, key, *args, **kwargs):
        read.append(self._child_path(key))
        return original(self, key, *args, **kwargs)

    monkeypatch.setattr(Node, "get", get)
    return read


def test_every_key_the_scenario_parser_reads_is_documented(keys_read):
    for data in [*maximal_scenarios(), parse_yaml_text(MINIMAL)]:
        scenarios.parse_scenario(data)
    read = scenario_paths(keys_read)
    assert read - documented_paths() == set(), sorted(read - documented_paths())
    assert "environment.magnetic_field.span_s" in read and "simulation.sensor_noise.seed" in read


def study_path(path: str, varied: list[str]) -> str:
    """A study path as the reference writes it: the scenario path of a grid, zip or dispersion
    entry as ``<path>`` (zip entries as grid's), a generator inside ``axis_angle.angle_deg`` as a
    generator, a distribution inside ``scale``, ``offset`` or a key of ``principal`` as a distribution."""
    if path.startswith("robustness.thresholds."):  # keyed by a metric column, which has dots of its own
        sense = path.rsplit(".", 1)[-1]
        return "robustness.thresholds.<name>" + (f".{sense}" if sense in ("at_most", "at_least") else "")
    for scope in ("grid", "zip", "monte_carlo.dispersions"):
        for scenario in sorted(varied, key=len, reverse=True):
            if path == f"{scope}.{scenario}" or path.startswith(f"{scope}.{scenario}."):
                path = ("grid" if scope == "zip" else scope) + ".<path>" + path[len(f"{scope}.{scenario}"):]
                path = re.sub(r"\.axis_angle\.angle_deg\.(?=\w+$)", ".", path)
                path = re.sub(rf"\.{PRINCIPAL_DISPERSION.name}\.({'|'.join(key.name for key in PRINCIPAL.keys)})\."
                              r"(?=\w)", ".", path)  # a distribution inside principal's keys: as a distribution
                return re.sub(r"\.(scale|offset)\.(?=\w)", ".", path)
    return path


def test_the_maximal_study_uses_every_documented_study_key_and_the_parser_reads_no_other(keys_read):
    data = parse_yaml_text(MAXIMAL_STUDY)
    study = parse_study(copy.deepcopy(data))
    assert len(study.cases) == 2 * 2 * 2 * 2 * 2  # four grid axes of two values, a zip of one, two samples
    varied = study.grid_paths + study.mc_paths
    study_keys = ("study", "scenario", "grid", "zip", "monte_carlo", "summary", "execution", "robustness", "resolved")
    read = {study_path(path, varied) for path in keys_read if path.split(".")[0] in study_keys}
    written = {study_path(path, varied) for path in yaml_paths({k: v for k, v in data.items() if k != "scenario"})}
    written |= {"scenario", "monte_carlo.dispersions.<path>: case_seed"}
    written -= {"resolved.version"}  # ignored: slewbench writes it for the record
    documented = {entry.path for entry in entries("Study file")}
    assert read - documented == set(), sorted(read - documented)
    assert written - documented == set(), sorted(written - documented)
    assert documented - written == set(), sorted(documented - written)


def test_every_value_generator_and_its_arguments_are_documented():
    documented = documented_paths()
    for name, generator in VALUE_GENERATORS.items():
        assert f"grid.<path>.{name}" in documented
        for key in generator.argument.section.keys if generator.argument.section else ():
            assert f"grid.<path>.{name}.{key.name}" in documented


def test_every_option_of_every_registered_planner_and_controller_is_documented():
    every = entries()
    for prefix, registry in (("planners", PLANNERS), ("controller", CONTROLLERS)):
        for name, cls in registry.items():
            fields = {f.name for f in dataclasses.fields(cls.Options)}
            listed = {entry.key.rsplit(".", 1)[-1] for entry in every if entry.key.startswith(f"{prefix}.{name}.")}
            assert listed == fields, (name, listed ^ fields)


# --- documented defaults are the defaults applied -------------------------------------------------

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
    return value


def verdict(parse, data: Any) -> Any:
    try:
        return plain(parse(data))
    except ScenarioError as error:
        return ("error", str(error))


def documented_default(entry: Entry) -> Any:
    assert entry.default.startswith("``") and entry.default.endswith("``"), entry
    return parse_yaml_text(f"value: {entry.default[2:-2]}")["value"]


def parent_and_key(data: dict, path: str) -> tuple[Any, str] | None:
    """The mapping that holds ``path`` in ``data`` (``[i]``: the first entry), or None."""
    *parents, key = re.split(r"\.(?![^\[]*\])", path.replace("[i]", ".[i]").replace("..", "."))
    node: Any = data
    for step in parents:
        if step == "[i]":
            node = node[0] if isinstance(node, list) and node else None
        else:
            node = node.get(step) if isinstance(node, dict) else None
        if node is None:
            return None
    return (node, key) if isinstance(node, dict) else None


def assert_defaults_applied(group: str, bases: list[str], parse, applies=lambda entry, data: True) -> int:
    """For each entry of ``group`` with a literal default and each base file that holds its
    parent mapping: the file without the key parses as the file with the key set to the default."""
    compared = 0
    parsed = {text: parse_yaml_text(text) for text in bases}  # read only: each case edits deep copies
    for entry in entries(group):
        if not entry.default.startswith("``"):
            continue  # required, or a default in words (a label: the name)
        for text in bases:
            data = parsed[text]
            found = parent_and_key(data, entry.path)
            if found is None or not applies(entry, data):
                continue
            without, with_default = copy.deepcopy(data), copy.deepcopy(data)
            parent_and_key(without, entry.path)[0].pop(found[1], None)
            parent_and_key(with_default, entry.path)[0][found[1]] = documented_default(entry)
            assert verdict(parse, without) == verdict(parse, with_default), (entry.path, text[:30])
            compared += 1
    return compared


def test_documented_scenario_defaults_are_the_defaults_the_loader_applies():
    compared = assert_defaults_applied("Scenario file", [MAXIMAL_A, MAXIMAL_B, MINIMAL], scenarios.parse_scenario)
    assert compared > 40


def test_documented_field_model_defaults_are_the_defaults_the_loader_applies():
    def same_model(entry, data):
        model = data["environment"]["magnetic_field"]["model"]
        return entry.key.startswith(f"environment.magnetic_field.{model}.")
    compared = assert_defaults_applied("Magnetic field models", [MAXIMAL_A, MAXIMAL_B], scenarios.parse_scenario,
                                       same_model)
    assert compared == sum(1 for entry in entries("Magnetic field models"))


def test_documented_study_defaults_are_the_defaults_the_study_parser_applies():
    def parse(data):
        study = parse_study(data, ROOT / "scenarios" / "study.yaml")
        return (dataclasses.replace(study, raw={}, cases=[]), [(c.key, c.varied) for c in study.cases])
    compared = assert_defaults_applied("Study file", [MAXIMAL_STUDY, MINIMAL_STUDY], parse)
    assert compared >= 10


@pytest.mark.parametrize("prefix, registry", [("planners", PLANNERS), ("controller", CONTROLLERS)])
def test_documented_option_defaults_are_the_defaults_the_options_take(prefix, registry):
    every = entries()
    for name, cls in registry.items():
        defaults = cls({}).options
        for entry in every:
            if entry.key.startswith(f"{prefix}.{name}."):
                option = entry.key.rsplit(".", 1)[-1]
                assert cls({option: documented_default(entry)}).options == defaults, (name, option)


def test_every_entry_has_a_meaning_and_unit_suffixes_agree_with_units():
    units = {"_deg": "deg", "_s": "s", "_km": "km", "_nT": "nT"}
    for entry in entries():
        assert entry.meaning.strip(), entry.path
        for suffix, unit in units.items():
            if entry.path.endswith(suffix):
                assert entry.unit == unit, entry


# --- the page and the command ---------------------------------------------------------------------

def test_the_rst_page_builds_with_sphinx_without_warnings(tmp_path):
    pytest.importorskip("sphinx", reason="the docs extra (pip install '.[docs]')")
    source = tmp_path / "source"
    source.mkdir()
    (source / "conf.py").write_text('project = "schema"\nextensions = []\n')
    page = schema_rst()
    (source / "index.rst").write_text(page)
    completed = subprocess.run([sys.executable, "-m", "sphinx", "-W", "-q", "-b", "html", str(source),
                                str(tmp_path / "html")], capture_output=True, text=True, timeout=600, check=False)
    assert completed.returncode == 0, completed.stderr[-3000:]
    words = unescape(re.sub(r"<[^>]+>", "", (tmp_path / "html" / "index.html").read_text()))
    for entry in entries():
        assert entry.path in words, entry.path
    labels = re.findall(r"^\.\. _(schema-[a-z0-9-]+):$", page, re.MULTILINE)
    assert len(labels) == len(set(labels)) == len(reference_parts())


def run_schema(*args: str) -> subprocess.CompletedProcess:
    """``python -m scenarios.cli schema ARGS`` in a new process: its exit status and streams."""
    return subprocess.run([sys.executable, "-m", "scenarios.cli", "schema", *args], capture_output=True, text=True,
                          timeout=300, cwd=ROOT, check=False)


def schema_here(capsys, *args: str) -> subprocess.CompletedProcess:
    """``slewbench schema ARGS`` through the command line's ``main`` in this process (what it prints
    does not depend on the process; :func:`run_schema` tests the process's exit status and streams)."""
    capsys.readouterr()
    status = main(["schema", *args])
    out, err = capsys.readouterr()
    return subprocess.CompletedProcess(["slewbench", "schema", *args], status, out, err)


def test_slewbench_schema_prints_the_entries_under_a_key(capsys):
    completed = run_schema("maneuver.initial")  # through a process: its status and output
    assert completed.returncode == 0, completed.stderr
    paths = [line for line in completed.stdout.splitlines() if line and not line[0].isspace() and "=" not in line
             and not line.startswith(("Scenario file", "The slew"))]
    assert [path for path in paths if path.count(".") < 3] == [
        "maneuver.initial", "maneuver.initial.q", "maneuver.initial.omega", "maneuver.initial.wheel_momentum"]
    assert "maneuver.initial.q.point.secondary.toward" in paths  # the attitude's forms
    assert "list of 3 numbers [rad/s]; default [0.0, 0.0, 0.0]" in completed.stdout
    collocation = schema_here(capsys, "planners.collocation.intervals")
    assert collocation.returncode == 0 and "planners[i].options.intervals" in collocation.stdout
    assert "integer; default 50; >= 1 and <= 2000" in collocation.stdout


def test_slewbench_schema_names_an_unknown_key_and_its_close_matches():
    completed = run_schema("manuever.duraton")
    assert completed.returncode == 2
    assert "manuever.duraton" in completed.stderr and "maneuver.duration" in completed.stderr
    assert "Traceback" not in completed.stderr


def test_schema_keys_select_what_they_name():
    everything = schema_text()
    assert all(entry.path in everything for entry in entries())
    # the YAML path of an option (indices ignored) selects it in every planner that has it
    selected = schema_text("planners[0].options.torque_fraction")
    having = sum("torque_fraction" in {f.name for f in dataclasses.fields(c.Options)} for c in PLANNERS.values())
    assert re.findall(r"^planners\[i\]\.options\.\w+$", selected, re.MULTILINE) == \
        ["planners[i].options.torque_fraction"] * having
    assert "controller.options.gain" in schema_text("controllers.bdot")
    # a key selects itself and what lies under it, not a longer name it begins (warm_start_options)
    warm = schema_text("planners.collocation.warm_start")
    assert re.findall(r"^planners\[i\]\.options\.\w+$", warm, re.MULTILINE) == ["planners[i].options.warm_start"]
    # a registered controller without options is a part of its own (it was "not a key", its close match itself)
    assert schema_text("controller.none").startswith("Controller options: none") and "it has none" in schema_text("controller.none")
    assert "execution.retries" in schema_text("study.execution") and "maneuver" not in schema_text("study.execution")
    scenario_part = schema_text("scenario")
    assert "simulation.compile" in scenario_part and "planners[i].options.intervals" in scenario_part
    assert "execution.workers" not in scenario_part
    with pytest.raises(ScenarioError, match="close matches: simulation.sensor_noise.seed, study.monte_carlo.seed"):
        schema_text("seed")


def test_every_study_path_the_reference_prints_selects_its_entry(capsys):
    """``slewbench schema`` prints a study entry under its YAML path (``grid.<path>.linspace``,
    ``monte_carlo.samples``): that path, typed back, selects it, as ``study.<key>`` does."""
    printed = [entry.path for entry in entries("Study file")]
    assert "grid.<path>.linspace" in printed and "monte_carlo.samples" in printed
    for path in printed:
        if path == "scenario":  # the study's base scenario: ``scenario`` names every scenario key
            continue
        assert path in schema_text(path).splitlines(), path
    assert "grid.<path>.linspace" in schema_text("grid.linspace").splitlines()  # the key without study.
    assert "scenario" in schema_text("study.scenario").splitlines()
    assert "Study file" not in schema_text("scenario")
    for key in ("grid.<path>.linspace", "monte_carlo.samples"):
        completed = schema_here(capsys, key)
        assert completed.returncode == 0 and key in completed.stdout.splitlines(), completed.stderr


def test_slewbench_schema_table_prints_the_slew_table_keys(capsys):
    """A slew-table file's keys were left out of the reference (a pointer to the guide instead);
    they are in it now, from the declarations ``slewbench table`` reads them by
    (``tests/test_slewtable_schema.py`` compares both)."""
    completed = schema_here(capsys, "table")
    assert completed.returncode == 0, completed.stderr
    lines = completed.stdout.splitlines()
    assert {"table.scenario", "table.axes", "table.execution.case_timeout_s", "table.refine.max_rounds"} <= set(lines)
    refine = schema_here(capsys, "table.refine")
    assert refine.returncode == 0 and "table.refine.tolerance" in refine.stdout.splitlines()
    assert "table.axes" not in refine.stdout.splitlines()
    assert "number or null; default null; > 0 and < 1" in refine.stdout and "--tolerance" in refine.stdout
    unknown = schema_here(capsys, "table.refine.tolerence")
    assert unknown.returncode == 2 and "Traceback" not in unknown.stderr
    assert "close matches: table.refine.tolerance" in unknown.stderr, unknown.stderr


class _Documented:
    """Solved with ``scipy.integrate.solve_bvp`` about :class:`~ocp.quat.Axis` (*Space Mechanics*,
    :math:`\\omega` and :func:`ocp.quat.error`), with ``q0* ⊗ qf``. The second sentence."""


def test_summary_lines_are_plain_text_for_the_terminal():
    assert summary_line(_Documented, module_first=False) == \
        "Solved with scipy.integrate.solve_bvp about Axis (Space Mechanics, omega and ocp.quat.error), with q0* ⊗ qf."
    registered = [*PLANNERS.values(), *CONTROLLERS.values()]
    for cls in registered:
        line = summary_line(cls)
        assert not re.search(r"``|:[a-z]+:`|(?<![\w*])\*\w", line), (cls, line)
    listing = subprocess.run([sys.executable, "-m", "scenarios.cli", "list"], capture_output=True, text=True,
                             timeout=300, cwd=ROOT, check=True).stdout
    assert "``" not in listing and ":class:" not in listing
    assert "q0* ⊗ qf" in listing  # a conjugate's star is not emphasis


# --- validated once -------------------------------------------------------------------------------

SMALL = """
name: small
spacecraft: {inertia: [2.0, 3.0, 4.0], wheels: {max_torque: 0.05}}
maneuver:
  duration: 20.0
  initial: {q: [1, 0, 0, 0], omega: [0, 0, 0]}
  final: {q: [0.9659258, 0.2588190, 0, 0], omega: [0, 0, 0]}
planners:
  - {name: eigenaxis, label: smooth}
  - {name: eigenaxis, label: fast, options: {profile: min_time}}
controllers:
  - {name: augmented_quaternion_feedback, options: {kp: 0.2, kd: 0.6}}
  - {name: eigenaxis_pd, options: {kp: 0.2, kd: 0.6}}
simulation: {sample_time: 0.5, duration: 25.0}
"""


def test_planners_and_controllers_are_validated_once_and_the_run_reuses_them(monkeypatch, tmp_path):
    calls: list[tuple[str, str]] = []
    original = ocp.options.parse_options

    def counting(options_class, values, path="options"):
        calls.append((options_class.__qualname__, path))
        return original(options_class, values, path)

    monkeypatch.setattr(ocp.options, "parse_options", counting)
    scenario = scenarios.parse_scenario(parse_yaml_text(SMALL))
    assert sorted(calls) == [("AugmentedQuaternionFeedback.Options", "controllers[0].options"),
                             ("EigenaxisPD.Options", "controllers[1].options"),
                             ("EigenaxisPlanner.Options", "planners[0].options"),
                             ("EigenaxisPlanner.Options", "planners[1].options")]
    calls.clear()
    cache = SolverCache()
    results = scenarios.run(scenario, cache=cache)
    assert [row.status for row in results.rows] == ["ok"] * 4
    from scenarios.codegen import generate
    generate(scenario, tmp_path / "c")
    assert calls == []  # the checks, the runner and codegen use the loader's instances
    planner = scenario.planners[1].planner
    assert planner.options.profile == "min_time" and planner.cache is None
    copied = planner.with_cache(cache)
    assert copied is not planner and copied.cache is cache and copied.options is planner.options
    assert planner.with_cache(None) is planner


# --- the extension guides, run as written --------------------------------------------------------

def code_blocks(guide: str, language: str) -> list[str]:
    text = (ROOT / "docs" / "extending" / guide).read_text()
    return [textwrap.dedent(match.group(2)) for match in
            re.finditer(r"^\.\. code-block:: (\w+)\n\n((?:(?:    .*)?\n)+)", text, re.MULTILINE)
            if match.group(1) == language]


def test_the_field_model_guide_registers_a_model_that_a_scenario_uses():
    namespace: dict[str, Any] = {}
    try:
        for code in code_blocks("environment.rst", "python"):
            # the guide's code as written (not this module's `from __future__ import annotations`)
            exec(compile(code, "environment.rst", "exec", dont_inherit=True), namespace)  # noqa: S102
        data = parse_yaml_text(code_blocks("environment.rst", "yaml")[0])
        scenario = scenarios.parse_scenario(copy.deepcopy(data))
        field = scenario.problem.environment.magnetic_field
        assert field == namespace["UniformField"]((0.0, 2e-5, 4e-5))
        axis, angle = np.array([0.0, 0.6, 0.8]), 1.1
        x = np.concatenate([quat.from_axis_angle(axis, angle), np.zeros(3)])
        cross = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
        rotation = np.eye(3) * np.cos(angle) + np.sin(angle) * cross + (1 - np.cos(angle)) * np.outer(axis, axis)
        expected = rotation.T @ np.array([0.0, 2e-5, 4e-5])  # the inertial field in body axes (Rodrigues)
        assert np.allclose(np.asarray(scenario.problem.model.field_body(x, 17.0)).ravel(), expected, rtol=1e-12)
        row = scenarios.run(scenario).rows[0]
        assert row.status == "ok" and row.closed_loop_metrics["energy_ratio"] < 1.0  # B-dot takes energy out
        assert "environment.magnetic_field.field_nT" in schema_text("environment.magnetic_field.uniform")
        data["environment"]["magnetic_field"]["field_nT"] = [0, 1]
        with pytest.raises(ScenarioError, match=r"environment\.magnetic_field\.field_nT: expected 3 numbers, got 2"):
            scenarios.parse_scenario(data)
    finally:
        MAGNETIC_FIELDS.pop("uniform", None)


def test_the_study_generator_guide_registers_a_generator_that_a_study_uses():
    namespace: dict[str, Any] = {}
    try:
        for code in code_blocks("study_generator.rst", "python"):
            exec(compile(code, "study_generator.rst", "exec", dont_inherit=True), namespace)  # noqa: S102
        data = parse_yaml_text(code_blocks("study_generator.rst", "yaml")[0])
        study = parse_study(copy.deepcopy(data), ROOT / "scenarios" / "study.yaml")
        assert [case.scenario["maneuver"]["duration"] for case in study.cases] == [60.0, 90.0, 120.0]
        assert [case.varied["maneuver.duration"] for case in study.cases] == [60.0, 90.0, 120.0]
        assert "grid.<path>.arange.step" in schema_text("study.grid.arange")
        data["grid"]["maneuver.duration"] = {"arange": {"start": 0, "stop": 1, "step": 1e-9}}
        with pytest.raises(ScenarioError, match=r"grid\.maneuver\.duration\.arange: expected 1 to 10000 values"):
            parse_study(data, ROOT / "scenarios" / "study.yaml")
    finally:
        VALUE_GENERATORS.pop("arange", None)


def test_a_field_model_option_with_any_declared_range_is_read_and_checked_by_it():
    """A user's field model may declare any Range: the scenario reads it, refuses a value outside it at
    its YAML path in the Range's own words, and the reference states it (no TypeError at load)."""
    @dataclasses.dataclass(frozen=True)
    class Scaled(FieldModel):
        name: ClassVar[str] = "scaled_test"
        b: float = 1.0

        @dataclasses.dataclass(frozen=True)
        class Options:
            gain: Annotated[float, ocp.options.Range(ge=1.0, lt=10.0)] = 2.0

        @classmethod
        def from_options(cls, options: Any, orbit: Any) -> Scaled:
            return cls(3e-5 * options.gain)

        def field_inertial(self, position: Any, t: Any) -> Any:
            return ca.DM([0.0, 0.0, self.b])

    MAGNETIC_FIELDS[Scaled.name] = Scaled
    try:
        data = parse_yaml_text(textwrap.dedent("""
            spacecraft: {inertia: [1, 1, 1], magnetorquers: {max_dipole: 0.1}, wheels: null}
            orbit: {altitude_km: 500}
            environment: {magnetic_field: {model: scaled_test, gain: 4.0}}
            name: scaled-field
            maneuver: {duration: 10, initial: {q: [1, 0, 0, 0]}, final: {q: null, omega: [0, 0, 0]}}
            planners: []
            controller: {name: bdot}
        """))
        scenario = scenarios.parse_scenario(copy.deepcopy(data))
        assert scenario.problem.environment.magnetic_field == Scaled(1.2e-4)
        for bad in (0.5, 10.0, "x"):
            data["environment"]["magnetic_field"]["gain"] = bad
            with pytest.raises(ScenarioError, match=r"environment\.magnetic_field\.gain: expected a (finite )?number"):
                scenarios.parse_scenario(copy.deepcopy(data))
        assert ">= 1" in schema_text("environment.magnetic_field.scaled_test") and "< 10" in schema_text(
            "environment.magnetic_field.scaled_test")
    finally:
        MAGNETIC_FIELDS.pop("scaled_test", None)
