"""The benchmark suite and ``slewbench bench``: the index and its problem files, the leaderboard's gap
against hand-worked values, the closed-form problem against its closed form, the peers, bad names
and output safety."""
from __future__ import annotations

import csv
import dataclasses
import json
import math
import shutil
import time

import casadi
import numpy as np
import pytest

from ocp import Spacecraft, Torquers, quat
from planners import PLANNERS, ManeuverProblem
from scenarios.bench import SUITE_FILE, load_suite
from scenarios.bench.leaderboard import (
    BENCH_FILES,
    certificate_text,
    gap,
    other_planners,
)
from scenarios.bench.peers import PEERS, PeerUnavailable, load_peer
from scenarios.bench.suite import OBJECTIVE_METRICS, OPTIMUM_KINDS
from scenarios.cli.commands import main
from scenarios.errors import ScenarioError
from scenarios.schema.loader import load
from scenarios.schema.read import read_yaml


def test_the_index_loads_and_every_problem_is_a_scenario_with_its_planners():
    suite = load_suite()
    assert suite.version == 3
    assert len(suite.problems) >= 10
    for problem in suite.problems.values():
        scenario = load(problem.file)  # an ordinary scenario: `slewbench run` runs it too
        assert sorted({spec.name for spec in scenario.planners}) == sorted(set(problem.planners)), problem.name
        assert all(name in PLANNERS for name in problem.planners)


def test_every_planner_that_accepts_a_problem_joins_its_rows_with_its_defaults():
    """Beside the scenario's rows, every other registered planner whose own check accepts the
    problem (oracle: ``problem_error`` of each registered planner, asked directly here) runs with
    its default options, labelled as such; one that refuses the problem does not."""
    suite = load_suite()
    for name in ("bilimoria_wie_90", "spin_repoint_min_energy"):
        scenario = load(suite.problems[name].file)
        named = {spec.name for spec in scenario.planners}
        accepting = {planner for planner, cls in PLANNERS.items()
                     if planner not in named and cls({}).problem_error(scenario.problem) is None}
        added = other_planners(scenario)
        assert {spec.name for spec in added} == accepting, name
        assert all(spec.label == f"{spec.name} (defaults)" for spec in added)
        assert all(spec.options == PLANNERS[spec.name]({}).options for spec in added)
    # the spin case starts spinning: a planner that needs a rest start refuses it and is left out
    spin = load(suite.problems["spin_repoint_min_energy"].file)
    refusing = {planner for planner, cls in PLANNERS.items() if cls({}).problem_error(spin.problem) is not None}
    assert refusing and not refusing & {spec.name for spec in other_planners(spin)}


def test_every_problem_states_its_source_optimum_and_tolerance():
    raw = read_yaml(SUITE_FILE)["problems"]
    for name, problem in load_suite().problems.items():
        entry = raw[name]
        assert problem.source and problem.optimum_source and problem.eigenaxis_source and problem.title
        assert problem.objective in OBJECTIVE_METRICS
        assert problem.optimum_kind in OPTIMUM_KINDS
        assert problem.optimum == entry["optimum"]["value"] > 0
        # A tolerance is a band around the optimum, not a licence: at most 0.1 % of it.
        assert 0 < problem.tolerance <= 1e-3 * problem.optimum, name
        if problem.optimum_kind == "best_known":  # ours: established by two methods, said so
            assert "ours" in problem.optimum_source, name


def test_a_malformed_index_names_the_field(tmp_path):
    shutil.copytree(SUITE_FILE.parent / "problems", tmp_path / "problems")
    text = SUITE_FILE.read_text().replace("    source: \"ours (the repository's minimum-time test case; no published value).\"\n", "")
    (tmp_path / "suite.yaml").write_text(text)
    with pytest.raises(ScenarioError, match=r"problems.full_inertia_150: missing source"):
        load_suite(tmp_path / "suite.yaml")
    (tmp_path / "suite.yaml").write_text(SUITE_FILE.read_text().replace("value: 3.2431", "value: fast"))
    with pytest.raises(ScenarioError, match=r"problems.bilimoria_wie_180.optimum.value: expected a number"):
        load_suite(tmp_path / "suite.yaml")


