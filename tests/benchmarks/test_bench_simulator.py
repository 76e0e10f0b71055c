"""Simulator timing. Target (issue 2): a 200 s closed loop, 1 s samples, three wheels and a
simple PD law, at most 50 ms median after the first call. Run: pytest tests/benchmarks"""
import numpy as np

from ocp import AttitudeModel, ReactionWheels, Simulator, Spacecraft, quat
from tests.conftest import WheelPD


def test_closed_loop_200_s(benchmark):
    spacecraft = Spacecraft([19.5, 19.0, 12.6], wheels=ReactionWheels.from_body_axes(max_torque=0.1))
    simulator = Simulator(AttitudeModel(spacecraft), sample_time=1.0)
    controller = WheelPD(quat.from_axis_angle([0, 1, 0], 1.0), kp=0.05, kd=0.3)
    x0 = np.r_[quat.IDENTITY, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    simulator.run(controller, x0, 200.0)  # first call
    result = benchmark(simulator.run, controller, x0, 200.0)
    assert result.t[-1] == 200.0
