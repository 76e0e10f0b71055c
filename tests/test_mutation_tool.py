"""The mutation check's tool (tests/mutation) on a two-file tree: a mutation that breaks the code is
caught, a no-op one survives, a snippet that is not there is an error, and the source tree is never
changed (the work happens in a temporary copy)."""
from tests.mutation.run import Mutation, run, table


def test_caught_survived_error_and_the_tree_untouched(tmp_path):
    (tmp_path / "calc.py").write_text("def double(x):\n    return 2 * x\n")
    (tmp_path / "test_calc.py").write_text("from calc import double\n\n\ndef test_double():\n    assert double(3) == 6\n")
    before = {p.name: p.read_text() for p in tmp_path.iterdir()}
    mutations = [Mutation("bad", "calc.py", "2 * x", "3 * x", ("test_calc.py",)),
                 Mutation("no-op", "calc.py", "2 * x", "x * 2", ("test_calc.py",)),
                 Mutation("declared", "calc.py", "2 * x", "x + x", ("test_calc.py",), equivalent="x + x is 2 x"),
                 Mutation("missing", "calc.py", "4 * x", "5 * x", ("test_calc.py",))]
    outcomes = run(mutations, root=tmp_path, timeout=120.0, echo=False)
    assert [o.result for o in outcomes] == ["caught", "survived", "equivalent", "error"]
    assert {p.name: p.read_text() for p in tmp_path.iterdir()} == before
    report = table(outcomes)
    assert "4 mutations: 1 caught, 1 survived, 1 equivalent" in report and "caught 50.0 %" in report


def test_every_listed_mutation_names_its_file_and_tests():
    from pathlib import Path

    from tests.mutation.mutations import MUTATIONS
    root = Path(__file__).resolve().parents[1]
    assert len({m.name for m in MUTATIONS}) == len(MUTATIONS) >= 60
    for m in MUTATIONS:
        # the snippet must still occur exactly once: a change to the code that moves it away would
        # otherwise leave its area silently unchecked until the next run of the tool
        assert (root / m.file).read_text().count(m.find) == 1, m.name
        assert m.find != m.replace and m.tests, m.name
        for test in m.tests:
            assert test.startswith("-") or (root / test.split("::")[0]).is_file(), (m.name, test)
    assert {m.file.split("/")[0] for m in MUTATIONS} >= {"ocp", "planners", "controllers", "scenarios"}
