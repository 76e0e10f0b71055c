"""Plausibility warnings on a validated scenario: values that the schema accepts but that are
almost certainly a unit slip (kilometres written as metres, degrees per second written as rad/s,
millinewton metres written as newton metres, an inertia in g mm² written as kg m²), or a layout
slip (wheels that cannot torque about every axis).

They are warnings, not errors: each names the YAML path, the value as written and the physical
reason it looks wrong, and suggests the value meant where one follows. ``slewbench validate``
prints them (``validate --strict`` counts each as a finding: exit 1) and ``slewbench run`` prints
them on standard error before planning; from Python, :func:`~scenarios.schema.loader.parse_scenario`
and :func:`~scenarios.schema.loader.load` issue each as a
:class:`~scenarios.errors.PlausibilityWarning` (:func:`warn_implausible`). Both paths read the
same findings, those of :func:`plausibility_warnings`. Each check of :data:`PLAUSIBILITY_CHECKS` has one physical
reason; a value that passes them all is not thereby right, only not obviously wrong.

Angles are in degrees (``_deg`` keys, ``axis_angle.angle_deg``), whose ranges the schema already
bounds; two have a range where a value in radians lands and no physical one does: a star tracker's
noise in arcsec (no upper bound, and radians lie far below any sensor's) and a keep-out cone about
the Sun or the Moon (below 1 deg it protects nothing, and 35 deg in radians is 0.61). An inertia that
violates the triangle inequality is an error of the loader, not a warning.

May import: :mod:`ocp` (the Earth's radius), :mod:`scenarios.errors` (the warning's class) and the :class:`~scenarios.schema.loader.Scenario`
it reads (for types only).
"""
from __future__ import annotations

import math
import sys
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ocp.dynamics.orbits import R_EARTH
from scenarios.errors import PlausibilityWarning

if TYPE_CHECKING:
    from scenarios.schema.loader import Scenario

__all__ = ["LOWEST_ORBIT_KM", "MAX_ANGULAR_ACCELERATION", "MAX_RATE", "MAX_RATE_TOLERANCE",
           "MAX_ATTITUDE_NOISE_DEG", "MAX_GYRO_ARW_DEG_PER_SQRT_H", "MAX_MAGNETIC_NOISE_T",
           "MAX_STAR_TRACKER_NOISE_ARCSEC", "MAX_STAR_TRACKER_RATE_HZ",
           "MIN_BRIGHT_BODY_CONE_DEG", "MIN_STAR_TRACKER_NOISE_ARCSEC", "MOON_DISTANCE_KM", "PLAUSIBILITY_CHECKS", "SLOW_SLEW_FACTOR", "Implausible", "plausibility_warnings",
           "warn_implausible"]

MIN_BRIGHT_BODY_CONE_DEG = 1.0
"""Half-angle [deg] of a keep-out cone about the Sun or the Moon below which it reads as radians
written as degrees: the bodies' discs are about 0.27 deg in radius and the sensors they blind keep
tens of degrees off them (35 deg written as 0.61 lands here; a cone of 1 deg or more is not judged)."""
MOON_DISTANCE_KM = 384_400.0
"""The Moon's mean distance from the Earth [km]: an orbit reaching beyond it is no Earth orbit the
two-body (and J2) model describes, the Moon's and the Sun's pull being comparable to the Earth's."""
LOWEST_ORBIT_KM = 100.0
"""The Kármán line [km] above the equatorial radius: an orbit whose perigee is lower re-enters
within hours, so no attitude manoeuvre is planned there."""
MAX_RATE = 1.0
"""Body rate [rad/s] (57 deg/s) at or above which a rate bound binds no slew: agile spacecraft slew
at a few degrees per second, so a bound of 1 rad/s is as implausible as one above it; a bound in
deg/s written as rad/s lands at or above it (1 deg/s written as 1 is flagged: the bar is inclusive)."""
MAX_RATE_TOLERANCE = 0.1
"""Rate tolerance [rad/s] (5.7 deg/s) at or above which a tolerance on a rate left over
(``requirements.final.rate``, the rate error after the slew; ``simulation.detumble_tolerance``, the
rate at which a tumble counts as stopped) decides nothing. A tolerance is a small part of the rates
a manoeuvre reaches, and the most agile spacecraft slew at a few deg/s (under 0.1 rad/s): at this
bar a spacecraft still slewing as fast as any does would meet it. The rate bounds' bar (1 rad/s)
would let a tolerance in deg/s written as rad/s through from 0.1 up to 1 deg/s (the usual final
rate tolerances and detumble ends); this one flags them, and no shipped scenario comes near it
(their tolerances are at most 0.01 rad/s)."""
MAX_ANGULAR_ACCELERATION = 5.0
"""Angular acceleration [rad/s²] an actuator's torque gives about the least principal axis above
which it is no attitude actuator (a full turn from rest in under 1.6 s); a torque in mN m written
as N m lands above it on any spacecraft of slewbench's examples."""
SLOW_SLEW_FACTOR = 10.0
"""How many times its time budget (``maneuver.duration``, every planner's) the least time a
rest-to-rest slew can take at the actuators' peak angular acceleration must exceed to warn: an
inertia in g mm² or g cm² written as kg m² (1e9 or 1e7 too large), or a torque bound a thousand
times too small, makes it thousands of times the budget. The time goes as the square root of the
inertia over the torque, so an inertia ``k`` times too large warns when ``√k`` times the slew's
share of its budget (at that bound) exceeds this factor: ``k > (10 / share)²``. The shipped
scenarios' slews take at most 0.4 of their budgets, so none warns with an inertia less than 625
times too large; ``eigenaxis_demo``'s, 21.4 s of 120 s (0.18), warns from 3,151 times: an inertia
a hundred times too large warns only where the slew already takes more than its whole budget."""

