"""The epoch and the Sun/Moon ephemeris (:mod:`ocp.dynamics.ephemeris`).

Oracles: ERFA's analytic models, independent of DE421 (``epv00``, the VSOP2000-fitted Earth, for the
Sun; ``moon98``, Meeus' lunar theory, for the Moon; both GCRS/BCRS), read at a TT built here by hand
from the calendar and the published TAI - UTC steps; the leap seconds' published values; hand-worked
dates.
"""
from __future__ import annotations

import datetime

import erfa
import numpy as np
import pytest

from ocp.dynamics.ephemeris import (
    EPHEMERIS_RANGE,
    check_epoch,
    moon_position,
    parse_utc,
    sun_position,
    tdb_julian_date,
)
from ocp.errors import ModelError

AU = 1.495978707e11  # m, IAU 2012
J2000 = datetime.datetime(2000, 1, 1, 12)  # JD 2451545.0, here on the UTC calendar

TAI_MINUS_UTC = [  # IERS Bulletin C: (first UTC day, TAI - UTC [s]) since 1999
    (datetime.datetime(1999, 1, 1), 32.0), (datetime.datetime(2006, 1, 1), 33.0),
    (datetime.datetime(2009, 1, 1), 34.0), (datetime.datetime(2012, 7, 1), 35.0),
    (datetime.datetime(2015, 7, 1), 36.0), (datetime.datetime(2017, 1, 1), 37.0)]


def tt_by_hand(epoch: datetime.datetime) -> tuple[float, float]:
    """TT of a UTC instant since 1999 as a two-part Julian date, without ERFA: the calendar day count
    from J2000, TAI - UTC from the table above, TT - TAI = 32.184 s."""
    leap = [step for start, step in TAI_MINUS_UTC if epoch >= start][-1]
    seconds = (epoch - J2000).total_seconds() + leap + 32.184
    return 2451545.0, seconds / 86400.0


