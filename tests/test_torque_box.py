"""``Spacecraft.body_torque_limit``, the per-axis box the controllers' allocation realises at every
corner, and its consumers: the co-state steering torque and the limit lines of the run figures.

The numbers are derived here. A four-wheel pyramid at elevation β (axes ``(c cos φ, c sin φ, s)``,
``φ = 45°, 135°, 225°, 315°``, ``c = cos β``, ``s = sin β``) has ``A Aᵀ = diag(2c², 2c², 4s²)``, so
the min-norm allocation of ``τ`` gives wheel ``i`` the torque
``(cos φ_i τx + sin φ_i τy) / (2c) + τz / (4s)``:

* along body x alone each wheel carries ``|cos φ_i| τx / (2c) = τx / (2√2 c)``: the largest torque
  along x is ``2√2 c g_max`` (β = 30°: ``√6 g_max``);
* at a corner ``(±b, ±b, ±b)`` of a cube the worst wheel carries ``b (1/(√2 c) + 1/(4s))``, and
  every wheel's row is the same, so the largest cube is ``g_max / (1/(√2 c) + 1/(4s))`` and no
  axis can grow beyond it (β = 30°: ``0.7596 g_max``).
"""
from __future__ import annotations

import itertools

import numpy as np
import pytest

from ocp import Magnetorquers, Measurement, ReactionWheels, Spacecraft, Torquers, quat
from planners import PLANNERS, ManeuverProblem
from planners.costate.tpbvp import FORMS
from scenarios.output.plot_data import WHEELS_TORQUE_NOTE
from scenarios.output.plots import RowFigure
from scenarios.output.report.figures import _torque_limit_lines
from tests.test_allocation_rule import FixedTorque

G_MAX = 0.01
BETA = np.deg2rad(30.0)
C, S = np.cos(BETA), np.sin(BETA)
PHI = np.deg2rad([45.0, 135.0, 225.0, 315.0])
PYRAMID_30 = np.vstack([C * np.cos(PHI), C * np.sin(PHI), S * np.ones(4)])
CUBE = G_MAX / (1 / (np.sqrt(2) * C) + 1 / (4 * S))  # 0.0075962 N m
ALONG_X = 2 * np.sqrt(2) * C * G_MAX  # sqrt(6) g_max = 0.0244949 N m
INERTIA = np.diag([3.0, 4.0, 5.0])


def _pyramid() -> Spacecraft:
    return Spacecraft(INERTIA, wheels=ReactionWheels(PYRAMID_30, max_torque=G_MAX))


def test_closed_forms_of_the_30_degree_pyramid():
    assert ALONG_X == pytest.approx(np.sqrt(6) * G_MAX, rel=1e-15)
    pinv = np.linalg.pinv(PYRAMID_30)
    corners = np.array(list(itertools.product([-1.0, 1.0], repeat=3)))
    assert np.max(np.abs(corners * CUBE @ pinv.T)) == pytest.approx(G_MAX, rel=1e-12)  # every corner, tight
    assert np.max(np.abs(pinv @ [ALONG_X, 0, 0])) == pytest.approx(G_MAX, rel=1e-12)


def test_pyramid_box_is_the_largest_cube_and_conservative_along_an_axis():
    pyramid = _pyramid()
    np.testing.assert_allclose(pyramid.body_torque_limit(), CUBE, rtol=1e-7)  # a linear programme's optimum
    assert pyramid.torque_along([1, 0, 0]) == pytest.approx(ALONG_X, rel=1e-12)
    assert pyramid.torque_along([1, 0, 0]) > 3.2 * pyramid.body_torque_limit()[0]
    assert not pyramid.torque_box_is_exact()


def test_torquers_beside_wheels_count_only_where_the_allocation_asks_them():
    """Three body-axis wheels: the allocation never asks the torquers, so the box is the wheels'
    (it was their sum, 0.03 N m, which the closed loop does not give); two wheels: the torquers
    give z alone."""
    three = Spacecraft(INERTIA, wheels=ReactionWheels.from_body_axes(max_torque=G_MAX), torquers=Torquers(0.02))
    np.testing.assert_array_equal(three.body_torque_limit(), [G_MAX] * 3)
    assert three.torque_box_is_exact()
    law = FixedTorque()
    law.reset(three, 1.0, target=(np.array([1.0, 0, 0, 0]), np.zeros(3)))
    law.asked = np.array([1.5 * G_MAX, 0.0, 0.0])  # within the old sum, beyond the wheels
    command = law(0.0, Measurement(0.0, np.array([1.0, 0, 0, 0]), np.zeros(3), np.zeros(3)), None)
    assert command.torque is None and abs(command.wheel_torque[0]) == pytest.approx(1.5 * G_MAX)
    two = Spacecraft(INERTIA, wheels=ReactionWheels.from_body_axes(2, max_torque=G_MAX), torquers=Torquers(0.02))
    np.testing.assert_array_equal(two.body_torque_limit(), [G_MAX, G_MAX, 0.02])
    assert two.torque_box_is_exact()
    # magnetorquers give no box (their torque depends on the field): the axis the wheels miss is 0
    np.testing.assert_array_equal(Spacecraft(INERTIA, wheels=ReactionWheels.from_body_axes(2, max_torque=G_MAX),
                                             magnetorquers=Magnetorquers(1.0)).body_torque_limit(), [G_MAX, G_MAX, 0.0])
    np.testing.assert_array_equal(Spacecraft(INERTIA, torquers=Torquers([0.62, 1.0, 1.0])).body_torque_limit(),
                                  [0.62, 1.0, 1.0])


