"""What ``slewbench validate`` and ``slewbench sweep`` say: a bad case's varied values (compact,
each visibly cut, the whole bounded), the command that resumes an interrupted sweep (with the
options given, quoted for a shell), and the terminal summary of a sweep (a group whose every case
crashed; crashed cases and other cases not ok counted apart)."""
from __future__ import annotations

import copy
import re
import shlex
import sqlite3
from pathlib import Path

import yaml

from scenarios import runner
from scenarios.cli.commands import main
from scenarios.errors import ScenarioError
from scenarios.schema.read import read_yaml
from scenarios.study import engine
from scenarios.study.spec import _case_error
from scenarios.study.types import Case
from tests.test_sweep import BASE, InlineExecutor

REPOSITORY = Path(__file__).resolve().parents[1]
NUMBER = r"-?[0-9][0-9.e+-]*"


def _significant_digits(text: str) -> int:
    """Significant digits of a printed number (``-15.3912`` -> 6, ``1.23457e+08`` -> 6)."""
    mantissa = text.lstrip("-").split("e")[0].replace(".", "").lstrip("0")
    return len(mantissa.rstrip("0")) or 1


# --- 1. a bad case's values ---------------------------------------------------------------------

def test_a_bad_case_shows_each_varied_vector_whole_and_compact(tmp_path, capsys):
    """The tester's study: the truth inertia scaled by a factor that some cases draw negative, a
    grid of slew angles and a dispersed initial error. Before the fix each value was its JSON text
    cut at 40 characters with no closing bracket (``inertia="[-10.43894936196218, -10.17128399370``),
    so the next path read as part of the vector. (The tester's uniform [-1, 1.1] is now refused at
    its entry; a normal factor has no bounds, so a case that draws it negative is refused by case.)"""
    (tmp_path / "eigenaxis_truth.yaml").write_text((REPOSITORY / "scenarios" / "eigenaxis_truth.yaml").read_text())
    study = tmp_path / "bad.yaml"
    study.write_text(yaml.safe_dump({
        "study": "bad-inertia", "scenario": "eigenaxis_truth.yaml",
        "grid": {"maneuver.final.q": {"axis_angle": {"axis": [0, 0, 1], "angle_deg": [30, 90]}}},
        "monte_carlo": {"samples": 5, "seed": 3, "dispersions": {
            "truth.spacecraft.inertia": {"scale": {"normal": {"mean": 0.0, "std": 1.0}}},
            "simulation.initial_attitude_error_deg": {"normal": {"mean": [0, 0, 0], "std": [1, 1, 1]}}}}},
        sort_keys=False))
    assert main(["validate", str(study)]) == 2
    error = capsys.readouterr().err
    vector = rf"\[({NUMBER}), ({NUMBER}), ({NUMBER})\]"
    found = re.search(rf"case [0-9]+ \[maneuver\.final\.q=({NUMBER}), truth\.spacecraft\.inertia={vector}, "
                      rf"simulation\.initial_attitude_error_deg={vector}\]: truth\.spacecraft\.inertia "
                      r"\(set by truth\.spacecraft\.inertia\): .*eigenvalues \[([^\]]*)\]", error)
    assert found, error
    angle, inertia, initial = found.group(1), found.groups()[1:4], found.groups()[4:7]
    assert float(angle) in (30.0, 90.0)
    for number in (*inertia, *initial):
        assert _significant_digits(number) <= 6, (number, error)
    # the truth inertia is diagonal: its eigenvalues, which the loader prints in full, are its moments
    moments = sorted(float(v) for v in found.group(8).split(","))
    shown = sorted(float(v) for v in inertia)
    assert all(abs(s - m) <= 5e-6 * abs(m) for s, m in zip(shown, moments)), (shown, moments)


def _case(varied):
    return Case(index=37, seed=1, point=0, varied=varied, scenario={})


def _header(error: ScenarioError) -> str:
    """The ``case 37 [...]`` part of a case error (before the scenario path)."""
    return str(error.path).split("]: simulation.duration", 1)[0] + "]"


