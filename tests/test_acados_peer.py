"""The acados benchmark peer (scenarios/bench/peers/acados.py): its request, its skip, and (slow, when an
interpreter with acados is configured) its minimum time against the published optimum.

Oracle: Bilimoria & Wie's published minimum time 3.2431 s (unit inertia, |u_i| <= 1, 180° about x); the peer's
RK4 multiple shooting on 50 intervals stops at its discretisation's optimum, within 2e-3 of it.
"""
from __future__ import annotations

import numpy as np
import pytest

from ocp import Spacecraft, Torquers, quat
from planners import ManeuverProblem
from scenarios.bench.peers import acados


def bilimoria_wie() -> ManeuverProblem:
    return ManeuverProblem(Spacecraft([1.0, 1.0, 1.0], torquers=Torquers(1.0)), quat.IDENTITY, np.zeros(3),
                           quat.from_axis_angle([1, 0, 0], np.pi), 10.0, omegaf=np.zeros(3))


def test_request_carries_the_problem():
    data = acados.problem_data(bilimoria_wie(), "min_time")
    assert data["inertia"] == np.eye(3).tolist()
    assert data["u_max"] == [1.0, 1.0, 1.0]
    assert data["x0"] == [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    assert np.allclose(data["qf"], [0.0, 1.0, 0.0, 0.0], atol=1e-15)
    assert data["omegaf"] == [0.0, 0.0, 0.0] and data["N"] == 50 and data["duration"] == 10.0
    with pytest.raises(ValueError, match="objective"):
        acados.problem_data(bilimoria_wie(), "min_fuel")


def test_default_guess_is_the_eigenaxis_slerp():
    data = acados.problem_data(bilimoria_wie(), "min_energy", intervals=4)
    states, T = acados._guess(data)
    assert T == 10.0 and states.shape == (7, 5)
    assert np.allclose(np.linalg.norm(states[:4], axis=0), 1.0)
    half = quat.from_axis_angle([1, 0, 0], np.pi / 2)  # halfway along the 180° slew
    assert np.allclose(states[:4, 2], half)
    assert np.all(states[4:] == 0.0)


def test_skipped_with_a_note_when_absent(monkeypatch):
    monkeypatch.setenv(acados.ENV_PYTHON, "/nonexistent/python")
    ok, note = acados.available()
    assert not ok and "/nonexistent/python" in note
    result = acados.solve(bilimoria_wie())
    assert result["skipped"] is True and "not an executable" in result["note"]


@pytest.mark.slow
def test_min_time_reaches_the_published_optimum():
    ok, note = acados.available()
    if not ok:
        pytest.skip(note)
    problem = bilimoria_wie()
    # a guess near the bang-bang optimum: the slew about x at the optimum's duration, rates from a
    # bang-bang profile about x (the eigenaxis guess at rest sends acados's QP to a failure)
    n, T0 = acados.N, 3.3
    t = np.linspace(0.0, T0, n + 1)
    rate = np.where(t < T0 / 2, t, T0 - t) * np.pi / (T0 / 2) ** 2
    angle = np.concatenate([[0.0], np.cumsum((rate[1:] + rate[:-1]) / 2 * np.diff(t))])
    states = np.vstack([np.cos(angle / 2), np.sin(angle / 2), 0 * t, 0 * t, rate + 0.05, 0.05 + 0 * t, 0.05 + 0 * t])
    result = acados.solve(problem, "min_time", guess=(states, T0))
    assert result["status"] == "ok", result
    assert result["objective"] == pytest.approx(3.2431, rel=2e-3)
    assert result["build_s"] > 0 and result["iterations"] > 0


@pytest.mark.slow
def test_the_bench_peer_leaves_the_eigenaxis_saddle_from_the_bench_start():
    """``slewbench bench``'s acados peer starts from collocation's first start (not the eigenaxis
    bang-bang, where it stopped at 2 sqrt(pi) = 3.5449 in 3 SQP iterations) and reaches the published
    optimum within its RK4 discretisation's 2e-3."""
    ok, note = acados.available()
    if not ok:
        pytest.skip(note)
    result = acados.PEER.solve(bilimoria_wie(), "min_time")
    assert result.status == "ok", result.message
    assert result.objective < 3.5
    assert result.objective == pytest.approx(3.2431, rel=2e-3)
    assert result.message.startswith("start: collocation's first (eigenaxis perturbed 1)")
    assert result.extra["start"] == result.message.split("; ")[0]


def test_bench_registry_skips_it_with_the_note(monkeypatch):
    base = pytest.importorskip("scenarios.bench.peers.base")  # the bench's peer contract
    monkeypatch.setenv(acados.ENV_PYTHON, "/nonexistent/python")
    with pytest.raises(base.PeerUnavailable, match="/nonexistent/python"):
        base.load_peer("acados")
    assert acados.PEER.problem_error(bilimoria_wie(), "min_time") is None
    assert "target" in acados.PEER.problem_error(
        ManeuverProblem(Spacecraft([1.0, 1.0, 1.0], torquers=Torquers(1.0)), quat.IDENTITY, np.zeros(3), None, 10.0),
        "min_time")


def test_worker_output_goes_to_its_log_and_into_the_error(tmp_path, monkeypatch, capfd):
    # A stand-in interpreter: prints what acados prints on every build (to stdout and stderr), then
    # dies without answering. The user's terminal sees none of it; the error quotes it.
    fake = tmp_path / "python"
    fake.write_text("#!/bin/sh\necho 'Version 3.6.7 currently in use.' >&2\necho 'gcc: fatal error' >&2\nexit 3\n")
    fake.chmod(0o755)
    monkeypatch.setenv(acados.ENV_PYTHON, str(fake))
    with acados.AcadosPeer() as peer, pytest.raises(RuntimeError) as raised:
        peer.build(bilimoria_wie(), "min_time")
    message = str(raised.value)
    assert "exit 3" in message and "gcc: fatal error" in message and "Version 3.6.7" in message
    out, err = capfd.readouterr()
    assert "Version 3.6.7" not in out + err and "gcc" not in out + err


def test_energy_scale_is_the_guess_energy():
    """The cost acados minimises is divided by the guess's energy, worked out here: a spin-up about x
    at a constant 0.1 rad/s² over the first half of 4 intervals of 1 s (T = 4 s), I = diag(2, 3, 4):
    torques [0.2, 0, 0] held on two intervals, Σ h ‖τ‖² = 2 × 0.04 = 0.08 (ω × I ω = 0 about x)."""
    problem = ManeuverProblem(Spacecraft([2.0, 3.0, 4.0], torquers=Torquers(1.0)), quat.IDENTITY, np.zeros(3),
                              quat.from_axis_angle([1, 0, 0], 0.3), 4.0, omegaf=np.zeros(3))
    states = np.zeros((7, 5))
    states[0] = 1.0
    states[4] = [0.0, 0.1, 0.2, 0.2, 0.2]
    data = acados.problem_data(problem, "min_energy", intervals=4, guess=(states, 4.0))
    assert acados.energy_scale(data) == pytest.approx(0.08, rel=1e-12)
    # at rest (the default guess) the rest-to-rest single-axis slew: 12 λ_max² θ² / T³ = 12 × 16 × 0.09 / 64
    assert acados.energy_scale(acados.problem_data(problem, "min_energy", intervals=4)) == pytest.approx(0.27, rel=1e-9)


@pytest.mark.slow
def test_min_energy_reaches_the_optimum_the_other_peers_reach():
    """The natural-motion problem's cost is of order 1e-8 N² m² s: unscaled, acados's absolute
    tolerance 1e-8 let it stop at 7.08679e-08 (21 % above) with its flag "ok" after 171 iterations.
    Scaled by the guess's energy it reaches its transcription's optimum (the suite's 5.8467e-8 is collocation's;
    FATROP and rockit reach 5.849307e-08 from this start and transcription, measured 2026-12-02)."""
    ok, note = acados.available()
    if not ok:
        pytest.skip(note)
    from pathlib import Path

    from scenarios import load

    root = Path(__file__).resolve().parents[1]
    problem = load(root / "scenarios/bench/problems/natural_motion_min_energy.yaml").problem
    result = acados.PEER.solve(problem, "min_energy")
    assert result.status == "ok", result.message
    assert result.objective == pytest.approx(5.849307e-08, rel=1e-6)


class _ScriptedWorker:
    """A stand-in for the acados worker: each build records its options, each solve answers what
    ``script(options)`` says for the last build's options."""

    def __init__(self, script):
        self.script, self.builds = script, []
        self._process = type("P", (), {"poll": staticmethod(lambda: None)})()

    def _ask(self, request):
        assert request["op"] == "build"
        self.builds.append(dict(request.get("options", {})))
        return {"build_s": 1.0}

    def solve(self):
        status, time_s = self.script(self.builds[-1])
        return {"objective": 3.2434 if status == "ok" else 9.9, "T": 3.2434, "time_s": time_s, "cpu_s": time_s,
                "status": status, "iterations": 17}


@pytest.mark.parametrize("case", ["capped_faster", "defaults_faster", "capped_only_after_fallback", "none"])
def test_the_bench_peer_reports_the_faster_converged_qp_setting(case):
    """Each HPIPM setting of ``QP_SETTINGS`` is built (with the fallback options after a QP failure)
    and solved; the faster converged solve is the row, every build in the build time, the note names
    the setting; when none converges the first setting's failure is reported."""
    capped = {"qp_solver_iter_max": 8, "qp_solver_warm_start": 1}
    assert list(acados.QP_SETTINGS) == [{}, capped]

    def script(options):
        is_capped = options.get("qp_solver_iter_max") == 8
        fallback = options.get("regularize_method") == "MIRROR"
        if case == "capped_faster":
            return "ok", 0.05 if is_capped else 0.10
        if case == "defaults_faster":
            return "ok", 0.20 if is_capped else 0.09
        if case == "capped_only_after_fallback":
            if is_capped:
                return ("ok", 0.30) if fallback else ("qp_failure", 0.01)
            return "maxiter", 1.5
        return ("maxiter" if not is_capped else "qp_failure"), 1.0

    peer = acados.AcadosBenchPeer()
    worker = peer._worker = _ScriptedWorker(script)
    result = peer.solve(bilimoria_wie(), "min_time")
    expected_builds = {"capped_faster": 2, "defaults_faster": 2, "capped_only_after_fallback": 3, "none": 3}[case]
    assert len(worker.builds) == expected_builds
    assert result.build_time_s == pytest.approx(float(expected_builds))
    assert [entry["options"].get("qp_solver_iter_max") for entry in result.extra["tried"]] == [None, 8]
    if case == "none":
        assert result.status == "failed" and result.objective is None
        assert result.message.endswith("acados: maxiter (HPIPM's defaults; none of 2 QP settings converged)")
        return
    assert result.status == "ok" and result.objective == pytest.approx(3.2434)
    chosen = {"capped_faster": 0.05, "defaults_faster": 0.09, "capped_only_after_fallback": 0.30}[case]
    assert result.solve_time_s == chosen
    if case == "defaults_faster":
        assert "qp_solver_iter_max" not in result.extra["options"]
        assert result.message.endswith("(HPIPM's defaults; the faster of 2 converged QP settings)")
    else:
        assert result.extra["options"]["qp_solver_iter_max"] == 8
        assert ("the only one of 2 QP settings that converged" if case == "capped_only_after_fallback"
                else "the faster of 2 converged QP settings") in result.message
    if case == "capped_only_after_fallback":
        assert result.extra["options"]["regularize_method"] == "MIRROR"
