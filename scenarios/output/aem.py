"""CCSDS Attitude Ephemeris Messages (AEM, CCSDS 504.0-B-2, KVN): a row's attitude history as a
file that attitude tools read, and a small reader for it.

The conventions of the standard, and how slewbench's map onto them:

* **Quaternion.** Version 2 writes ``Q1 Q2 Q3 QC``, scalar **last**, and the quaternion "from
  ``REF_FRAME_A`` to ``REF_FRAME_B``" is the rotation that carries A's basis vectors onto B's,
  so that coordinates transform as :math:`X_B = M_{BA} X_A` (annex F2). With ``REF_FRAME_A`` the
  inertial frame and ``REF_FRAME_B`` the body (``SC_BODY_1``), that rotation is slewbench's
  body-to-inertial ``q`` itself (:math:`v_I = R(q) v_B`, so :math:`M_{BA} = R(q)^T`): the
  components are only reordered, ``[q1, q2, q3, q0]``. Version 2 has no ``ATTITUDE_DIR`` and no
  ``QUATERNION_TYPE`` (both removed, annex J).
* **Frames.** ``REF_FRAME_A = GCRF`` (the ICRF's axes), ``CENTER_NAME = EARTH``,
  ``REF_FRAME_B = SC_BODY_1``; the body rate of ``QUATERNION/ANGVEL`` is in body axes
  (``ANGVEL_FRAME = SC_BODY_1``) and in **deg/s** (4.2.4.6).
* **Time.** Time tags are absolute: ``epoch + t`` (``t`` elapsed SI seconds, leap seconds
  counted) in the chosen ``TIME_SYSTEM`` (:data:`TIME_SYSTEMS`): UTC (a leap second is written
  ``23:59:60``, 4.2.4.7.3), TAI, TT, TDB or GPS (TAI − 19 s), through ERFA, with nanosecond digits. A run without
  an ``epoch`` has no absolute time and no GCRF; it is refused (:class:`~scenarios.errors.ScenarioError`
  naming ``epoch``), never given an invented date.
* **Numbers.** 16 significant digits (``d.dddddddddddddddE±xx``, the most 6.8.4 allows):
  a value read back differs from the double written by at most half a unit in the 16th digit
  (below 1e-16 for a quaternion component). ``-0`` is written ``0``; NaN and infinities are not
  allowed (6.8.5), so a series holding one is refused.
* **Sign.** ``q`` and ``-q`` are one attitude; the series is written without sign jumps
  (:func:`ocp.quat.continuous`), so that a reader's interpolation between samples is meaningful.
* **Interpolation.** ``QUATERNION``: ``LINEAR``, degree 1; ``QUATERNION/ANGVEL``: ``HERMITE``,
  degree 3 (the rates are the derivatives at the nodes); a segment of fewer than degree + 1 lines
  declares degree lines − 1 (a reader such as Orekit interpolates over degree + 1 lines), one of a
  single line no interpolation. Each segment's whole span is usable.
* **Rate jumps.** A reference whose body rate jumps (natural motion's step stop: an impulse, which
  no consumer's interpolation may smooth over) is written as one segment per stretch between its
  jumps (:func:`rate_jump_starts`): a segment ends at the last sample before a jump, with the rate
  on that side, and the next starts at the first sample after it, with the rate on its side; the
  interval between them belongs to no segment, so a reader interpolates across no jump (the
  standard's segments: each metadata block with its own ``START_TIME``/``STOP_TIME`` and
  ``USEABLE_START_TIME``/``USEABLE_STOP_TIME``, 4.2.2).
* **Traceability.** The header comments of an export name the run's slewbench version and date,
  the run directory (a trade study's case: ``<sweep>/cases/<N>``), every provenance entry of
  ``results.json`` but the scenario (seeds included) and the scenario's ``truth:`` section as run
  (a Monte Carlo case's dispersed values), one key per line.

:func:`aem_text` writes one message (one segment, or one per stretch between the given segment
starts), :func:`read_aem` reads a KVN AEM (any number of segments; the data of the quaternion
types) and :func:`time_tags` gives the time tags.
"""
from __future__ import annotations

