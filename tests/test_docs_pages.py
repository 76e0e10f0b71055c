"""Hand-written documentation pages against what they describe.

Each test reads a page's text and checks it against the code or the files it names, with an
oracle that is not the page: the files in ``scenarios/``, the class attributes of
:class:`planners.Planner`, the message the requirement scoring writes, the header
:func:`scenarios.output.writer.write_timeseries` writes, and the loader's verdict on the YAML a
page describes. (The pages' code blocks run in ``tests/test_readme.py`` and
``tests/test_extension_guides.py``.)
"""
from __future__ import annotations

import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import scenarios
from ocp import Spacecraft
from planners import Planner
from scenarios.requirements.scoring import unhonoured
from scenarios.schema import parse_yaml_text, read_yaml

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
SHIPPED = sorted((ROOT / "scenarios").glob("*.yaml"))
STUDIES = [path for path in SHIPPED if "study" in read_yaml(path)]
SCENARIOS = [path for path in SHIPPED if path not in STUDIES]
NUMBERS = {"two": 2, "three": 3, "four": 4, "five": 5, "six": 6, "seven": 7, "eight": 8}


def section(text: str, start: str, end: str) -> str:
    """The text from the first ``start`` to the next ``end`` after it (both must be there)."""
    begin = text.index(start)
    return text[begin:text.index(end, begin + len(start))]


def list_table_rows(text: str) -> list[list[str]]:
    """The rows of the first ``.. list-table::`` in ``text``: each a list of its cells' text."""
    lines = text[text.index(".. list-table::"):].splitlines()[1:]
    rows: list[list[str]] = []
    indent = None
    for line in lines:
        match = re.match(r"^(\s*)(\* -|  -)(.*)$", line)
        if match and (indent is None or len(match.group(1)) == indent):
            indent = len(match.group(1))
            if match.group(2) == "* -":
                rows.append([match.group(3).strip()])
            else:
                rows[-1].append(match.group(3).strip())
        elif line.strip() and indent is not None and len(line) - len(line.lstrip()) > indent + 2:
            rows[-1][-1] = (rows[-1][-1] + " " + line.strip()).strip()
        elif line.strip() and not line.lstrip().startswith(":") and indent is not None:
            break  # the text after the table
    return rows


# --- docs/guide/scenarios.rst and studies.rst: the shipped files --------------------------------

def test_the_list_of_shipped_scenarios_names_every_scenario_file():
    listed = section((DOCS / "guide" / "scenarios.rst").read_text(), "The scenarios shipped", "The command line")
    missing = [path.name for path in SCENARIOS if f"``{path.name}``" not in listed]
    assert not missing, f"scenario files missing from docs/guide/scenarios.rst's list: {missing}"
    count = re.search(r"``study_\*\.yaml``\s*- (\w+) trade studies", listed)
    assert count and NUMBERS[count.group(1)] == len(STUDIES), (count and count.group(1), len(STUDIES))


def test_the_shipped_studies_paragraph_names_every_study_file():
    paragraph = section((DOCS / "guide" / "studies.rst").read_text(), "The shipped studies", "A study file")
    missing = [path.name for path in STUDIES if f"``scenarios/{path.name}``" not in paragraph]
    assert not missing, f"study files missing from docs/guide/studies.rst: {missing}"


# --- docs/extending/planner.rst: the capabilities ------------------------------------------------

def planner_capability_rows() -> list[list[str]]:
    text = (DOCS / "extending" / "planner.rst").read_text()
    return list_table_rows(section(text, "Capabilities\n", "What the conformance check verifies"))


def test_every_capability_row_has_a_declaration_and_a_meaning():
    rows = planner_capability_rows()
    assert rows[0] == ["declaration", "meaning"]
    for row in rows[1:]:
        assert len(row) == 2 and all(row), f"a capability row with a missing cell: {row}"
        assert row[0].startswith("``"), row


