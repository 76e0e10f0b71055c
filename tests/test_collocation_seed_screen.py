"""A seed planner whose reference is not finite, or raises when sampled, is no start of collocation.

With ``seed_planners: auto`` collocation seeds from every registered ``cheap`` planner that accepts
the problem, plugins included. A fresh-eyes plugin author (2026-12-02) found that a cheap planner
whose reference turns NaN after T/2 left the built-in collocation in its solver for over 20 minutes
(the NaN went into the start), and one whose reference raised when sampled made the built-in
collocation row fail. Oracle: the same problem without the bad seed planner (the answer must not
change), and the skipped seed named with the reason.
"""
import numpy as np
import pytest

from ocp import ReactionWheels, Spacecraft, quat
from planners import (
    PLANNERS,
    ManeuverProblem,
    Planner,
    Reference,
    ReferenceSample,
    inverse_dynamics_torque,
)


class _CycloidReference(Reference):
    """θ(s) = θ_f (s − sin 2πs / 2π) about the eigenaxis, rest to rest; ``defect`` breaks it after T/2."""

    def __init__(self, problem: ManeuverProblem, defect: str) -> None:
        rotation = quat.to_rotation_vector(quat.error(problem.qf, problem.q0))
        self.angle = float(np.linalg.norm(rotation))
        self.axis, self.q0, self.defect = rotation / self.angle, problem.q0, defect
        super().__init__("bad_seed", problem.duration, problem.spacecraft.inertia)

    def _evaluate(self, t):
        s, w = t / self.duration, 2 * np.pi
        theta = self.angle * (s - np.sin(w * s) / w)
        rate = self.angle * (1 - np.cos(w * s)) / self.duration
        acc = self.angle * w * np.sin(w * s) / self.duration ** 2
        q = quat.product(self.q0, quat.from_axis_angle(self.axis, theta))
        omega, omega_dot = rate[:, None] * self.axis, acc[:, None] * self.axis
        if self.defect == "nan":
            q = np.where((t > 0.5 * self.duration)[:, None], np.nan, q)
        elif self.defect == "nan_window":  # between the screening's 129 points, on collocation points
            q = np.where(((t > 0.517 * self.duration) & (t < 0.522 * self.duration))[:, None], np.nan, q)
        elif self.defect == "raise" and np.any(t > 0.5 * self.duration):
            raise RuntimeError("simulated crash inside _evaluate")
        elif self.defect == "after_end" and np.any(t > self.duration):
            raise RuntimeError("sampled after T")
        return ReferenceSample(q, omega, omega_dot, inverse_dynamics_torque(self.inertia, omega, omega_dot))


def _bad_seed_planner(defect: str) -> type[Planner]:
    class BadSeed(Planner):
        name = "bad_seed"
        cheap = True

        def _plan(self, problem):
            return _CycloidReference(problem, defect)

    return BadSeed


def _problem() -> ManeuverProblem:
    spacecraft = Spacecraft([3.0, 4.0, 5.0], wheels=ReactionWheels(np.eye(3), max_torque=0.2))
    return ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.from_axis_angle([0, 0, 1], np.deg2rad(18.0)),
                           60.0, omegaf=np.zeros(3))


@pytest.fixture(scope="module")
def clean():
    """The answer without the bad seed planner."""
    reference = PLANNERS["collocation"]({"intervals": 30}).plan(_problem())
    assert reference.ok, reference.message
    return reference


@pytest.mark.parametrize("defect, reason", [("nan", "non-finite q at t = "),
                                            ("raise", "sampling its reference raised RuntimeError"),
                                            ("nan_window", "intervals is not finite at ")])
def test_a_bad_seed_is_skipped_and_named(monkeypatch, clean, defect, reason):
    monkeypatch.setitem(PLANNERS, "bad_seed", _bad_seed_planner(defect))
    planner = PLANNERS["collocation"]({"intervals": 30})
    assert "bad_seed" in planner._seed_names(_problem())  # not vacuous: it would seed the solve
    reference = planner.plan(_problem())
    assert reference.ok, reference.message
    skipped = reference.stats["seeds"]["skipped"]
    assert any(entry.startswith("bad_seed: ") and reason in entry for entry in skipped), skipped
    assert reference.stats["objective"] == pytest.approx(clean.stats["objective"], rel=1e-6)


def test_a_candidate_with_a_nan_is_no_feasible_slew():
    # start_violations compares each sample with the bounds; a NaN compares false with all of them
    # and read as feasible (a faster candidate would then seed a solve from a NaN)
    from planners.collocation.certificate import start_violations
    from planners.collocation.problem import variable_bounds

    problem = _problem()
    reference = _CycloidReference(problem, "nan_window")
    broken = start_violations(problem, reference, variable_bounds(problem, None, 1.0), None, (), 601, 1e-6, 1e-6)
    assert broken.get("not finite", 0) > 0, broken
    clean = _CycloidReference(problem, "none")
    assert start_violations(problem, clean, variable_bounds(problem, None, 1.0), None, (), 601, 1e-6, 1e-6) == {}


def test_a_start_is_read_on_its_duration_only(monkeypatch):
    # The screening samples [0, T], where a start is read: sampling after T integrated the torque-free
    # coast of every start (scipy, per start) and tripled the spin case's plan time (73 -> 200 ms)
    monkeypatch.setitem(PLANNERS, "bad_seed", _bad_seed_planner("after_end"))
    reference = PLANNERS["collocation"]({"intervals": 30}).plan(_problem())
    assert reference.ok, reference.message
    assert not any(entry.startswith("bad_seed") for entry in reference.stats["seeds"]["skipped"])