import datetime
import json
import re
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp.dynamics.ephemeris import parse_utc, tdb_julian_date
from ocp.quat import continuous, unit_norm_error
from planners.reference import JUMP_TOLERANCE
from scenarios.errors import ScenarioError

if TYPE_CHECKING:
    from scenarios.output.export import RunRecord

__all__ = [
    "ATTITUDE_TYPES",
    "TIME_SYSTEMS",
    "AemMessage",
    "AemOptions",
    "AemSegment",
    "aem_text",
    "check_aem_export",
    "format_number",
    "provenance_comments",
    "rate_jump_starts",
    "read_aem",
    "time_tags",
    "write_aem_files",
]

Array = NDArray[np.float64]

AEM_VERSION = "2.0"
"""``CCSDS_AEM_VERS`` written: CCSDS 504.0-B-2."""
TIME_SYSTEMS = ("UTC", "TAI", "TT", "TDB", "GPS")
"""``TIME_SYSTEM`` values slewbench writes (SANA time systems)."""
_TAI_OFFSET_S = {"TAI": 0.0, "TT": 32.184, "GPS": -19.0}
"""Time scales a constant offset from TAI [s] (TT = TAI + 32.184 s, GPS = TAI - 19 s exactly);
UTC and TDB are converted by ERFA."""
ATTITUDE_TYPES = {"QUATERNION": ("LINEAR", 1), "QUATERNION/ANGVEL": ("HERMITE", 3)}
"""``ATTITUDE_TYPE`` values slewbench writes, with the interpolation method and degree declared."""
INERTIAL_FRAME = "GCRF"
"""``REF_FRAME_A``: slewbench's inertial frame (geocentric, ICRF axes)."""
BODY_FRAME = "SC_BODY_1"
"""``REF_FRAME_B`` (and ``ANGVEL_FRAME``): the spacecraft body frame."""
TIME_DIGITS = 9
"""Decimal digits of the seconds in a time tag (nanoseconds)."""
_SECONDS_PER_DAY = 86400.0
_DATA_COLUMNS = {"QUATERNION": 4, "QUATERNION/DERIVATIVE": 8, "QUATERNION/ANGVEL": 7}


def time_tags(epoch: datetime.datetime | str, t: ArrayLike, time_system: str = "UTC") -> list[str]:
    """CCSDS time tags (``YYYY-MM-DDThh:mm:ss.fffffffff``) of ``epoch + t`` in ``time_system``.

    Parameters
    ----------
    epoch : datetime.datetime or str
        The instant of ``t = 0``, UTC (:func:`ocp.dynamics.ephemeris.parse_utc`).
    t : (N,) array_like
        SI seconds elapsed since the epoch [s] (a leap second between is counted).
    time_system : str, optional
        One of :data:`TIME_SYSTEMS`.

    Returns
    -------
    list of str
        One tag per time, seconds to :data:`TIME_DIGITS` decimals; in UTC a leap second reads
        ``23:59:60``.
    """
    import erfa  # ERFA's time scales, as in the ephemeris

    if time_system not in TIME_SYSTEMS:
        raise ValueError(f"time system {time_system!r} is not one of {', '.join(TIME_SYSTEMS)}")
    t = np.atleast_1d(np.asarray(t, dtype=float)).reshape(-1)
    start = parse_utc(epoch)
    with warnings.catch_warnings():
        # "dubious year": after ERFA's last leap second TAI - UTC is held (ocp.dynamics.ephemeris)
        warnings.simplefilter("ignore", erfa.ErfaWarning)
        if time_system == "TDB":
            day1, day2 = tdb_julian_date(start, t)
        else:
            second = start.second + start.microsecond * 1e-6
            utc1, utc2 = erfa.dtf2d("UTC", start.year, start.month, start.day, start.hour, start.minute, second)
            tai1, tai2 = erfa.utctai(utc1, utc2)
            day1, day2 = np.full(t.shape, float(tai1)), float(tai2) + t / _SECONDS_PER_DAY
            if time_system == "UTC":
                day1, day2 = erfa.taiutc(day1, day2)
            else:
                day2 = day2 + _TAI_OFFSET_S[time_system] / _SECONDS_PER_DAY
        years, months, days, hmsf = erfa.d2dtf(time_system, TIME_DIGITS, day1, day2)
    return [f"{y:04d}-{mo:02d}-{d:02d}T{c['h']:02d}:{c['m']:02d}:{c['s']:02d}.{c['f']:0{TIME_DIGITS}d}"
            for y, mo, d, c in zip(years, months, days, hmsf)]


