"""The AEM's segment logic against oracles outside the writer: the standard's segment spans (CCSDS
504.0-B-2, 4.2.2: a segment's useable span lies within its START_TIME .. STOP_TIME, which its data
lines bound, and a reader interpolates only inside a segment) read back from the text, and a rate
known in closed form to be smooth (no jump), whose derivative peaks between two samples."""
import itertools

import numpy as np
import pytest

from scenarios.output.aem import aem_text, rate_jump_starts, read_aem

EPOCH = "2027-03-20T12:00:00Z"


@pytest.mark.parametrize("starts", [[3], [2, 6], [7]])
def test_each_segments_span_is_its_own_data_lines_and_no_segment_reaches_into_a_jump(starts):
    t = np.arange(8) * 0.5
    q = np.tile([1.0, 0.0, 0.0, 0.0], (8, 1))
    omega = np.zeros((8, 3))
    segments = read_aem(aem_text(EPOCH, t, q, omega, object_name="x", segment_starts=starts)).segments
    assert [len(s.epochs) for s in segments] == np.diff([0, *starts, 8]).tolist()
    for segment in segments:
        meta = segment.metadata
        assert meta["START_TIME"] == meta["USEABLE_START_TIME"] == segment.epochs[0]
        assert meta["STOP_TIME"] == meta["USEABLE_STOP_TIME"] == segment.epochs[-1]
    for before, after in itertools.pairwise(segments):  # ISO tags of one format order as text
        assert before.metadata["USEABLE_STOP_TIME"] < after.metadata["USEABLE_START_TIME"]


def test_a_smooth_rate_whose_derivative_peaks_between_samples_is_not_a_jump():
    """ω = A sin(a t), sampled at ±h/2 about the peak of ω̇ = A a cos(a t): the change over the step,
    2 A sin(a h / 2), exceeds h times the derivative at both ends, A a h cos(a h / 2) (by tan x / x,
    1.06 at x = a h / 2 = 0.4), but not twice it; nor twice its neighbouring steps' (the
    estimate without ω̇). Nothing jumps: one segment."""
    a, h, amplitude = 0.8, 1.0, 0.01
    t = np.arange(-3.5, 4.0, h)  # samples at ±h/2 about each peak of cos at t = 0
    omega = np.zeros((t.size, 3))
    omega[:, 2] = amplitude * np.sin(a * t)
    omega_dot = np.zeros((t.size, 3))
    omega_dot[:, 2] = amplitude * a * np.cos(a * t)
    middle = np.searchsorted(t, 0.0)
    change = abs(omega[middle, 2] - omega[middle - 1, 2])
    assert change > 1.05 * h * max(abs(omega_dot[middle, 2]), abs(omega_dot[middle - 1, 2]))
    assert rate_jump_starts(t, omega, omega_dot) == []
    # from the neighbouring steps' quotients (no ω̇): the step about the peak is no jump either (the
    # first and last steps, with one neighbour each, are not asked: a heuristic at the series' ends)
    assert middle not in rate_jump_starts(t, omega, None)
