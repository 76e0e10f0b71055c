"""The AEM export's GPS time system (CCSDS ADM, SANA): GPS = TAI - 19 s exactly, so GPS - UTC is
TAI - UTC - 19 s: 17 s during 2016, 18 s from 2017-01-01. The expected tags are written by hand."""
from __future__ import annotations

from scenarios.output.aem import time_tags


def test_gps_tags_are_tai_minus_19_seconds_by_hand():
    assert time_tags("2027-06-21T10:30:00Z", [0.0, 1.5], "GPS") == [
        "2027-06-21T10:30:18.000000000", "2027-06-21T10:30:19.500000000"]


def test_gps_counts_the_leap_second_that_utc_inserts():
    # 2016-12-31T23:59:59 UTC is 23:59:59 + 17 s GPS; 2 SI seconds later (23:59:60 in UTC, then
    # 00:00:00) GPS has run on uniformly
    assert time_tags("2016-12-31T23:59:59Z", [0.0, 1.0, 2.0], "GPS") == [
        "2017-01-01T00:00:16.000000000", "2017-01-01T00:00:17.000000000", "2017-01-01T00:00:18.000000000"]
