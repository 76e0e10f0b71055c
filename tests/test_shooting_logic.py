"""Multiple shooting's path constraints hold where it says they do: at the end of every RK4 step, at
that step's time (``positions()``, which the multiplier transfer reads), checked on a body at rest
(it stays at rest: no torque, no environment) against a pointing window that opens between two steps."""
import numpy as np

from ocp import AttitudeModel, Spacecraft, Torquers
from ocp.geometry import PointingConstraint
from ocp.transcription.problem import OptimalControlProblem
from ocp.transcription.shooting import MultipleShooting


def test_path_constraints_are_at_the_ends_of_the_rk4_steps_at_their_times():
    model = AttitudeModel(Spacecraft([2.0, 3.0, 4.0], torquers=Torquers(0.1)))
    # keep the x axis 0.5 rad off inertial x from t = 1.5 s on: broken at rest at the identity
    window = PointingConstraint("keep_out[0]", np.array([1.0, 0.0, 0.0]), True, 0.5, window=(1.5, np.inf))
    problem = OptimalControlProblem(model, cones=(window,))
    shooting = MultipleShooting(intervals=5, substeps=4)
    interval = shooting.interval(problem)
    t0, h = 10.0, 4.0  # steps end at 11, 12, 13, 14 s; with t0 = 0: at 1, 2, 3, 4 s
    rest = np.r_[1.0, 0.0, 0.0, 0.0, np.zeros(3), np.zeros(model.nu)]
    _, at_rest, _ = interval.function(rest, np.zeros(model.nu), t0, h, np.zeros(3))
    assert np.all(np.array(at_rest).ravel() > 0.0)  # inside the window: broken at every step
    _, path, _ = interval.function(rest, np.zeros(model.nu), 0.0, h, np.zeros(3))
    path = np.array(path).ravel()
    _, positions = shooting.positions(problem, interval)
    np.testing.assert_array_equal(positions, [0.25, 0.5, 0.75, 1.0])
    np.testing.assert_array_equal(path == -1.0, [True, False, False, False])  # 1 s before 1.5 s, then inside
    np.testing.assert_allclose(path[1:], np.array(at_rest).ravel()[1:], rtol=1e-14)  # the same attitude