def test_pyramid_with_two_failed_wheels_gives_z():
    """Wheels 1 and 3 of the 45-deg-azimuth pyramid left: ``a1 + a3 = (0, 0, 2s)``, so z gets
    ``2 s g_max`` and x, y nothing alone (their directions need the failed wheels)."""
    for elevation in (BETA, np.arcsin(1 / np.sqrt(3))):  # 30 deg; the (±1, ±1, 1)/√3 pyramid, whose
        c, s = np.cos(elevation), np.sin(elevation)       # projector leaves rounding where zeros are
        axes = np.vstack([c * np.cos(PHI), c * np.sin(PHI), s * np.ones(4)])
        failed = Spacecraft(INERTIA, wheels=ReactionWheels(axes, max_torque=G_MAX, failed=[0, 2]))
        assert failed.torque_along([0, 0, 1]) == pytest.approx(2 * s * G_MAX, rel=1e-12)
        np.testing.assert_allclose(failed.body_torque_limit(), [0.0, 0.0, 2 * s * G_MAX], rtol=1e-12)


def test_costate_steering_torque_defaults_to_the_box():
    """``M_c = diag(τ) W u``: the default τ is the box, whatever the direction u turns to it stays
    within what the allocation gives."""
    for spacecraft, expected in ((_pyramid(), [CUBE] * 3),
                                 (Spacecraft(INERTIA, wheels=ReactionWheels.from_body_axes(max_torque=G_MAX),
                                             torquers=Torquers(0.02)), [G_MAX] * 3)):
        problem = ManeuverProblem(spacecraft, np.array([1.0, 0, 0, 0]), np.zeros(3), None, 10.0,
                                  omegaf=np.array([0.01, 0.0, 0.0]))
        planner = PLANNERS["costate_tpbvp"]({"objective": "rate_acquisition", "weighting": [0.5, 1.0, 1.0]})
        system = FORMS["rate_acquisition"](problem, planner.options)
        np.testing.assert_allclose(system.torque_map, np.diag(expected) @ np.diag([0.5, 1.0, 1.0]), rtol=1e-7)
        rng = np.random.default_rng(7)
        directions = rng.normal(size=(200, 3))
        torques = (directions / np.linalg.norm(directions, axis=1, keepdims=True)) @ system.torque_map.T
        wheels = spacecraft.wheels
        assert np.max(np.abs(torques @ np.linalg.pinv(wheels.axes).T)) <= G_MAX * (1 + 1e-7)


def test_figure_limit_lines_say_conservative_where_the_box_is_not_the_set():
    (level, name, colour), = _torque_limit_lines(_pyramid())
    assert level == pytest.approx(CUBE, rel=1e-7) and "conservative" in name and colour is None
    (level, name, _), = _torque_limit_lines(Spacecraft(INERTIA, wheels=ReactionWheels.from_body_axes(max_torque=0.1)))
    assert level == 0.1 and name == "limit ±0.1 N m" + WHEELS_TORQUE_NOTE
    lines = _torque_limit_lines(Spacecraft(INERTIA, wheels=ReactionWheels.from_body_axes(2, max_torque=G_MAX),
                                           torquers=Torquers(0.02)))
    assert [(level, name) for level, name, _ in lines] == [
        (G_MAX, "τx limit ±0.01" + WHEELS_TORQUE_NOTE), (G_MAX, "τy limit ±0.01" + WHEELS_TORQUE_NOTE),
        (0.02, "τz limit ±0.02" + WHEELS_TORQUE_NOTE)]