def test_the_norm_bounded_problem_meets_its_closed_form():
    problem = load_suite().problems["norm_bounded_eigenaxis"]
    scenario = load(problem.file)
    spacecraft = scenario.problem.spacecraft
    inertia = spacecraft.inertia
    assert np.allclose(inertia, inertia[0, 0] * np.eye(3))  # spherical
    wheels = spacecraft.wheels
    assert wheels is not None
    assert wheels.count == 1 and np.allclose(wheels.axes[:, 0], [1.0, 0.0, 0.0])
    # theta from the scenario's quaternions, by hand: q = [cos(theta/2), sin(theta/2) e]
    qf = scenario.problem.qf
    assert qf is not None
    theta = 2.0 * math.atan2(np.linalg.norm(qf[1:]), qf[0])
    axis = qf[1:] / np.linalg.norm(qf[1:])
    assert np.allclose(axis, [1.0, 0.0, 0.0])  # about the wheel's axis
    u_max = float(np.max(wheels.max_torque))
    closed_form = 2.0 * math.sqrt(theta * inertia[0, 0] / u_max)
    assert closed_form == pytest.approx(2.0 * math.sqrt(math.pi / 2 * 2.0 / 0.1), rel=1e-7)  # the stated data
    assert problem.optimum == pytest.approx(closed_form, abs=1e-6)
    assert problem.eigenaxis == pytest.approx(closed_form, abs=1e-6)
    # The double integrator's bang-bang, integrated by hand: half the time at +u, half at -u.
    t_half = closed_form / 2.0
    rate_peak = u_max / inertia[0, 0] * t_half
    assert rate_peak * t_half == pytest.approx(theta, rel=1e-12)  # the area under the triangle


def test_the_unit_inertia_eigenaxis_values_are_the_closed_form():
    suite = load_suite()
    for name, degrees in (("bilimoria_wie_180", 180), ("bilimoria_wie_90", 90), ("bilimoria_wie_45", 45)):
        assert suite.problems[name].eigenaxis == pytest.approx(2.0 * math.sqrt(math.radians(degrees)), abs=1e-4)


def test_gap_and_certificate_columns_by_hand():
    assert gap(3.5449077, 3.2431) == pytest.approx((0.3018077, 0.3018077 / 3.2431))
    assert gap(None, 1.0) == (None, None)
    assert gap(float("nan"), 1.0) == (None, None)
    assert certificate_text({"certificate": {"verdict": "certified", "summary": "KKT 1e-9, SOSC"}}) == "KKT 1e-9, SOSC"
    assert certificate_text({"certificate": {"verdict": "first-order"}}) == "first-order"
    assert certificate_text({"iterations": 3}) == "-"
    assert certificate_text(None) == "-"


def test_the_peer_registry_is_lazy_and_a_missing_peer_is_a_note():
    assert set(PEERS) >= {"fatrop", "rockit", "acados"}
    assert PEERS["acados"] == "scenarios.bench.peers.acados"
    with pytest.raises(PeerUnavailable, match="peer nowhere skipped"):
        load_peer("nowhere", {"nowhere": "scenarios.bench.peers.not_a_module"})
    try:
        import rockit  # type: ignore[import-not-found]  # noqa: F401
    except ImportError:
        with pytest.raises(PeerUnavailable, match="rockit-meco"):
            load_peer("rockit")


def test_the_fatrop_peer_meets_the_single_axis_minimum_energy_closed_form():
    # Rest to rest, theta about x, spherical J, fixed T, bounds inactive: the optimum of the integral
    # of u^2 is 12 J^2 theta^2 / T^3 (the cubic angle profile); FATROP holds the torque piecewise
    # constant on 50 intervals, within 1e-3 of it.
    peer = load_peer("fatrop")
    J, theta, T = 2.0, 1.0, 10.0
    problem = ManeuverProblem(Spacecraft([J, J, J], torquers=Torquers(1.0)), quat.IDENTITY, np.zeros(3),
                              quat.from_axis_angle([1, 0, 0], theta), T, omegaf=np.zeros(3))
    assert peer.problem_error(problem, "min_energy") is None
    result = peer.solve(problem, "min_energy")
    assert result.status == "ok", result.message
    assert result.objective == pytest.approx(12 * J**2 * theta**2 / T**3, rel=1e-3)
    assert result.iterations is not None and result.solve_time_s > 0