def test_a_long_value_is_cut_inside_its_brackets_or_quotes():
    long_vector = "[" + ", ".join(repr(0.1 * i + 1e-9) for i in range(1000)) + "]"  # as the tables record it
    error = _case_error(_case({"a.vector": long_vector, "b.text": "x" * 500, "c.matrix": [[1.5] * 40] * 40,
                               "d.number": 2.0}),
                        ScenarioError("simulation.duration", "expected a positive number"))
    header = _header(error)
    assert "a.vector=[1e-09, 0.1, 0.2, 0.3, " in header
    vector = header.split("a.vector=", 1)[1].split(", b.text=", 1)[0]
    text = header.split("b.text=", 1)[1].split(", c.matrix=", 1)[0]
    matrix = header.split("c.matrix=", 1)[1].split(", d.number=", 1)[0]
    assert vector.endswith(", ...]") and len(vector) <= 80, vector
    assert re.fullmatch(r'"x+\.\.\."', text) and len(text) <= 80, text
    assert matrix.startswith("[[1.5, 1.5") and matrix.endswith("...]") and len(matrix) <= 80, matrix
    assert matrix.count("[") == matrix.count("]"), matrix
    assert header.endswith("d.number=2.0]"), header
    assert error.message == "expected a positive number"


def test_many_varied_values_are_counted_past_a_bounded_list():
    varied = {f"planners[{i}].options.weight": [0.123456789] * 3 for i in range(40)}
    header = _header(_case_error(_case(varied), ScenarioError("simulation.duration", "bad")))
    assert header.startswith("case 37 [planners[0].options.weight=[0.123457, 0.123457, 0.123457], ")
    shown = header.count(".options.weight=")
    assert 3 <= shown < 40 and header.endswith(f", ... {40 - shown} more of 40 values]"), header
    assert len(header) <= 400, len(header)


# --- 2. the command that resumes ------------------------------------------------------------------

def _spaced_study(tmp_path: Path) -> tuple[Path, Path]:
    folder = tmp_path / "my studies"
    folder.mkdir()
    study = folder / "tiny study.yaml"
    study.write_text(yaml.safe_dump({"study": "tiny-study", "scenario": copy.deepcopy(BASE),
                                     "grid": {"maneuver.duration": [30.0, 31.0]}}))
    return study, tmp_path / "out dir"


def _resume_line(error: str) -> list[str]:
    line = error.split("Resume with:\n", 1)[1].splitlines()[0]
    return shlex.split(line)


def test_an_interrupted_sweep_says_how_to_resume_with_the_options_given(tmp_path, monkeypatch, capsys):
    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(engine, "sweep", interrupted)
    study, out = _spaced_study(tmp_path)
    assert main(["sweep", str(study), "--out", str(out), "--workers", "1", "--no-plots"]) == 130
    error = capsys.readouterr().err
    assert _resume_line(error) == ["slewbench", "sweep", str(study), "--out", str(out), "--resume",
                                   "--workers", "1", "--no-plots"], error
    assert main(["sweep", str(study), "--out", str(out), "--resume"]) == 130  # no options: none repeated
    assert _resume_line(capsys.readouterr().err) == ["slewbench", "sweep", str(study), "--out", str(out), "--resume"]


class _Cluster:
    address = "tcp://10.0.0.7:8786"

    def close(self):
        pass


def test_the_resume_command_keeps_the_scheduler(tmp_path, monkeypatch, capsys):
    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(engine, "connect_scheduler", lambda address, where: _Cluster())
    monkeypatch.setattr(engine, "sweep", interrupted)
    study, out = _spaced_study(tmp_path)
    assert main(["sweep", str(study), "--out", str(out), "--scheduler", _Cluster.address]) == 130
    assert _resume_line(capsys.readouterr().err) == ["slewbench", "sweep", str(study), "--out", str(out),
                                                     "--resume", "--scheduler", _Cluster.address]


def test_a_full_disk_says_how_to_resume_with_the_options_given(tmp_path, monkeypatch, capsys):
    def full(*args, **kwargs):
        raise sqlite3.OperationalError("database or disk is full")

    monkeypatch.setattr(engine, "sweep", full)
    study, out = _spaced_study(tmp_path)
    assert main(["sweep", str(study), "--out", str(out), "--workers", "2", "--no-plots"]) == 2
    error = capsys.readouterr().err
    command = re.search(r"resume with `([^`]*)`", error)
    assert command, error
    assert shlex.split(command.group(1)) == ["slewbench", "sweep", str(study), "--out", str(out), "--resume",
                                             "--workers", "2", "--no-plots"], error


