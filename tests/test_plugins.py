"""Plugins reach the command line and the library without editing slewbench (scenarios.schema.plugins).

A real distribution is built on a temporary path: a ``*.dist-info`` directory with ``METADATA`` and
``entry_points.txt`` (group ``slewbench.plugins``) beside the plugin's module, put on the
subprocess's ``sys.path`` through ``PYTHONPATH``, so that ``importlib.metadata`` finds it as it
finds a ``pip install``-ed one. The plugin is the planner guide's cubic eigenaxis slew
(docs/extending/planner.rst) and the environment guide's uniform field. The command line is run
in subprocesses; the oracles are the planner contract's conformance check and the closed form
``∫‖u‖² dt = 12 I_z² θ² / T³`` of a rest-to-rest cubic slew about a principal axis, not the
plugin's printout.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from planners import PLANNERS

ROOT = Path(__file__).resolve().parents[1]

CUBIC = '''
from dataclasses import dataclass
from typing import Annotated, Any, ClassVar

import casadi as ca
import numpy as np

from ocp import quat
from ocp.dynamics.environment import MAGNETIC_FIELDS, FieldModel
from ocp.options import Range
from planners import PLANNERS, ManeuverProblem, Planner, Reference, ReferenceSample, inverse_dynamics_torque


class CubicSlewReference(Reference):
    def __init__(self, problem: ManeuverProblem, duration: float) -> None:
        rotation = quat.to_rotation_vector(quat.error(problem.qf, problem.q0))
        self.angle = float(np.linalg.norm(rotation))
        self.axis = rotation / self.angle if self.angle > 0 else np.array([1.0, 0.0, 0.0])
        self.q0 = problem.q0
        super().__init__("cubic_slew", duration, problem.spacecraft.inertia)

    def _evaluate(self, t):
        s = t / self.duration
        theta = self.angle * (3 * s**2 - 2 * s**3)
        rate = self.angle * (6 * s - 6 * s**2) / self.duration
        acceleration = self.angle * (6 - 12 * s) / self.duration**2
        q = quat.product(self.q0, quat.from_axis_angle(self.axis, theta))
        omega = rate[:, None] * self.axis
        omega_dot = acceleration[:, None] * self.axis
        return ReferenceSample(q, omega, omega_dot, inverse_dynamics_torque(self.inertia, omega, omega_dot))


class CubicSlewPlanner(Planner):
    name = "cubic_slew"

    @dataclass(frozen=True)
    class Options:
        time_fraction: Annotated[float, Range(gt=0.0, le=1.0)] = 1.0

    def problem_error(self, problem):
        if np.any(problem.omega0) or (problem.omegaf is not None and np.any(problem.omegaf)):
            return "cubic_slew is rest to rest: initial and final rates must be zero"
        return super().problem_error(problem)

    def _plan(self, problem):
        return CubicSlewReference(problem, self.options.time_fraction * problem.duration)


@dataclass(frozen=True)
class UniformField(FieldModel):
    """A field of fixed direction and strength in inertial axes."""

    name: ClassVar[str] = "uniform"
    b: tuple = (0.0, 0.0, 3.0e-5)

    @dataclass(frozen=True)
    class Options:
        """Options of ``uniform``.

        Attributes
        ----------
        field_nT : tuple of 3 floats
            The field [nT], inertial axes.
        """

        field_nT: Annotated[tuple[float, float, float], Range()] = (0.0, 0.0, 30000.0)

    @classmethod
    def from_options(cls, options, orbit):
        return cls(tuple(1e-9 * value for value in options.field_nT))

    def field_inertial(self, position, t):
        return ca.DM(self.b)


PLANNERS[CubicSlewPlanner.name] = CubicSlewPlanner
MAGNETIC_FIELDS[UniformField.name] = UniformField
'''

SCENARIO = """\
name: cubic-slew-demo
spacecraft:
  inertia: [19.5, 19.0, 12.6]
  wheels: {max_torque: 0.1, max_momentum: 4.0}
maneuver:
  duration: 120.0
  initial: {q: [1, 0, 0, 0], omega: [0, 0, 0]}
  final: {q: [0.7071068, 0, 0, 0.7071068], omega: [0, 0, 0]}   # 90 deg about z