def test_bench_writes_the_leaderboard_with_the_hand_worked_gap(tmp_path, capsys):
    out = tmp_path / "board"
    code = main(["bench", "--problems", "bilimoria_wie_90", "--planners", "eigenaxis", "fatrop", "--out", str(out)])
    printed = capsys.readouterr().out
    assert code == 0
    assert "[1/1] bilimoria_wie_90" in printed
    assert sorted(p.name for p in out.iterdir() if not p.name.startswith(".")) == sorted(BENCH_FILES)
    rows = list(csv.DictReader((out / "leaderboard.csv").open()))
    eigenaxis = next(row for row in rows if row["planner"] == "eigenaxis")
    # 2 sqrt(pi/2) = 2.5066283 against the best known 2.42112: +0.0855083, +3.5318 %
    assert float(eigenaxis["value"]) == pytest.approx(2.5066283, abs=1e-6)
    assert float(eigenaxis["gap_abs"]) == pytest.approx(0.0855083, abs=1e-6)
    assert float(eigenaxis["gap_rel"]) == pytest.approx(0.0855083 / 2.42112, abs=1e-6)
    assert eigenaxis["reached"] == "False" and eigenaxis["certificate"] == "-"
    peer = next(row for row in rows if row["kind"] == "peer")
    assert peer["planner"] == "fatrop" and peer["status"] in ("ok", "failed")
    if peer["value"]:
        assert float(peer["gap_abs"]) == pytest.approx(float(peer["value"]) - 2.42112, abs=1e-12)
    data = json.loads((out / "leaderboard.json").read_text())
    assert data["suite_version"] == 3 and data["slewbench"] and data["date"].endswith("Z") and data["platform"]
    assert [problem["name"] for problem in data["problems"]] == ["bilimoria_wie_90"]
    assert len(data["rows"]) == len(rows) == 2
    text = (out / "leaderboard.md").read_text()
    assert "## bilimoria_wie_90" in text and "+0.0855" in text
    assert "| eigenaxis | planner | 1 | 1 | 0 | 3.53e-02 |" in text  # the summary: one row with a gap, not at the optimum
    assert text.index("| eigenaxis | planner |") < text.index("| fatrop | peer |")  # planners, then peers
    assert "optimum 2.42112 ± 0.0002" in text  # the optimum with the digits of its tolerance
    assert eigenaxis["plan_status"] == eigenaxis["status"] == "ok"
    assert data["environment"]["peers"] == {"fatrop": f"FATROP plugin of CasADi {casadi.CasadiMeta.version()}"}
    assert (out / "gap_vs_time.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_row_that_solves_another_problem_has_no_gap(tmp_path, capsys):
    """A user read costate_tpbvp's fixed 10 s on Bilimoria & Wie as a minimum time 6.76 s from the
    optimum, and natural motion's impulse as an energy of 0. The rows, by hand: costate_tpbvp and
    eigenaxis with defaults keep the 10 s bound (fixed-time plans); natural motion's rate steps at
    its stop (an impulse); collocation at 3.2431 keeps its gap."""
    out = tmp_path / "board"
    assert main(["bench", "--problems", "bilimoria_wie_180", "natural_motion_min_energy", "--planners", "collocation",
                 "costate_tpbvp", "natural_motion", "--out", str(out)]) == 0
    capsys.readouterr()
    rows = {(row["problem"], row["label"]): row for row in csv.DictReader((out / "leaderboard.csv").open())}
    fixed = rows[("bilimoria_wie_180", "costate_tpbvp (defaults)")]
    assert float(fixed["value"]) == 10.0 and fixed["gap_abs"] == "" and fixed["reached"] == ""
    assert "keeps the scenario's bound T = 10 s" in fixed["message"]
    optimal = rows[("bilimoria_wie_180", "collocation")]
    assert float(optimal["gap_abs"]) == pytest.approx(float(optimal["value"]) - 3.2431, abs=1e-12)
    impulse = rows[("natural_motion_min_energy", "natural motion")]
    assert impulse["value"] == "" and impulse["gap_abs"] == "" and impulse["message"].startswith("impulse")
    summary = (out / "leaderboard.md").read_text().split("## Summary")[1]
    costate = next(line for line in summary.splitlines() if line.startswith("| costate_tpbvp |"))
    # 2 rows, 1 with a gap (natural motion's energy, not B&W's 10 s): its median |gap|
    assert [cell.strip() for cell in costate.split("|")[3:5]] == ["2", "1"]
    assert costate.split("|")[6].strip() != "-" and float(costate.split("|")[6]) < 1e-3
    assert "median \\|gap\\| (rel)" in summary


@pytest.mark.parametrize("argv, expected", [
    (["--problems", "no_such_problem"], "--problems: unknown problem 'no_such_problem'"),
    (["--planners", "no_such_planner"], "--planners: unknown planner or peer 'no_such_planner'"),
    (["--planners", "acados", "--no-peers"], "--planners: names only peers (acados) and --no-peers runs none"),
    # ran the problem twice: two identical leaderboard rows, counted twice in its medians
    (["--problems", "bilimoria_wie_45", "bilimoria_wie_45", "--planners", "eigenaxis", "--no-peers"],
     "--problems: 'bilimoria_wie_45' is given 2 times; give each name once"),
    (["--problems", "bilimoria_wie_45", "--planners", "eigenaxis", "eigenaxis", "--no-peers"],
     "--planners: 'eigenaxis' is given 2 times; give each name once"),
])
def test_unknown_names_exit_2_before_anything_is_written(tmp_path, capsys, argv, expected):
    out = tmp_path / "board"
    assert main(["bench", *argv, "--out", str(out)]) == 2
    assert f"slewbench: error in option: {expected}" in capsys.readouterr().err  # an option's, not the scenario's
    assert not out.exists()


def test_a_planner_row_reports_its_second_plan_the_first_paying_the_build(monkeypatch):
    # the peers report their second solve; a planner row must not carry its NLP build either
    from planners.eigenaxis import EigenaxisPlanner
    from scenarios.bench.leaderboard import run_bench
    plans = []
    original = EigenaxisPlanner._plan

    def counted(self, problem):
        reference = original(self, problem)
        plans.append(reference)
        return reference

    monkeypatch.setattr(EigenaxisPlanner, "_plan", counted)
    board = run_bench(load_suite(), problems=["bilimoria_wie_45"], planners=["eigenaxis"])
    assert len(plans) == 2 and [row.planner for row in board.rows] == ["eigenaxis"]
    assert board.rows[0].plan_time_s == plans[1].plan_time_s  # the second plan's time, set by Planner.plan


def test_a_failed_row_has_no_other_problem_note():
    from planners.reference import FailedReference
    from scenarios.bench.leaderboard import _other_problem
    problem = load_suite().problems["spin_repoint_min_energy"]
    scenario = load(problem.file)
    failed = FailedReference("costate_tpbvp", "solve_bvp failed")
    assert failed.duration == 0.0  # a failed plan's duration: not "its own duration" of another problem
    assert _other_problem(problem, scenario, failed, None, False) == ""


@pytest.mark.parametrize("name, options, expected", [
    ("collocation", {"objective": "min_time"}, True),
    ("collocation", {"objective": "weighted", "time_weight": 1.0, "energy_weight": 1.0}, True),
    ("collocation", {}, False),  # minimum energy over the scenario's T
    ("eigenaxis", {"profile": "min_time"}, True),
    ("eigenaxis", {}, False),
    ("costate_tpbvp", {"objective": "rate_acquisition"}, True),
    ("costate_tpbvp", {"objective": "rate_acquisition", "final_time": "fixed"}, False),
    ("costate_tpbvp", {}, False),
    ("shape_polynomial", {}, True),  # duration: rate_limit, the shortest t_f within the rate bound
    ("shape_polynomial", {"duration": "scenario"}, False),
    ("spin_extremal", {}, False),  # no class method: does not minimise time
])
def test_which_planners_minimise_time(name, options, expected):
    from planners.capabilities import minimises_time
    planner = PLANNERS[name](options)
    assert minimises_time(type(planner), planner.options) is expected


def test_a_minimum_time_gap_is_for_planners_that_minimise_time_whatever_their_duration():
    # the rule read the duration before: a minimum-time plan ending exactly at the bound lost its
    # gap, and a plan of its own duration that minimises nothing kept one
    from types import SimpleNamespace

    from scenarios.bench.leaderboard import _other_problem
    problem = load_suite().problems["bilimoria_wie_180"]
    scenario = load(problem.file)
    bound = scenario.problem.duration
    at_bound, own = SimpleNamespace(duration=bound, ok=True), SimpleNamespace(duration=4.0, ok=True)
    assert _other_problem(problem, scenario, at_bound, None, True) == ""
    assert _other_problem(problem, scenario, own, None, True) == ""
    assert "a fixed-time plan" in _other_problem(problem, scenario, at_bound, None, False)
    assert "without minimising it" in _other_problem(problem, scenario, own, None, False)


def test_bench_never_touches_what_slewbench_did_not_write(tmp_path, capsys):
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("keep")
    fast = ["bench", "--problems", "bilimoria_wie_45", "--planners", "eigenaxis", "--no-peers", "--no-plots"]
    assert main([*fast, "--out", str(mine)]) == 2  # a user's directory
    assert "did not create" in capsys.readouterr().err
    assert sorted(p.name for p in mine.iterdir()) == ["notes.txt"]
    out = tmp_path / "board"
    assert main([*fast, "--out", str(out)]) == 0
    (out / "user.txt").write_text("keep")
    assert main([*fast, "--out", str(out)]) == 0  # its own files are replaced, the user's kept
    assert (out / "user.txt").read_text() == "keep"
    assert (out / "leaderboard.csv").is_file() and not (out / "gap_vs_time.png").exists()


@pytest.mark.slow
def test_the_whole_suite_runs_in_five_minutes(tmp_path, capsys):
    start = time.perf_counter()
    assert main(["bench", "--out", str(tmp_path / "board")]) == 0
    elapsed = time.perf_counter() - start
    capsys.readouterr()
    data = json.loads((tmp_path / "board" / "leaderboard.json").read_text())
    suite = load_suite()
    assert {row["problem"] for row in data["rows"]} == set(suite.problems)
    assert elapsed < 300.0


def test_a_row_reaches_the_optimum_only_when_ok_and_a_peer_at_the_eigenaxis_saddle_is_noted():
    from scenarios.bench.leaderboard import EIGENAXIS_NOTE, _note, _peer_row, _reached
    from scenarios.bench.peers.base import PeerResult
    problem = load_suite().problems["bilimoria_wie_180"]  # optimum 3.2431, eigenaxis 2 sqrt(pi)
    assert _reached("ok", 1e-5, problem) is True
    assert _reached("violated", 1e-5, problem) is False  # within the tolerance, but it breaks a requirement
    assert _reached("failed", 0.0, problem) is False
    assert _reached("ok", None, problem) is None
    at_saddle = _peer_row(problem, "fatrop", PeerResult(2.0 * math.sqrt(math.pi), 0.01, "ok", 3, ""))
    assert at_saddle.message.startswith(EIGENAXIS_NOTE) and _note(at_saddle).startswith("stopped at the eigenaxis")
    at_optimum = _peer_row(problem, "fatrop", PeerResult(3.24312, 0.01, "ok", 30, "start: ours; fatrop: ok"))
    assert at_optimum.reached and at_optimum.message == "start: ours; fatrop: ok"
    assert _note(at_optimum) == "start: ours; fatrop: ok"  # a peer's note names its start, ok or not
    assert _note(dataclasses.replace(at_optimum, kind="planner")) == ""  # an ok planner row has none
    # where the eigenaxis slew is the optimum (the norm-bounded problem), reaching it is no saddle
    closed = load_suite().problems["norm_bounded_eigenaxis"]
    row = _peer_row(closed, "fatrop", PeerResult(closed.optimum, 0.01, "ok", 5, ""))
    assert row.reached and not row.message.startswith(EIGENAXIS_NOTE)


def test_the_markdown_cuts_a_long_note_in_its_cell_and_gives_it_whole_below_the_table():
    from scenarios.bench.leaderboard import NOTE_CHARS, Leaderboard, _peer_row
    from scenarios.bench.peers.base import PeerResult
    suite = load_suite()
    problem = suite.problems["bilimoria_wie_180"]
    long = "start: ours; " + "acados stopped: " + "x" * 150 + " (the end of the note)"
    rows = [_peer_row(problem, "acados", PeerResult(None, 0.5, "failed", 500, long)),
            _peer_row(problem, "fatrop", PeerResult(3.24312, 0.01, "ok", 30, "start: ours; fatrop: ok"))]
    markdown = Leaderboard(suite, [problem], rows).to_markdown()
    table = [line for line in markdown.splitlines() if line.startswith("| acados (peer)")]
    assert len(table) == 1 and "(the end of the note)" not in table[0] and table[0].count("x") < NOTE_CHARS
    assert table[0].rstrip(" |").endswith("… [1]")
    assert f"[1] {long}" in markdown.splitlines()  # whole, after the table
    assert "| start: ours; fatrop: ok |" in markdown and "[2]" not in markdown  # a short note stays in its cell


def _suite_problem(name):
    return load(load_suite().problems[name].file).problem


def test_the_peers_start_is_collocations_first_start_seeded_and_perturbed_for_minimum_time():
    """The bench's peer start (``first_start_guess``) on Bilimoria & Wie 180°: for minimum time the
    eigenaxis slew's smooth profile over the duration bound (the eigenaxis planner's own sample is
    the oracle), perturbed at the planner's 3 % (every entry moved, none by more than 5 sigma), and
    the same on every call whatever numpy's global random state (seed 0 of its own generator); for
    minimum energy (no perturbation in ``collocation``'s first start) the eigenaxis slew itself."""
    from scenarios.bench.peers._shooting import N, eigenaxis_guess, first_start_guess

    problem = _suite_problem("bilimoria_wie_180")
    first = first_start_guess(problem, "min_time")
    np.random.seed(12345)
    np.random.rand(100)
    again = first_start_guess(problem, "min_time")
    assert np.array_equal(first.states, again.states) and first.duration == again.duration
    assert first.start == again.start == "start: collocation's first (eigenaxis perturbed 1), T0 9.941 s"
    smooth = PLANNERS["eigenaxis"]({"profile": "smooth"}).plan(problem)
    assert smooth.duration == problem.duration == 10.0
    sample = smooth.sample(np.linspace(0.0, smooth.duration, N + 1))
    unperturbed = np.vstack([np.asarray(sample.q).T, np.asarray(sample.omega).T])
    assert first.states.shape == (7, N + 1)
    sigma = 0.03 * (np.abs(unperturbed) + 1e-3)  # AUTO_FIRST of |value| + the state floor 1e-3
    moved = np.abs(first.states - unperturbed)
    assert np.all(moved > 0.0) and np.all(moved < 5.0 * sigma)
    assert first.duration != 10.0 and abs(first.duration - 10.0) < 5.0 * 0.03 * 10.0
    # minimum energy: the unperturbed eigenaxis slew over the problem's duration, as the peers had it
    energy = _suite_problem("natural_motion_min_energy")
    guess = first_start_guess(energy, "min_energy")
    states, duration = eigenaxis_guess(energy, "min_energy")
    assert guess.duration == duration == energy.duration
    assert np.allclose(guess.states, states, rtol=0.0, atol=1e-12)
    assert guess.start == "start: collocation's first (eigenaxis), T0 110 s"


def test_the_fatrop_peer_leaves_the_bilimoria_wie_saddle_from_the_bench_start():
    """From the bench's start the FATROP peer reaches Bilimoria & Wie's published 3.2431 (its RK4,
    N = 50 optimum, within 2e-3); from the eigenaxis bang-bang it stays at that stationary point,
    2 sqrt(pi) = 3.5449: the bench must not start the peers there."""
    from scenarios.bench.peers._shooting import eigenaxis_guess
    from scenarios.bench.peers.fatrop import build_opti

    problem = _suite_problem("bilimoria_wie_180")
    result = load_peer("fatrop").solve(problem, "min_time")
    assert result.status == "ok", result.message
    assert result.objective is not None and result.objective < 3.5
    assert result.objective == pytest.approx(3.2431, rel=2e-3)
    assert result.message.startswith("start: collocation's first (eigenaxis perturbed 1)")
    assert result.extra["start"] == result.message.split("; ")[0]
    opti, cost = build_opti(problem, *eigenaxis_guess(problem, "min_time"))
    assert float(opti.solve().value(cost)) == pytest.approx(2.0 * math.sqrt(math.pi), abs=1e-4)


def test_the_plan_is_ranked_and_the_closed_loop_shown_beside_it(tmp_path, capsys):
    """keep_out_melton_scaled: collocation's minimum-time plan keeps the cone (+0.0091 deg) within the
    tolerance of the optimum; its tracking controller dips 0.0009 deg into the cone in closed loop.
    The plan reaches the optimum; the run's status stays violated, with the closed loop's reason."""
    out = tmp_path / "board"
    assert main(["bench", "--problems", "keep_out_melton_scaled", "--planners", "collocation", "eigenaxis",
                 "--no-plots", "--out", str(out)]) == 0
    capsys.readouterr()
    rows = {row["label"]: row for row in csv.DictReader((out / "leaderboard.csv").open())}
    plan = rows["collocation"]
    assert plan["plan_status"] == "ok" and plan["reached"] == "True"
    assert abs(float(plan["gap_abs"])) <= 1e-3
    assert plan["status"] == "violated" and "cone (closed loop)" in plan["message"]
    assert "cone (reference)" not in plan["message"]
    eigenaxis = rows["eigenaxis"]  # through the cone's centre: the plan itself breaks it
    assert eigenaxis["plan_status"] == "violated" and eigenaxis["reached"] == "False"
    text = (out / "leaderboard.md").read_text()
    assert "| collocation | planner | ok | violated | 2.58994 |" in text
    assert "| collocation | planner | 1 | 1 | 1 |" in text


@pytest.mark.parametrize("value, tolerance, expected", [
    (11.21, 1e-4, "11.2100"),          # down to the tolerance's digit, zeros kept
    (2.5897, 1e-3, "2.5897"),          # never fewer digits than the value as stated
    (5.8467e-8, 3e-12, "5.8467e-08"),
    (136.64, 0.05, "136.64"),
])
def test_the_optimum_is_printed_with_the_digits_of_its_tolerance(value, tolerance, expected):
    from scenarios.bench.leaderboard import _with_tolerance

    assert _with_tolerance(value, tolerance) == expected


def test_each_row_s_plan_is_scored_through_its_own_controller(monkeypatch):
    """A reference tracked by two controllers is scored once per controller (the actuator demand goes
    through that controller's allocation); before, every row took the first controller's status."""
    from scenarios import run
    from scenarios.bench import leaderboard
    from scenarios.schema.loader import ControllerSpec

    problem = load_suite().problems["bilimoria_wie_180"]
    scenario = load(problem.file)
    first = scenario.controllers[0]
    second = ControllerSpec(first.name, first.options, label="second")
    specs = [spec for spec in scenario.planners if spec.name == "eigenaxis"][:1]
    scenario = dataclasses.replace(scenario, planners=specs, controllers=[first, second])
    results = run(scenario)
    calls = []

    def status(scenario, row, controller):
        calls.append((id(row.reference), id(controller)))
        return "ok" if controller is first.controller else "violated"

    monkeypatch.setattr(leaderboard, "_plan_status", status)
    rows = leaderboard._planner_rows(problem, scenario, results, specs)
    assert [row.plan_status for row in rows] == ["ok", "violated"]
    assert calls == [(id(results.rows[0].reference), id(first.controller)),
                     (id(results.rows[0].reference), id(second.controller))]
    assert results.rows[0].reference is results.rows[1].reference  # one plan, two controllers
