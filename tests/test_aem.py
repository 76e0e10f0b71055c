"""CCSDS Attitude Ephemeris Messages (scenarios.output.aem): the KVN text, its numbers, its time tags
and its quaternion convention, checked against CCSDS 504.0-B-2 as written (annex F2's matrix, annex
G's example, hand-worked leap-second and time-scale values) and against an independent, maintained
reader (``ccsds-ndm-py``, the ``test`` extra; those checks skip without it)."""
import datetime
import math
import re

import numpy as np
import pytest

from scenarios.errors import ScenarioError
from scenarios.output.aem import aem_text, format_number, read_aem, time_tags

EPOCH = "2027-03-20T12:00:00Z"


def independent():
    """The maintained reader, installed for the tests only."""
    return pytest.importorskip("ccsds_ndm", reason="ccsds-ndm-py (the `test` extra) reads AEMs independently")


def m_ba(q1, q2, q3, qc):
    """CCSDS 504.0-B-2 annex F2: the matrix with X_B = M_BA X_A, typed from the standard."""
    return np.array([
        [q1**2 - q2**2 - q3**2 + qc**2, 2 * (q1 * q2 + q3 * qc), 2 * (q1 * q3 - q2 * qc)],
        [2 * (q1 * q2 - q3 * qc), -q1**2 + q2**2 - q3**2 + qc**2, 2 * (q2 * q3 + q1 * qc)],
        [2 * (q1 * q3 + q2 * qc), 2 * (q2 * q3 - q1 * qc), -q1**2 - q2**2 + q3**2 + qc**2]])


def smooth_history(n=200, seed=3):
    """A smooth attitude history (scalar first, no sign flips) and body rate [rad/s]: a random walk
    of small rotations, so the samples are neither trivial nor aligned with the axes."""
    rng = np.random.default_rng(seed)
    t = np.cumsum(rng.uniform(0.05, 0.5, n)) - 0.05
    q = np.empty((n, 4))
    q[0] = rng.normal(size=4)
    q[0] /= np.linalg.norm(q[0])
    for k in range(1, n):
        nxt = q[k - 1] + 0.05 * rng.normal(size=4)
        q[k] = nxt / np.linalg.norm(nxt)
    omega = rng.normal(scale=0.02, size=(n, 3))
    return t, q, omega


def test_round_trip_through_its_own_reader_gives_the_quaternions_and_rates_to_1e_12():
    t, q, omega = smooth_history()
    assert np.all(np.sum(q[1:] * q[:-1], axis=1) > 0)  # no sign flip for the writer to remove
    message = read_aem(aem_text(EPOCH, t, q, omega, object_name="test sat"))
    segment, = message.segments
    assert message.header["CCSDS_AEM_VERS"] == "2.0"
    assert np.max(np.abs(segment.quaternions() - q)) < 1e-12
    assert np.max(np.abs(np.radians(segment.values[:, 4:]) - omega)) < 1e-12
    assert segment.epochs == time_tags(EPOCH, t)


def test_the_independent_reader_reads_the_same_quaternions_times_and_metadata():
    ndm = independent()
    t, q, omega = smooth_history(seed=8)
    text = aem_text(EPOCH, t, q, omega, object_name="test sat", object_id="2027-012A", originator="esa")
    message = ndm.from_str(text)
    message.validate()
    segment, = message.segments
    meta = segment.metadata
    assert (meta.ref_frame_a, meta.ref_frame_b, meta.time_system) == ("GCRF", "SC_BODY_1", "UTC")
    assert (meta.attitude_type, meta.angvel_frame, meta.object_id) == ("QUATERNION/ANGVEL", "SC_BODY_1", "2027-012A")
    data = segment.data.attitude_states_numpy
    q_read = np.column_stack([data[:, 3], data[:, :3]])  # Q1 Q2 Q3 QC -> scalar first
    assert np.max(np.abs(q_read - q)) < 1e-12
    assert np.max(np.abs(np.radians(data[:, 4:]) - omega)) < 1e-12
    # the first and the last time tag: 2027-03-20T12:00:00Z plus t, worked out by hand from t's values
    first = datetime.datetime(2027, 3, 20, 12) + datetime.timedelta(seconds=float(t[0]))
    assert segment.data.attitude_states_epochs[0].startswith(first.strftime("%Y-%m-%dT%H:%M:%S"))
    assert meta.start_time == segment.data.attitude_states_epochs[0]
    assert meta.stop_time == segment.data.attitude_states_epochs[-1]


