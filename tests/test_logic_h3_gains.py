"""The quaternion PD laws' gains seen through the closed loop they make (``controllers.base``'s
``gain_matrix`` and ``check_gain``, read by ``augmented_quaternion_feedback`` and ``eigenaxis_pd``).

Oracles, none produced by the code under test:

* the linear attitude-error dynamics. Near the target ``q = q_f ⊗ (1, θ/2)`` so ``q_e ≈ θ/2`` and
  ``θ̇ ≈ ω``; the gyroscopic term is of second order. The law ``u = −K q_e − C ω`` then gives
  ``J θ̈ + C θ̇ + ½ K θ = 0``. With scalar gains ``K = k J``, ``C = c J`` every axis is
  ``θ̈ + c θ̇ + ½ k θ = 0``: asking ``ω_n, ζ`` means ``k = 2 ω_n²``, ``c = 2 ζ ω_n`` and the poles are
  the roots of ``s² + 2 ζ ω_n s + ω_n²`` (each three times), whatever the inertia. The poles of the
  law are measured by central differences of its command at the target, in a state matrix written
  here with NumPy, and compared with those roots (or, for full matrices, with the eigenvalues of the
  matrix pencil built from the requested ``K`` and ``C``);
* the Lyapunov function of the spin paper's appendix, ``V = 2 k (1 − q_e0) + ½ ωᵀω``, whose rate
  is ``V̇ = −c ωᵀω`` for scalar gains: with ``c = 0`` it is conserved along the nonlinear closed
  loop (integrated with SciPy's DOP853, the law's torque on a rigid body written here);
* the energy a gain feeds in: a rate gain with ``x ᵀ C x < 0`` for some ``x`` has a closed-loop pole
  in the right half plane (the pencil's eigenvalues), so it must be refused; a skew (gyroscopic)
  part does no work and must not be.

Mutations these catch (python -m tests.mutation -k controller-; each survived
tests/test_controller_conformance.py): a scalar gain not times the inertia, a zero gain refused,
the gain check reading the matrix's lower triangle instead of its symmetric part.
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from controllers import CONTROLLERS
from ocp import Measurement, Spacecraft, Torquers

LAWS = ("eigenaxis_pd", "augmented_quaternion_feedback")


def _product(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Hamilton product, scalar first (written out here, not ocp.quat)."""
    p0, pv, q0, qv = p[0], p[1:], q[0], q[1:]
    return np.r_[p0 * q0 - pv @ qv, p0 * qv + q0 * pv + np.cross(pv, qv)]


def _inertia() -> np.ndarray:
    """Principal moments 15, 25, 35 kg m² in rotated axes: a scalar gain not times J would give each
    axis another frequency, by a factor up to 1.5."""
    angle = 0.7
    axis = np.array([1.0, -2.0, 2.0]) / 3.0
    skew = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    rotation = np.eye(3) + np.sin(angle) * skew + (1 - np.cos(angle)) * skew @ skew
    return rotation @ np.diag([15.0, 25.0, 35.0]) @ rotation.T


TARGET = np.array([0.5, -0.5, 0.5, 0.5])


def _law(name: str, kp, kd):
    spacecraft = Spacecraft(_inertia(), torquers=Torquers(1e3))
    law = CONTROLLERS[name]({"kp": kp, "kd": kd, "hold_compensation": False})
    law.reset(spacecraft, 0.1, (TARGET, np.zeros(3)))
    return law


def _torque(law, theta: np.ndarray, omega: np.ndarray) -> np.ndarray:
    angle = np.linalg.norm(theta)
    small = np.r_[np.cos(angle / 2), np.sinc(angle / (2 * np.pi)) * theta / 2]  # exp(θ/2), sin(x)/x safe at 0
    q = _product(TARGET, small)
    return np.asarray(law(0.0, Measurement(0.0, q, omega, np.zeros(0)), None).torque, dtype=float)


def _measured_poles(law) -> np.ndarray:
    """Eigenvalues of the linearised closed loop x = (θ, ω): θ̇ = ω, J ω̇ = u(θ, ω) (ω × J ω is of
    second order at rest), the law's Jacobians by central differences."""
    inertia, h = _inertia(), 1e-6
    columns = []
    for i in range(6):
        step = np.zeros(6)
        step[i] = h
        plus, minus = _torque(law, step[:3], step[3:]), _torque(law, -step[:3], -step[3:])
        columns.append((plus - minus) / (2 * h))
    jacobian = np.array(columns).T  # (3, 6): du/dθ, du/dω
    state = np.zeros((6, 6))
    state[:3, 3:] = np.eye(3)
    state[3:] = np.linalg.solve(inertia, jacobian)
    return np.linalg.eigvals(state)


def _pencil_poles(stiffness: np.ndarray, damping: np.ndarray) -> np.ndarray:
    """Poles of J θ̈ + C θ̇ + ½ K θ = 0 from the requested matrices."""
    inertia = _inertia()
    state = np.zeros((6, 6))
    state[:3, 3:] = np.eye(3)
    state[3:, :3] = -np.linalg.solve(inertia, 0.5 * stiffness)
    state[3:, 3:] = -np.linalg.solve(inertia, damping)
    return np.linalg.eigvals(state)