def test_every_capability_the_planner_base_class_declares_is_in_the_table():
    declared = [name for name, kind in Planner.__annotations__.items() if str(kind).startswith("ClassVar")]
    assert {"closed_form", "cheap", "honours", "example_options"} <= set(declared)
    first_cells = " ".join(row[0] for row in planner_capability_rows())
    assert [name for name in declared if f"``Planner.{name}``" not in first_cells] == []


def test_the_honours_row_quotes_the_message_of_a_planner_that_does_not_honour_a_kind():
    row = next(row for row in planner_capability_rows() if row[0] == "``Planner.honours``")
    template = re.search(r"``(<name> does not honour the <kind> requirement[^`]*)``", row[1])
    assert template, row[1]
    from planners import PLANNERS

    planner = PLANNERS["natural_motion"]()  # honours none
    requirements = SimpleNamespace(actuators=None, kinds=("pointing",))
    assert unhonoured(requirements, planner) == \
        template.group(1).replace("<name>", "natural_motion").replace("<kind>", "pointing")
    for kind in ("pointing", "actuators", "rate"):
        assert f'``"{kind}"``' in row[1]


# --- docs/outputs.rst: the time series ------------------------------------------------------------

def test_the_time_series_prose_names_every_group_of_reference_columns(tmp_path):
    from scenarios.output.writer import write_timeseries

    samples, n_w = 2, 3
    simulation = SimpleNamespace(t=np.arange(samples + 1.0), x=np.zeros((samples + 1, 7 + n_w)),
                                 wheel_momentum=np.zeros((samples + 1, n_w)), applied_torque=np.zeros((samples, 3)))
    write_timeseries(SimpleNamespace(label="row", simulation=simulation, reference=None),
                     tmp_path / "row.csv")
    header = (tmp_path / "row.csv").read_text().splitlines()[0].split(",")
    groups = {re.sub(r"(\d|_[xyz])$", "", column) for column in header if column.startswith("ref_")}
    assert groups == {"ref_q", "ref_omega", "ref_omega_dot"}
    prose = section((DOCS / "outputs.rst").read_text(), "``timeseries/<row>.csv``", ".. include::")
    assert [group for group in sorted(groups) if f"``{group}" not in prose] == []


# --- docs/guide/maneuvers.rst: the quaternion form -----------------------------------------------

def test_the_quaternion_form_is_body_to_its_frame_as_the_guide_says():
    forms = list_table_rows(section((DOCS / "guide" / "maneuvers.rst").read_text(), "The forms", "Frames and"))
    quaternion = next(row for row in forms if row[0].startswith("``quaternion:"))
    assert quaternion[1].startswith("body to ``frame``") and "v_frame = R(q) v_body" in quaternion[1]
    # Oracle: the LVLH axes of the orbit, v_I = M v_LVLH; a body vector b is R(q_form) b in LVLH axes.
    data = read_yaml(ROOT / "scenarios" / "cubesat_12u_ground_target.yaml")
    q_form = np.array([0.8, 0.2, -0.4, 0.4]) / np.linalg.norm([0.8, 0.2, -0.4, 0.4])
    data["maneuver"]["initial"]["q"] = {"quaternion": q_form.tolist(), "frame": "lvlh"}
    problem = scenarios.parse_scenario(data).problem
    lvlh = np.array(problem.model.environment.orbit.lvlh_matrix(0.0), dtype=float)

    def matrix(q: np.ndarray) -> np.ndarray:  # body to inertial, scalar first (Shuster's form, by hand)
        w, v = q[0], q[1:]
        cross = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
        return (w * w - v @ v) * np.eye(3) + 2 * np.outer(v, v) + 2 * w * cross

    for body in np.eye(3):
        assert np.allclose(lvlh.T @ matrix(problem.q0) @ body, matrix(q_form) @ body, atol=1e-12)