def test_the_quaternion_is_from_the_inertial_frame_to_the_body_as_annex_f_defines_it():
    ndm = independent()
    # slewbench's q for the body turned +90 deg about inertial z: the body x axis lies along inertial y
    quarter = [math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4)]
    # 120 deg about (1, 1, 1): body x along inertial y, body y along inertial z, body z along inertial x
    cyclic = [0.5, 0.5, 0.5, 0.5]
    text = aem_text(EPOCH, [0.0, 1.0], [quarter, cyclic], object_name="x")
    data = ndm.from_str(text).segments[0].data.attitude_states_numpy
    # annex F2.2: frame B is frame A turned +90 deg about Z; X_A = [1, 0, 0] has X_B = [0, -1, 0]
    m = m_ba(*data[0])
    assert np.allclose(m @ [1, 0, 0], [0, -1, 0], atol=1e-15)
    assert np.allclose(m @ [0, 1, 0], [1, 0, 0], atol=1e-15)  # inertial y is the body x axis
    m = m_ba(*data[1])
    for inertial, body in (([0, 1, 0], [1, 0, 0]), ([0, 0, 1], [0, 1, 0]), ([1, 0, 0], [0, 0, 1])):
        assert np.allclose(m @ inertial, body, atol=1e-15)


def test_a_leap_second_is_written_23_59_60_and_the_other_time_systems_by_their_offsets():
    epoch = "2016-12-31T23:59:58Z"  # TAI - UTC went from 36 s to 37 s at the end of this day
    t = [0.0, 1.0, 2.0, 3.0, 3.25]
    assert time_tags(epoch, t, "UTC") == ["2016-12-31T23:59:58.000000000", "2016-12-31T23:59:59.000000000",
                                          "2016-12-31T23:59:60.000000000", "2017-01-01T00:00:00.000000000",
                                          "2017-01-01T00:00:00.250000000"]
    assert time_tags(epoch, t[:2], "TAI") == ["2017-01-01T00:00:34.000000000", "2017-01-01T00:00:35.000000000"]
    assert time_tags(epoch, t[:1], "TT") == ["2017-01-01T00:01:06.184000000"]  # TT = TAI + 32.184 s
    # TDB - TT from the series' leading terms (Explanatory Supplement): 1.657 ms sin g + 0.014 ms sin 2g
    tt_jd = 2457754.5 + 66.184 / 86400.0
    g = math.radians(357.53 + 0.98560028 * (tt_jd - 2451545.0))
    expected = 66.184 + 0.001657 * math.sin(g) + 0.000014 * math.sin(2 * g)
    tdb = time_tags(epoch, t[:1], "TDB")[0]
    assert tdb.startswith("2017-01-01T00:01:")
    assert abs(float(tdb[-12:]) + 60.0 - expected) < 3e-5


def test_a_leap_second_inside_a_run_reads_back_in_the_independent_reader():
    ndm = independent()
    q = np.tile([1.0, 0.0, 0.0, 0.0], (4, 1))
    message = ndm.from_str(aem_text("2016-12-31T23:59:59Z", [0.0, 1.0, 2.0, 3.0], q, object_name="x"))
    message.validate()
    assert message.segments[0].data.attitude_states_epochs[1] == "2016-12-31T23:59:60.000000000"


def test_numbers_have_16_significant_digits_and_no_negative_zero():
    assert format_number(-0.0) == "0.000000000000000E+00"
    assert format_number(1.0 / 3.0) == "3.333333333333333E-01"
    assert format_number(-123456.789) == "-1.234567890000000E+05"
    with pytest.raises(ValueError):
        format_number(float("nan"))
    t, q, omega = smooth_history(n=30)
    text = aem_text(EPOCH, t, -q, omega, object_name="x")
    data = text[text.index("DATA_START") + len("DATA_START"):text.index("DATA_STOP")].split()
    numbers = [item for item in data if "T" not in item]
    assert len(numbers) == 30 * 7
    # CCSDS 504.0-B-2 6.8.4.2: a mantissa of at most 16 digits with its point second
    assert all(re.fullmatch(r"-?\d\.\d{15}E[+-]\d\d", item) for item in numbers)
    assert all(len(line) <= 254 for line in text.splitlines())  # 6.6.1


def test_a_series_with_sign_jumps_is_written_continuous_and_the_same_attitudes():
    t, q, omega = smooth_history(n=50, seed=5)
    flipped = q.copy()
    flipped[10:20] *= -1.0
    flipped[33] *= -1.0
    read = read_aem(aem_text(EPOCH, t, flipped, omega, object_name="x")).segments[0].quaternions()
    assert np.all(np.sum(read[1:] * read[:-1], axis=1) > 0)
    assert np.max(np.abs(read - q)) < 1e-12  # the first sample's sign kept, the rest follow it


def test_no_epoch_is_refused_naming_epoch_and_bad_series_are_refused():
    t, q, omega = smooth_history(n=5)
    with pytest.raises(ScenarioError, match="epoch"):
        aem_text(None, t, q, omega, object_name="x")
    with pytest.raises(ValueError, match="non-finite"):
        aem_text(EPOCH, t, np.where(np.arange(20).reshape(5, 4) == 7, np.nan, q), object_name="x")
    with pytest.raises(ValueError, match="increase"):
        aem_text(EPOCH, t[::-1], q, object_name="x")
    with pytest.raises(ValueError, match="two samples"):
        aem_text(EPOCH, t[:1], q[:1], object_name="x")