planners:
  - {name: cubic_slew, label: cubic, options: {time_fraction: 0.8}}
controller: {name: augmented_quaternion_feedback, options: {kp: 0.06, kd: 0.48}}
simulation: {sample_time: 0.5, duration: 140.0}
"""


def distribution(site: Path, name: str, modules: dict[str, str], entry_points: dict[str, str]) -> Path:
    """Install a distribution by hand on ``site``: its modules and a dist-info with entry points."""
    site.mkdir(parents=True, exist_ok=True)
    for module, source in modules.items():
        (site / f"{module}.py").write_text(source)
    info = site / f"{name.replace('-', '_')}-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(
        "[slewbench.plugins]\n" + "".join(f"{key} = {value}\n" for key, value in entry_points.items()))
    return site


def slewbench(args: list[str], cwd: Path, site: Path | None = None, plugins: str | None = None,
              code: str | None = None) -> subprocess.CompletedProcess[str]:
    """``python -m scenarios.cli ARGS`` (or ``python -c CODE``) with ``site`` on the path."""
    env = {key: value for key, value in os.environ.items() if key not in ("SLEWBENCH_PLUGINS", "PYTHONPATH")}
    env["PYTHONPATH"] = os.pathsep.join([str(site)] * (site is not None) + [str(ROOT)])
    env["MPLBACKEND"] = "Agg"
    if plugins is not None:
        env["SLEWBENCH_PLUGINS"] = plugins
    command = [sys.executable, "-c", code] if code is not None else [sys.executable, "-m", "scenarios.cli", *args]
    return subprocess.run(command, cwd=cwd, env=env, capture_output=True, text=True, timeout=300,
                          check=False)


@pytest.fixture(scope="module")
def cubic_site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A site directory holding the distribution ``slewbench-cubic`` (entry point ``cubic``)."""
    return distribution(tmp_path_factory.mktemp("site"), "slewbench-cubic", {"cubic_slew": CUBIC},
                        {"cubic": "cubic_slew"})


def test_an_installed_plugin_plans_from_the_command_line(cubic_site: Path, tmp_path: Path) -> None:
    (tmp_path / "cubic.yaml").write_text(SCENARIO)
    done = slewbench(["run", "cubic.yaml", "--out", "out", "--no-plots"], tmp_path, cubic_site)
    assert done.returncode == 0, done.stderr
    rows = json.loads((tmp_path / "out" / "results.json").read_text())["rows"]
    assert [(row["planner"], row["status"]) for row in rows] == [("cubic_slew", "ok")], rows
    # the oracle: 90 deg about the z principal axis (I_z = 12.6) in 0.8 * 120 s, closed form
    closed_form = 12 * 12.6**2 * (np.pi / 2) ** 2 / 96.0**3
    assert rows[0]["reference"]["int_u2"] == pytest.approx(closed_form, rel=1e-5)


def test_the_library_loads_the_same_plugin_and_it_passes_the_conformance_check(cubic_site: Path,
                                                                               tmp_path: Path) -> None:
    (tmp_path / "cubic.yaml").write_text(SCENARIO)
    code = """
import scenarios
scenario = scenarios.load("cubic.yaml")   # the face's first use loads the plugins
from planners import PLANNERS
from planners.conformance import check_reference, standard_problems
planner = PLANNERS["cubic_slew"]({"time_fraction": 0.8})
checked = []
for name, problem in standard_problems().items():
    if planner.problem_error(problem) is None:
        check_reference(problem, planner.plan(problem))
        checked.append(name)
print(scenario.planners[0].name, type(planner).__module__, ",".join(checked))
"""
    done = slewbench([], tmp_path, cubic_site, code=code)
    assert done.returncode == 0, done.stderr
    name, module, checked = done.stdout.split()
    assert (name, module) == ("cubic_slew", "cubic_slew")
    assert "rest_to_rest" in checked.split(","), checked