MIN_STAR_TRACKER_NOISE_ARCSEC = 0.05
"""Star-tracker noise [arcsec, 1 sigma] below which every axis of ``noise_arcsec`` is no star
tracker's: the most precise flown reach about 0.1 arcsec across the boresight, a small satellite's
1 to 10 arcsec (and several times that about the boresight). A noise in radians written as arcsec
(5 arcsec = 2.4e-5 rad) lands thousands of times below it; zero (a perfect sensor, meant) does not
warn."""

MAX_STAR_TRACKER_NOISE_ARCSEC = 3600.0
"""Star-tracker noise [arcsec, 1 sigma] above which an axis of ``noise_arcsec`` is no star tracker's:
one degree. The coarsest (nanosatellite) trackers reach tens of arcsec across the boresight and a
few hundred about it; a degree is a Sun sensor's accuracy, and trackers' fields of view are only 8
to 25 deg, so a noise of degrees would put the stars out of the frame the sensor matches. Beyond
180 deg (648,000 arcsec) the schema refuses it
(:data:`~scenarios.schema.estimation.STAR_TRACKER_NOISE_LIMIT_ARCSEC`)."""
MAX_STAR_TRACKER_RATE_HZ = 1000.0
"""Star-tracker update rate [Hz] above which ``rate_hz`` is no star tracker's: a kHz. Trackers expose
their detector for tens to hundreds of milliseconds per frame and update at 1 to 30 Hz. A rate
above the controller's sample rate (``1 / simulation.sample_time``) warns too: the simulation gives
at most one update per sample, so it acts as ``null`` (every sample). Beyond 1e7 Hz the schema
refuses it (:data:`~ocp.estimation.sensors.STAR_TRACKER_RATE_LIMIT_HZ`)."""
MAX_ATTITUDE_NOISE_DEG = 10.0
"""Attitude measurement noise [deg, 1 sigma] (``simulation.sensor_noise.attitude_deg``) above which no
attitude sensor is that coarse: Sun sensors and magnetometer-based attitude give 0.5 to 5 deg, star
trackers arcseconds. Beyond 180 deg the schema refuses it."""
MAX_MAGNETIC_NOISE_T = 1.0e-4
"""Magnetometer noise or bias [T] (``simulation.sensor_noise.magnetic_field``,
``simulation.sensors.magnetometer.noise_T`` and the largest entry of ``bias_T``) above which the
error exceeds the field it measures: the Earth's is at most 6.5e-5 T at its surface and 1e-5 to
5e-5 T in low orbit; magnetometers' noise is nT (1e-9 T). A value in nT written as T (1e9 too
large) is mostly beyond 1 T, an error of the schema that says so
(:data:`~scenarios.schema.estimation.MAX_MAGNETIC_NOISE_T`)."""
MAX_GYRO_ARW_DEG_PER_SQRT_H = math.degrees(MAX_RATE_TOLERANCE) * 60.0
"""Gyro angle random walk [deg/√h] (344) at or above which the gyro's white rate noise over one
second has a standard deviation of :data:`MAX_RATE_TOLERANCE` (0.1 rad/s, 5.7 deg/s), as large as
the rates the most agile spacecraft slew at: the bar of ``simulation.sensor_noise.rate``, the
noise of the rate measured without a gyro model. Navigation gyros have 0.001 to 0.01 deg/√h,
MEMS gyros 0.1 to a few deg/√h."""


@dataclass(frozen=True)
class Implausible:
    """One plausibility warning.

    Parameters
    ----------
    path : str
        The YAML path of the value (``orbit.altitude_km``).
    value : str
        The value as written, with its unit (``500000 km``).
    reason : str
        Why it looks wrong, and the value probably meant where one follows.
    """

    path: str
    value: str
    reason: str

    def __str__(self) -> str:
        return f"{self.path}: {self.value} {self.reason}"


PlausibilityCheck = Callable[["Scenario"], Iterator[Implausible]]


_GROUPED_BELOW = 1e15
"""Numbers in a warning's text are written with their thousands grouped below this, in exponent form
from it."""