# CCSDS 504.0-B-2 annex G, figure G-4 (the lines "< intervening data records omitted here >" left out)
ANNEX_G4 = """CCSDS_AEM_VERS = 2.0
CREATION_DATE = 2002-11-04T17:22:31
ORIGINATOR    = NASA/JPL
MESSAGE_ID    = A701523

META_START
COMMENT This file was produced by M.R. Somebody, MSOO NAV/JPL.
COMMENT It is to be used for attitude reconstruction only. The relative accuracy of these
COMMENT attitudes is 0.1 degrees per axis.
OBJECT_NAME       = MARS_GLOBAL_SURVEYOR
OBJECT_ID         = 1996-062A
CENTER_NAME       = MARS BARYCENTER
REF_FRAME_A         = EME2000
REF_FRAME_B         = SC_BODY_1
TIME_SYSTEM       = UTC
START_TIME        = 1996-11-28T21:29:07.2555
USEABLE_START_TIME = 1996-11-28T22:08:02.5555
USEABLE_STOP_TIME  = 1996-11-30T01:18:02.5555
STOP_TIME         = 1996-11-30T01:28:02.5555
ATTITUDE_TYPE     = QUATERNION
INTERPOLATION_METHOD = HERMITE
INTERPOLATION_DEGREE = 7
META_STOP

DATA_START
1996-11-28T21:29:07.2555 0.56748 0.03146 0.45689 0.68427
1996-11-28T22:08:03.5555 0.42319 -0.45697 0.23784 0.74533
1996-11-28T22:08:04.5555 -0.84532 0.26974 -0.06532 0.45652
1996-11-30T01:28:02.5555 0.74563 -0.45375 0.36875 0.31964
DATA_STOP

META_START
COMMENT This block begins after trajectory correction maneuver TCM-3.
OBJECT_NAME       = mars_global_surveyor
OBJECT_ID         = 1996-062A
CENTER_NAME       = MARS BARYCENTER
REF_FRAME_A         = EME2000
REF_FRAME_B         = SC_BODY_1
TIME_SYSTEM       = UTC
START_TIME        = 1996-12-18T12:05:00.5555
USEABLE_START_TIME = 1996-12-18T12:10:00.5555
USEABLE_STOP_TIME  = 1996-12-28T21:23:00.5555
STOP_TIME         = 1996-12-28T21:28:00.5555
ATTITUDE_TYPE     = QUATERNION
META_STOP

DATA_START
1996-12-18T12:05:00.5555 -0.64585 0.018542 -0.23854 0.72501
1996-12-18T12:10:05.5555 0.87451 -0.43475 0.13458 0.16767
1996-12-18T12:10:10.5555 0.03125 -0.65874 0.23458 0.71418
1996-12-28T21:28:00.5555 -0.25485 0.58745 -0.36845 0.67394
DATA_STOP
"""


def test_the_standards_example_reads_the_same_in_both_readers():
    message = read_aem(ANNEX_G4)
    assert message.header["MESSAGE_ID"] == "A701523"
    first, second = message.segments
    assert first.metadata["INTERPOLATION_DEGREE"] == "7" and "INTERPOLATION_METHOD" not in second.metadata
    assert first.comments[2] == "attitudes is 0.1 degrees per axis."
    assert second.epochs[-1] == "1996-12-28T21:28:00.5555"
    # scalar last in the file, scalar first once read: QC of the first line is 0.68427
    assert first.quaternions()[0].tolist() == [0.68427, 0.56748, 0.03146, 0.45689]
    assert second.values[0].tolist() == [-0.64585, 0.018542, -0.23854, 0.72501]
    ndm = independent()
    other = ndm.from_str(ANNEX_G4)
    for mine, theirs in zip(message.segments, other.segments):
        assert np.array_equal(mine.values, theirs.data.attitude_states_numpy)
        assert mine.epochs == list(theirs.data.attitude_states_epochs)
        assert mine.metadata["REF_FRAME_A"] == theirs.metadata.ref_frame_a


@pytest.mark.parametrize("text, fragment", [
    (ANNEX_G4.replace("CCSDS_AEM_VERS = 2.0\n", ""), "CCSDS_AEM_VERS"),
    (ANNEX_G4.replace("0.56748 0.03146 0.45689 0.68427", "0.56748 0.03146 0.45689"), "3 numbers"),
    (ANNEX_G4.rsplit("DATA_STOP", 1)[0], "ends inside"),
    (ANNEX_G4.replace("META_STOP\n\nDATA_START\n1996-11", "DATA_START\n1996-11", 1), "unexpected"),
])
def test_the_reader_refuses_a_malformed_message(text, fragment):
    with pytest.raises(ValueError, match=fragment):
        read_aem(text)
