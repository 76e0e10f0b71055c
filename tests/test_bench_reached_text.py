"""``slewbench bench``'s last line counts the rows at the optimum by the optimum's kind
(docs/guide/bench.rst): a published optimum is not called "best known".

Oracle: the suite index's own kinds (bilimoria_wie_180 and xte_150 published, bilimoria_wie_90
best known, norm_bounded_eigenaxis closed form), and rows marked by hand as reaching them.
"""
from __future__ import annotations

from scenarios.bench.leaderboard import BenchRow, Leaderboard
from scenarios.bench.suite import load_suite


def row(problem: str, reached: bool | None) -> BenchRow:
    return BenchRow(problem, "x", "x", "planner", "ok", 1.0, 0.0, 0.0, reached, 0.1, None, "-")


def test_the_rows_at_the_optimum_are_counted_by_its_kind():
    suite = load_suite()
    assert suite.problems["bilimoria_wie_180"].optimum_kind == suite.problems["xte_150"].optimum_kind == "published"
    assert suite.problems["bilimoria_wie_90"].optimum_kind == "best_known"
    assert suite.problems["norm_bounded_eigenaxis"].optimum_kind == "closed_form"
    problems = [suite.problems[name] for name in ("bilimoria_wie_180", "xte_150")]
    board = Leaderboard(suite, problems, [row("bilimoria_wie_180", True), row("xte_150", True), row("xte_150", False)])
    assert board.reached_text() == "2 at the optimum (2 published)"
    problems += [suite.problems["bilimoria_wie_90"], suite.problems["norm_bounded_eigenaxis"]]
    board = Leaderboard(suite, problems, [row("bilimoria_wie_90", True), row("bilimoria_wie_180", True),
                                          row("norm_bounded_eigenaxis", True), row("bilimoria_wie_90", None)])
    assert board.reached_text() == "3 at the optimum (1 best known, 1 published, 1 closed form)"
    assert Leaderboard(suite, problems, [row("xte_150", False)]).reached_text() == "0 at the optimum"


def test_the_command_prints_it(tmp_path, capsys):
    from scenarios.cli import main
    assert main(["bench", "--problems", "norm_bounded_eigenaxis", "--planners", "eigenaxis", "--no-peers",
                 "--no-plots", "--out", str(tmp_path / "board")]) == 0
    printed = capsys.readouterr().out
    assert "best known optimum" not in printed
    assert "at the optimum (1 closed form)" in printed, printed
