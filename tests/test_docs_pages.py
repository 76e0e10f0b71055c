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
