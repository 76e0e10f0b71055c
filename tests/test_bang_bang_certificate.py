"""The shot bang-bang minimum time and its certificate (planners.collocation.certificate:
``time_error``'s switch-time shooting, ``bang_bang_certificate``): the switch times and T are those
of the continuous problem, not of the shooting's RK4 steps, and the sign test of the switching
functions refuses a wrong sign between its samples.

Oracle, independent of the code under test: scipy's DOP853 (rtol 1e-13) flying the bang-bang
control (the dynamics written out in tests/test_collocation_bang_bang.py), and Newton's method on
the final conditions with those flights (a finite-difference Jacobian): the exact optimum with the
returned switching structure. Published: Betts 2010, sect. 6.8, XTE 28.6304077 s, 9e-7 s above it.
"""
import numpy as np
import pytest

import planners.collocation.certificate as certificate
from tests.test_collocation_bang_bang import flown, plan, problem_of

CASES = ("bilimoria_wie_180", "full_inertia_150", "xte_150")


def final_miss(problem, times, controls, T):
    """DOP853's final miss: the vector part of ``conj(q_f) ⊗ q(T)`` and ``ω(T) − ω_f``."""
    end, _ = flown(problem, times, controls, T)
    q, qf = end[:4], np.asarray(problem.qf, dtype=float)
    vector = qf[0] * q[1:] - q[0] * qf[1:] - np.cross(qf[1:], q[1:])
    return np.concatenate([vector, end[4:7] - np.asarray(problem.omegaf, dtype=float)])


def exact_optimum(problem, times, controls, T):
    """Switch times and T (as many as the final conditions) that DOP853's flight meets them with:
    Newton's method from the given ones, forward differences of 1e-6 s."""
    z = np.append(np.asarray(times, dtype=float), float(T))
    assert len(z) == 6  # the cases here: 5 switches, 6 conditions
    for _ in range(6):
        r = final_miss(problem, z[:-1], controls, z[-1])
        if np.max(np.abs(r)) < 1e-13:
            break
        J = np.empty((6, 6))
        for k in range(6):
            moved = z.copy()
            moved[k] += 1e-6
            J[:, k] = (final_miss(problem, moved[:-1], controls, moved[-1]) - r) / 1e-6
        z = z - np.linalg.solve(J, r)
    assert np.max(np.abs(final_miss(problem, z[:-1], controls, z[-1]))) < 1e-12
    return z


@pytest.fixture(scope="module")
def planned():
    return {name: plan(name) for name in CASES}


@pytest.mark.parametrize("name", CASES)
def test_the_shot_switch_times_and_T_are_the_exact_optimum(planned, name):
    # the shooting's RK4 steps (12 per arc) put T 1.6e-6 s below the exact optimum on XTE and
    # 2e-7 s above it on the full inertia; their error taken off, T within 1e-9 of itself and the
    # switches within 1e-8 of T (2e-9 on the full inertia, whose RK4 error at 12 steps is the least
    # asymptotic: 14 times that of 24, not 16)
    reference = planned[name]
    shooting = reference.stats["shooting"]
    times, controls, T = shooting["switch_times_s"], shooting["controls"], reference.duration
    assert T == shooting["shooting_T_s"] and reference.stats["certificate"]["verdict"] == "certified"
    exact = exact_optimum(problem_of(name), times, controls, T)
    assert abs(T - exact[-1]) < 1e-9 * T, (T, exact[-1])
    assert np.max(np.abs(np.asarray(times) - exact[:-1])) < 1e-8 * T
    assert shooting["steps_per_arc"] == certificate.SHOOTING_STEPS
    # the correction is the RK4 steps' error of T: the exact T minus that of the RK4 optimum
    rk4_T = T - shooting["rk4_correction_s"]
    assert abs(abs(exact[-1] - rk4_T) - abs(shooting["rk4_correction_s"])) < 0.02 * abs(exact[-1] - rk4_T)


def test_xte_is_betts_value_to_its_digits(planned):
    # Betts's 28.6304077 is 9e-7 s above the exact optimum (28.6304068)
    assert planned["xte_150"].duration == pytest.approx(28.6304068, abs=1e-7)


def certify(name, times, controls, T):
    problem = problem_of(name)
    bound = np.broadcast_to(np.asarray(problem.spacecraft.torquers.max_torque, dtype=float), (3,))
    x0 = np.asarray(problem.initial_state[:7], dtype=float)
    xf = np.concatenate([problem.qf, problem.omegaf])
    return certificate.bang_bang_certificate(problem.model, x0, xf, np.zeros(3), np.asarray(times), np.asarray(controls),
                                             T, -bound, bound, True)


