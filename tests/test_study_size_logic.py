"""scenarios.study.spec.size_note at its edges: a study of exactly LARGE_STUDY cases is not large
("more than"), one more is; and the timing command names the base scenario where the study file
says it is (relative to the study file), whatever the working directory.

Oracles: case counts by hand (Monte Carlo samples of one grid point) and the path built by hand.
"""
from __future__ import annotations

import shutil
from pathlib import Path

import scenarios.study.spec as spec
from scenarios.study.spec import load_study, size_note

BASE = Path("scenarios/eigenaxis_demo.yaml").resolve()


def _study_file(folder: Path, cases: int, scenario: str) -> Path:
    path = folder / f"s{cases}.yaml"
    path.write_text(f"study: s{cases}\nscenario: {scenario}\nmonte_carlo: {{samples: {cases}, seed: 1, dispersions: "
                    "{simulation.sensor_noise.seed: case_seed}}\n")
    return path


def test_exactly_the_threshold_is_not_large_and_one_more_is(tmp_path, monkeypatch):
    monkeypatch.setattr(spec, "LARGE_STUDY", 3)  # the rule, at a size that loads fast
    assert size_note(load_study(_study_file(tmp_path, 3, str(BASE))), 1) is None
    note = size_note(load_study(_study_file(tmp_path, 4, str(BASE))), 1)
    assert note is not None and note.startswith("note: 4 cases is a large study (over 3)")


def test_the_timing_command_names_the_scenario_beside_the_study_file(tmp_path, monkeypatch):
    folder = tmp_path / "studies"
    folder.mkdir()
    shutil.copy(BASE, folder / "base.yaml")
    path = _study_file(folder, 2, "base.yaml")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    monkeypatch.setattr(spec, "LARGE_STUDY", 1)
    note = size_note(load_study(path), 2)
    assert note is not None
    assert f"slewbench run {folder / 'base.yaml'} --no-plots" in note, note