def format_number(value: float) -> str:
    """A finite number in the KVN floating-point form with 16 significant digits (6.8.4.2).

    Parameters
    ----------
    value : float
        A finite number.

    Returns
    -------
    str
        ``d.dddddddddddddddE±xx``; ``-0`` is written as ``0`` (6.8.5 does not allow ``-0``).
    """
    if not np.isfinite(value):
        raise ValueError(f"an AEM holds finite numbers only, not {value}")
    return f"{float(value) + 0.0:.15E}"


def _kvn_text(text: str) -> str:
    """A KVN text value: printable ASCII, one case (6.6.3, 6.8.6), blanks as written."""
    ascii_text = "".join(c if 32 <= ord(c) < 127 else "_" for c in text).strip()
    return ascii_text.upper() or "UNKNOWN"


KVN_LINE = 254
"""Longest line of a KVN message [characters], line ends not counted (CCSDS 504.0-B-2)."""


def _excerpt(text: str, size: int = 40) -> str:
    """``text`` as a repr, cut to about ``size`` characters."""
    return repr(text) if len(text) <= size else f"{text[:size]!r}..."


def _comment(text: str) -> list[str]:
    """``COMMENT`` lines for ``text`` (printable ASCII, at most 254 characters a line)."""
    lines = []
    for line in text.splitlines() or [""]:
        clean = "".join(c if 32 <= ord(c) < 127 else "?" for c in line)
        while True:
            lines.append(f"COMMENT {clean[:240]}".rstrip())
            clean = clean[240:]
            if not clean:
                break
    return lines


