"""Every absence in the leaderboard carries its reason, and every value shown is one (report 51 M4,
L2): a peer not on a problem's rows is a note naming the peer, the problem and why (the peer's own
``problem_error``, or the suite's ``peers: {skip: <why>}``; a bare ``peers: false`` is refused), and
a row whose energy is not finite (an impulse, a free start included) shows no value, with the reason,
as natural motion's stop does.

Oracles: the suite index as written (a copy edited here), the peers' contract
(:func:`scenarios.bench.peers.base.box_torque_problem_error`, asked directly), and the problem's
data: the spin re-pointing starts at ω0 = [0.2, 0, 0] rad/s and the eigenaxis slew from rest, so
the step between them is an impulse, whose energy ∫‖u‖² dt is not finite.
"""
from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from scenarios.bench import SUITE_FILE, load_suite
from scenarios.bench.leaderboard import Leaderboard, run_bench
from scenarios.bench.peers.base import PeerResult, box_torque_problem_error
from scenarios.errors import ScenarioError
from scenarios.schema.loader import load


def _suite_copy(tmp_path, old: str, new: str):
    shutil.copytree(SUITE_FILE.parent / "problems", tmp_path / "problems")
    text = SUITE_FILE.read_text()
    assert old in text
    (tmp_path / "suite.yaml").write_text(text.replace(old, new, 1))
    return tmp_path / "suite.yaml"


XTE = "    planners: [collocation, eigenaxis]\n  norm_bounded_eigenaxis:"


def test_peers_not_asked_without_a_reason_is_refused(tmp_path):
    path = _suite_copy(tmp_path, XTE, XTE.replace("\n  norm", "\n    peers: false\n  norm"))
    with pytest.raises(ScenarioError) as caught:
        load_suite(path)
    assert caught.value.path == "problems.xte_150.peers" and "{skip: <why" in caught.value.message
    assert "got False" in caught.value.message


def test_peers_not_asked_are_a_note_per_peer_with_the_suites_reason(tmp_path):
    path = _suite_copy(tmp_path, XTE, XTE.replace("\n  norm", "\n    peers: {skip: \"kept for planners\"}\n  norm"))
    suite = load_suite(path)
    problem = suite.problems["xte_150"]
    assert not problem.peers and problem.peers_skip == "kept for planners"
    assert problem.metadata()["peers_skip"] == "kept for planners"
    board = run_bench(suite, ["xte_150"], planners=[], peers=["fatrop"])
    assert "peer fatrop not asked on xte_150: kept for planners" in board.notes, board.notes
    with pytest.raises(ScenarioError, match=r"problems.xte_150.peers.skip: expected a non-empty text"):
        load_suite(_suite_copy(tmp_path / "empty", XTE, XTE.replace("\n  norm", "\n    peers: {skip: \"\"}\n  norm")))


def test_every_problem_of_the_shipped_suite_has_a_row_or_a_note_of_each_peer(monkeypatch):
    """The peer's solve is replaced (its answer is not what is tested): per problem, a fatrop row
    exactly where its contract accepts the problem, else a note with the contract's reason."""
    from scenarios.bench.peers import fatrop

    monkeypatch.setattr(fatrop.PEER, "solve", lambda problem, objective: PeerResult(1.0, 0.0, "ok", 1, "stub"))
    suite = load_suite()
    board = run_bench(suite, None, planners=[], peers=["fatrop"])
    for name, problem in suite.problems.items():
        reason = box_torque_problem_error(load(problem.file).problem, problem.objective)
        rows = [row for row in board.rows if row.problem == name and row.planner == "fatrop"]
        notes = [note for note in board.notes if note.startswith("peer fatrop ") and f" on {name}:" in note]
        if reason is None:
            assert len(rows) == 1 and not notes, name
        else:
            assert not rows and notes == [f"peer fatrop skipped on {name}: {reason}"], (name, notes)
    # the two problems whose absence went unexplained
    assert any(note.startswith("peer fatrop skipped on norm_bounded_eigenaxis: only ideal body-axis torquers")
               for note in board.notes)
    assert any(note.startswith("peer fatrop skipped on keep_out_melton_scaled: pointing") for note in board.notes)


def test_a_free_start_with_an_impulse_shows_no_value_and_says_why():
    suite = load_suite()
    problem = suite.problems["spin_repoint_min_energy"]
    scenario = load(problem.file)
    assert np.linalg.norm(scenario.problem.omega0) > 0.1  # it starts spinning
    board = run_bench(suite, [problem.name], planners=["eigenaxis"])
    (row,) = board.rows
    assert row.planner == "eigenaxis" and row.plan_status == "ok"
    assert row.value is None and row.gap_abs is None and row.reached is None
    assert row.message.startswith("leaves omega0 free: solves another problem, no gap; impulse: its rate jumps from "
                                  "the problem's initial rate"), row.message
    assert "int_u2 is not finite; no value" in row.message
    data = json.loads(json.dumps(board.to_json(), allow_nan=False))  # valid JSON: no Infinity
    assert data["rows"][0]["value"] is None
    section = board.to_markdown().split(f"## {problem.name}")[1]  # the problem's table, not the summary
    line = next(line for line in section.splitlines() if line.startswith("| eigenaxis |"))
    assert line.split("|")[5].strip() == "-", line


def test_the_markdown_explains_its_value_iterations_and_certificate_columns():
    suite = load_suite()
    text = Leaderboard(suite, [suite.problems["xte_150"]]).to_markdown()
    legend = next(line for line in text.splitlines() if line.startswith("Value: "))
    assert "Iterations: " in legend and "Certificate: " in legend and "1 seed" in legend
    assert text.index(legend) < text.index("## xte_150")
