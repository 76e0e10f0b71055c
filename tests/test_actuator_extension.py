"""A new actuator kind joins through the extension point alone (``Actuator`` + ``actuator_kind``).

The kind below, a pair of opposed thrusters on a lever arm, is defined here and nowhere in the
workbench: no workbench file names it. The spacecraft carries it, the model's dynamics, the
saturation (numeric and symbolic), the collocation bounds and a closed-loop run use it, and each
is checked against a value worked out by hand or a closed form.
"""
from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import casadi as ca
import numpy as np
import pytest

from ocp import AttitudeModel, Command, ReactionWheels, Simulator, Spacecraft, quat
from ocp.dynamics import ACTUATOR_KINDS, Actuator, ActuatorModel, actuator_kind
from planners import ManeuverProblem
from planners.collocation.problem import variable_bounds


@dataclass(frozen=True)
class ThrusterPair(Actuator):
    """Two thrusters at ``±arm`` [m] from the centre of mass, thrusting along ``∓direction``
    (positive thrust) or ``±direction`` (negative thrust, the other nozzles): a couple
    ``2 f (arm × direction)`` [N m] for a thrust ``f`` per thruster [N], ``|f| <= max_thrust``."""

    name: ClassVar[str] = "thrusters"
    block: ClassVar[str] = "thrust"
    command: ClassVar[str] = "thrust"

    arm: tuple[float, float, float]
    direction: tuple[float, float, float]
    max_thrust: float

    @property
    def control_size(self) -> int:
        return 1

    def control_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        return np.array([-self.max_thrust]), np.array([self.max_thrust])

    def body_torque(self, u: Any, state: Any, field_body: Any) -> Any:
        return 2.0 * ca.DM(np.cross(self.arm, self.direction)) * u

    def saturate(self, asked: Sequence[float], state: Sequence[float], dt: float) -> tuple[list[float], bool]:
        (f,) = asked
        return [min(max(f, -self.max_thrust), self.max_thrust)], abs(f) >= self.max_thrust

    def saturate_symbolic(self, u: Any, state: Any, dt: Any) -> tuple[Any, list[Any]]:
        return ca.fmin(ca.fmax(u, -self.max_thrust), self.max_thrust), [ca.fabs(u) >= self.max_thrust]


@pytest.fixture
def thrusters() -> Iterator[type[ThrusterPair]]:
    actuator_kind(ThrusterPair)
    yield ThrusterPair
    ACTUATOR_KINDS.pop(ThrusterPair.name)


def _spacecraft(with_wheels: bool) -> Spacecraft:
    pair = ThrusterPair(arm=(0.0, 0.5, 0.0), direction=(0.0, 0.0, 1.0), max_thrust=0.2)
    wheels = ReactionWheels.from_body_axes(max_torque=0.05) if with_wheels else None
    return Spacecraft([2.0, 4.0, 5.0], wheels=wheels, thrusters=pair)


def test_the_model_adds_the_new_kind_after_the_wheels_and_its_torque_to_the_dynamics(thrusters):
    model = AttitudeModel(_spacecraft(with_wheels=True))
    assert model.control_slices == {"wheels": slice(0, 3), "thrust": slice(3, 4)}
    assert (model.nx, model.nu) == (10, 4)
    # Hand-worked: I = diag(2, 4, 5), ω = (0.1, 0.2, 0), h_w = (0, 0, 0.2) on the body axes,
    # g = (0.01, 0, -0.02), f = 0.3 N. H = I ω + h_w = (0.2, 0.8, 0.2), ω × H = (0.04, -0.02, 0.04),
    # -A g = (-0.01, 0, 0.02), the couple 2 f (arm × direction) = 0.6 (0.5, 0, 0) = (0.3, 0, 0):
    # I ω̇ = (0.25, 0.02, -0.02), ω̇ = (0.125, 0.005, -0.004); q̇ = ½ [0, ω] at q = 1; ḣ_w = g.
    x = [1.0, 0.0, 0.0, 0.0, 0.1, 0.2, 0.0, 0.0, 0.0, 0.2]
    u = [0.01, 0.0, -0.02, 0.3]
    xdot = model.rhs(x, u, 0.0, np.zeros(3)).full().ravel()
    expected = [0.0, 0.05, 0.1, 0.0, 0.125, 0.005, -0.004, 0.01, 0.0, -0.02]
    np.testing.assert_allclose(xdot, expected, rtol=0, atol=1e-15)
    torque = model.body_torque(x, u, 0.0).full().ravel()
    np.testing.assert_allclose(torque, [0.29, 0.0, 0.02], rtol=0, atol=1e-15)


