"""The certificate's verdicts at their edges (ocp.nlp.certificate.certificate): "first-order" needs
the scaled KKT residual *at most* the tolerance, "first-order, bang-bang" the switching agreement *at
least* the threshold, and both need the first-order evidence; a collocation plan under the
allocation's equalities gives no switching evidence (Pontryagin's sign rule per control does not
hold with equalities among the controls: planners/collocation/certificate.py).

Oracles: the documented rules (docs and docstrings: "at most", "least") applied to evidence built
by hand at the boundary values; a minimum-time plan on a four-wheel pyramid.
"""
from __future__ import annotations

import numpy as np

from ocp import ReactionWheels, Spacecraft, quat
from ocp.nlp.certificate import (
    KKT_TOLERANCE,
    SWITCHING_THRESHOLD,
    KKTResiduals,
    Switching,
    certificate,
)
from planners import PLANNERS, ManeuverProblem


def _kkt(scaled: float) -> KKTResiduals:
    return KKTResiduals(*[scaled] * 8, 1.0)


def test_a_residual_at_the_tolerance_is_first_order():
    assert certificate(_kkt(KKT_TOLERANCE), "strict local minimum")["verdict"] == "certified"
    assert certificate(_kkt(KKT_TOLERANCE), "not checked: big")["verdict"] == "first-order"
    above = float(np.nextafter(KKT_TOLERANCE, 1.0))
    assert certificate(_kkt(above), "strict local minimum")["verdict"] == "not certified"
    assert certificate(_kkt(1e-4), "strict local minimum", kkt_tolerance=1e-4)["verdict"] == "certified"


def test_an_agreement_at_the_threshold_is_bang_bang():
    at = Switching(SWITCHING_THRESHOLD, 0.0, 0.0, 1.0 - SWITCHING_THRESHOLD, 1e-3)
    below = Switching(float(np.nextafter(SWITCHING_THRESHOLD, 0.0)), 0.0, 0.0, 0.1, 1e-3)
    assert certificate(_kkt(1e-9), "not checked: big", at)["verdict"] == "first-order, bang-bang"
    assert certificate(_kkt(1e-9), "not checked: big", below)["verdict"] == "first-order"
    custom = Switching(0.5, 0.0, 0.0, 0.5, 1e-3)
    assert certificate(_kkt(1e-9), "not checked: big", custom, switching_threshold=0.5)["verdict"] == \
        "first-order, bang-bang"


def test_switching_evidence_without_first_order_certifies_nothing():
    bang = Switching(1.0, 0.0, 0.0, 0.0, 1e-3)
    assert certificate(_kkt(1e-3), "not checked: big", bang)["verdict"] == "not certified"
    assert certificate(None, "not checked: no multipliers", bang)["verdict"] == "not certified"


def test_a_plan_under_the_allocations_equalities_gives_no_switching_evidence():
    s = 1.0 / np.sqrt(3.0)
    pyramid = np.array([[1, 1, 1], [-1, 1, 1], [-1, -1, 1], [1, -1, 1]], float).T * s  # four wheels: a null space
    spacecraft = Spacecraft(np.diag([20.0, 17.0, 14.0]), wheels=ReactionWheels(pyramid, max_torque=0.01, max_momentum=0.5))
    problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3),
                              quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), np.radians(30.0)), 90.0, omegaf=np.zeros(3))
    reference = PLANNERS["collocation"]({"objective": "min_time", "intervals": 10}).plan(problem)
    assert reference.ok
    record = reference.stats["certificate"]
    assert record["switching"] is None and record["verdict"] != "first-order, bang-bang", record
