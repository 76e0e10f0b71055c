"""``Simulator.run``'s error for a ``target`` that is not a pair names its type and what was
expected, not the object's repr (a ManeuverProblem's runs to pages of arrays)."""
from __future__ import annotations

import numpy as np
import pytest

from controllers import CONTROLLERS
from ocp import AttitudeModel, Simulator, Spacecraft, quat
from planners import ManeuverProblem

SPACECRAFT = Spacecraft([19.5, 19.0, 12.6])


def run_with(target):
    simulator = Simulator(AttitudeModel(SPACECRAFT), sample_time=1.0)
    simulator.run(CONTROLLERS["none"](), np.concatenate([quat.IDENTITY, np.zeros(3)]), 10.0, target=target)


def test_a_problem_as_target_is_named_by_its_type_with_what_to_pass():
    problem = ManeuverProblem(SPACECRAFT, q0=quat.IDENTITY, omega0=np.zeros(3), qf=quat.from_axis_angle([0, 1, 0], 1.0),
                              duration=100.0, omegaf=np.zeros(3))
    with pytest.raises(ValueError) as caught:
        run_with(problem)
    message = str(caught.value)
    assert message.startswith("target must be a pair (q_f, omega_f)")
    assert "got type ManeuverProblem; pass its (qf, omegaf): target=(problem.qf, problem.omegaf)" in message
    assert "Spacecraft(" not in message and "array(" not in message and "\n" not in message


def test_a_sequence_of_the_wrong_length_is_named_by_its_length():
    with pytest.raises(ValueError, match=r"got a list of 3 items$"):
        run_with([quat.IDENTITY, None, None])
    with pytest.raises(ValueError, match=r"got type ndarray$"):
        run_with(quat.IDENTITY)
