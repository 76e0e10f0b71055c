"""The second-order check's refinement of a degenerate point (``ocp.nlp.second_order``) at its
edges, against hand-worked curvatures.

The refinement tries ``δ / √10, δ / 10, ...`` (δ = 1e-6 ‖H‖∞) down to its floor 1e-10 ‖H‖∞, the
floor itself included, and certifies at the first threshold below every curvature on ``Z`` where the
factorisation passes its accuracy guard at that threshold. Unconstrained quadratics ``f = a x² + b y²``
at 0: ``∇²f = diag(2a, 2b)``, ``‖H‖∞ = 2a``, the curvatures 2a and 2b.
"""
from __future__ import annotations

import math
import re

import numpy as np
import pytest

from ocp.nlp import second_order
from ocp.nlp.second_order import second_order_check
from tests.test_second_order import nlp


def check(f, n=2):
    return second_order_check(nlp(f, n=n), np.zeros(n), np.zeros(n), np.zeros(0))


def test_a_curvature_between_the_floor_and_the_next_threshold_is_certified_at_the_floor():
    """f = x² + 2e-10 y²: ‖H‖∞ = 2, δ = 2e-6, the floor 2e-10 and the threshold before it
    2e-10 √10 = 6.3e-10. The curvature 4e-10 lies between: certified, at the floor exactly."""
    found = check(lambda x: x[0] ** 2 + 2e-10 * x[1] ** 2)
    assert found.certified, found.message
    assert found.curvature_threshold == pytest.approx(2e-10, rel=1e-6)


@pytest.mark.parametrize("b, certified", [(5e-9, False), (5e-7, True)])
def test_the_floor_is_relative_to_the_hessians_scale(b, certified):
    """f = 1000 x² + b y²: ‖H‖∞ = 2000, δ = 2e-3, the floor 1e-10 × 2000 = 2e-7. A curvature 2b of
    1e-8 (5e-12 ‖H‖∞) is below it: degenerate, not certified (an absolute floor of 1e-10 would
    certify it); 1e-6 (5e-10 ‖H‖∞) is above it: certified."""
    found = check(lambda x: 1000.0 * x[0] ** 2 + b * x[1] ** 2)
    assert found.certified is certified, found.message
    if certified:
        assert 2e-7 * (1 - 1e-9) <= found.curvature_threshold < 2 * b
    else:
        assert found.degenerate and found.curvature_threshold == pytest.approx(2e-3)


def test_the_guard_is_applied_at_each_threshold_the_refinement_tries(monkeypatch):
    """The Hessian diag(2, 3e-9) turned by 30° (entries that round): ‖H‖∞ = 2 cos 30° (cos 30° +
    sin 30°) = 2.366 (and 3e-9 less), δ = 2.366e-6; its curvature 3e-9 is certified at δ / 1000 =
    2.4e-9, not before. The guard asks the factorisation's backward error × ‖K‖ to stay below
    threshold / ‖H‖∞ / GUARD at the threshold tried. Measured at δ (a guard no factorisation passes
    says it), it is E; with GUARD set so that δ passes by 30 E, the threshold δ / 100 asks for
    0.3 E and fails: the refinement stops there, and the point is not certified (a guard applied
    at δ alone would certify it)."""
    c, s = math.cos(math.pi / 6), math.sin(math.pi / 6)

    def f(x):
        u, v = c * x[0] - s * x[1], s * x[0] + c * x[1]
        return u ** 2 + 1.5e-9 * v ** 2

    scale = 2.0 * c * (c + s)
    delta = 1e-6 * scale
    control = check(f)  # with the module's guard
    assert control.certified and control.curvature_threshold == pytest.approx(delta / 1000.0, rel=1e-8)
    monkeypatch.setattr(second_order, "GUARD", 1e300)
    refused = check(f).message
    measured = re.search(r"backward error (\S+) × ‖K‖ (\S+) above", refused)
    assert measured, refused
    error = float(measured.group(1)) * float(measured.group(2))
    assert error > 0.0
    monkeypatch.setattr(second_order, "GUARD", delta / scale / (30.0 * error))
    found = check(f)
    assert not found.certified and found.degenerate, found.message
    assert found.curvature_threshold == pytest.approx(delta, rel=1e-8)


def test_a_strongly_active_bound_at_zero_is_near_within_its_tolerance():
    """min x² − y² + y with y ≥ 0, at (0, 1e-9): an interior-point solver stops that far inside its
    bound. The bound's multiplier −1 (strongly active) fixes y: f = x² + y − y² ≥ 0 nearby, a strict
    minimum with curvature 2 along x. A bound at 0 is near within 1e-6 (1 + |0|), not within
    1e-6 × |0| = 0: read as free, y's curvature −2 would show."""
    found = second_order_check(nlp(lambda x: x[0] ** 2 - x[1] ** 2 + x[1]), np.array([0.0, 1e-9]),
                               np.array([0.0, -1.0]), np.zeros(0), lbx=[-1, 0], ubx=[1, 1])
    assert found.certified and found.negative_curvatures == 0, found.message


def test_a_fixed_variables_multiplier_is_not_asked_to_balance_its_gradient():
    """min (x − 1)² + y² with x fixed at 0 (equal bounds), its multiplier reported 0: a fixed
    variable's multiplier takes any value, so the gradient 2 along x is no stationarity residual;
    y is free with curvature 2: certified."""
    found = second_order_check(nlp(lambda x: (x[0] - 1.0) ** 2 + x[1] ** 2), np.zeros(2), np.zeros(2), np.zeros(0),
                               lbx=[0.0, -1.0], ubx=[0.0, 1.0])
    assert found.certified and found.negative_curvatures == 0, found.message