def aem_text(epoch: datetime.datetime | str | None, t: ArrayLike, q: ArrayLike, omega: ArrayLike | None = None, *,
             object_name: str, object_id: str = "UNKNOWN", originator: str = "SLEWBENCH",
             time_system: str = "UTC", created: datetime.datetime | None = None,
             header_comments: Sequence[str] = (), comments: Sequence[str] = (),
             segment_starts: Sequence[int] = ()) -> str:
    """One AEM (KVN, version 2.0) of an attitude history: one segment, or one per stretch between
    ``segment_starts``.

    Parameters
    ----------
    epoch : datetime.datetime, str or None
        The instant of ``t = 0``, UTC; ``None`` is refused (no absolute time, no GCRF).
    t : (N,) array_like
        Sample times [s] from the epoch, increasing, at least two.
    q : (N, 4) array_like
        Attitude, body to inertial (GCRF), scalar first (slewbench's convention); each of unit
        norm within :data:`ocp.quat.UNIT_NORM_TOLERANCE` (:func:`ocp.quat.unit_norm_error`, the
        rule of the YAML loader and ``ManeuverProblem``), then normalised.
    omega : (N, 3) array_like, optional
        Body rate [rad/s], body axes: written as ``QUATERNION/ANGVEL`` in deg/s; ``None``:
        ``QUATERNION``.
    object_name, object_id : str
        ``OBJECT_NAME`` and ``OBJECT_ID`` (upper-cased; ``UNKNOWN`` when not known, 4.2.3).
    originator : str, optional
        ``ORIGINATOR``: the creating agency or operator.
    time_system : str, optional
        ``TIME_SYSTEM`` of every time tag (:data:`TIME_SYSTEMS`).
    created : datetime.datetime, optional
        ``CREATION_DATE`` (UTC; default now).
    header_comments, comments : sequence of str, optional
        ``COMMENT`` lines after the version line and at the start of each segment's metadata.
    segment_starts : sequence of int, optional
        Indices of the samples that start a new segment (in ``1 .. N-1``; a rate jump between
        sample ``k - 1`` and sample ``k``, :func:`rate_jump_starts`): each segment has its own
        metadata, whose ``START_TIME``, ``USEABLE_START_TIME``, ``USEABLE_STOP_TIME`` and
        ``STOP_TIME`` are its first and last samples' (a comment says why it ends or starts there).
        Empty (default): one segment.

    Returns
    -------
    str
        The message, lines ended by a line feed.

    Raises
    ------
    ScenarioError
        Without an epoch (at ``epoch``).
    ValueError
        Fewer than two samples, times not increasing, shapes that disagree, non-finite values, a
        quaternion that is zero or not of unit norm (naming its index and value) or a segment
        start outside ``1 .. N-1``.
    """
    if epoch is None:
        raise ScenarioError("epoch", "no epoch: the times are not absolute and the inertial frame is not the GCRF; a "
                                     "CCSDS AEM needs both (give the scenario an `epoch`, UTC)")
    t = np.asarray(t, dtype=float).reshape(-1)
    q = np.asarray(q, dtype=float)
    if q.shape != (t.size, 4):
        raise ValueError(f"q must be ({t.size}, 4), got {q.shape}")
    if t.size < 2:
        raise ValueError("an AEM needs at least two samples to interpolate between")
    columns = [q]
    attitude_type = "QUATERNION"
    if omega is not None:
        omega = np.asarray(omega, dtype=float)
        if omega.shape != (t.size, 3):
            raise ValueError(f"omega must be ({t.size}, 3), got {omega.shape}")
        columns.append(omega)
        attitude_type = "QUATERNION/ANGVEL"
    if not all(np.all(np.isfinite(block)) for block in [t, *columns]):
        raise ValueError("the series holds non-finite values, which an AEM cannot carry (CCSDS 504.0-B-2, 6.8.5)")
    for index, sample in enumerate(q):  # the library's rule for a quaternion given as input: never normalised quietly
        problem = unit_norm_error(sample)
        if problem is not None:
            raise ValueError(f"q[{index}] = {sample.tolist()}: {problem}")
    if np.any(np.diff(t) <= 0.0):
        raise ValueError("sample times must increase strictly")
    tags = time_tags(epoch, t, time_system)
    if len(set(tags)) != len(tags):
        raise ValueError(f"samples closer than 1e-{TIME_DIGITS} s give repeated time tags")
    q_continuous = continuous(q / np.linalg.norm(q, axis=1, keepdims=True))
    data = np.hstack([q_continuous[:, 1:], q_continuous[:, :1]] + ([np.degrees(omega)] if omega is not None else []))
    method, degree = ATTITUDE_TYPES[attitude_type]
    created = created or datetime.datetime.now(datetime.timezone.utc)
    if created.tzinfo is not None:
        created = created.astimezone(datetime.timezone.utc).replace(tzinfo=None)
    lines = [f"CCSDS_AEM_VERS = {AEM_VERSION}"]
    for text in header_comments:
        lines += _comment(text)
    lines += [f"CREATION_DATE = {created.strftime('%Y-%m-%dT%H:%M:%S')}",
              f"ORIGINATOR = {_kvn_text(originator)}", ""]
    starts = sorted({int(k) for k in segment_starts})
    if starts and not (starts[0] >= 1 and starts[-1] <= t.size - 1):
        raise ValueError(f"segment starts must lie in 1 .. {t.size - 1}, got {starts}")
    bounds = list(zip([0, *starts], [*starts, t.size]))
    for number, (first, stop) in enumerate(bounds, start=1):
        lines.append("META_START")
        for text in comments:
            lines += _comment(text)
        if len(bounds) > 1:
            why = [f"the body rate jumps between {t[first - 1]:.9g} s and {t[first]:.9g} s"] if first > 0 else []
            why += [f"the body rate jumps between {t[stop - 1]:.9g} s and {t[stop]:.9g} s"] if stop < t.size else []
            lines += _comment(f"segment {number} of {len(bounds)}, t = {t[first]:.9g} s to {t[stop - 1]:.9g} s: "
                              + " and ".join(why) + " (no interpolation across a jump)")
        lines += [f"OBJECT_NAME = {_kvn_text(object_name)}", f"OBJECT_ID = {_kvn_text(object_id)}",
                  "CENTER_NAME = EARTH", f"REF_FRAME_A = {INERTIAL_FRAME}", f"REF_FRAME_B = {BODY_FRAME}",
                  f"TIME_SYSTEM = {time_system}", f"START_TIME = {tags[first]}",
                  f"USEABLE_START_TIME = {tags[first]}", f"USEABLE_STOP_TIME = {tags[stop - 1]}",
                  f"STOP_TIME = {tags[stop - 1]}", f"ATTITUDE_TYPE = {attitude_type}"]
        if omega is not None:
            lines.append(f"ANGVEL_FRAME = {BODY_FRAME}")
        # a reader interpolating over degree + 1 lines (Orekit's tabulated provider) needs that many
        # in the segment: a short segment declares a lower degree, one line none (nothing to interpolate)
        usable = min(degree, stop - first - 1)
        if usable >= 1:
            lines += [f"INTERPOLATION_METHOD = {method}", f"INTERPOLATION_DEGREE = {usable}"]
        lines += ["META_STOP", "", "DATA_START"]
        lines += [" ".join([tag, *(format_number(v) for v in row)])
                  for tag, row in zip(tags[first:stop], data[first:stop])]
        lines += ["DATA_STOP", ""]
    return "\n".join(lines)


