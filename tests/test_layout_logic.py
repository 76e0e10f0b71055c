"""The vector layouts of ``ocp.dynamics.layout`` against their documented convention: the control
``u = [g (n_w), m (3), τ_t (3)]`` and the reference row ``[q*, ω*, ω̇*, τ*]``; the model's body torque
read through the layout against ``−A g + τ_t`` computed by hand."""
import numpy as np

from ocp import (
    AttitudeModel,
    Command,
    Magnetorquers,
    ReactionWheels,
    Spacecraft,
    Torquers,
)
from ocp.dynamics.actuators import ActuatorModel
from ocp.dynamics.layout import control_layout, reference_rows

PYRAMID = np.array([[1.0, 0.0, 0.0, 1.0], [0.0, 1.0, 0.0, 1.0], [0.0, 0.0, 1.0, 1.0]]) / [1.0, 1.0, 1.0, np.sqrt(3.0)]


def every_actuator():
    """Four wheels, magnetorquers and torquers: three blocks of sizes 4, 3, 3."""
    return Spacecraft([2.0, 3.0, 4.0], wheels=ReactionWheels(PYRAMID), magnetorquers=Magnetorquers(0.2),
                      torquers=Torquers(0.1))


def test_the_control_blocks_follow_one_another_in_the_documented_order():
    slices, nu = control_layout(every_actuator())
    assert slices == {"wheels": slice(0, 4), "dipole": slice(4, 7), "torquers": slice(7, 10)}
    assert nu == 10


def test_each_command_lands_in_its_block_and_the_model_reads_it_there():
    """The actuator model writes each command in its block; the model's body torque from that ``u``
    is ``−A g + τ_t`` (no field model: the dipole gives no torque), A the wheel axes by hand."""
    spacecraft = every_actuator()
    model = AttitudeModel(spacecraft)
    g, m, tau = np.array([0.01, -0.02, 0.03, 0.005]), np.array([0.1, 0.2, -0.1]), np.array([0.05, -0.04, 0.02])
    u = ActuatorModel(spacecraft, model.control_slices, model.nu).command_vector(Command(wheel_torque=g, dipole=m, torque=tau))
    np.testing.assert_array_equal(u, np.concatenate([g, m, tau]))
    x = np.r_[1.0, 0.0, 0.0, 0.0, np.zeros(3), np.zeros(4)]
    torque = np.array(model.body_torque(x, u, 0.0)).ravel()
    np.testing.assert_allclose(torque, -PYRAMID @ g + tau, rtol=0, atol=1e-15)


def test_regulation_rows_hold_the_target_rate_in_the_rate_columns():
    """Without a reference: ``[q_f, ω_f, 0, 0]`` on every row (the rows' documented layout)."""
    q_f, omega_f = np.array([0.5, 0.5, 0.5, 0.5]), np.array([0.01, -0.02, 0.03])
    rows = reference_rows(None, [0.0, 1.0, 2.5], target=(q_f, omega_f))
    assert rows.shape == (3, 13)
    np.testing.assert_array_equal(rows, np.tile(np.r_[q_f, omega_f, np.zeros(6)], (3, 1)))
    free = reference_rows(None, 0.0, target=(None, omega_f))  # a free final attitude: q* zero
    np.testing.assert_array_equal(free, np.r_[np.zeros(4), omega_f, np.zeros(6)][None, :])