# --- docs/guide/library.rst: reading YAML, and the wheels -------------------------------------------

def python_blocks(text: str) -> list[str]:
    """The bodies of the ``.. code-block:: python`` directives of an RST text, in order."""
    blocks, lines = [], text.splitlines()
    for number, line in enumerate(lines):
        directive = re.match(r"^(\s*)\.\. code-block:: python\s*$", line)
        if directive:
            body = []
            for following in lines[number + 1:]:
                if following.strip() and len(following) - len(following.lstrip()) <= len(directive.group(1)):
                    break
                body.append(following)
            blocks.append("\n".join(body))
    return blocks


def test_no_python_block_of_the_guides_reads_yaml_with_pyyaml():
    """PyYAML reads ``2.0e4`` as text, which the loader refuses: the guides teach slewbench's reader."""
    pages = sorted((DOCS / "guide").glob("*.rst")) + sorted((DOCS / "extending").glob("*.rst"))
    assert python_blocks((DOCS / "extending" / "planner.rst").read_text())  # the extractor finds blocks
    using = [page.name for page in pages for block in python_blocks(page.read_text())
             if re.search(r"yaml\.(safe_)?load\b|^\s*import yaml\b", block, re.MULTILINE)]
    assert using == []
    library = " ".join(python_blocks((DOCS / "guide" / "library.rst").read_text()))
    assert "read_yaml(" in library


def test_read_yaml_reads_every_shipped_file_the_loader_accepts():
    for path in SHIPPED:
        data = read_yaml(path)
        (scenarios.parse_study if path in STUDIES else scenarios.parse_scenario)(data, path)


WHEELS = """
name: wheels
spacecraft: {inertia: [2.0, 3.0, 4.0]WHEELS, torquers: {max_torque: 0.1}}
maneuver: {duration: 20.0, initial: {q: [1, 0, 0, 0], omega: [0, 0, 0]}, final: {q: [1, 0, 0, 0], omega: [0, 0, 0]}}
planners: [{name: eigenaxis}]
controller: {name: none}
simulation: {sample_time: 0.5}
"""


@pytest.mark.parametrize(("wheels", "count"), [("", 3), (", wheels: {}", 3), (", wheels: null", 0),
                                               (", wheels: none", 0), (", wheels: ~", 0)])
def test_the_wheels_of_a_scenario_file_are_as_the_library_guide_says(wheels, count):
    text = " ".join((DOCS / "guide" / "library.rst").read_text().split())
    assert "``spacecraft.wheels`` absent or ``wheels: {}`` gives three wheels on the body axes" in text
    assert "``wheels: null`` (or ``none``, or ``~``) gives none" in text
    model = scenarios.parse_scenario(parse_yaml_text(WHEELS.replace("WHEELS", wheels))).problem.model
    assert model.n_wheels == count
    if count:
        assert np.array_equal(model.spacecraft.wheels.axes, np.eye(3))
        assert np.all(np.isinf(model.spacecraft.wheels.max_torque)) and np.all(np.isinf(model.spacecraft.wheels.max_momentum))
    assert Spacecraft([2.0, 3.0, 4.0]).wheels is None  # the library's default: no wheels


# --- README.md and docs/guide/scenarios.rst: the closed-loop defaults -----------------------------

def _number(text: str) -> float:
    return float(text.replace(",", ""))