def rate_jump_starts(t: ArrayLike, omega: ArrayLike, omega_dot: ArrayLike | None = None,
                     jump_times: Sequence[float] = ()) -> list[int]:
    """Where a sampled body rate jumps: the indices of the first samples after each jump.

    Between samples ``k`` and ``k + 1`` (``h`` apart) the rate jumps when it changes by more than
    :data:`~planners.reference.JUMP_TOLERANCE` plus twice what its derivative explains over the
    step, ``2 h max(‖ω̇_k‖, ‖ω̇_{k+1}‖)`` (the derivative where it is not finite: the larger of
    the neighbouring steps' ``‖Δω‖ / h``). A smooth rate changes by at most ``h`` times its
    largest derivative over the step, which differs from the ends' by ``O(h²)``; a jump smaller
    than what the derivative explains over a step cannot be told from the samples, hence
    ``jump_times`` (a run's recorded ``rate_jump_time_s``): a jump at ``t_k`` itself splits on the
    side of the larger change.

    Parameters
    ----------
    t : (N,) array_like
        Increasing sample times [s].
    omega : (N, 3) array_like
        Body rate at ``t`` [rad/s].
    omega_dot : (N, 3) array_like, optional
        Its derivative [rad/s²] (NaN where not known); ``None``: not known.
    jump_times : sequence of float, optional
        Times [s] of jumps known otherwise; those outside ``(t[0], t[-1]]`` are ignored.

    Returns
    -------
    list of int
        Increasing indices in ``1 .. N-1``: a segment starts at each.
    """
    t = np.asarray(t, dtype=float).reshape(-1)
    omega = np.asarray(omega, dtype=float).reshape(t.size, 3)
    if t.size < 2:
        return []
    h = np.diff(t)
    change = np.linalg.norm(np.diff(omega, axis=0), axis=1)
    quotient = change / h
    derivative = (np.full(t.size, np.nan) if omega_dot is None
                  else np.linalg.norm(np.asarray(omega_dot, dtype=float).reshape(t.size, 3), axis=1))
    left = np.concatenate([[0.0], quotient[:-1]])  # the step before each step
    right = np.concatenate([quotient[1:], [0.0]])  # the step after
    neighbours = np.maximum(left, right)
    slope_start = np.where(np.isfinite(derivative[:-1]), derivative[:-1], neighbours)
    slope_end = np.where(np.isfinite(derivative[1:]), derivative[1:], neighbours)
    explained = JUMP_TOLERANCE + 2.0 * h * np.maximum(slope_start, slope_end)
    starts = {int(k) + 1 for k in np.flatnonzero(change > explained)}
    for time in jump_times:
        if time is None or not np.isfinite(time) or not t[0] < time <= t[-1]:
            continue
        k = int(np.searchsorted(t, time, side="left"))  # t[k-1] < time <= t[k]
        if np.isclose(t[k], time, rtol=0.0, atol=1e-9) and k + 1 < t.size and change[k] > change[k - 1]:
            k += 1  # the sample at the jump holds the rate before it
        starts.add(k)
    return sorted(starts)


