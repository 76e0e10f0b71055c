"""How ``collocation`` imposes its requirements tighter than stated, against the rules its docs give
(``planners.collocation.requirements``), worked by hand: a broken cone is tightened by 1.5 times its
violation (reported in degrees, imposed in radians) plus ``POINTING_STEP``; a broken bound's imposed
value is divided by ``1 + 1.5 v + BOUND_STEP``; a window is widened by one mesh interval, or by half the
distance to the run's end when nearer, so that an end the window leaves out stays out."""
from types import SimpleNamespace

import numpy as np
import pytest

from ocp.geometry import PointingConstraint
from planners.collocation.requirements import (
    BOUND_STEP,
    POINTING_STEP,
    DenseCheck,
    Requirements,
    Tightening,
    _saturated_within,
    imposed_pointing,
)


def cone(name, keep_out=True, angle=0.5, window=(0.0, np.inf)):
    return PointingConstraint(name, np.array([1.0, 0.0, 0.0]), keep_out, angle, window=window)


def test_a_broken_cone_is_tightened_by_its_violation_in_radians_and_the_others_are_kept():
    requirements = Requirements((cone("keep_out[0]"), cone("keep_in[0]", keep_out=False), cone("star")), max_rate=0.1,
                                actuator_margin=0.1)
    before = Tightening((0.01, 0.02, 0.03), rate=0.05, actuators=0.1)
    check = DenseCheck({"keep_out[0]": -2.0, "keep_in[0]": 1.0, "star": -0.4},
                       {"keep_out[0]": 2.0, "star": 0.4, "rate": 0.02, "actuators.wheels.state": 0.01}, 100)
    after = before.after(check, requirements)
    assert after.pointing == pytest.approx((0.01 + 1.5 * 2.0 * np.pi / 180 + POINTING_STEP, 0.02,
                                            0.03 + 1.5 * 0.4 * np.pi / 180 + POINTING_STEP), rel=1e-14)
    # the imposed bound (1 - taken) of the limit divided by 1 + 1.5 v + BOUND_STEP
    assert 1.0 - after.rate == pytest.approx(0.95 / (1.0 + 0.03 + BOUND_STEP), rel=1e-14)
    assert 1.0 - after.actuators == pytest.approx(0.9 / (1.0 + 0.015 + BOUND_STEP), rel=1e-14)
    unchanged = before.after(DenseCheck({}, {}, 100), requirements)
    assert unchanged == before


def test_a_window_is_widened_by_one_interval_or_half_the_distance_to_the_run_s_end():
    duration, interval = 100.0, 4.0
    requirements = Requirements((cone("wide", window=(20.0, 60.0)), cone("near", window=(3.0, 98.0)),
                                 cone("whole", window=(0.0, np.inf))))
    tightening = Tightening((0.01, 0.0, 0.02))
    wide, near, whole = imposed_pointing(requirements, tightening, interval, duration)
    assert wide.window == (16.0, 64.0) and wide.angle == pytest.approx(0.51, rel=1e-15)
    assert near.window == (1.5, 99.0)  # 3 s and 2 s from the ends: half of each, t = 0 and T stay out
    assert near.window[0] > 0.0 and near.window[1] < duration
    assert whole.window == (0.0, np.inf) and whole.angle == pytest.approx(0.52, rel=1e-15)
    free = imposed_pointing(requirements, tightening, None, duration)  # a free final time: as stated
    assert [c.window for c in free] == [(20.0, 60.0), (3.0, 98.0), (0.0, np.inf)]


def test_the_first_solve_takes_the_cone_margin_and_the_rate_bound_s_share_only():
    requirements = Requirements((cone("a"), cone("b")), max_rate=0.2, actuator_margin=0.1)
    first = Tightening.initial(requirements, 0.03, rate_bound=0.15)
    assert first == Tightening((0.03, 0.03), rate=pytest.approx(0.25, rel=1e-15), actuators=0.0)
    assert Tightening.initial(requirements, 0.03).rate == 0.0  # the requirement's own bound
    assert Tightening.initial(requirements, 0.03, rate_bound=0.3).rate == 0.0  # never loosened


def test_controls_saturated_within_their_limits_on_either_side_only():
    """The controls lie between the lower and the upper saturation bound: within a limit only when
    the larger magnitude of the two is (an unbounded or zero limit is not read)."""
    limits = np.array([1.0, 1.0, np.inf, 0.0])

    def within(low, high):
        return _saturated_within(SimpleNamespace(control_bounds=(np.array(low), np.array(high))), slice(0, 4), limits)

    assert within([-1.0, -0.5, -9.0, -9.0], [0.5, 1.0, 9.0, 9.0])
    assert not within([-1.2, -0.5, 0.0, 0.0], [0.5, 0.5, 0.0, 0.0])  # the lower bound beyond the limit
    assert not within([-0.5, -0.5, 0.0, 0.0], [0.5, 1.2, 0.0, 0.0])
    assert not _saturated_within(SimpleNamespace(control_bounds=None), slice(0, 4), limits)