def test_schema_and_list_show_the_plugins_names(cubic_site: Path, tmp_path: Path) -> None:
    schema = slewbench(["schema", "environment.magnetic_field.uniform"], tmp_path, cubic_site)
    assert schema.returncode == 0, schema.stderr
    assert "environment.magnetic_field.field_nT" in schema.stdout
    listing = slewbench(["list"], tmp_path, cubic_site)
    assert listing.returncode == 0, listing.stderr
    label = "entry point 'cubic' = cubic_slew (slewbench-cubic 0.1)"
    cubic_line = next(line for line in listing.stdout.splitlines() if line.strip().startswith("cubic_slew "))
    assert cubic_line.endswith(f"[plugin: {label}]")
    assert not any("[plugin:" in line for line in listing.stdout.splitlines() if "eigenaxis" in line)
    assert f"  {label}: planner cubic_slew; magnetic field model uniform" in listing.stdout.splitlines()


def test_without_the_plugin_the_name_is_unknown(tmp_path: Path) -> None:
    (tmp_path / "cubic.yaml").write_text(SCENARIO)
    done = slewbench(["validate", "cubic.yaml"], tmp_path)
    assert done.returncode == 2
    assert "unknown planner 'cubic_slew'" in done.stderr


def test_a_plugin_that_fails_to_import_is_named_with_its_exception(tmp_path: Path) -> None:
    site = distribution(tmp_path / "site", "slewbench-broken",
                        {"broken_plugin": "raise RuntimeError('the plugin is broken on purpose')\n"},
                        {"broken": "broken_plugin"})
    done = slewbench(["list"], tmp_path, site)
    assert done.returncode == 2, done.stdout
    assert done.stderr.strip() == ("slewbench: plugin error: plugin entry point 'broken' = broken_plugin "
                                   "(slewbench-broken 0.1) failed to load: RuntimeError: the plugin is "
                                   "broken on purpose")
    assert "Traceback" not in done.stderr and done.stdout == ""


def test_a_plugin_taking_a_registered_name_is_refused(tmp_path: Path) -> None:
    impostor = ("from planners import PLANNERS\n"
                "class Impostor(PLANNERS['eigenaxis']):\n    pass\n"
                "PLANNERS['eigenaxis'] = Impostor\n")
    site = distribution(tmp_path / "site", "slewbench-impostor", {"impostor": impostor}, {"impostor": "impostor"})
    done = slewbench(["list"], tmp_path, site)
    assert done.returncode == 2, done.stdout
    assert ("plugin entry point 'impostor' = impostor (slewbench-impostor 0.1) registers a name already taken, "
            "refused: planner 'eigenaxis' (already provided by slewbench)") in done.stderr
    assert "Traceback" not in done.stderr


def test_two_plugins_with_one_name_the_second_is_refused_naming_the_first(cubic_site: Path,
                                                                           tmp_path: Path) -> None:
    (tmp_path / "again.py").write_text(CUBIC.replace("MAGNETIC_FIELDS[UniformField.name] = UniformField", ""))
    done = slewbench(["list"], tmp_path, cubic_site, plugins=str(tmp_path / "again.py"))
    assert done.returncode == 2
    assert (f"plugin SLEWBENCH_PLUGINS file {tmp_path / 'again.py'} registers a name already taken, refused: "
            "planner 'cubic_slew' (already provided by entry point 'cubic' = cubic_slew (slewbench-cubic 0.1))"
            ) in done.stderr


def test_the_environment_variable_loads_a_file_or_a_module_on_the_path(tmp_path: Path) -> None:
    (tmp_path / "local_cubic.py").write_text(CUBIC)
    (tmp_path / "cubic.yaml").write_text(SCENARIO)
    by_file = slewbench(["validate", "cubic.yaml"], tmp_path, plugins="./local_cubic.py")
    assert by_file.returncode == 0, by_file.stderr
    assert "valid scenario 'cubic-slew-demo' with 1 planner(s)" in by_file.stdout
    listing = slewbench(["list"], tmp_path, tmp_path, plugins=" local_cubic , ")  # a module of PYTHONPATH
    assert "  SLEWBENCH_PLUGINS module local_cubic: planner cubic_slew; magnetic field model uniform" \
        in listing.stdout.splitlines(), listing.stderr
    missing = slewbench(["list"], tmp_path / "..", plugins="local_cubic")  # not on the path
    assert missing.returncode == 2
    assert ("plugin SLEWBENCH_PLUGINS module local_cubic failed to load: ModuleNotFoundError: No module named "
            "'local_cubic'") in missing.stderr
    assert "SLEWBENCH_PLUGINS=./local_cubic.py" in missing.stderr


