"""A plugin's planner or controller that misbehaves fails its own rows, named, not the run.

A user's planner whose reference is NaN somewhere or whose ``_evaluate`` raises, and a user's law
that raises or returns NaN mid-simulation, used to stop ``slewbench run`` with "internal error",
exit 1 and nothing written. Each row of such a planner or law is now ``failed`` with a message
naming it, what was wrong and when; the other rows run and are written, and the exit status is
the documented one for failed rows (0; 1 under ``--strict``). ``slewbench list`` and ``schema``
describe a plugin's classes by their own docstrings.
"""
from __future__ import annotations

import importlib.util
import json
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
import pytest

from controllers import CONTROLLERS, Controller
from ocp import quat
from ocp.options import Range
from planners import (
    PLANNERS,
    ManeuverProblem,
    Planner,
    Reference,
    ReferenceSample,
    inverse_dynamics_torque,
)
from scenarios.cli import main
from scenarios.schema.reference import summary_line

T = 60.0
"""The manoeuvre's duration [s]."""
RUNAWAY = 1e4
"""The ``runaway`` defect's peak rate across the slew axis [rad/s], at T/2."""
RUNAWAY_END = 0.05
"""The ``runaway`` defect's rate at T [rad/s] (the manoeuvre asks rest)."""


class _CubicReference(Reference):
    """A rest-to-rest eigenaxis cubic in the angle, with a defect on demand."""

    def __init__(self, problem: ManeuverProblem, defect: str) -> None:
        rotation = quat.to_rotation_vector(quat.error(problem.qf, problem.q0))
        self.angle = float(np.linalg.norm(rotation))
        self.axis = rotation / self.angle
        self.q0 = problem.q0
        self.defect = defect
        super().__init__("test_cubic", problem.duration, problem.spacecraft.inertia)

    def _evaluate(self, t: np.ndarray) -> ReferenceSample:
        s = t / self.duration
        scale = 0.9 if self.defect == "short" else 1.0  # "short": 90 % of the angle, at rest at T
        theta = scale * self.angle * (3 * s**2 - 2 * s**3)
        omega = (scale * self.angle * (6 * s - 6 * s**2) / self.duration)[:, None] * self.axis
        omega_dot = (scale * self.angle * (6 - 12 * s) / self.duration**2)[:, None] * self.axis
        if self.defect == "runaway":  # q reaches qf, but ω peaks at RUNAWAY mid-slew and ends RUNAWAY_END off rest
            across = np.cross(self.axis, [1.0, 0.0, 0.0] if abs(self.axis[0]) < 0.9 else [0.0, 1.0, 0.0])
            across /= np.linalg.norm(across)
            extra = RUNAWAY * np.sin(np.pi * s) ** 2 + RUNAWAY_END * s**3
            extra_dot = (RUNAWAY * np.pi * np.sin(2 * np.pi * s) + 3 * RUNAWAY_END * s**2) / self.duration
            omega = omega + extra[:, None] * across
            omega_dot = omega_dot + extra_dot[:, None] * across
        q = quat.product(self.q0, quat.from_axis_angle(self.axis, theta))
        torque = inverse_dynamics_torque(self.inertia, omega, omega_dot)
        if self.defect == "nan_late":  # q is NaN after T/2, so at T too (the coast after T starts there)
            q = q.copy()
            q[t > 0.5 * self.duration] = np.nan
        if self.defect == "nan_mid":  # the torque only, on (0.4 T, 0.6 T)
            torque = torque.copy()
            torque[(t > 0.4 * self.duration) & (t < 0.6 * self.duration)] = np.nan
        if self.defect == "raise" and np.any(t > 0.5 * self.duration):
            raise RuntimeError("simulated crash inside _evaluate")
        return ReferenceSample(q, omega, omega_dot, torque)


class _CubicPlanner(Planner):
    name = "test_cubic"

    @dataclass(frozen=True)
    class Options:
        defect: Literal["none", "nan_late", "nan_mid", "raise", "short", "runaway"] = "none"

    def _plan(self, problem: ManeuverProblem) -> Reference:
        return _CubicReference(problem, self.options.defect)