def _assert_same_poles(measured: np.ndarray, expected: np.ndarray, scale: float) -> None:
    key = lambda z: (round(z.real / scale, 4), round(z.imag / scale, 4))  # noqa: E731
    np.testing.assert_allclose(sorted(measured, key=key), sorted(expected, key=key), rtol=0, atol=1e-6 * scale)


@pytest.mark.parametrize("name", LAWS)
@pytest.mark.parametrize("omega_n, zeta", [(0.1, 0.7), (0.05, 0.3), (0.2, 1.5)])
def test_scalar_gains_put_every_pole_at_the_asked_frequency_and_damping(name, omega_n, zeta):
    law = _law(name, 2 * omega_n**2, 2 * zeta * omega_n)
    root = np.sqrt(complex(zeta**2 - 1))
    expected = np.repeat([omega_n * (-zeta + root), omega_n * (-zeta - root)], 3)
    _assert_same_poles(_measured_poles(law), expected, omega_n)


@pytest.mark.parametrize("name", LAWS)
def test_no_rate_gain_leaves_an_undamped_oscillator_at_omega_n(name):
    omega_n = 0.1
    for zero in (0.0, 0):
        poles = _measured_poles(_law(name, 2 * omega_n**2, zero))
        _assert_same_poles(poles, np.repeat([1j * omega_n, -1j * omega_n], 3), omega_n)


@pytest.mark.parametrize("name", LAWS)
def test_no_attitude_gain_leaves_free_drift_and_rate_decay(name):
    c = 0.3
    poles = _measured_poles(_law(name, 0, c))
    _assert_same_poles(poles, np.repeat([0.0, -c], 3), c)


def test_without_damping_the_lyapunov_function_is_conserved_along_the_nonlinear_loop():
    """``V = 2 k (1 − q_e0) + ½ ωᵀω`` is constant with ``c = 0`` and falls as ``∫ c ωᵀω`` with
    ``c > 0`` (scalar gains), over a 100 deg swing integrated with DOP853."""
    inertia, k = _inertia(), 0.02
    inverse = np.linalg.inv(inertia)
    target_conjugate = TARGET * np.array([1, -1, -1, -1])

    def lyapunov(q, omega):
        return 2 * k * (1 - abs(_product(target_conjugate, q)[0])) + 0.5 * omega @ omega

    for c in (0.0, 0.05):
        law = _law("augmented_quaternion_feedback", k, c)

        def rates(_, x):
            q, omega = x[:4] / np.linalg.norm(x[:4]), x[4:7]
            torque = np.asarray(law(0.0, Measurement(0.0, q, omega, np.zeros(0)), None).torque, dtype=float)
            dw = inverse @ (torque - np.cross(omega, inertia @ omega))
            return np.r_[0.5 * _product(q, np.r_[0.0, omega]), dw, c * omega @ omega]

        axis = np.array([2.0, 1.0, -2.0]) / 3.0
        q0 = _product(TARGET, np.r_[np.cos(np.deg2rad(50)), np.sin(np.deg2rad(50)) * axis])
        omega0 = np.array([0.01, -0.02, 0.005])
        run = solve_ivp(rates, (0.0, 60.0), np.r_[q0, omega0, 0.0], method="DOP853", rtol=1e-10, atol=1e-12)
        x = run.y[:, -1]
        v0, v1 = lyapunov(q0, omega0), lyapunov(x[:4] / np.linalg.norm(x[:4]), x[4:7])
        assert abs(v1 + x[7] - v0) < 1e-8 * v0  # V + ∫ c ωᵀω is conserved
        if c > 0:
            assert x[7] > 0.1 * v0  # and the damping did take energy out


@pytest.mark.parametrize("name", LAWS)
def test_a_gyroscopic_rate_gain_is_accepted_and_placed_as_the_pencil_says(name):
    """``C = c J + G`` with ``G`` skew and large: ``θ̇ᵀ G θ̇ = 0`` (no work), so it is a valid gain
    though its lower triangle alone is indefinite; the poles are those of the pencil, all stable."""
    inertia, k, c = _inertia(), 0.02, 0.1
    gyro = np.array([[0.0, 8.0, -3.0], [-8.0, 0.0, 5.0], [3.0, -5.0, 0.0]])
    damping = c * inertia + gyro
    lower = np.tril(damping) + np.tril(damping, -1).T
    assert np.linalg.eigvalsh(lower).min() < 0  # the lower triangle read alone would look pumping
    expected = _pencil_poles(k * inertia, damping)
    assert expected.real.max() < 0  # energy ½θ̇ᵀJθ̇ + ¼kθᵀJθ falls as c θ̇ᵀJθ̇: asymptotically stable
    law = _law(name, k, damping.tolist())
    _assert_same_poles(_measured_poles(law), expected, 0.1)


@pytest.mark.parametrize("name", LAWS)
def test_a_rate_gain_that_pumps_energy_in_is_refused(name):
    """Lower triangle c J, upper triangle large: ``x ᵀ C x < 0`` for some ``x``, and the closed loop
    it would make has a pole in the right half plane (the pencil's eigenvalues)."""
    inertia, k, c = _inertia(), 0.02, 0.1
    damping = c * inertia + np.triu(np.full((3, 3), 30.0), 1)
    assert np.linalg.eigvalsh(0.5 * (damping + damping.T)).min() < 0
    assert _pencil_poles(k * inertia, damping).real.max() > 0
    with pytest.raises(ValueError, match="kd"):
        _law(name, k, damping.tolist())