def test_the_closed_loop_defaults_the_readme_and_the_guide_state_are_the_schemas():
    from ocp.metrics import DEFAULT_SETTLING_TOLERANCE_DEG
    from scenarios.schema.loader import SIMULATION

    readme = " ".join(section((ROOT / "README.md").read_text(), "**Other simulation defaults.**",
                              "- **Spacecraft").split())
    stated = {"sample_time": re.search(r"`sample_time` ([\d.]+) s", readme),
              "max_step": re.search(r"at most ([\d.]+) s \(`max_step`\)", readme),
              "max_samples": re.search(r"at most ([\d,]+) samples \(`max_samples`\)", readme)}
    assert all(stated.values()), readme
    assert {key: _number(match.group(1)) for key, match in stated.items()} == \
        {key: SIMULATION[key].default for key in stated}
    # The settling tolerance has no fixed default (null): the final-error requirement's bound when
    # the scenario states one, else the metric's 0.5 deg.
    assert SIMULATION["settling_tolerance_deg"].default is None
    settling = re.search(r"`settling_tolerance_deg` ([\d.]+) \(or `requirements\.final\.error_deg` when the "
                         r"scenario states it\)", readme)
    assert settling and _number(settling.group(1)) == DEFAULT_SETTLING_TOLERANCE_DEG, readme
    guide = " ".join(section((DOCS / "guide" / "scenarios.rst").read_text(), "The other closed-loop defaults",
                             "Keys added").split())
    sample = re.search(r"``sample_time`` ([\d.]+) s", guide)
    step = re.search(r"``max_step`` ([\d.]+) s", guide)
    assert sample and step, guide
    assert (_number(sample.group(1)), _number(step.group(1))) == \
        (SIMULATION["sample_time"].default, SIMULATION["max_step"].default)


# --- docs/guide/scenarios.rst: the exit statuses ---------------------------------------------------

def test_the_exit_status_table_names_every_command_an_interrupt_ends_with_130():
    from scenarios.cli.status import EXIT_INTERRUPTED, INTERRUPTED_STATUS

    table = section((DOCS / "guide" / "scenarios.rst").read_text(), "Exit status\n", "The closed-loop window")
    row = " ".join(section(table, f"\n{EXIT_INTERRUPTED} ", "\n=====").split())
    commands = {command for command, status in INTERRUPTED_STATUS.items() if status == EXIT_INTERRUPTED}
    assert commands == {"sweep", "table"}
    assert "a sweep interrupted" in row and "``table``" in row, row



# --- docs/guide/slew_table.rst: a bare count that reads like degrees ---------------------------------

def test_the_slew_table_pages_bare_count_example_is_what_the_command_prints(tmp_path, capsys):
    """The page's ``--axes 12 ... --angles 90`` example, run on ``collocation_min_time.yaml`` (the
    page's first example scenario): it exits 2 and prints the message the page quotes, word for
    word (with the default polytope grid, 12 axes are 14, so the page must say ``--grid fibonacci``)."""
    from scenarios.cli import main

    text = " ".join((DOCS / "guide" / "slew_table.rst").read_text().split())
    found = re.search(r"confirms the work: ``(--axes [^`]+)`` exits 2 with ``([^`]+)``", text)
    assert found, "the example moved: update this test"
    arguments, quoted = found.group(1).split(), found.group(2)
    out = tmp_path / "out"
    status = main(["table", str(ROOT / "scenarios" / "collocation_min_time.yaml"), *arguments, "--out", str(out),
                   "--no-plots"])
    err = " ".join(capsys.readouterr().err.split())
    assert status == 2 and quoted in err, (arguments, quoted, err)
    assert not out.exists()

# --- docs/guide/slew_table.rst: the NetCDF file ------------------------------------------------------

def test_the_netcdf_attributes_and_variables_the_slew_table_page_lists_are_the_files(tmp_path):
    from scipy.io import netcdf_file

    from scenarios.slewtable.files import write_table_files
    from tests.test_table_status import synthetic_table

    write_table_files(synthetic_table(tmp_path), tmp_path, plots=False)
    with netcdf_file(tmp_path / "slew_table.nc", "r", mmap=False) as nc:
        written = set(nc._attributes)
        variables = set(nc.variables)
    item = " ".join(section((DOCS / "guide" / "slew_table.rst").read_text(), "``slew_table.nc``\n",
                            "``fit.json``\n").split())
    attributes = set(re.findall(r"``(\w+)``", item[item.index("Global attributes:"):]))
    attributes -= {"CF-1.8"}
    conditional = {"duration_s"}  # written for a table of a fixed duration only
    assert written <= attributes and attributes - written <= conditional, (sorted(written), sorted(attributes))
    listed = set(re.findall(r"``(\w+)``", item[item.index("variables"):item.index("Global attributes:")]))
    table_variables = {name for name in variables if not name.startswith(("held_out_", "check_"))}
    assert table_variables <= listed, sorted(table_variables - listed)