class _PD(Controller):
    """A PD law on the quaternion error with the reference's torque fed forward, NumPy only."""

    name = "test_pd"

    @dataclass(frozen=True)
    class Options:
        kp: Annotated[float, Range(ge=0.0)] = 0.5
        kd: Annotated[float, Range(ge=0.0)] = 1.0
        defect: Literal["none", "nan", "raise", "reset", "array"] = "none"

    def reset(self, spacecraft: Any, sample_time: float, target: Any = None) -> None:
        super().reset(spacecraft, sample_time, target)
        if self.options.defect == "reset":
            raise KeyError("simulated crash in reset")
        self.K = self.options.kp * spacecraft.inertia
        self.D = self.options.kd * spacecraft.inertia

    def __call__(self, t: float, measurement: Any, reference: Any) -> Any:
        row = self.reference_rows(reference, np.array([t]))[0]
        q_e = quat.error(measurement.q, row[0:4])
        u = -self.K @ q_e[1:4] - self.D @ (measurement.omega - row[4:7]) + row[10:13]
        if t >= 20.0 and self.options.defect == "nan":
            u = u * np.nan
        if t >= 20.0 and self.options.defect == "raise":
            raise ValueError("simulated crash in the law")
        if self.options.defect == "array":
            return u  # a torque array, not a Command
        return self.allocate(u, measurement)

    def symbolic_error(self) -> str | None:
        return "test_pd is written in NumPy only"


@pytest.fixture
def registered(monkeypatch: pytest.MonkeyPatch) -> None:
    """The test planner and law in the registries, as a plugin registers them."""
    monkeypatch.delenv("SLEWBENCH_PLUGINS", raising=False)
    monkeypatch.setitem(PLANNERS, _CubicPlanner.name, _CubicPlanner)
    monkeypatch.setitem(CONTROLLERS, _PD.name, _PD)


def _scenario(tmp_path: Path, planners: str, controllers: str) -> Path:
    path = tmp_path / "scenario.yaml"
    path.write_text(f"""\
name: plugin-failures
spacecraft:
  inertia: [3.0, 4.0, 5.0]
  wheels: {{max_torque: 0.2}}
maneuver:
  duration: {T}
  initial: {{q: [1, 0, 0, 0], omega: [0, 0, 0]}}
  final: {{q: [0.7071068, 0, 0, 0.7071068], omega: [0, 0, 0]}}
planners:
{planners}
controllers:
{controllers}
simulation: {{sample_time: 0.1, duration: 70.0}}
""")
    return path


def _rows(out: Path) -> dict[str, dict[str, Any]]:
    return {row["label"]: row for row in json.loads((out / "results.json").read_text())["rows"]}


def test_a_planner_whose_reference_is_nan_or_raises_fails_its_rows_only(registered: None, tmp_path: Path,
                                                                        capsys: pytest.CaptureFixture[str]) -> None:
    path = _scenario(tmp_path, planners="""\
  - {name: test_cubic, label: good}
  - {name: test_cubic, label: nan_late, options: {defect: nan_late}}
  - {name: test_cubic, label: nan_mid, options: {defect: nan_mid}}
  - {name: test_cubic, label: raise, options: {defect: raise}}
  - {name: eigenaxis, label: eigenaxis}""", controllers="""\
  - {name: test_pd, label: pd}""")
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 0  # failed rows: exit 0 (documented)
    rows = _rows(out)
    assert [rows[label]["status"] for label in ("good", "eigenaxis")] == ["ok", "ok"]
    # the first sample after T/2 of the 2001 uniform times on [0, T] is 1001 T/2000 = 30.03 s
    assert rows["nan_late"]["status"] == "failed"
    assert rows["nan_late"]["message"].startswith("test_cubic: its reference is not finite at t = 30.03 s (q;")
    # the torque is NaN on (0.4 T, 0.6 T): first at 801 T/2000 = 24.03 s
    assert rows["nan_mid"]["status"] == "failed"
    assert rows["nan_mid"]["message"].startswith("test_cubic: its reference is not finite at t = 24.03 s (torque;")
    assert rows["raise"]["status"] == "failed"
    assert rows["raise"]["message"] == ("test_cubic: sampling its reference raised RuntimeError: simulated crash "
                                        "inside _evaluate")
    captured = capsys.readouterr()
    assert "internal error" not in captured.err
    assert "RuntimeError: simulated crash inside _evaluate" in captured.err  # the planner's traceback is shown
    assert main(["run", str(path), "--out", str(tmp_path / "strict"), "--no-plots", "--strict"]) == 1
    assert (tmp_path / "strict" / "results.json").exists()