def provenance_comments(provenance: dict[str, Any], directory: Path | None = None) -> list[str]:
    """Comment lines that make an export traceable to its run (and a trade study's case).

    Parameters
    ----------
    provenance : dict
        ``results.json``'s ``provenance`` (:func:`~scenarios.output.provenance.run_provenance`).
    directory : Path, optional
        The run directory (a study's case re-run in full: ``<sweep>/cases/<N>``).

    Returns
    -------
    list of str
        ``run directory <path>``; ``provenance <entry> = <value>`` per entry but the scenario's
        data (nested ones dotted: ``seeds.simulation.sensor_noise.seed``); ``truth.<key> =
        <value>`` per key of the scenario's ``truth:`` section as run (a Monte Carlo case's
        dispersed values; a matrix ``truth.<key>[i]`` one row a line), or a line saying the plant
        is the design model.
    """
    lines = [] if directory is None else [f"run directory {directory}"]
    for key, value in _leaves(provenance, ""):
        if key != "scenario" and not key.startswith("scenario."):
            lines.append(f"provenance {key} = {_json_text(value)}")
    scenario = provenance.get("scenario")
    if isinstance(scenario, dict):
        truth = scenario.get("truth")
        if isinstance(truth, dict) and truth:
            for key, value in _leaves(truth, ""):  # a matrix one row a line, under a comment line's length
                rows = value if isinstance(value, list) and value and all(isinstance(v, list) for v in value) else None
                lines += ([f"truth.{key} = {_json_text(value)}"] if rows is None
                          else [f"truth.{key}[{i}] = {_json_text(item)}" for i, item in enumerate(rows)])
        else:
            lines.append("no truth section: the closed loop integrated the design model")
    return lines


def _leaves(value: Any, path: str) -> list[tuple[str, Any]]:
    """``(dotted path, value)`` of the leaves of nested dicts (lists are leaves)."""
    if isinstance(value, dict) and value:
        return [leaf for key, item in value.items() for leaf in _leaves(item, f"{path}.{key}" if path else str(key))]
    return [(path, value)]


def _json_text(value: Any) -> str:
    return value if isinstance(value, str) else json.dumps(value, default=str)


@dataclass(frozen=True)
class AemSegment:
    """One metadata block and its data, as read.

    Parameters
    ----------
    metadata : dict of str to str
        The metadata keywords and their values, as written.
    epochs : list of str
        The data lines' time tags, as written.
    values : (N, K) ndarray
        The data lines' numbers, in the order of the standard (quaternions scalar last).
    comments : list of str
        The metadata and data comments.
    """

    metadata: dict[str, str]
    epochs: list[str]
    values: Array
    comments: list[str] = field(default_factory=list)

    def quaternions(self) -> Array:
        """The quaternions from ``REF_FRAME_A`` to ``REF_FRAME_B``, reordered scalar first.

        Returns
        -------
        (N, 4) ndarray
            ``[QC, Q1, Q2, Q3]`` per line: for ``REF_FRAME_A`` inertial and ``REF_FRAME_B`` the
            body, slewbench's body-to-inertial ``q``.
        """
        if not self.metadata.get("ATTITUDE_TYPE", "").startswith("QUATERNION"):
            raise ValueError(f"ATTITUDE_TYPE {self.metadata.get('ATTITUDE_TYPE')} holds no quaternion")
        return np.column_stack([self.values[:, 3], self.values[:, :3]])


@dataclass(frozen=True)
class AemMessage:
    """A KVN AEM, as read by :func:`read_aem`.

    Parameters
    ----------
    header : dict of str to str
        ``CCSDS_AEM_VERS``, ``CREATION_DATE``, ``ORIGINATOR`` (and ``MESSAGE_ID``, ...).
    segments : list of AemSegment
        The segments in file order.
    comments : list of str
        The header comments.
    """

    header: dict[str, str]
    segments: list[AemSegment]
    comments: list[str] = field(default_factory=list)


_KEY_VALUE = re.compile(r"^\s*([A-Z0-9_]+)\s*=\s*(.*?)\s*$")