def test_a_failed_plugin_leaves_no_name_behind(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    from scenarios.schema import plugins

    (tmp_path / "half.py").write_text("from planners import PLANNERS\n"
                                      "PLANNERS['half_registered'] = PLANNERS['eigenaxis']\n"
                                      "raise ValueError('fails after registering')\n")
    monkeypatch.setenv(plugins.ENVIRONMENT_VARIABLE, str(tmp_path / "half.py"))
    before = dict(PLANNERS)
    with pytest.raises(plugins.PluginError, match="failed to load: ValueError: fails after registering"):
        plugins.load_plugins()
    assert dict(PLANNERS) == before
    assert "half" not in sys.modules
    assert plugins.provider("planner", "half_registered") is None


def test_an_entry_point_naming_a_class_is_refused(tmp_path: Path) -> None:
    site = distribution(tmp_path / "site", "slewbench-class", {"cubic_slew": CUBIC},
                        {"cubic": "cubic_slew:CubicSlewPlanner"})
    done = slewbench(["list"], tmp_path, site)
    assert done.returncode == 2
    assert "it names the class CubicSlewPlanner: name its module" in done.stderr


def test_a_study_value_generator_plugin_from_its_guide_reaches_validate(tmp_path: Path) -> None:
    guide = (ROOT / "docs" / "extending" / "study_generator.rst").read_text()
    block = guide.split(".. code-block:: python\n", 1)[1].split("\nA study then writes it", 1)[0]
    (tmp_path / "arange_plugin.py").write_text(textwrap.dedent(block))
    (tmp_path / "study.yaml").write_text(f"study: eigenaxis-durations\nscenario: {ROOT / 'scenarios' / 'eigenaxis_demo.yaml'}\n"
                                         "grid:\n  maneuver.duration: {arange: {start: 60, stop: 150, step: 30}}\n")
    without = slewbench(["validate", "study.yaml"], tmp_path)
    assert without.returncode == 2 and "arange" in without.stderr
    done = slewbench(["validate", "study.yaml"], tmp_path, plugins="arange_plugin.py")
    assert done.returncode == 0, done.stderr
    assert "3 cases (3 grid point(s) x 1 sample(s)), varying maneuver.duration" in done.stdout


def test_a_refused_clash_restores_the_registry(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    from scenarios.schema import plugins

    (tmp_path / "clash.py").write_text("from planners import PLANNERS\n"
                                       "PLANNERS['clash_new'] = PLANNERS['natural_motion']\n"
                                       "PLANNERS['eigenaxis'] = PLANNERS['natural_motion']\n")
    monkeypatch.setenv(plugins.ENVIRONMENT_VARIABLE, str(tmp_path / "clash.py"))
    before = dict(PLANNERS)
    with pytest.raises(plugins.PluginError, match="refused: planner 'eigenaxis' \\(already provided by slewbench\\)"):
        plugins.load_plugins()
    assert dict(PLANNERS) == before and list(PLANNERS) == list(before)
    assert all(PLANNERS[name] is before[name] for name in before)


def test_a_sweep_runs_its_cases_with_the_plugin_planner(tmp_path: Path) -> None:
    (tmp_path / "local_cubic.py").write_text(CUBIC)
    scenario = "\n".join("  " + line for line in SCENARIO.replace("name: cubic-slew-demo", "name: cubic-study")
                         .splitlines())
    (tmp_path / "study.yaml").write_text(f"study: cubic-study\nscenario:\n{scenario}\n"
                                         "grid:\n  maneuver.duration: [100.0, 120.0]\n")
    done = slewbench(["sweep", "study.yaml", "--out", "sweep", "--no-plots", "--workers", "2"], tmp_path,
                     plugins=str(tmp_path / "local_cubic.py"))
    assert done.returncode == 0, done.stderr
    cases = (tmp_path / "sweep" / "cases.csv").read_text().splitlines()[1:]
    assert len(cases) == 2 and all(",cubic_slew,augmented_quaternion_feedback,ok," in case for case in cases), cases


def test_a_plugin_file_named_after_a_package_does_not_replace_it(tmp_path: Path) -> None:
    # Before: controllers.py was imported as the module `controllers`, replacing slewbench's package:
    # an ImportError traceback and "internal error", exit 1.
    (tmp_path / "plug").mkdir()  # not the working directory, which `python -m` puts on the path
    (tmp_path / "plug" / "controllers.py").write_text(CUBIC)
    done = slewbench(["list"], tmp_path, plugins="./plug/controllers.py")
    assert done.returncode == 0, done.stderr
    assert "cubic_slew" in done.stdout and "Traceback" not in done.stderr


def test_a_plugin_that_calls_sys_exit_is_a_plugin_error(tmp_path: Path) -> None:
    (tmp_path / "quits.py").write_text("import sys\nsys.exit(3)\n")
    done = slewbench(["list"], tmp_path, plugins="./quits.py")
    assert done.returncode == 2, (done.returncode, done.stderr)
    assert "plugin SLEWBENCH_PLUGINS file ./quits.py failed to load: SystemExit: 3" in done.stderr


def test_a_file_the_script_imported_is_not_loaded_twice(tmp_path: Path) -> None:
    # Before: the variable's file ran again as a second module, whose registration clashed with the
    # script's own import ("already provided by slewbench").
    (tmp_path / "cubic_slew.py").write_text(CUBIC)
    (tmp_path / "cubic.yaml").write_text(SCENARIO)
    code = ("import sys; sys.path.insert(0, '.'); import cubic_slew, scenarios\n"
            "print(scenarios.load('cubic.yaml').planners[0].name)\n")
    done = slewbench([], tmp_path, plugins="./cubic_slew.py", code=code)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "cubic_slew"


def test_a_second_thread_waits_for_the_plugins(tmp_path: Path) -> None:
    # Before: the second thread found the loading flag set, loaded nothing and went on before the
    # plugin had registered its planner ("unknown planner 'cubic_slew'").
    (tmp_path / "slow_cubic.py").write_text("import time\ntime.sleep(1.0)\n" + CUBIC)
    (tmp_path / "cubic.yaml").write_text(SCENARIO)
    code = ("import threading, scenarios\nout = {}\n"
            "def go(k):\n    try:\n        out[k] = scenarios.load('cubic.yaml').planners[0].name\n"
            "    except Exception as error:\n        out[k] = repr(error)\n"
            "threads = [threading.Thread(target=go, args=(k,)) for k in (0, 1)]\n"
            "[t.start() for t in threads]; [t.join() for t in threads]\nprint(sorted(out.values()))\n")
    done = slewbench([], tmp_path, plugins="./slow_cubic.py", code=code)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "['cubic_slew', 'cubic_slew']", done.stdout


@pytest.mark.parametrize("entry, kind", [("scenario.yaml", "a file"), ("{tmp}", "a directory"),
                                         ("./nowhere/plugin", "a path")])
def test_an_entry_that_is_a_path_but_not_a_py_file_is_named_as_such(entry: str, kind: str,
                                                                    monkeypatch: pytest.MonkeyPatch,
                                                                    tmp_path: Path) -> None:
    """SLEWBENCH_PLUGINS=scenario.yaml was imported as the module name 'scenario.yaml': 'No module
    named 'scenario'' and the hint to give ./scenario.py; './nowhere/plugin' gave a TypeError about
    relative imports. A package directory named without a slash is still a module name."""
    from scenarios.schema import plugins

    monkeypatch.chdir(tmp_path)
    (tmp_path / "scenario.yaml").write_text(SCENARIO)
    text = entry.format(tmp=tmp_path)
    monkeypatch.setenv(plugins.ENVIRONMENT_VARIABLE, text)
    with pytest.raises(plugins.PluginError) as error:
        plugins.load_plugins()
    assert str(error.value) == (f"plugin SLEWBENCH_PLUGINS entry {text} failed to load: ValueError: {text} is {kind}, "
                                "not a .py file or a module name: give the path of a .py file or a module "
                                "importable from sys.path (mypackage.plugins)")
    (tmp_path / "a_package").mkdir()
    monkeypatch.setenv(plugins.ENVIRONMENT_VARIABLE, "a_package")
    with pytest.raises(plugins.PluginError, match="module a_package failed to load: ModuleNotFoundError"):
        plugins.load_plugins()