def angle_deg(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angle between rows [deg] (atan2: accurate at small angles)."""
    a, b = np.atleast_2d(a), np.atleast_2d(b)
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.einsum("ij,ij->i", a, b)))


def random_epochs(count: int, seed: int) -> list[datetime.datetime]:
    """Epochs drawn uniformly over 2000-2050, to the microsecond."""
    rng = np.random.default_rng(seed)
    start, span = datetime.datetime(2000, 1, 1), (datetime.datetime(2050, 1, 1) - datetime.datetime(2000, 1, 1))
    return [start + datetime.timedelta(seconds=float(s)) for s in rng.uniform(0, span.total_seconds(), count)]


# --- DE421 against ERFA's analytic models ---------------------------------------------------------

def test_the_sun_and_the_moon_agree_with_erfas_analytic_models_over_2000_to_2050():
    epochs = random_epochs(250, seed=27)
    sun = np.vstack([sun_position(e, 0.0) for e in epochs])
    moon = np.vstack([moon_position(e, 0.0) for e in epochs])
    tt1, tt2 = np.array([tt_by_hand(e) for e in epochs]).T
    # TDB - TT (< 1.7 ms) is below both models' use here: epv00 and moon98 read TT or TDB alike
    sun_erfa = -erfa.epv00(tt1, tt2)[0]["p"] * AU          # heliocentric Earth, reversed
    moon_erfa = erfa.moon98(tt1, tt2)["p"] * AU
    sun_angle, moon_angle = angle_deg(sun, sun_erfa), angle_deg(moon, moon_erfa)
    sun_distance = np.abs(np.linalg.norm(sun, axis=1) - np.linalg.norm(sun_erfa, axis=1))
    moon_distance = np.abs(np.linalg.norm(moon, axis=1) - np.linalg.norm(moon_erfa, axis=1))
    print(f"\nworst over {len(epochs)} epochs 2000-2050: Sun {sun_angle.max():.2e} deg, "
          f"{sun_distance.max() / 1e3:.3f} km; Moon {moon_angle.max():.2e} deg, {moon_distance.max() / 1e3:.2f} km")
    assert sun_angle.max() < 0.01
    assert moon_angle.max() < 0.05
    # distances: epv00 is good to a few km (DE405), moon98 to 31.7 km at worst (ELP/MPP02)
    assert sun_distance.max() < 20e3
    assert moon_distance.max() < 40e3


def test_one_call_evaluates_an_array_of_times_as_single_calls_do():
    epoch = datetime.datetime(2031, 5, 17, 4, 30)
    t = np.array([0.0, 1234.5, 7200.0, -600.0])
    for position in (sun_position, moon_position):
        table = position(epoch, t)
        assert table.shape == (4, 3)
        singles = np.vstack([position(epoch + datetime.timedelta(seconds=float(s)), 0.0) for s in t])
        np.testing.assert_allclose(table, singles, rtol=0, atol=1e-3)  # m (no leap second in between)
    assert sun_position(epoch, 0.0).shape == (1, 3)


def test_the_sun_at_the_2000_march_equinox_lies_20_arcsec_ahead_of_the_true_equinox_of_date():
    # 2000-03-20 07:35 UT (Astronomical Almanac, to the minute): the *apparent* Sun crosses the true
    # equinox of date. The geometric Sun is ahead of it by the aberration, 20.49"/r in ecliptic
    # longitude (r in au). ERFA's bias-precession-nutation matrix (IAU 2006/2000A) takes the GCRF to
    # the true equator and equinox of date; there the Sun must lie at that longitude on the ecliptic
    # (obliquity 23.4393 deg), within the minute's motion (2.5" in longitude).
    epoch = datetime.datetime(2000, 3, 20, 7, 35)
    sun = sun_position(epoch, 0.0)[0]
    distance_au = np.linalg.norm(sun) / AU
    assert 0.995 < distance_au < 0.997                                    # March: 0.9960 au
    longitude, obliquity = np.radians(20.49 / 3600.0 / distance_au), np.radians(23.4393)
    expected = np.array([np.cos(longitude), np.sin(longitude) * np.cos(obliquity),
                         np.sin(longitude) * np.sin(obliquity)])
    of_date = erfa.pnm06a(*tt_by_hand(epoch)) @ sun
    assert angle_deg(of_date, expected)[0] < 3.0 / 3600.0
    assert angle_deg(of_date, np.array([1.0, 0.0, 0.0]))[0] > 15.0 / 3600.0         # not the apparent Sun


# --- time scales and leap seconds -----------------------------------------------------------------

def _seconds_after(jd: tuple[np.ndarray, np.ndarray], utc: datetime.datetime) -> float:
    """``jd`` minus the UTC calendar instant [s] (differences first: no loss of precision)."""
    return float(((jd[0][0] - 2451545.0) + jd[1][0]) * 86400.0 - (utc - J2000).total_seconds())


@pytest.mark.parametrize("utc, tt_minus_utc", [
    (datetime.datetime(2016, 12, 31, 23, 59, 59), 68.184),   # TAI - UTC = 36 s before the leap second
    (datetime.datetime(2017, 1, 1, 0, 0, 0), 69.184),        # 37 s after
    (datetime.datetime(2012, 6, 30, 12), 66.184),             # 34 s before 2012-07-01
    (datetime.datetime(2000, 1, 1, 12), 64.184)])              # 32 s
def test_tdb_is_utc_plus_the_leap_seconds_plus_32_184_s_within_the_tdb_periodic_terms(utc, tt_minus_utc):
    assert abs(_seconds_after(tdb_julian_date(utc, 0.0), utc) - tt_minus_utc) < 1.7e-3  # |TDB - TT| < 1.7 ms


def test_a_run_across_the_2016_leap_second_counts_it():
    before = datetime.datetime(2016, 12, 31, 23, 59, 59)
    after = datetime.datetime(2017, 1, 1)
    # two SI seconds after 23:59:59 is 00:00:00 (23:59:60 lies between), not 00:00:01
    assert abs(_seconds_after(tdb_julian_date(before, 2.0), after) - 69.184) < 1.7e-3
    np.testing.assert_allclose(moon_position(before, 2.0), moon_position(after, 0.0), rtol=0, atol=1e-3)
    one_later = moon_position(after + datetime.timedelta(seconds=1), 0.0)
    assert np.linalg.norm(moon_position(before, 2.0) - one_later) > 500.0  # the Moon moves ~1 km/s about the Earth
    t = np.array([0.0, 1.0, 2.0, 3.0])
    elapsed = np.diff(np.sum(np.array(tdb_julian_date(before, t)), axis=0)) * 86400.0
    np.testing.assert_allclose(elapsed, 1.0, atol=1e-4)  # TDB advances with the SI seconds, leap or not


def test_a_leap_second_cannot_be_an_epoch():
    with pytest.raises(ModelError, match="leap second") as error:
        parse_utc("2016-12-31T23:59:60Z")
    assert error.value.field == "epoch" and "2016-12-31T23:59:60Z" in error.value.message


# --- parse_utc and check_epoch --------------------------------------------------------------------

@pytest.mark.parametrize("text, expected", [
    ("2025-01-01", datetime.datetime(2025, 1, 1)),
    ("2025-01-01T06:00:00", datetime.datetime(2025, 1, 1, 6)),
    ("2025-01-01T06:00:00Z", datetime.datetime(2025, 1, 1, 6)),
    ("2025-01-01 06:00:00.250z", datetime.datetime(2025, 1, 1, 6, 0, 0, 250000)),
    ("2025-01-01T06:00:00+02:00", datetime.datetime(2025, 1, 1, 4)),
    ("2025-01-01T01:30:00-05:30", datetime.datetime(2025, 1, 1, 7)),
    ("2025-01-01T00:30:00+01:00", datetime.datetime(2024, 12, 31, 23, 30)),
    ("  2025-03-04T05:06:07  ", datetime.datetime(2025, 3, 4, 5, 6, 7)),
])
def test_parse_utc_reads_iso_dates_and_date_times_in_utc(text, expected):
    value = parse_utc(text)
    assert value == expected and value.tzinfo is None


def test_parse_utc_takes_dates_and_datetimes_and_round_trips():
    assert parse_utc(datetime.date(2030, 2, 3)) == datetime.datetime(2030, 2, 3)
    tz = datetime.timezone(datetime.timedelta(hours=-3))
    assert parse_utc(datetime.datetime(2030, 2, 3, 22, tzinfo=tz)) == datetime.datetime(2030, 2, 4, 1)
    for epoch in random_epochs(50, seed=3):
        assert parse_utc(epoch.isoformat()) == epoch
        assert parse_utc(epoch.isoformat() + "Z") == epoch
        assert parse_utc(epoch.replace(tzinfo=datetime.timezone.utc).isoformat()) == epoch
        assert parse_utc(epoch) == epoch


@pytest.mark.parametrize("bad", ["2025-02-30", "yesterday", "", "2025-13-01", "01/02/2025", "2025-01-01T25:00",
                                 2025, 2025.5, None, ["2025-01-01"]])
def test_parse_utc_rejects_what_is_no_iso_instant_naming_it(bad):
    with pytest.raises(ModelError) as error:
        parse_utc(bad)
    assert error.value.field == "epoch"
    assert "expected a date like 2025-01-01" in error.value.message and str(bad)[:10] in error.value.message


def test_check_epoch_accepts_the_range_and_rejects_a_run_that_leaves_it():
    low, high = EPHEMERIS_RANGE
    assert check_epoch("2025-06-01T00:00:00Z", 86400.0) == datetime.datetime(2025, 6, 1)
    assert check_epoch(low) == low and check_epoch(high - datetime.timedelta(seconds=10), 10.0)
    outside: list[tuple[datetime.datetime | str, float]] = [
        (low - datetime.timedelta(seconds=1), 0.0), (high, 1.0), (high - datetime.timedelta(hours=1), 7200.0),
        ("1950-01-01", 0.0), ("2250-01-01", 0.0)]
    for epoch, duration in outside:
        with pytest.raises(ModelError, match=r"DE421\) covers 1960-01-01 to 2200-01-01") as error:
            check_epoch(epoch, duration)
        assert error.value.field == "epoch"
    for duration in (-1.0, float("nan"), float("inf")):
        with pytest.raises(ModelError, match="duration"):
            check_epoch("2025-01-01", duration)


def test_positions_outside_the_range_are_refused_as_model_errors():
    with pytest.raises(ModelError, match="DE421"):
        sun_position(datetime.datetime(2199, 12, 31, 23), np.array([0.0, 7200.0]))
    with pytest.raises(ModelError, match="DE421"):
        moon_position(datetime.datetime(1960, 1, 1, 0, 30), np.array([-3600.0, 0.0]))
    # near the range's ends (past ERFA's leap-second table too) it answers
    assert np.isfinite(sun_position(datetime.datetime(2199, 12, 31), 3600.0)).all()
    assert np.isfinite(moon_position(datetime.datetime(1960, 1, 1), 0.0)).all()