def read_aem(text: str) -> AemMessage:
    """Read a KVN AEM (CCSDS 504.0-B-2; version 1 files read too, their keywords kept as written).

    Parameters
    ----------
    text : str
        The message.

    Returns
    -------
    AemMessage
        The header, and per segment its metadata, time tags and numbers.

    Raises
    ------
    ValueError
        A line out of place, a missing ``CCSDS_AEM_VERS``, a block not closed, or a data line
        whose count of numbers does not fit its ``ATTITUDE_TYPE``.
    """
    header: dict[str, str] = {}
    header_comments: list[str] = []
    segments: list[AemSegment] = []
    state = "header"
    metadata: dict[str, str] = {}
    comments: list[str] = []
    epochs: list[str] = []
    rows: list[list[float]] = []
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line:
            continue
        if line.startswith("COMMENT"):
            (header_comments if state == "header" else comments).append(line[len("COMMENT"):].strip())
            continue
        if line == "META_START" and state in ("header", "between"):
            if state == "header" and "CCSDS_AEM_VERS" not in header:
                raise ValueError("no CCSDS_AEM_VERS before the first META_START")
            state, metadata, comments, epochs, rows = "meta", {}, [], [], []
        elif line == "META_STOP" and state == "meta":
            state = "after_meta"
        elif line == "DATA_START" and state == "after_meta":
            state = "data"
        elif line == "DATA_STOP" and state == "data":
            segments.append(AemSegment(metadata, epochs, np.array(rows, dtype=float).reshape(len(rows), -1), comments))
            state = "between"
        elif state == "data":
            fields = line.split()
            expected = _DATA_COLUMNS.get(metadata.get("ATTITUDE_TYPE", ""))
            if expected is not None and len(fields) != expected + 1:
                raise ValueError(f"line {number}: {len(fields) - 1} numbers, {metadata['ATTITUDE_TYPE']} has {expected}")
            epochs.append(fields[0])
            rows.append([float(value) for value in fields[1:]])
        elif state in ("header", "meta") and (match := _KEY_VALUE.match(line)):
            (header if state == "header" else metadata)[match.group(1)] = match.group(2)
        else:
            raise ValueError(f"line {number}: unexpected {line[:40]!r} ({state.replace('_', ' ')})")
    if state != "between":
        raise ValueError(f"the message ends inside a block ({state.replace('_', ' ')}) or has no segment")
    return AemMessage(header, segments, header_comments)


@dataclass(frozen=True)
class AemOptions:
    """Options of the ``aem`` export (:data:`scenarios.output.export.EXPORT_FORMATS`).

    Parameters
    ----------
    time_system : str, optional
        ``TIME_SYSTEM``: ``UTC`` (default), ``TAI``, ``TT``, ``TDB`` or ``GPS`` (TAI − 19 s).
    attitude_type : str, optional
        ``QUATERNION/ANGVEL`` (default: quaternion and body rate) or ``QUATERNION``.
    originator : str, optional
        ``ORIGINATOR``: your agency or operator (the abbreviation of the SANA registry of
        organizations).
    object_name : str, optional
        ``OBJECT_NAME``; empty: the scenario's name.
    object_id : str, optional
        ``OBJECT_ID``, the international designator (``2027-012A``); ``UNKNOWN`` by default.
    """

    time_system: str = "UTC"
    attitude_type: str = "QUATERNION/ANGVEL"
    originator: str = "SLEWBENCH"
    object_name: str = ""
    object_id: str = "UNKNOWN"