def test_the_torque_limit_label_says_it_does_not_bound_the_wheels_reference():
    """With three body-axis wheels (box exact), a non-principal inertia and a minimum-time eigenaxis
    slew from rest, the reference's rigid-body torque I ω̇ + ω × I ω crosses the line (1.045, 0.888,
    1.142 x) while the wheels' torque I ω̇ + ω × H (H = 0) stays within it: the label says the line is
    the solid curves' only. With torquers alone the two torques are one, within the line: no note."""
    inertia = np.array([[20.0, 1.5, -1.0], [1.5, 17.0, 0.8], [-1.0, 0.8, 14.0]])
    axis = np.array([0.6, -0.3, 0.74]) / np.linalg.norm([0.6, -0.3, 0.74])
    for spacecraft, wheels in ((Spacecraft(inertia, wheels=ReactionWheels.from_body_axes(max_torque=0.05,
                                                                                          max_momentum=5.0)), True),
                               (Spacecraft(inertia, torquers=Torquers(0.05)), False)):
        problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.from_axis_angle(axis, np.radians(150)),
                                  400.0, omegaf=np.zeros(3))
        reference = PLANNERS["eigenaxis"]({"profile": "min_time"}).plan(problem)
        assert reference.status == "ok", reference.message
        t = np.unique(np.concatenate([np.linspace(0.0, reference.duration, 20001),
                                      np.asarray(reference.breakpoints) + 1e-9]))
        sample = reference.sample(np.minimum(t, reference.duration))
        rigid = sample.omega_dot @ inertia.T + np.cross(sample.omega, sample.omega @ inertia.T)
        (level, name, _), = _torque_limit_lines(spacecraft)
        assert level == 0.05
        if wheels:  # H = 0: the wheels give I ω̇, within the line; the reference's torque is not
            assert np.max(np.abs(sample.omega_dot @ inertia.T)) <= 0.05 * (1 + 1e-9)
            assert np.max(np.abs(rigid)) / 0.05 == pytest.approx(1.142, abs=1e-3)
            assert name == "limit ±0.05 N m" + WHEELS_TORQUE_NOTE and "solid only" in name
        else:
            assert np.max(np.abs(rigid)) <= 0.05 * (1 + 1e-6)
            assert name == "limit ±0.05 N m"
        figure = RowFigure(3 if wheels else 0, True, True, limited=(("torque", True),))
        labels = [line.get_label().replace("\n", " ") for line in figure.panels["torque"].get_lines()]
        assert ("±limit" + WHEELS_TORQUE_NOTE if wheels else "±limit") in labels


def test_a_row_figure_names_a_conservative_box_as_such():
    """A tester saw a pyramid's unsaturated x torque (0.0065 N m) above the dotted "±limit" line
    (0.0039 N m): the line is the box the wheels give on all axes at once, the largest cube inside
    the realised set, and along one axis they give more. The legend must say so; the body-axis
    wheels' line is the whole set and keeps its "±limit"."""
    from types import SimpleNamespace

    from scenarios.output.plot_data import row_series

    skewed = Spacecraft(np.diag([0.3, 0.32, 0.14]), wheels=ReactionWheels(
        np.array([[1.0, 0.6, 0.0], [0.0, 0.8, 0.0], [0.0, 0.0, 1.0]]), max_torque=0.004, max_momentum=0.03))
    body = Spacecraft(np.diag([0.3, 0.32, 0.14]), wheels=ReactionWheels(np.eye(3), max_torque=0.004, max_momentum=0.03))
    # the oracle: along x the skewed wheels give more than the box's x bound (wheel 2 adds 0.6 of its torque)
    assert skewed.torque_along([1, 0, 0]) > skewed.body_torque_limit()[0] * (1 + 1e-6)
    assert body.torque_along([1, 0, 0]) == pytest.approx(body.body_torque_limit()[0], rel=1e-9)
    t = np.linspace(0.0, 10.0, 11)
    x = np.hstack([np.tile([1.0, 0, 0, 0], (11, 1)), np.zeros((11, 6))])
    simulation = SimpleNamespace(t=t, x=x, q=x[:, 0:4], omega=x[:, 4:7], wheel_momentum=x[:, 7:],
                                 applied_torque=np.zeros((10, 3)), applied_u=np.zeros((10, 3)))
    row = SimpleNamespace(label="r", planner="eigenaxis", controller="c", simulation=simulation, reference=None)
    labels = {}
    for name, spacecraft in (("skewed", skewed), ("body", body)):
        shape = row_series(row, quat.IDENTITY, spacecraft).shape
        figure = RowFigure(*shape)
        labels[name] = " ".join(line.get_label().replace("\n", " ") for line in figure.panels["torque"].get_lines())
    assert "conservative" in labels["skewed"] and "±box on all axes at once" in labels["skewed"], labels
    assert "conservative" not in labels["body"] and "±limit" in labels["body"], labels
