"""Gaps the mutation check found in the eigenaxis bang profiles' budget (planners.eigenaxis).

A slew that starts spinning: the bang profiles start at rest, and the wheels take the body's
momentum at once, ``h_w = h_0 + A⁺ I ω_0`` (the total momentum ``I ω_0 + A h_0`` is conserved). The
oracle is the closed form of a bang-coast-bang about a principal axis with three body-axis wheels
(``A = 1``), worked by hand: ``α = g_max / I_z``; the z wheel holds ``H_z − I_z θ̇`` (``H_z = I_z ω_0z``
is conserved: the rotation is about z), so ``θ̇ <= (h_max + H_z) / I_z``; the x and y wheels hold
the transverse momentum ``H_⊥`` turning in the body (within ``h_max``) and take its gyroscopic
torque ``θ̇ |H_⊥|`` (within ``g_max``, not binding here).
"""
import numpy as np
import pytest

from ocp import ReactionWheels, Spacecraft, quat
from planners import PLANNERS, ManeuverProblem

INERTIA = np.diag([2.0, 2.5, 3.0])
G_MAX, H_MAX = 0.01, 0.05


def bang_coast_bang_time(angle, alpha, w_max):
    """Rest-to-rest minimum time with |θ̈| <= alpha and |θ̇| <= w_max."""
    if angle <= w_max**2 / alpha:
        return 2 * np.sqrt(angle / alpha)
    return angle / w_max + w_max / alpha


@pytest.mark.parametrize("omega0", [[0.0, 0.0, 0.01], [0.015, 0.0, 0.01], [0.0, 0.0, -0.01]])
def test_a_spinning_start_gives_its_momentum_to_the_wheels(omega0):
    omega0 = np.asarray(omega0)
    angle = np.radians(170.0)
    wheels = ReactionWheels(np.eye(3), max_torque=G_MAX, max_momentum=H_MAX)
    problem = ManeuverProblem(Spacecraft(INERTIA, wheels=wheels), quat.IDENTITY, omega0,
                              quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), angle), 300.0, omegaf=np.zeros(3))
    held = INERTIA @ omega0  # the wheels' momenta once the body is stopped (A = 1)
    transverse = np.linalg.norm(held[:2])
    w_max = (H_MAX + held[2]) / INERTIA[2, 2]
    assert transverse <= H_MAX and transverse * w_max < G_MAX  # the x, y wheels: neither bound binds
    expected = bang_coast_bang_time(angle, G_MAX / INERTIA[2, 2], w_max)
    reference = PLANNERS["eigenaxis"]({"profile": "min_time"}).plan(problem)
    assert reference.status == "ok", reference.message
    assert reference.duration == pytest.approx(expected, rel=1e-9)
    assert "capped by the wheels' momentum bound" in reference.message


@pytest.mark.parametrize("degrees, feasible", [(90.0, False), (10.0, True)])
def test_stored_momentum_the_rotation_itself_takes_beyond_the_bound_is_refused(degrees, feasible):
    """Body-axis wheels holding H = [0.04, 0.04, 0] N m s (each within h_max = 0.05), a slew about z:
    I e is along z, so the x and y wheels' momenta do not depend on the rate; they hold H turning in
    the body, H_x(θ) = 0.04 (cos θ + sin θ), 0.0566 N m s at θ = 45 deg: no profile turns 90 deg
    within the bound, while 10 deg (at most 0.0463) is feasible."""
    h0 = np.array([0.04, 0.04, 0.0])
    wheels = ReactionWheels(np.eye(3), max_torque=G_MAX, max_momentum=H_MAX)
    angle = np.radians(degrees)
    theta = np.linspace(0.0, angle, 100001)
    peak = np.max(np.abs(np.stack([h0[0] * np.cos(theta) + h0[1] * np.sin(theta),
                                   -h0[0] * np.sin(theta) + h0[1] * np.cos(theta)])))
    assert (peak <= H_MAX) == feasible
    problem = ManeuverProblem(Spacecraft(INERTIA, wheels=wheels), quat.IDENTITY, np.zeros(3),
                              quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), angle), 300.0, omegaf=np.zeros(3),
                              wheel_momentum0=h0)
    for profile in ("min_time", "trapezoidal"):
        reference = PLANNERS["eigenaxis"]({"profile": profile}).plan(problem)
        if feasible:
            assert reference.status == "ok", reference.message
        else:
            assert reference.status == "infeasible" and "max_momentum" in reference.message, reference.message


def test_positive_root_is_the_largest_rate_within_the_bound(rng):
    """``_positive_root(g, c, b)``: the largest ``w >= 0`` with ``g w² + c w <= b``, against the
    larger root of the quadratic by numpy.roots (or ``b / c`` when g = 0), and the edge cases by hand."""
    from planners.eigenaxis import _positive_root

    for _ in range(50):
        g, c, b = rng.uniform(0.0, 2.0), rng.uniform(0.0, 2.0), rng.uniform(1e-3, 2.0)
        expected = max(np.roots([g, c, -b]).real)
        assert _positive_root(g, c, b) == pytest.approx(expected, rel=1e-12)
        assert _positive_root(0.0, c, b) == pytest.approx(b / c, rel=1e-15)
        assert _positive_root(g, 0.0, b) == pytest.approx(np.sqrt(b / g), rel=1e-12)
    assert _positive_root(0.0, 0.0, 1.0) == np.inf  # nothing grows with the rate
    assert _positive_root(1.0, 1.0, np.inf) == np.inf  # an unlimited actuator caps no rate
    assert _positive_root(1.0, 0.0, 0.0) == 0.0  # a zero bound: only w = 0 (not 0 / 0)
    assert _positive_root(0.0, 1.0, 0.0) == 0.0


def test_smallest_cap_refuses_a_nan_wherever_it_is():
    """Python's ``min`` keeps or drops a NaN by its position; a NaN cap is a bug upstream and is
    refused, first, last or among finite caps."""
    from planners.eigenaxis import _smallest_cap

    assert _smallest_cap() == np.inf
    assert _smallest_cap(np.inf, 2.0, 0.5) == 0.5
    for caps in ((np.nan, 1.0), (1.0, np.nan), (0.3, np.nan, np.inf), (np.nan,)):
        with pytest.raises(AssertionError, match="NaN"):
            _smallest_cap(*caps)
