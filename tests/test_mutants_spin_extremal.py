"""Spin extremals' bookkeeping against oracles of their own: the torque amplitudes are the peaks of
the sampled torque of eq. 31, the attitude cost does not see the sign of the target (the double
cover), and an optimum found with r < 0 is reported as the same extremal with r > 0 (an injected
solver answer, compared with ω*(t) = [v, r sin θ, r cos θ] written out here)."""
from types import SimpleNamespace

import numpy as np
import pytest

import planners.spin_extremal as spin
from ocp import quat

MOMENTS = np.array([19.5, 19.0, 12.6])


@pytest.mark.parametrize(("v", "r", "c"), [(0.2, 0.05, 0.01), (-0.3, 0.02, -0.04), (0.1, 0.08, 0.2)])
def test_torque_amplitudes_are_the_peaks_of_the_torque(v, r, c):
    period = 2 * np.pi / abs(v + c)
    t = np.linspace(0.0, period, 200001)
    peaks = np.max(np.abs(spin.extremal_torque(t, v, r, c, 0.3, MOMENTS)), axis=0)
    np.testing.assert_allclose(spin.torque_amplitudes(v, r, c, MOMENTS), peaks, rtol=1e-8)


def test_the_attitude_cost_is_blind_to_the_sign_of_the_target(rng):
    q, target = quat.random_unit(rng, 5), quat.random_unit(rng)
    np.testing.assert_allclose(spin.attitude_cost(q, -target), spin.attitude_cost(q, target), rtol=1e-14)
    assert spin.attitude_cost(-target, target) == 0.0


def test_an_optimum_with_negative_r_is_the_same_extremal(monkeypatch):
    v, T = 0.2, 150.0
    raw = np.array([-0.03, 0.012, 0.7])  # (r, c, β) as an unbounded solver may return it

    def fake(*_args, **_kwargs):
        return SimpleNamespace(x=raw.copy(), stats=lambda: {})

    monkeypatch.setattr(spin, "solve_multistart", fake)
    planner = spin.SpinExtremalPlanner()
    params, _ = planner._optimise(None, v, T, MOMENTS, quat.IDENTITY)
    assert params.r > 0
    reference = spin.SpinExtremalReference(quat.IDENTITY, v, params, T, MOMENTS, "", {})
    t = np.linspace(0.0, T, 11)
    theta = (v + raw[1]) * t + raw[2]
    np.testing.assert_allclose(reference.omega(t), np.column_stack([np.full_like(t, v), raw[0] * np.sin(theta),
                                                                    raw[0] * np.cos(theta)]), atol=1e-14)
