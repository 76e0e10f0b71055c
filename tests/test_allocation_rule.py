"""One allocation rule: who takes the torque the wheels cannot give, and how the torque is split,
is the same in the controllers' allocation (a closed-loop sample: a law called on a measurement),
in the collocation planner's allocation constraints and in ``Spacecraft.allocation_rows``.

The oracle is written here: the working wheels' minimum-norm torques by ``numpy.linalg.lstsq``,
what they leave, ``r = τ_w − A_w A_w⁺ τ_w``, to the torquers when there are any (all of ``r``),
else to the magnetorquers (the dipole ``B × r / |B|²``, whose torque is the part of ``r`` across
the field), else to nobody; the body-torque Jacobians of the actuators are written by hand.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from controllers.base import Controller
from ocp import Magnetorquers, Measurement, ReactionWheels, Spacecraft, Torquers
from ocp.dynamics.layout import control_layout
from planners import PLANNERS, ManeuverProblem
from planners.collocation.allocation import allocation_constraints, allocation_error

PYRAMID = np.array([[1, 1, 1], [-1, 1, 1], [-1, -1, 1], [1, -1, 1]], float).T / np.sqrt(3)
TWO_SKEWED = np.array([[1.0, 1.0, 0.0], [0.0, 1.0, 1.0]]).T / np.sqrt(2)  # span: a plane, not a body plane
INERTIA = np.array([[20.0, 0.5, -0.3], [0.5, 17.0, 0.4], [-0.3, 0.4, 14.0]])
FIELD = np.array([2.1e-5, -1.3e-5, 3.4e-5])  # T, body axes: along no wheel plane or axis
RNG_SEED = 20261202


def _sc(axes, failed=(), torquers=False, magnetorquers=False) -> Spacecraft:
    return Spacecraft(INERTIA, wheels=ReactionWheels(axes, max_torque=0.05, max_momentum=1.0, failed=failed),
                      torquers=Torquers(0.02) if torquers else None,
                      magnetorquers=Magnetorquers(50.0) if magnetorquers else None)


# name -> (spacecraft, the actuator that takes the residual, stated here, not read from the code)
MIXES = {
    "two wheels alone": (_sc(TWO_SKEWED), None),
    "two wheels + torquers": (_sc(TWO_SKEWED, torquers=True), "torquers"),
    "two wheels + magnetorquers": (_sc(TWO_SKEWED, magnetorquers=True), "magnetorquers"),
    "two wheels + torquers + magnetorquers": (_sc(TWO_SKEWED, torquers=True, magnetorquers=True), "torquers"),
    "pyramid, one failed": (_sc(PYRAMID, failed=[1]), None),
    "pyramid, one failed + torquers + magnetorquers": (_sc(PYRAMID, failed=[1], torquers=True, magnetorquers=True),
                                                       "torquers"),
    "pyramid + torquers": (_sc(PYRAMID, torquers=True), "torquers"),
    "pyramid, two failed + torquers + magnetorquers": (_sc(PYRAMID, failed=[0, 2], torquers=True, magnetorquers=True),
                                                       "torquers"),
    "pyramid, two failed + magnetorquers": (_sc(PYRAMID, failed=[0, 2], magnetorquers=True), "magnetorquers"),
    "no wheels: magnetorquers": (Spacecraft(INERTIA, magnetorquers=Magnetorquers(50.0)), "magnetorquers"),
}


class FixedTorque(Controller):
    """A law asking a fixed torque ``u`` at every sample (the allocation is the base class's)."""

    name = "fixed_torque_for_tests"

    @dataclass(frozen=True)
    class Options:
        pass

    asked = np.zeros(3)

    def __call__(self, t, measurement, reference):
        return self.allocate(self.asked, measurement)


def _skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


BLOCK = {"wheels": "wheels", "torquers": "torquers", "magnetorquers": "dipole"}  # kind -> its block of u


def _jacobians(spacecraft: Spacecraft) -> dict[str, np.ndarray]:
    """Body torque per actuator kind, by hand: wheels −A g, torquers τ, magnetorquers m × B = −[B]× m."""
    by_kind = {"wheels": -spacecraft.wheel_axes, "torquers": np.eye(3), "magnetorquers": -_skew(FIELD)}
    return {actuator.name: by_kind[actuator.name] for actuator in spacecraft.actuators}


def _oracle(spacecraft: Spacecraft, wheel_torque_asked: np.ndarray, sink: str | None) -> dict[str, np.ndarray]:
    """Per actuator, the command the rule gives for the wheels' torque ``τ_w``."""
    commands = {}
    residual = wheel_torque_asked.copy()
    wheels = spacecraft.wheels
    if wheels is not None:
        working = wheels.working
        g = np.zeros(wheels.count)
        if working.any():
            g[working] = -np.linalg.lstsq(wheels.axes[:, working], wheel_torque_asked, rcond=None)[0]  # min norm
        commands["wheels"] = g
        residual = wheel_torque_asked + wheels.axes @ g
    if np.linalg.norm(residual) <= 1e-12 * np.linalg.norm(wheel_torque_asked):
        residual = np.zeros(3)
    for actuator in spacecraft.actuators:
        if actuator.name == "wheels":
            continue
        if actuator.name != sink or not residual.any():
            commands[actuator.name] = np.zeros(3)
        elif sink == "torquers":
            commands[sink] = residual
        else:  # magnetorquers: the dipole across the field whose m × B is r's part across B
            commands[sink] = np.cross(FIELD, residual) / (FIELD @ FIELD)
    return commands


def _measurement(spacecraft: Spacecraft, rng: np.random.Generator) -> Measurement:
    return Measurement(0.0, np.array([1.0, 0.0, 0.0, 0.0]), rng.normal(0.0, 0.02, 3),
                       rng.normal(0.0, 0.1, spacecraft.n_wheels), field_body=FIELD)


@pytest.mark.parametrize("mix", MIXES)
def test_controller_sample_follows_the_rule(mix):
    """A law's command at a sample: the wheels' min-norm torques of ``τ_w = u + ω × A h_w``, the rest
    to the actuator the rule names, nothing to the others."""
    spacecraft, sink = MIXES[mix]
    assert (None if spacecraft.residual_actuator is None else spacecraft.residual_actuator.name) == sink
    slices, _ = control_layout(spacecraft)
    law = FixedTorque()
    law.reset(spacecraft, 1.0, target=(np.array([1.0, 0, 0, 0]), np.zeros(3)))
    rng = np.random.default_rng(RNG_SEED)
    for _ in range(5):
        law.asked = rng.normal(0.0, 0.01, 3)
        measurement = _measurement(spacecraft, rng)
        u = law.command_vector(law(0.0, measurement, None))
        momentum = spacecraft.wheel_axes @ measurement.wheel_momentum
        expected = _oracle(spacecraft, law.asked + np.cross(measurement.omega, momentum), sink)
        for name, command in expected.items():
            np.testing.assert_allclose(u[slices[BLOCK[name]]], command, rtol=1e-10, atol=1e-14 * max(1.0, abs(command).max()),
                                       err_msg=f"{mix}: {name}")


@pytest.mark.parametrize("mix", [name for name, (_, sink) in MIXES.items()
                                 if not (sink == "magnetorquers" and "no wheels" not in name)])
def test_collocation_constraints_give_the_controllers_split(mix):
    """The collocation controls with ``E u = 0``, the failed wheels at 0 (their bounds) and the body
    torque the closed loop realises: one torque per actuator, the oracle's; and the controller's
    command meets ``E u = 0``."""
    spacecraft, sink = MIXES[mix]
    slices, nu = control_layout(spacecraft)
    rows = allocation_constraints(spacecraft)
    rows = np.zeros((0, nu)) if rows is None else rows
    jacobian = np.zeros((3, nu))
    for name, block in _jacobians(spacecraft).items():
        jacobian[:, slices[BLOCK[name]]] = block
    failed = np.zeros((0, nu))
    if spacecraft.wheels is not None:
        failed = np.eye(nu)[slices[BLOCK["wheels"]]][~spacecraft.wheels.working]
    system = np.vstack([rows, failed, jacobian])
    _, singular, right = np.linalg.svd(system)
    null = right[int(np.sum(singular > 1e-9 * singular.max())):]
    for name, block in _jacobians(spacecraft).items():  # the null space moves no actuator's torque
        np.testing.assert_allclose(null[:, slices[BLOCK[name]]] @ block.T, 0.0, atol=1e-9, err_msg=f"{mix}: {name}")
        if name != "magnetorquers":  # nor its command (a dipole along B gives no torque)
            np.testing.assert_allclose(null[:, slices[BLOCK[name]]], 0.0, atol=1e-9, err_msg=f"{mix}: {name}")
    rng = np.random.default_rng(RNG_SEED)
    for _ in range(5):
        asked = rng.normal(0.0, 0.01, 3)
        oracle = _oracle(spacecraft, asked, sink)
        realised = sum(block @ oracle[name] for name, block in _jacobians(spacecraft).items())
        u = np.linalg.lstsq(system, np.concatenate([np.zeros(len(rows) + len(failed)), realised]), rcond=None)[0]
        assert np.linalg.norm(system @ u - np.concatenate([np.zeros(len(rows) + len(failed)), realised])) \
            <= 1e-12 * np.linalg.norm(realised)
        for name, block in _jacobians(spacecraft).items():
            np.testing.assert_allclose(block @ u[slices[BLOCK[name]]], block @ oracle[name], rtol=1e-9,
                                       atol=1e-12 * np.linalg.norm(asked), err_msg=f"{mix}: {name}")
        controller = np.zeros(nu)
        for name, command in oracle.items():
            controller[slices[BLOCK[name]]] = command
        np.testing.assert_allclose(rows @ controller, 0.0, atol=1e-12 * np.linalg.norm(controller))


@pytest.mark.parametrize("mix", MIXES)
def test_allocation_rows_name_the_same_sink(mix):
    """``allocation_rows``: the rows of the residual carry the limits of the rule's actuator (the
    torquers' 0.02 N m), 0 where it is the magnetorquers or nobody; none when the wheels span 3 axes."""
    spacecraft, sink = MIXES[mix]
    matrix, limits = spacecraft.allocation_rows()
    wheels = spacecraft.wheels
    n_wheel_rows = 0 if wheels is None else int(wheels.working.sum())
    span = 0 if wheels is None else np.linalg.matrix_rank(wheels.axes[:, wheels.working])
    assert matrix.shape[0] == n_wheel_rows + (3 if span < 3 else 0)
    if span < 3:
        np.testing.assert_array_equal(limits[n_wheel_rows:], 0.02 if sink == "torquers" else 0.0)


def test_collocation_refuses_magnetorquers_beside_wheels_spanning_two_axes():
    """What the closed loop realises with the residual on the magnetorquers, ``τ − (r·B̂) B̂``, is
    not what a plan with magnetorquer torque in the wheels' span would do: the planner refuses,
    naming why; magnetorquers alone, or beside three working wheels, are planned."""
    spacecraft, _ = MIXES["two wheels + magnetorquers"]
    law = FixedTorque()
    law.reset(spacecraft, 1.0, target=(np.array([1.0, 0, 0, 0]), np.zeros(3)))
    law.asked = np.array([0.0, 0.0, 0.01])
    command = law(0.0, Measurement(0.0, np.array([1.0, 0, 0, 0]), np.zeros(3), np.zeros(2), field_body=FIELD), None)
    given = -spacecraft.wheel_axes @ command.wheel_torque + np.cross(command.dipole, FIELD)
    normal = np.cross(TWO_SKEWED[:, 0], TWO_SKEWED[:, 1])
    residual = (normal @ law.asked) * normal / (normal @ normal)
    np.testing.assert_allclose(given, law.asked - (residual @ FIELD) * FIELD / (FIELD @ FIELD), atol=1e-15)
    assert np.linalg.norm(given - law.asked) > 0.1 * np.linalg.norm(law.asked)  # the loss is not rounding
    for mix in ("two wheels + magnetorquers", "pyramid, two failed + magnetorquers"):
        message = allocation_error(MIXES[mix][0], "collocation")
        assert message is not None and "magnetorquers" in message and "across the field" in message
        problem = ManeuverProblem(MIXES[mix][0], np.array([1.0, 0, 0, 0]), np.zeros(3),
                                  np.array([np.cos(0.2), np.sin(0.2), 0.0, 0.0]), 60.0, omegaf=np.zeros(3))
        refused = PLANNERS["collocation"]({"intervals": 4}).problem_error(problem)
        assert refused is not None and "across the field" in refused
    for mix in ("no wheels: magnetorquers", "pyramid, one failed + torquers + magnetorquers"):
        assert allocation_error(MIXES[mix][0], "collocation") is None