# --- 3. the terminal summary ----------------------------------------------------------------------

def test_the_summary_shows_a_group_whose_every_case_crashed(tmp_path, monkeypatch, capsys):
    """A Monte Carlo over two durations: every case at 40 s raises (3 crashed cases, both planner
    rows of each), and one case at 30 s has its ``fast`` row failed (not ok, but not crashed)."""
    original, real_sweep = runner.run, engine.sweep
    seen: list[float] = []

    def flaky(scenario, **kwargs):
        if scenario.problem.duration == 40.0:
            raise RuntimeError("planner exploded")
        results = original(scenario, **kwargs)
        seen.append(scenario.problem.duration)
        if len(seen) == 1:
            row = next(r for r in results.rows if r.label == "fast")
            row.status = "failed"
        return results

    monkeypatch.setattr(runner, "run", flaky)
    monkeypatch.setattr(engine, "sweep", lambda study, workers=None, store=None, progress=False, cluster=None:
                        real_sweep(study, InlineExecutor(), store=store))
    study = tmp_path / "study.yaml"
    study.write_text(yaml.safe_dump({
        "study": "crashing-group", "scenario": copy.deepcopy(BASE), "grid": {"maneuver.duration": [30.0, 40.0]},
        "monte_carlo": {"samples": 3, "seed": 5, "dispersions": {
            "simulation.initial_attitude_error_deg": {"normal": {"mean": [0, 0, 0], "std": [1, 1, 1]}}}}}))
    out = tmp_path / "out"
    # crashed cases: the tables are written, and the sweep exits 1 saying so (docs/guide/studies.rst)
    assert main(["sweep", str(study), "--out", str(out), "--workers", "1", "--no-plots"]) == 1
    captured = capsys.readouterr()
    said = captured.out
    assert captured.err.startswith("slewbench: 3 of 6 cases crashed (raised, ran out of case_timeout_s or killed "
                                   "their worker)"), captured.err
    assert "\n  3 cases: RuntimeError: planner exploded (" in captured.err, captured.err
    assert re.search(r"; of the 6 cases stored, 3 crashed and 1 others? ha(s|ve) a row not ok; wrote ", said), said
    lines = said.splitlines()
    for label in ("smooth", "fast"):
        assert [line for line in lines if re.fullmatch(rf"  40(\.0)?, {label}: no completed case \(3 crashed\)",
                                                       line)], said
        assert [line for line in lines if re.fullmatch(rf"  30(\.0)?, {label}: every requirement [0-9]/3 = .*",
                                                       line)], said


# --- 4. a dispersed quaternion ------------------------------------------------------------------

def _quaternion_study(tmp_path: Path, path: str, std: float) -> Path:
    """The eigenaxis demo with its ``path`` quaternion offset by a normal draw of ``std`` per number
    (a path ending in ``.quaternion``: the attitude written in the mapping form first)."""
    scenario = read_yaml(REPOSITORY / "scenarios" / "eigenaxis_demo.yaml")
    if path.endswith(".quaternion"):
        end = path.split(".")[1]
        scenario["maneuver"][end]["q"] = {"quaternion": scenario["maneuver"][end]["q"]}
    study = {"study": "dispersed-quaternion", "scenario": scenario,
             "monte_carlo": {"samples": 20, "seed": 1,
                             "dispersions": {path: {"offset": {"normal": {"mean": [0, 0, 0, 0], "std": [std] * 4}}}}}}
    file = tmp_path / "study.yaml"
    file.write_text(yaml.safe_dump(study))
    return file