def test_the_certificate_measures_the_miss_of_the_exact_flight(planned):
    # switch times and T 5.7e-8 of T off the exact optimum (XTE's RK4 error of 12 steps per arc)
    # miss the final state by more than BANG_BANG_MISS flown exactly: not certified, and the
    # certificate's miss is DOP853's, as at the certified optimum
    reference = planned["xte_150"]
    shooting, record = reference.stats["shooting"], reference.stats["certificate"]
    assert record["verdict"] == "certified" and record["pontryagin"]["miss"] < 1e-12
    assert record["pontryagin"]["steps_per_arc"] == certificate.SHOOTING_STEPS
    assert record["pontryagin"]["rk4_time_error_s"] == pytest.approx(abs(shooting["rk4_correction_s"]), rel=0.02)
    problem = problem_of("xte_150")
    z = np.append(shooting["switch_times_s"], reference.duration)
    # flown exactly, the certified optimum misses by 1.4e-10 (its switches 1e-9 s off the exact ones)
    assert np.max(np.abs(final_miss(problem, z[:-1], shooting["controls"], z[-1]))) < 1e-9
    moved = z * (1 - 5.7e-8)
    miss = np.max(np.abs(final_miss(problem, moved[:-1], shooting["controls"], moved[-1])))
    assert miss > certificate.BANG_BANG_MISS
    refused = certify("xte_150", moved[:-1], shooting["controls"], moved[-1])
    assert refused["verdict"] != "certified" and not refused["pontryagin"]["first_order"]
    assert refused["pontryagin"]["miss"] == pytest.approx(miss, rel=0.02)


def test_a_long_rk4_error_doubles_the_steps(monkeypatch):
    # with a threshold below XTE's correction (5.7e-8 of T) the shooting and the certificate take
    # 24 steps per arc: the same exact optimum
    monkeypatch.setattr(certificate, "SHOOTING_RICHARDSON", 1e-8)
    reference = plan("xte_150")
    shooting = reference.stats["shooting"]
    assert shooting["steps_per_arc"] == 2 * certificate.SHOOTING_STEPS
    assert reference.stats["certificate"]["pontryagin"]["steps_per_arc"] == 2 * certificate.SHOOTING_STEPS
    assert abs(shooting["rk4_correction_s"]) < 2e-7  # 1.6e-6 / 16
    exact = exact_optimum(problem_of("xte_150"), shooting["switch_times_s"], shooting["controls"], reference.duration)
    assert abs(reference.duration - exact[-1]) < 1e-9 * reference.duration


# the sign test on switching functions given at the RK4 steps' ends: one control, |u| <= 1, at
# +1 (σ < 0) until its switch at t = 1 and at −1 (σ > 0) after, T = 3, 12 steps per arc
STEPS, SWITCH, END = 12, 1.0, 3.0
U = np.array([[1.0, -1.0]])
LOW, HIGH = np.array([-1.0]), np.array([1.0])


def sign_test(values, rates):
    """``_sign_test`` of σ and σ̇ given per arc as functions of the time (arrays of it)."""
    times = np.stack([np.linspace(0.0, SWITCH, STEPS + 1), np.linspace(SWITCH, END, STEPS + 1)])
    sigma = np.stack([values(times[k], k) for k in range(2)])[..., None]
    sigma_dot = np.stack([rates(times[k], k) for k in range(2)])[..., None]
    return certificate._sign_test(times, sigma, sigma_dot, U, LOW, HIGH)


def test_a_clean_switch_passes_the_sign_test():
    result = sign_test(lambda t, k: t - SWITCH, lambda t, k: np.ones_like(t))
    assert result["wrong_sign"] == 0.0 and result["zero"] == 0.0
    # |σ| / max|σ| over d / T: (d / 2) / (d / 3), and σ̇ T / max|σ| at the switch: 3 / 2
    assert result["strictness"] == pytest.approx(1.5)
    assert result["agreement"].wrong == 0.0


def test_a_wrong_sign_below_the_agreement_tolerance_near_a_switch_is_refused():
    # σ −9e-4 of its largest (2) at the first step's end after the switch (1/18 of T after it):
    # the agreement counts it as zero (BANG_BANG_SIGN) and its strictness margin is 9e-4 / (1/18),
    # 0.016: the old test passed it
    def values(t, k):
        v = t - SWITCH
        return np.where(np.isclose(t, SWITCH + 2.0 / STEPS), -9e-4 * 2.0, v) if k == 1 else v

    def rates(t, k):
        return np.where(np.isclose(t, SWITCH + 2.0 / STEPS), 0.0, 1.0) if k == 1 else np.ones_like(t)

    result = sign_test(values, rates)
    assert result["agreement"].wrong == 0.0  # below BANG_BANG_SIGN: not seen by the agreement
    assert result["wrong_sign"] == pytest.approx(9e-4, rel=1e-6)
    assert result["wrong_sign"] > certificate.BANG_BANG_ZERO