def _grouped(value: float, decimals: int = 0) -> str:
    """``value`` with its thousands grouped (``57,296``) below ``_GROUPED_BELOW``, beyond that in
    exponent form (``7.011e+262``): a user's 1e261 rad/s is no 263-digit number in a warning."""
    if abs(value) < _GROUPED_BELOW:
        return f"{value:,.{decimals}f}"
    return f"{value:.4g}"


def _number(value: Any) -> float | None:
    """``value`` as a finite float, or None (absent, null, text, a bool)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        return None
    return float(value)


def _numbers(value: Any) -> list[float] | None:
    """A number or a list of numbers as floats, or None when it is neither."""
    one = _number(value)
    if one is not None:
        return [one]
    if isinstance(value, list) and value and all(_number(item) is not None for item in value):
        return [float(item) for item in value]
    return None


def _mapping(data: Any, *keys: str) -> dict[str, Any]:
    """``data[keys[0]][keys[1]]...`` when every level is a mapping, else an empty one."""
    for key in keys:
        data = data.get(key) if isinstance(data, dict) else None
    return data if isinstance(data, dict) else {}


def _orbit_altitude(scenario: Scenario) -> Iterator[Implausible]:
    """A circular or Keplerian orbit whose apogee lies beyond the Moon, or whose perigee lies below
    the Kármán line (a two-line element set, read from its fixed format, is not checked)."""
    orbit = _mapping(scenario.data, "orbit")
    radius_km = R_EARTH / 1e3
    eccentricity = _number(orbit.get("eccentricity")) or 0.0
    for key, to_radius in (("altitude_km", lambda v: v + radius_km), ("semi_major_axis_km", lambda v: v)):
        value = _number(orbit.get(key))
        if value is None:
            continue
        apogee = to_radius(value) * (1 + eccentricity) - radius_km
        perigee = to_radius(value) * (1 - eccentricity) - radius_km
        height = "altitude" if eccentricity == 0 else "apogee altitude"
        if apogee + radius_km > MOON_DISTANCE_KM:  # the Moon's distance is from the Earth's centre
            meant = value / 1e3
            guess = (f"; did you mean {meant:g} (metres written as kilometres)?"
                     if LOWEST_ORBIT_KM <= to_radius(meant) * (1 - eccentricity) - radius_km else "")
            yield Implausible(f"orbit.{key}", f"{value:g} km",
                              f"puts the orbit's {height} at {_grouped(apogee)} km ({_grouped(apogee + radius_km)} km from "
                              f"the Earth's centre), beyond the Moon's distance ({MOON_DISTANCE_KM:,.0f} km), where "
                              f"the Earth's two-body orbit no longer holds{guess}")
        elif perigee < LOWEST_ORBIT_KM:
            where = "altitude" if eccentricity == 0 else "perigee altitude"
            yield Implausible(f"orbit.{key}", f"{value:g} km",
                              f"puts the orbit's {where} at {perigee:,.4g} km, below {LOWEST_ORBIT_KM:g} km (the "
                              "Kármán line), where the atmosphere ends an orbit within hours; is the value in km?")


def _rate_bounds(scenario: Scenario) -> Iterator[Implausible]:
    """A bound on the body rate at or above :data:`MAX_RATE` (a bound in deg/s written as rad/s)."""
    data = scenario.data or {}
    bounds = [("maneuver.max_rate", _mapping(data, "maneuver").get("max_rate")),
              ("requirements.rate.max", _mapping(data, "requirements", "rate").get("max"))]
    planners = data.get("planners")
    for index, planner in enumerate(planners if isinstance(planners, list) else []):
        bounds.append((f"planners[{index}].options.max_rate", _mapping(planner, "options").get("max_rate")))
    yield from _rates_at_or_above(bounds, MAX_RATE, "a bound no attitude slew comes near")


def _rate_tolerances(scenario: Scenario) -> Iterator[Implausible]:
    """A tolerance on a rate left over at or above :data:`MAX_RATE_TOLERANCE` (a tolerance in deg/s
    written as rad/s)."""
    data = scenario.data or {}
    tolerances = [("requirements.final.rate", _mapping(data, "requirements", "final").get("rate")),
                  ("simulation.detumble_tolerance", _mapping(data, "simulation").get("detumble_tolerance"))]
    yield from _rates_at_or_above(tolerances, MAX_RATE_TOLERANCE,
                                  "a tolerance that a spacecraft still slewing as fast as any does would meet")


def _rate_noise(scenario: Scenario) -> Iterator[Implausible]:
    """A rate measurement noise (``simulation.sensor_noise.rate``, 1 sigma per axis) at or above
    :data:`MAX_RATE_TOLERANCE` (a noise in deg/s written as rad/s)."""
    noise = _mapping(scenario.data or {}, "simulation", "sensor_noise").get("rate")
    yield from _rates_at_or_above([("simulation.sensor_noise.rate", noise)], MAX_RATE_TOLERANCE,
                                  "a noise that hides the rate of a spacecraft slewing as fast as any does")


def _rates_at_or_above(given: list[tuple[str, Any]], bar: float, why: str) -> Iterator[Implausible]:
    """The rates [rad/s] of ``given`` (YAML path, value as written) at or above ``bar``, each
    saying ``why`` that is implausible and the value meant if it was written in deg/s."""
    for path, written in given:
        value = _number(written)
        if value is not None and value >= bar:
            yield Implausible(path, f"{value:g} rad/s",
                              f"is {_grouped(math.degrees(value), 0 if value >= 1 else 1)} deg/s, at or above {bar:g} rad/s "
                              f"({math.degrees(bar):.2g} deg/s), {why}; did you mean {math.radians(value):.4g} rad/s "
                              f"({value:g} deg/s)?")


def _peak_acceleration(scenario: Scenario) -> float:
    """The actuators' peak angular acceleration [rad/s²]: the body torque box's norm over the least
    principal moment (``inf`` when unlimited, 0 without a stated bound: magnetorquers alone)."""
    spacecraft = scenario.problem.spacecraft
    least = float(np.linalg.eigvalsh(spacecraft.inertia)[0])
    return float(np.linalg.norm(spacecraft.body_torque_limit())) / least


def _boundary_rates(scenario: Scenario) -> Iterator[Implausible]:
    """A boundary rate (``maneuver.initial.omega``, ``maneuver.final.omega``) at or above
    :data:`MAX_RATE` that the actuators could not give or take away within the manoeuvre, even at
    their peak angular acceleration (the body torque box over the least principal moment): a rate
    in deg/s written as rad/s; with wheels alone, also one whose momentum ``‖J ω‖`` exceeds what
    all working wheels store together. A fast spin the actuators can reach (a spin-up) is left
    alone, and so is a spacecraft without a stated torque bound (magnetorquers alone: their torque
    depends on the field)."""
    problem = scenario.problem
    spacecraft = problem.spacecraft
    peak = _peak_acceleration(scenario)  # rad/s^2, inf when unlimited
    if peak == 0.0:  # no torque bound it can state (magnetorquers alone: the field decides): not judged
        return
    reach = peak * problem.duration
    wheels = spacecraft.wheels
    storage = math.inf  # wheels alone conserve the total momentum: they hold at most the sum of their bounds
    if wheels is not None and all(actuator is wheels for actuator in spacecraft.actuators):
        storage = float(sum(float(wheels.max_momentum[i]) for i in range(wheels.count) if i not in wheels.failed))
    for where, rate in (("initial", problem.omega0), ("final", problem.omegaf)):
        if rate is None:
            continue
        norm = float(np.linalg.norm(rate))
        momentum = float(np.linalg.norm(spacecraft.inertia @ np.asarray(rate, dtype=float)))
        if norm < MAX_RATE or (norm <= reach and momentum <= storage):
            continue
        why = (f"more than the actuators can change in maneuver.duration ({peak:.3g} rad/s² at most about the "
               f"least principal axis for {problem.duration:g} s: {reach:.3g} rad/s)" if norm > reach else
               f"more than the wheels alone can take (its momentum ‖J ω‖ = {momentum:.3g} N m s against the "
               f"{storage:.3g} N m s all working wheels store together)")
        yield Implausible(f"maneuver.{where}.omega", f"{np.asarray(rate).tolist()} rad/s",
                          f"has ‖ω‖ = {norm:.4g} rad/s ({_grouped(math.degrees(norm))} deg/s), at or above {MAX_RATE:g} "
                          f"rad/s and {why}; did you mean {[round(math.radians(float(w)), 6) for w in rate]} "
                          "rad/s (deg/s written as rad/s)?")


def _rate_error(scenario: Scenario) -> Iterator[Implausible]:
    """An initial rate error (``simulation.initial_rate_error``, added to the closed loop's true
    initial rate) at or above :data:`MAX_RATE_TOLERANCE`, or more than the actuators can take out
    within the closed-loop window (``simulation.duration``, else ``maneuver.duration``) even at
    their peak angular acceleration (the body torque box over the least principal moment). An error
    of the rate the closed loop starts from is a small part of the rates a manoeuvre reaches (a
    rate knowledge error, a handoff's residual; the shipped scenarios' are 0.002 rad/s); at
    0.1 rad/s it exceeds what the most agile spacecraft slew at (a rate in deg/s written as rad/s),
    and one the actuators cannot remove within the window leaves every row's closed loop still
    tumbling at its end, whatever the controller. A spacecraft without a stated torque bound
    (magnetorquers alone) is judged by the first bar only."""
    error = np.asarray(scenario.simulation.initial_rate_error, dtype=float)
    norm = float(np.linalg.norm(error))
    if not norm > 0.0:
        return
    peak = _peak_acceleration(scenario)
    window = scenario.simulation.duration or scenario.problem.duration
    reach = peak * window
    slip = norm >= MAX_RATE_TOLERANCE
    beyond = peak > 0.0 and norm > reach
    if not (slip or beyond):
        return
    why = []
    if slip:
        why.append(f"at or above {MAX_RATE_TOLERANCE:g} rad/s ({math.degrees(MAX_RATE_TOLERANCE):.2g} deg/s): an error "
                   "of the rate the closed loop starts from as large as the rates the most agile spacecraft slew at")
    if beyond:
        why.append(f"more than the actuators can take out within the closed-loop window ({peak:.3g} rad/s² at most "
                   f"about the least principal axis for {window:g} s: {reach:.3g} rad/s), so no row's closed loop "
                   "removes it")
    written = _numbers(_mapping(scenario.data, "simulation").get("initial_rate_error"))
    shown = written if written is not None and len(written) == 3 else error.tolist()
    meant = (f"; did you mean {[round(math.radians(v), 6) for v in shown]} rad/s (deg/s written as rad/s)?"
             if slip else "; is the error meant, or the torque bound too small?")
    yield Implausible("simulation.initial_rate_error", f"{shown} rad/s",
                      f"has ‖δω‖ = {norm:.4g} rad/s ({_grouped(math.degrees(norm), 1)} deg/s), {' and '.join(why)}"
                      f"{meant}")


def _torques(scenario: Scenario) -> Iterator[Implausible]:
    """An actuator torque bound that would turn the spacecraft at more than
    :data:`MAX_ANGULAR_ACCELERATION` about its least principal axis (mN m written as N m)."""
    least = float(np.linalg.eigvalsh(scenario.problem.spacecraft.inertia)[0])
    for path in ("spacecraft.wheels.max_torque", "spacecraft.torquers.max_torque", "truth.wheels.max_torque"):
        *section, key = path.split(".")
        values = _numbers(_mapping(scenario.data, *section).get(key))
        if not values:
            continue
        largest = max(values)
        acceleration = largest / least
        if acceleration > MAX_ANGULAR_ACCELERATION:
            shown = f"{largest:g} N m" if len(values) == 1 else f"{values} N m (largest {largest:g})"
            yield Implausible(path, shown,
                              f"on a least principal moment of inertia of {least:g} kg m² gives {acceleration:.3g} "
                              f"rad/s², above {MAX_ANGULAR_ACCELERATION:g} rad/s² (a full turn from rest in "
                              f"{math.sqrt(4 * math.pi / acceleration):.2g} s); did you mean {largest / 1e3:g} N m "
                              "(mN m written as N m)?")


def _slew_time(scenario: Scenario) -> Iterator[Implausible]:
    """A rest-to-rest slew the actuators could not make in :data:`SLOW_SLEW_FACTOR` times its
    budget, ``maneuver.duration``, even at their peak angular acceleration ``α = ‖τ‖ / λ_min`` (the body torque box's norm
    over the least principal moment): an inertia far too large for its torque (g mm² written as
    kg m²), or a torque far too small. From rest to rest, ``‖J ω‖`` grows and falls at most at
    ``‖τ‖``, so a turn by ``θ`` takes at least the bang-bang time ``2 √(θ / α)``. A slew that does
    not start and end at rest, one without a final attitude, and a spacecraft without a stated
    torque bound (magnetorquers alone) or with an unbounded one are left alone."""
    problem = scenario.problem
    if problem.qf is None or problem.omegaf is None or np.any(problem.omega0) or np.any(problem.omegaf):
        return
    spacecraft = problem.spacecraft
    least = float(np.linalg.eigvalsh(spacecraft.inertia)[0])
    torque = float(np.linalg.norm(spacecraft.body_torque_limit()))
    if not 0.0 < torque < math.inf:
        return
    angle = 2.0 * math.acos(min(1.0, abs(float(np.dot(problem.q0, problem.qf)))))
    shortest = 2.0 * math.sqrt(angle * least / torque)
    budget = problem.duration  # maneuver.duration: every planner's time budget (a longer slew is infeasible)
    if shortest <= SLOW_SLEW_FACTOR * budget:
        return
    written = _mapping(scenario.data, "spacecraft").get("inertia")
    yield Implausible("spacecraft.inertia", f"{written} kg m²",
                      f"(least principal moment {least:g} kg m²) with the actuators' body torque bound (‖τ‖ = "
                      f"{torque:.3g} N m) turns the spacecraft at {torque / least:.3g} rad/s² at most, so the "
                      f"{math.degrees(angle):.4g} deg rest-to-rest slew takes at least {_grouped(shortest)} s (the "
                      f"bang-bang time 2 √(θ / α)), "
                      f"{_grouped(shortest / budget)} times maneuver.duration ({budget:g} s, the manoeuvre's time budget): "
                      "no slew within it stays within the actuators' torque bound: a planner that takes its own "
                      "time ends after the budget (its row infeasible), one planned over it asks more torque than "
                      "the actuators give (its row violated under the actuator requirement, or infeasible where the "
                      "planner holds the limits); is the "
                      "inertia in kg m² (g mm² written as kg m² is 1e9 too large, g cm² 1e7) and the torque in N m?")


def _disturbance(scenario: Scenario) -> Iterator[Implausible]:
    """A constant disturbance torque (``environment.disturbance_torque``) larger than the actuators
    give against it: the largest torque along ``−τ_d`` within the wheels' and torquers'
    ``max_torque``, through the controllers' allocation (:meth:`~ocp.Spacecraft.torque_along`).
    No controller then holds an attitude, so every run drifts away; a torque in mN m or µN m
    written as N m lands there. A spacecraft that gives no stated torque against it (magnetorquers
    alone: the field decides; failed wheels that leave that direction bare) or an unbounded one is
    left alone."""
    written = _mapping(scenario.data, "environment").get("disturbance_torque")
    values = _numbers(written)
    if values is None or len(values) != 3:
        return
    torque = np.array(values)
    norm = float(np.linalg.norm(torque))
    if not 0.0 < norm < math.inf:
        return
    counter = scenario.problem.spacecraft.torque_along(-torque)
    if not 0.0 < counter < norm:  # 0: no stated bound that way; inf: unlimited; or the actuators hold it
        return
    yield Implausible("environment.disturbance_torque", f"{values} N m",
                      f"has ‖τ_d‖ = {norm:.3g} N m, more than the actuators give against it ({counter:.3g} N m "
                      "along −τ_d within the wheels' and torquers' max_torque): no controller holds an attitude, "
                      f"so every run drifts away; did you mean {[round(v / 1e3, 9) for v in values]} N m (mN m written "
                      "as N m)?")


def _wheel_axes(scenario: Scenario) -> Iterator[Implausible]:
    """Three or more wheels whose axes span fewer than three directions, with no other actuator:
    a layout slip (a pyramid's elevation written as 0, an axis repeated), since a spacecraft flies
    three or more wheels to torque about every axis. Two wheels (the underactuated problem) and
    failed wheels (a failure studied) are meant, and left alone."""
    spacecraft = scenario.problem.spacecraft
    wheels = spacecraft.wheels
    if wheels is None or wheels.count < 3 or any(actuator is not wheels for actuator in spacecraft.actuators):
        return
    _, singular, rows = np.linalg.svd(np.asarray(wheels.axes, dtype=float).T)
    rank = int(np.sum(singular > 1e-6 * singular[0]))
    if rank == 3:
        return
    missing = rows[-1]  # a body direction no wheel torques about
    shape = "a plane" if rank == 2 else "one line"
    written = _mapping(scenario.data, "spacecraft", "wheels").get("axes")
    yield Implausible("spacecraft.wheels.axes", f"{written} ({wheels.count} wheels)",
                      f"span only {shape}: no wheel torques about the body direction "
                      f"{np.round(missing / np.max(np.abs(missing)), 4).tolist()}, and the spacecraft has no other "
                      "actuator; did you mean a layout spanning three axes (a pyramid's axes tilted out of the "
                      "plane)? Underactuated control is written with two wheels, or a wheel listed in failed.")


def _star_tracker_noise(scenario: Scenario) -> Iterator[Implausible]:
    """A star tracker's noise (``simulation.sensors.star_tracker.noise_arcsec``) whose largest axis
    is positive and below :data:`MIN_STAR_TRACKER_NOISE_ARCSEC` (radians written as arcsec)."""
    written = _mapping(scenario.data or {}, "simulation", "sensors", "star_tracker").get("noise_arcsec")
    values = _numbers(written)
    if values is None or not 0.0 < max(values) < MIN_STAR_TRACKER_NOISE_ARCSEC:
        return
    meant = [float(f"{math.degrees(value) * 3600.0:.4g}") for value in values]
    yield Implausible("simulation.sensors.star_tracker.noise_arcsec", f"{written} arcsec",
                      f"is at most {max(values):.3g} arcsec (1 sigma), below "
                      f"{MIN_STAR_TRACKER_NOISE_ARCSEC:g} arcsec on every axis, where no star tracker is (the most "
                      f"precise reach about 0.1 arcsec); did you mean {meant} arcsec (radians written as arcsec)?")



def _star_tracker_coarse(scenario: Scenario) -> Iterator[Implausible]:
    """A star tracker's noise (``simulation.sensors.star_tracker.noise_arcsec``) whose largest axis
    is above :data:`MAX_STAR_TRACKER_NOISE_ARCSEC` (a degree: no star tracker)."""
    written = _mapping(scenario.data or {}, "simulation", "sensors", "star_tracker").get("noise_arcsec")
    values = _numbers(written)
    if values is None or not max(values) > MAX_STAR_TRACKER_NOISE_ARCSEC:
        return
    yield Implausible("simulation.sensors.star_tracker.noise_arcsec", f"{written} arcsec",
                      f"is up to {_grouped(max(values))} arcsec ({max(values) / 3600.0:.4g} deg, 1 sigma), above "
                      f"{MAX_STAR_TRACKER_NOISE_ARCSEC:,.0f} arcsec (1 deg), where no star tracker is: plausible "
                      "noises are 0.1 to 100 arcsec across the boresight and up to a few hundred about it")


def _star_tracker_rate(scenario: Scenario) -> Iterator[Implausible]:
    """A star tracker's update rate (``simulation.sensors.star_tracker.rate_hz``) above
    :data:`MAX_STAR_TRACKER_RATE_HZ` (no star tracker) or above the controller's sample rate (it
    updates at every sample, as ``null`` does)."""
    rate = _number(_mapping(scenario.data or {}, "simulation", "sensors", "star_tracker").get("rate_hz"))
    sample_time = scenario.simulation.sample_time
    if rate is None:
        return
    sampled = rate * sample_time > 1.0 + 1e-9  # more than one update per sample asked
    fast = rate > MAX_STAR_TRACKER_RATE_HZ
    if not (sampled or fast):
        return
    why = []
    if fast:
        why.append(f"above {MAX_STAR_TRACKER_RATE_HZ:,.0f} Hz, where no star tracker is (they update at 1 to 30 Hz)")
    if sampled:
        why.append(f"above the controller's sample rate ({1.0 / sample_time:.4g} Hz: simulation.sample_time "
                   f"{sample_time:g} s), so it gives one update a sample, as null (every sample) does")
    yield Implausible("simulation.sensors.star_tracker.rate_hz", f"{_grouped(rate, 0 if rate >= 1 else 3)} Hz",
                      f"is {' and '.join(why)}; plausible: 1 to 30 Hz, at most 1 / sample_time")


def _gyro_noise(scenario: Scenario) -> Iterator[Implausible]:
    """A gyro's angle random walk (``simulation.sensors.gyro.arw_deg_per_sqrt_h``) at or above
    :data:`MAX_GYRO_ARW_DEG_PER_SQRT_H` (a one-second rate noise of 0.1 rad/s)."""
    arw = _number(_mapping(scenario.data or {}, "simulation", "sensors", "gyro").get("arw_deg_per_sqrt_h"))
    if arw is None or arw < MAX_GYRO_ARW_DEG_PER_SQRT_H:
        return
    yield Implausible("simulation.sensors.gyro.arw_deg_per_sqrt_h", f"{_grouped(arw, 0 if arw >= 1 else 3)} deg/√h",
                      f"is a white rate noise of {math.radians(arw) / 60.0:.4g} rad/s over one second, at or above "
                      f"{MAX_GYRO_ARW_DEG_PER_SQRT_H:.0f} deg/√h ({MAX_RATE_TOLERANCE:g} rad/s over one second), "
                      "a noise that hides the rate of a spacecraft slewing as fast as any does; plausible: 0.001 "
                      "(navigation) to a few (MEMS) deg/√h")


def _attitude_noise(scenario: Scenario) -> Iterator[Implausible]:
    """An attitude measurement noise (``simulation.sensor_noise.attitude_deg``) above
    :data:`MAX_ATTITUDE_NOISE_DEG`."""
    noise = _number(_mapping(scenario.data or {}, "simulation", "sensor_noise").get("attitude_deg"))
    if noise is None or not noise > MAX_ATTITUDE_NOISE_DEG:
        return
    yield Implausible("simulation.sensor_noise.attitude_deg", f"{noise:g} deg",
                      f"is above {MAX_ATTITUDE_NOISE_DEG:g} deg (1 sigma per axis), coarser than any attitude sensor: "
                      "plausible: arcseconds (a star tracker) to a few degrees (Sun sensors, magnetometers)")


def _magnetic_noise(scenario: Scenario) -> Iterator[Implausible]:
    """A magnetometer noise or bias above :data:`MAX_MAGNETIC_NOISE_T` (nT written as T)."""
    data = scenario.data or {}
    magnetometer = _mapping(data, "simulation", "sensors", "magnetometer")
    given = [("simulation.sensor_noise.magnetic_field", _mapping(data, "simulation", "sensor_noise").get("magnetic_field")),
             ("simulation.sensors.magnetometer.noise_T", magnetometer.get("noise_T")),
             ("simulation.sensors.magnetometer.bias_T", magnetometer.get("bias_T"))]
    for path, written in given:
        values = _numbers(written)
        if values is None or not max(abs(v) for v in values) > MAX_MAGNETIC_NOISE_T:
            continue
        largest = max(abs(v) for v in values)
        yield Implausible(path, f"{written} T",
                          f"is up to {largest:g} T, above {MAX_MAGNETIC_NOISE_T:g} T, more than the Earth's field it "
                          "measures (at most 6.5e-5 T); plausible: a few nT (1e-9 T) to a few hundred nT")


BRIGHT_BODIES = {"sun": "Sun", "moon": "Moon"}
"""The keep-out targets (``keep_out``, ``exclusion_deg`` keys) :func:`_bright_body_cones` judges, and their names."""


def _bright_body_cones(scenario: Scenario) -> Iterator[Implausible]:
    """A keep-out cone about the Sun or the Moon (``requirements.pointing.<name>`` with ``keep_out:
    sun`` or ``moon``, a star tracker's ``exclusion_deg.sun`` or ``.moon``) with a half-angle above 0
    and below :data:`MIN_BRIGHT_BODY_CONE_DEG` (radians written as degrees): the bodies' own discs
    are 0.27 deg in radius, and a sensor the Sun or the Moon blinds needs tens of degrees (star
    trackers 25-45 deg off the Sun, 10-25 deg off the Moon), so such a cone protects nothing."""
    data = scenario.data or {}
    given: list[tuple[str, str, Any]] = []  # (path, body, the angle as written)
    for name, entry in _mapping(data, "requirements", "pointing").items():
        if isinstance(entry, dict) and isinstance(entry.get("keep_out"), str) and entry["keep_out"] in BRIGHT_BODIES:
            given.append((f"requirements.pointing.{name}.angle_deg", entry["keep_out"], entry.get("angle_deg")))
    for body, angle in _mapping(data, "simulation", "sensors", "star_tracker", "exclusion_deg").items():
        if isinstance(body, str) and body in BRIGHT_BODIES:
            given.append((f"simulation.sensors.star_tracker.exclusion_deg.{body}", body, angle))
    for path, body, written in given:
        value = _number(written)
        if value is None or not 0.0 < value < MIN_BRIGHT_BODY_CONE_DEG:
            continue
        yield Implausible(path, f"{written} deg",
                          f"is a cone of {value:g} deg about the {BRIGHT_BODIES[body]}, below "
                          f"{MIN_BRIGHT_BODY_CONE_DEG:g} deg, where it protects nothing (the disc itself is 0.27 deg in "
                          f"radius; a sensor it blinds needs tens of degrees); did you mean "
                          f"{math.degrees(value):.4g} deg (radians written as degrees)?")

PLAUSIBILITY_CHECKS: dict[str, PlausibilityCheck] = {
    "orbit_altitude": _orbit_altitude,
    "rate_bounds": _rate_bounds,
    "rate_tolerances": _rate_tolerances,
    "rate_noise": _rate_noise,
    "boundary_rates": _boundary_rates,
    "initial_rate_error": _rate_error,
    "actuator_torques": _torques,
    "slew_time": _slew_time,
    "disturbance": _disturbance,
    "wheel_axes": _wheel_axes,
    "star_tracker_noise": _star_tracker_noise,
    "star_tracker_coarse": _star_tracker_coarse,
    "star_tracker_rate": _star_tracker_rate,
    "gyro_noise": _gyro_noise,
    "attitude_noise": _attitude_noise,
    "magnetic_noise": _magnetic_noise,
    "bright_body_cones": _bright_body_cones,
}
"""Name -> check: each yields the :class:`Implausible` values of a validated scenario."""


def plausibility_warnings(scenario: Scenario) -> list[Implausible]:
    """Every check of :data:`PLAUSIBILITY_CHECKS` on ``scenario``, in order.

    Parameters
    ----------
    scenario : Scenario
        A validated scenario (its ``data``, the YAML as given, names the paths and values).

    Returns
    -------
    list of Implausible
        The warnings; empty when nothing looks like a unit slip.
    """
    with np.errstate(over="ignore", invalid="ignore"):  # a bound of 1e300 N m: its norm is inf (as unlimited),
        # not numpy's RuntimeWarning printed amid the findings
        return [warning for check in PLAUSIBILITY_CHECKS.values() for warning in check(scenario)]


def _caller_stacklevel() -> int | None:
    """The ``stacklevel`` of :func:`warnings.warn`, called from :func:`warn_implausible`, that names
    the caller of the schema (of ``parse_scenario`` or ``load``); ``None`` when that caller is
    slewbench's own code (a study's case, a slew table's entry, the command line, which report the
    findings their way or not at all)."""
    level, frame = 2, sys._getframe(2)  # 1: warn_implausible; 2: its caller
    while frame is not None and str(frame.f_globals.get("__name__", "")).startswith("scenarios.schema."):
        level, frame = level + 1, frame.f_back  # type: ignore[assignment]
    if frame is None or str(frame.f_globals.get("__name__", "")).split(".")[0] == "scenarios":
        return None
    return level


def warn_implausible(scenario: Scenario) -> list[Implausible]:
    """Issue each of :func:`plausibility_warnings` as a :class:`~scenarios.errors.PlausibilityWarning`,
    when the schema was called from outside :mod:`scenarios` (a user's script or test).

    The warning names the YAML path, the value as written and the reason (the text ``slewbench
    validate`` prints), and points at the line that called ``parse_scenario`` or ``load``. Called
    from slewbench's own code (a study's cases, a slew table's entries, the command line, which
    prints the findings itself), it warns of nothing. Python shows a warning once per text and line
    by default; ``warnings.simplefilter("error", PlausibilityWarning)`` makes them errors,
    ``"ignore"`` silences them.

    Parameters
    ----------
    scenario : Scenario
        A validated scenario.

    Returns
    -------
    list of Implausible
        The findings warned about (empty when called from slewbench's own code).
    """
    level = _caller_stacklevel()
    if level is None:
        return []
    found = plausibility_warnings(scenario)
    for finding in found:
        warnings.warn(PlausibilityWarning(finding.path, finding.value, finding.reason), stacklevel=level)
    return found