# --- docs/guide/bench.rst: the problems of the suite ------------------------------------------------

def test_the_bench_pages_problem_table_is_the_suites_index():
    suite = read_yaml(ROOT / "scenarios" / "bench" / "suite.yaml")
    text = (DOCS / "guide" / "bench.rst").read_text()
    assert f"(``version: {suite['version']}``" in text
    rows = list_table_rows(section(text, "The problems of version", "The command\n"))
    assert rows[0] == ["name", "objective", "optimum", "source"]
    assert f"The problems of version {suite['version']}" in text
    named: list[str] = []
    kinds = {"published": "published", "best_known": "best known", "closed_form": "closed form"}
    for names, objective, optimum, _ in rows[1:]:
        row_names = re.findall(r"``(\w+)``", names)
        values = [float(value) for value in re.findall(r"(?<![\w.])(\d+\.\d+(?:e-?\d+)?)(?: s)?", optimum)]
        for k, name in enumerate(row_names):
            problem = suite["problems"][name]
            assert objective == problem["objective"], name
            assert kinds[problem["optimum"]["kind"]] in optimum, (name, optimum)
            if values:  # a closed form may be stated as its formula
                assert values[k] == pytest.approx(problem["optimum"]["value"], rel=0, abs=1e-12), (name, optimum)
            if "±" in optimum:
                assert float(re.search(r"± (\S+) s", optimum).group(1)) == problem["optimum"]["tolerance"], name
        named += row_names
    assert named == list(suite["problems"])


# --- docs/guide/detumbling.rst: the IGRF table's default window ------------------------------------

IGRF = """
name: igrf-window
spacecraft: {inertia: [2.0, 3.0, 4.0], torquers: {max_torque: 0.1}, wheels: none}
orbit: {altitude_km: 600, inclination_deg: 97.79}
environment: {magnetic_field: {model: igrf, epoch: 2025-01-01}}
maneuver: {duration: 120.0, initial: {q: [1, 0, 0, 0], omega: [0, 0, 0]}, final: {q: [0, 0, 0, 1], omega: [0, 0, 0]}}
PLANNERS
controller: {name: eigenaxis_pd}
simulation: {sample_time: 1.0SIMULATION}
"""


@pytest.mark.parametrize(("planners", "duration", "span"), [
    ("planners: [{name: eigenaxis}]", None, 2 * 120.0 + 60.0),    # twice the manoeuvre, the longer
    ("planners: [{name: eigenaxis}]", 140.0, 2 * 120.0 + 60.0),
    ("planners: [{name: eigenaxis}]", 400.0, 400.0 + 60.0),        # the closed-loop window, the longer
    ("planners: []", None, 120.0 + 60.0),                          # no planner: the closed-loop window
    ("planners: []", 400.0, 400.0 + 60.0)])
def test_the_igrf_tables_default_window_is_as_the_detumbling_page_says(planners, duration, span):
    text = " ".join((DOCS / "guide" / "detumbling.rst").read_text().split())
    assert ("By default the closed-loop window or, when there are planners, twice the manoeuvre's duration if "
            "that is longer, plus 60 s") in text
    extra = "" if duration is None else f", duration: {duration}"
    data = parse_yaml_text(IGRF.replace("PLANNERS", planners).replace("SIMULATION", extra))
    assert scenarios.parse_scenario(data).problem.environment.magnetic_field.span == span
