"""A suite index whose ``planners`` names a planner that is not registered is refused at its YAML
path, with the close name: the list is published in the leaderboard's metadata as the planners
that apply, and a typo there went out unchecked."""
import shutil

import pytest

from scenarios.bench.suite import SUITE_FILE, load_suite
from scenarios.errors import ScenarioError


def test_a_misspelt_planner_in_the_suite_is_refused_naming_it(tmp_path):
    shutil.copytree(SUITE_FILE.parent / "problems", tmp_path / "problems")
    text = SUITE_FILE.read_text()
    line = "    planners: [collocation, eigenaxis]\n"
    assert line in text
    (tmp_path / "suite.yaml").write_text(text.replace(line, "    planners: [collocation, eigenaxsi]\n", 1))
    with pytest.raises(ScenarioError) as caught:
        load_suite(tmp_path / "suite.yaml")
    assert caught.value.path == "problems.bilimoria_wie_180.planners[1]"
    assert "unknown planner 'eigenaxsi'" in str(caught.value) and "did you mean 'eigenaxis'" in str(caught.value)

