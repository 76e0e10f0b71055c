"""The truth plant's motor torque noise on a failed wheel: a failed wheel produces no torque, so its
noise is zero (``TruthPlant.draw_noise``'s contract), and the working wheels' noise is the documented
stream, ``numpy.random.default_rng([seed, 2])`` normals times the deviations, drawn for every wheel
(a failure does not shift the other wheels' draws)."""
import numpy as np

from ocp import AttitudeModel, ReactionWheels, SensorNoise, Simulator, Spacecraft
from ocp.dynamics.truth import Truth, TruthPlant
from tests.test_truth_plant import Constant


def test_a_failed_wheel_has_no_torque_noise_and_the_others_keep_their_stream():
    spacecraft = Spacecraft([19.5, 19.0, 12.6], wheels=ReactionWheels(np.eye(3), spin_inertia=0.01, failed=[1]))
    design = AttitudeModel(spacecraft)
    std = np.array([1e-3, 2e-3, 5e-4])
    plant = TruthPlant(design, Truth(wheel_torque_noise=std))
    noise = plant.draw_noise(7, 10)
    normals = np.random.default_rng([7, 2]).standard_normal((10, 3))
    np.testing.assert_array_equal(noise[:, 1], 0.0)
    np.testing.assert_allclose(noise[:, [0, 2]], (normals * std)[:, [0, 2]], rtol=0, atol=1e-18)
    # and in the loop: the failed wheel is given nothing, noise included
    result = Simulator(design, 0.5, plant=plant).run(Constant([0.01, 0.01, 0.0]), np.r_[1.0, 0, 0, 0, 0, 0, 0, 0, 0, 0],
                                                      5.0, noise=SensorNoise(seed=7))
    np.testing.assert_array_equal(result.applied_u[:, 1], 0.0)