def test_a_reference_that_misses_the_target_fails_its_row_without_a_final_requirement(registered: None,
                                                                                     tmp_path: Path) -> None:
    # The scenario has no requirements.final: the 10 % short slew (81 of 90 deg, a 9 deg miss at rest:
    # the oracle is the construction) used to be "ok" with ref.final_error_deg 9; a planner whose
    # reference does not perform its manoeuvre is a planner defect (planners.conformance.check_boundary)
    path = _scenario(tmp_path, planners="""\
  - {name: test_cubic, label: good}
  - {name: test_cubic, label: short, options: {defect: short}}""", controllers="""\
  - {name: test_pd, label: pd}""")
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 0
    rows = _rows(out)
    assert rows["good"]["status"] == "ok"
    assert rows["short"]["status"] == "failed"
    message = rows["short"]["message"]
    assert message.startswith("test_cubic: q(T = 60 s) = ") and "but the problem asks qf = " in message
    assert "(error 0.157 rad > 2e-05)" in message  # 9 deg


def test_a_law_whose_reset_raises_or_that_returns_no_command_fails_its_rows_only(registered: None,
                                                                                 tmp_path: Path) -> None:
    # before: "internal error", exit 1, nothing written (a reviewer, 2026-12-02)
    path = _scenario(tmp_path, planners="""\
  - {name: test_cubic, label: cubic}""", controllers="""\
  - {name: test_pd, label: reset, options: {defect: reset}}
  - {name: test_pd, label: array, options: {defect: array}}
  - {name: test_pd, label: pd}""")
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 0
    rows = _rows(out)
    assert rows["cubic / pd"]["status"] == "ok"
    assert rows["cubic / reset"]["message"] == "simulation: test_pd raised KeyError in reset: 'simulated crash in reset'"
    assert rows["cubic / array"]["message"].startswith(
        "simulation: test_pd raised TypeError at t = 0 s: the law returned ndarray, not an ocp.Command")
    assert rows["cubic / reset"]["status"] == rows["cubic / array"]["status"] == "failed"


def test_a_reference_whose_rate_runs_away_does_not_widen_its_own_end_tolerance(registered: None,
                                                                              tmp_path: Path) -> None:
    # The "runaway" reference reaches qf but ends 0.05 rad/s (2.9 deg/s) off the rest asked, after a
    # 1e4 rad/s excursion mid-slew. The rate tolerance scaled with the reference's own peak (1e-7 +
    # 1e-5 * 1e4 = 0.1 rad/s) and passed it: an ok row. Scaled with the problem (by hand: the 90 deg
    # slew over 60 s, pi/2 / 60 = 0.0262 rad/s, so 1e-7 + 1e-5 * 0.0262 = 3.6e-7 rad/s) it fails.
    from scenarios.runner import plan_row
    from scenarios.schema.loader import load
    scenario = load(_scenario(tmp_path, planners="""\
  - {name: test_cubic, label: good}
  - {name: test_cubic, label: runaway, options: {defect: runaway}}""", controllers="""\
  - {name: test_pd, label: pd}"""))
    planned = scenario.planners[1].planner.plan(scenario.problem)
    peak = float(np.max(np.linalg.norm(planned.omega(np.linspace(0.0, T, 201)), axis=1)))
    assert peak > 0.99 * RUNAWAY  # the excursion the old tolerance scaled with
    good, runaway = (plan_row(scenario, spec, None)[0] for spec in scenario.planners)
    assert good.ok
    assert runaway.status == "failed", runaway.message
    tolerance = 1e-7 + 1e-5 * (np.pi / 2) / T
    assert f"(error {RUNAWAY_END:.3g} rad/s > {tolerance:.2g})" in runaway.message, runaway.message
    assert runaway.message.startswith("test_cubic: ω(T = 60 s) = ") and "does not perform the manoeuvre" in runaway.message