def test_a_dispersed_quaternion_off_the_unit_sphere_is_one_error_at_its_entry(tmp_path, capsys):
    """Four numbers drawn independently leave the unit sphere: one error at the dispersion's entry,
    counting the cases (norms computed here with NumPy from the same draws: std 0.05 per number moves
    the norm by about 0.05, far beyond 1e-3) and naming the forms that disperse a rotation. Before,
    the first such case stopped the check with the loader's advice to normalise that case's
    quaternion, which nothing in a study can do."""
    for path in ("maneuver.final.q", "maneuver.initial.q", "maneuver.final.q.quaternion"):
        status = main(["sweep", str(_quaternion_study(tmp_path, path, 0.05)), "--dry-run"])
        err = " ".join(capsys.readouterr().err.split())
        assert status == 2, err
        found = re.search(rf"monte_carlo\.dispersions\.{re.escape(path)}: (\d+) of 20 cases draw a quaternion whose "
                          r"norm is not within 0\.001 of 1", err)
        assert found and int(found.group(1)) >= 15, err
        assert "normalise it" not in err and "case 1 [" not in err, err
        attitude = path.removesuffix(".quaternion")
        assert f"{attitude}.axis_angle.angle_deg" in err and f"{attitude}.axis_angle.axis" in err, err
        assert ("simulation.initial_attitude_error_deg" in err) == (attitude == "maneuver.initial.q"), err


def test_a_dispersed_quaternion_within_the_norm_tolerance_is_still_taken(tmp_path, capsys):
    """Draws whose norms stay within 1e-3 of 1 (std 1e-4 per number) are quaternions as written ones
    are: normalised by the loader, the dry run passes."""
    assert main(["sweep", str(_quaternion_study(tmp_path, "maneuver.final.q", 1e-4)), "--dry-run"]) == 0, \
        capsys.readouterr().err


# --- 5. a Monte Carlo whose samples share one noise history --------------------------------------

def _noise_study(tmp_path: Path, dispersions: dict, name: str = "study.yaml") -> str:
    """The eigenaxis demo (sensor noise 0.005 deg and 1e-5 rad/s, seed 1) under 4 samples of ``dispersions``."""
    study = {"study": "noise", "scenario": str(REPOSITORY / "scenarios" / "eigenaxis_demo.yaml"),
             "monte_carlo": {"samples": 4, "seed": 1, "dispersions": dispersions}}
    file = tmp_path / name
    file.write_text(yaml.safe_dump(study))
    return str(file)


def test_a_monte_carlo_whose_samples_share_the_noise_seed_is_noted(tmp_path, capsys):
    """Every case runs with the base scenario's noise seed (read here from the cases themselves): the
    samples see one noise history, and validate and the dry run say so, naming the fix. With the
    seed drawn per case (case_seed), or no noise, nothing is said. Before, nothing was said either way
    (a user's 20-case Monte Carlo had its worst sample at the same instant in every case)."""
    from scenarios.study.spec import load_study

    shared = _noise_study(tmp_path, {"simulation.initial_attitude_error_deg": {
        "normal": {"mean": [0, 0, 0], "std": [1, 1, 1]}}})
    seeds = {case.scenario["simulation"]["sensor_noise"]["seed"] for case in load_study(shared).cases}
    assert seeds == {1}  # the oracle: one seed for all 4 cases
    for command in (["validate", shared], ["sweep", shared, "--dry-run"]):
        assert main(command) == 0
        out = " ".join(capsys.readouterr().out.split())
        assert ("note: the 4 Monte Carlo samples of each grid point share one sensor-noise history" in out
                and "'simulation.sensor_noise.seed: case_seed'" in out), out
    drawn = _noise_study(tmp_path, {"simulation.initial_attitude_error_deg": {
        "normal": {"mean": [0, 0, 0], "std": [1, 1, 1]}}, "simulation.sensor_noise.seed": "case_seed"}, "drawn.yaml")
    assert len({case.scenario["simulation"]["sensor_noise"]["seed"] for case in load_study(drawn).cases}) == 4
    quiet = _noise_study(tmp_path, {"simulation.sensor_noise.attitude_deg": {"uniform": {"low": 0.0, "high": 0.0}},
                                    "simulation.sensor_noise.rate": {"uniform": {"low": 0.0, "high": 0.0}}},
                         "quiet.yaml")
    for path in (drawn, quiet):
        assert main(["validate", path]) == 0
        assert "sensor-noise history" not in capsys.readouterr().out, path
