"""A mistyped planner name gets the registries' "did you mean" (planners.errors.UnknownNameError)
in a study file and in ``slewbench bench --planners`` / ``--problems``, as ``PLANNERS[...]`` does."""
from __future__ import annotations

from pathlib import Path

import pytest

from scenarios.cli import main


def test_a_study_grid_with_a_mistyped_planner_suggests_the_name(tmp_path, capsys):
    study = tmp_path / "typo.yaml"
    study.write_text("study: typo\nscenario: " + str(Path("scenarios/eigenaxis_demo.yaml").resolve())
                     + "\ngrid:\n  planners[0].name: [eigenaxis, eigenaxsi]\n")
    assert main(["sweep", str(study), "--dry-run"]) == 2
    err = capsys.readouterr().err
    assert "unknown planner 'eigenaxsi'" in err and "(did you mean 'eigenaxis'?)" in err, err


def test_a_scenario_with_a_mistyped_planner_suggests_the_name(tmp_path):
    import scenarios
    path = tmp_path / "s.yaml"
    text = open("scenarios/eigenaxis_demo.yaml").read()
    path.write_text(text.replace("{name: eigenaxis,", "{name: eigenaxsi,", 1))
    with pytest.raises(scenarios.ScenarioError, match=r"unknown planner 'eigenaxsi'.*\(did you mean 'eigenaxis'\?\)"):
        scenarios.load(path)


@pytest.mark.parametrize("argv, words", [
    (["--planners", "colocation"], "--planners: unknown planner or peer 'colocation'"),
    (["--problems", "bilimoria_wie_18"], "--problems: unknown problem 'bilimoria_wie_18'"),
])
def test_bench_suggests_a_close_name(tmp_path, capsys, argv, words):
    assert main(["bench", *argv, "--out", str(tmp_path / "board")]) == 2
    err = capsys.readouterr().err
    assert words in err and "(did you mean '" in err, err
    assert "(did you mean 'collocation'?)" in err or "(did you mean 'bilimoria_wie_180'?)" in err