def test_a_law_that_raises_or_returns_nan_fails_its_rows_only(registered: None, tmp_path: Path,
                                                               capsys: pytest.CaptureFixture[str]) -> None:
    path = _scenario(tmp_path, planners="""\
  - {name: test_cubic, label: cubic}""", controllers="""\
  - {name: test_pd, label: raise, options: {defect: raise}}
  - {name: test_pd, label: nan, options: {defect: nan}}
  - {name: test_pd, label: pd}""")
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 0
    rows = _rows(out)
    assert rows["cubic / pd"]["status"] == "ok"
    assert rows["cubic / raise"]["status"] == "failed"
    assert rows["cubic / raise"]["message"] == ("simulation: test_pd raised ValueError at t = 20 s: simulated crash "
                                                "in the law")
    assert rows["cubic / nan"]["status"] == "failed"
    assert rows["cubic / nan"]["message"].startswith(
        "simulation: test_pd returned a non-finite command at t = 20 s: u = [nan, nan, nan]; a law must give finite")
    captured = capsys.readouterr()
    assert "internal error" not in captured.err
    assert "ValueError: simulated crash in the law" in captured.err  # the law's traceback is shown


_TWO_CLASSES = '''\
"""A module docstring that describes neither class alone."""
from dataclasses import dataclass

from controllers import CONTROLLERS, Controller
from planners import PLANNERS, Planner


class SplitPlanner(Planner):
    """A planner with a docstring of its own. More text."""

    name = "test_split_planner"

    @dataclass(frozen=True)
    class Options:
        pass

    def _plan(self, problem):
        raise NotImplementedError


class SplitLaw(Controller):
    """A law with a docstring of its own. More text."""

    name = "test_split_law"

    @dataclass(frozen=True)
    class Options:
        pass

    def __call__(self, t, measurement, reference):
        raise NotImplementedError

    def symbolic_error(self):
        return "none"
'''


def _load_without_sys_modules(path: Path, name: str) -> Any:
    """A plugin's way of loading its code from a file: the module is not put in ``sys.modules``."""
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert name not in sys.modules
    return module


def test_list_and_schema_describe_classes_of_a_module_outside_sys_modules(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "split_impl.py").write_text(_TWO_CLASSES)
    module = _load_without_sys_modules(tmp_path / "split_impl.py", "split_impl_not_in_sys_modules")
    monkeypatch.delenv("SLEWBENCH_PLUGINS", raising=False)
    monkeypatch.setitem(PLANNERS, "test_split_planner", module.SplitPlanner)
    monkeypatch.setitem(CONTROLLERS, "test_split_law", module.SplitLaw)
    assert summary_line(module.SplitPlanner) == "A planner with a docstring of its own."
    assert main(["list"]) == 0
    listed = capsys.readouterr().out
    assert "A law with a docstring of its own." in listed
    assert main(["schema", "planners.test_split_planner"]) == 0
    assert "A planner with a docstring of its own." in capsys.readouterr().out


def test_list_prefers_each_class_docstring_when_one_module_registers_several(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    (tmp_path / "split_mod.py").write_text(_TWO_CLASSES)
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, "split_mod", raising=False)
    import split_mod  # type: ignore[import-not-found]

    monkeypatch.setitem(PLANNERS, "test_split_planner", split_mod.SplitPlanner)
    monkeypatch.setitem(CONTROLLERS, "test_split_law", split_mod.SplitLaw)
    assert summary_line(split_mod.SplitPlanner) == "A planner with a docstring of its own."
    assert summary_line(split_mod.SplitLaw) == "A law with a docstring of its own."
    # one registered class in its module: the module's docstring, as for the built-ins
    monkeypatch.delitem(CONTROLLERS, "test_split_law")
    assert summary_line(split_mod.SplitPlanner) == "A module docstring that describes neither class alone."