def test_the_saturation_clips_the_new_kind_numerically_and_symbolically(thrusters):
    model = AttitudeModel(_spacecraft(with_wheels=True))
    actuators = ActuatorModel(model.spacecraft, model.control_slices, model.nu)
    # 0.3 N asked of a 0.2 N thruster: 0.2 N applied, at its limit; the wheels asked nothing.
    applied, saturated = actuators.apply(Command(other={"thrust": [0.3]}), np.zeros(3), 0.5)
    assert applied.tolist() == [0.0, 0.0, 0.0, 0.2] and saturated
    # -0.1 N is within the limit; a wheel torque of 0.06 N m on a 0.05 N m wheel is clipped.
    command = Command(wheel_torque=np.array([0.06, 0.0, 0.0]), other={"thrust": [-0.1]})
    applied, saturated = actuators.apply(command, np.zeros(3), 0.5)
    assert applied.tolist() == [0.05, 0.0, 0.0, -0.1] and saturated
    applied, saturated = actuators.apply(Command(other={"thrust": [-0.1]}), np.zeros(3), 0.5)
    assert applied.tolist() == [0.0, 0.0, 0.0, -0.1] and not saturated
    # The closed loop's symbolic saturation gives the same.
    u, h = ca.SX.sym("u", 4), ca.SX.sym("h", 3)
    symbolic = ca.Function("sat", [u, h], list(actuators.apply_symbolic(u, h, 0.5)))
    out, flag = symbolic([0.06, 0.0, 0.0, -0.1], np.zeros(3))
    assert out.full().ravel().tolist() == [0.05, 0.0, 0.0, -0.1] and float(flag) == 1.0
    out, flag = symbolic([0.0, 0.0, 0.0, 0.3], np.zeros(3))
    assert out.full().ravel().tolist() == [0.0, 0.0, 0.0, 0.2] and float(flag) == 1.0
    assert actuators.command_vector(command).tolist() == [0.06, 0.0, 0.0, -0.1]


def test_the_collocation_bounds_the_new_kind(thrusters):
    spacecraft = _spacecraft(with_wheels=True)
    problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.IDENTITY, 10.0)
    _, _, u_low, u_high = variable_bounds(problem, None)
    assert u_low.tolist() == [-0.05, -0.05, -0.05, -0.2] and u_high.tolist() == [0.05, 0.05, 0.05, 0.2]


class _ConstantThrust:
    """A controller that asks a constant thrust of the pair."""

    def reset(self, spacecraft: Spacecraft, sample_time: float, target: Any = None) -> None:
        pass

    def __call__(self, t: float, measurement: Any, reference: Any) -> Command:
        return Command(other={"thrust": np.array([0.5])})  # above the 0.2 N limit: 0.2 N applied


def test_a_closed_loop_run_spins_the_body_up_about_the_couple_axis(thrusters):
    # No wheels: the couple (0.2 N: 2 · 0.2 · 0.5 = 0.2 N m) acts about the principal x axis, so
    # from rest ω_x = 0.2 t / 2 and the attitude is a rotation about x by 0.05 t² (closed form).
    model = AttitudeModel(_spacecraft(with_wheels=False))
    result = Simulator(model, 0.5).run(_ConstantThrust(), [1.0, 0, 0, 0, 0, 0, 0], 4.0)
    assert result.saturated.all() and np.all(result.applied_u == 0.2)
    np.testing.assert_allclose(result.omega[:, 0], 0.1 * result.t, rtol=0, atol=1e-12)
    np.testing.assert_allclose(result.omega[:, 1:], 0.0, atol=1e-15)
    expected_q = quat.from_axis_angle([1.0, 0.0, 0.0], 0.05 * result.t[-1] ** 2)
    np.testing.assert_allclose(result.q[-1], expected_q, rtol=0, atol=1e-10)


def test_a_kind_is_refused_under_a_name_that_is_not_registered():
    from ocp import ModelError

    pair = ThrusterPair(arm=(0.0, 0.5, 0.0), direction=(0.0, 0.0, 1.0), max_thrust=0.2)
    with pytest.raises(ModelError, match="thrusters: not a registered actuator kind"):
        Spacecraft([2.0, 4.0, 5.0], thrusters=pair)


def test_a_kind_cannot_take_a_registered_name_or_block(thrusters):
    @dataclass(frozen=True)
    class Impostor(ThrusterPair):
        block: ClassVar[str] = "dipole"
        name: ClassVar[str] = "impostor"

    with pytest.raises(ValueError, match="taken by Magnetorquers"):
        actuator_kind(Impostor)


def test_a_spacecraft_with_only_the_new_kind_is_planned_not_refused(thrusters):
    """The momentum-conservation check (ManeuverProblem.unreachable) knows wheels only: any other
    kind decides nothing there (it read torquers and magnetorquers by name, and refused every slew
    of a thruster-only spacecraft as 'no working actuator'). The couple 2 f (arm × direction) =
    0.2 N m about x, I_x = 2: bang-bang 2 sqrt(θ I_x / u) = 6.3246 s for 1 rad."""
    from planners import PLANNERS, ManeuverProblem

    problem = ManeuverProblem(_spacecraft(with_wheels=False), quat.IDENTITY, np.zeros(3),
                              quat.from_axis_angle([1.0, 0.0, 0.0], 1.0), 20.0, omegaf=np.zeros(3))
    assert problem.unreachable() is None
    reference = PLANNERS["collocation"]({"objective": "min_time"}).plan(problem)
    assert reference.ok, reference.message
    assert reference.duration == pytest.approx(2.0 * np.sqrt(1.0 * 2.0 / 0.2), rel=1e-6)