def test_a_wrong_sign_between_the_samples_is_refused():
    # on the arc after the switch σ = 1 at the steps' ends but for a dip inside the 7th step:
    # its ends' slopes -4.05 and 4.05 (per step) make the cubic 1 − 4.05 s (1 − s), −0.0125 at
    # its middle and positive at every sample (s = 0.4: 0.028)
    h = (END - SWITCH) / STEPS
    dip = (SWITCH + 6 * h, SWITCH + 7 * h)

    def values(t, k):
        return t - SWITCH if k == 0 else np.where(t == SWITCH, 0.0, 1.0)

    def rates(t, k):
        if k == 0:
            return np.ones_like(t)
        rate = np.where(t == SWITCH, 1.0, 0.0)
        return rate + np.where(np.isclose(t, dip[0]), -4.05 / h, 0.0) + np.where(np.isclose(t, dip[1]), 4.05 / h, 0.0)

    result = sign_test(values, rates)
    assert result["agreement"].wrong == 0.0
    largest = 1 + 4.05 * 4 / 27  # the neighbouring steps' cubics 1 + 4.05 s² (1 − s) at s = 2/3
    assert result["wrong_sign"] == pytest.approx(0.0125 / largest, rel=1e-6)
    assert result["strictness"] > certificate.BANG_BANG_STRICT  # the samples alone: strict


def test_a_switch_crossing_zero_the_wrong_way_is_not_strict():
    # σ̇ at the switch (both arcs' ends) of the wrong sign, 0.02 of max|σ| / T: the wrong side's
    # excursions beside it, 1e-6 of max|σ|, are below the co-state's error; the slope's sign
    # refuses it (its size passed the old test's |σ̇| T / max|σ| >= BANG_BANG_STRICT)
    slope = -0.02 * 2.0 / END

    def rates(t, k):
        return np.where(t == SWITCH, slope, 1.0)

    result = sign_test(lambda t, k: t - SWITCH, rates)
    assert result["wrong_sign"] < certificate.BANG_BANG_ZERO
    assert result["strictness"] < 0 < certificate.BANG_BANG_STRICT


@pytest.mark.parametrize("found, check", [({"wrong_sign": 1e-4}, "first_order"), ({"strictness": -0.5}, "strict")])
def test_the_certificate_refuses_what_the_sign_test_finds(planned, monkeypatch, found, check):
    real = certificate._sign_test
    monkeypatch.setattr(certificate, "_sign_test", lambda *args: {**real(*args), **found})
    shooting = planned["xte_150"].stats["shooting"]
    record = certify("xte_150", shooting["switch_times_s"], shooting["controls"], planned["xte_150"].duration)
    assert record["verdict"] != "certified" and not record["pontryagin"][check]
    monkeypatch.setattr(certificate, "_sign_test", real)
    assert certify("xte_150", shooting["switch_times_s"], shooting["controls"],
                   planned["xte_150"].duration)["verdict"] == "certified"


def test_a_hamiltonian_above_its_tolerance_is_measured_again_with_twice_the_steps(planned, monkeypatch):
    # XTE's |H| is 9.8e-7 with 12 steps per arc, the discrete co-state's own error: with the
    # tolerance at 5e-7 the certificate doubles the steps once (|H| 6e-8) and certifies; with it
    # at 1e-8 it refuses after that one doubling
    shooting = planned["xte_150"].stats["shooting"]
    args = ("xte_150", shooting["switch_times_s"], shooting["controls"], planned["xte_150"].duration)
    assert 5e-7 < certify(*args)["pontryagin"]["hamiltonian"] < certificate.BANG_BANG_HAMILTONIAN
    monkeypatch.setattr(certificate, "BANG_BANG_HAMILTONIAN", 5e-7)
    record = certify(*args)
    assert record["verdict"] == "certified" and record["pontryagin"]["steps_per_arc"] == 24
    assert record["pontryagin"]["hamiltonian"] < 1e-7
    monkeypatch.setattr(certificate, "BANG_BANG_HAMILTONIAN", 1e-8)
    record = certify(*args)
    assert record["verdict"] != "certified" and record["pontryagin"]["steps_per_arc"] == 24