def check_aem_export(run: RunRecord, options: AemOptions) -> None:
    """Refuse, before anything is written, a run or options an AEM cannot take.

    Parameters
    ----------
    run : scenarios.output.export.RunRecord
        The finished run.
    options : AemOptions
        The export's options.

    Raises
    ------
    ScenarioError
        An option that is not a valid value (at ``--option NAME``: a time system or attitude type
        not listed, a name too long for its KVN line, with characters outside printable ASCII, or
        an empty originator or object ID), or a run without an epoch
        (at ``epoch``).
    """
    if options.time_system not in TIME_SYSTEMS:
        raise ScenarioError("--option time_system", f"{options.time_system!r} is not one of {', '.join(TIME_SYSTEMS)}")
    if options.attitude_type not in ATTITUDE_TYPES:
        raise ScenarioError("--option attitude_type",
                            f"{options.attitude_type!r} is not one of {', '.join(ATTITUDE_TYPES)}")
    for name, keyword in (("originator", "ORIGINATOR"), ("object_name", "OBJECT_NAME"), ("object_id", "OBJECT_ID")):
        text, room = getattr(options, name), KVN_LINE - len(f"{keyword} = ")
        unwritable = sorted({c for c in text if not 32 <= ord(c) < 127})
        if unwritable:  # written as "_": the message would carry another name than the one given
            raise ScenarioError(f"--option {name}", f"{text!r} has characters a KVN line cannot carry "
                                                    f"({', '.join(repr(c) for c in unwritable)}): expected "
                                                    "printable ASCII (letters, digits, spaces, punctuation)")
        if name != "object_name" and not text.strip():  # written UNKNOWN: not the value given
            raise ScenarioError(f"--option {name}", f"{text!r} is empty: expected the {keyword} value "
                                                    f"(leave the option out for its default, {getattr(AemOptions, name)})")
        if len(text) > room:  # the line would break the KVN limit: a message other readers refuse
            raise ScenarioError(f"--option {name}", f"{len(text)} characters ({_excerpt(text)}): expected at most "
                                                    f"{room}, so that the {keyword} line keeps to the {KVN_LINE} "
                                                    "characters of a KVN line")
    if run.epoch is None:
        raise ScenarioError("epoch", f"the run in {run.directory} has no epoch (results.json \"epoch\": null), so its "
                                     "times are not absolute and its inertial frame is not the GCRF; a CCSDS AEM "
                                     "needs both: give the scenario an `epoch` (UTC, e.g. 2027-03-20T12:00:00Z) and "
                                     "run it again")


def write_aem_files(run: RunRecord, directory: Path, options: AemOptions) -> list[str]:
    """The ``aem`` export: ``<row>.closed_loop.aem`` and ``<row>.reference.aem`` per simulated row,
    traceable to the run (:func:`provenance_comments`), a reference split at its rate jumps
    (:func:`rate_jump_starts`, with the row's recorded ``rate_jump_time_s``).

    Parameters
    ----------
    run : scenarios.output.export.RunRecord
        The finished run.
    directory : Path
        Where to write the files.
    options : AemOptions
        The messages' time system, attitude type and names.

    Returns
    -------
    list of str
        Notes: the rows (or histories) left out, and why.

    Raises
    ------
    ScenarioError
        As :func:`check_aem_export`.
    """
    check_aem_export(run, options)
    notes = []
    produced = f"slewbench {run.provenance.get('slewbench', '?')}, run finished {run.provenance.get('date_utc', '?')}"
    traced = provenance_comments(run.provenance, run.directory)
    for row in run.rows:
        if row.timeseries is None:
            notes.append(f"row {row.label!r}: not simulated ({row.status}), no attitude history to export")
            continue
        series = row.series()
        pair = f"{row.planner or 'regulation'} / {row.controller}"
        for scope, q, omega in (("closed_loop", series["q"], series["omega"]),
                                ("reference", series["ref_q"], series["ref_omega"])):
            words = scope.replace("_", " ")
            if np.all(np.isnan(q)):
                notes.append(f"row {row.label!r}: no reference (regulation mode), no reference AEM")
                continue
            # the reference's rate may jump (an impulse); the closed loop's, integrated under finite torques, does not
            starts = (rate_jump_starts(series["t"], omega, series["ref_omega_dot"], row.rate_jump_times)
                      if scope == "reference" and np.all(np.isfinite(omega)) else [])
            try:
                text = aem_text(run.epoch, series["t"], q,
                                omega if options.attitude_type == "QUATERNION/ANGVEL" else None,
                                object_name=options.object_name or run.scenario, object_id=options.object_id,
                                originator=options.originator, time_system=options.time_system,
                                header_comments=[f"{produced}: scenario {run.scenario}", *traced],
                                comments=[f"row {row.label} ({pair}), status {row.status}: {words} attitude",
                                          (f"quaternion from GCRF to SC_BODY_1 (slewbench's body-to-inertial q), "
                                           f"t = 0 at {run.epoch}")],
                                segment_starts=starts)
            except ValueError as error:
                notes.append(f"row {row.label!r}: {words} not exported: {error}")
                continue
            (directory / f"{row.stem}.{scope}.aem").write_text(text, encoding="ascii")
    return notes
