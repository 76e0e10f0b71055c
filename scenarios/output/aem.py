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
  ``23:59:60``, 4.2.4.7.3), TAI, TT or TDB, through ERFA, with nanosecond digits. A run without
  an ``epoch`` has no absolute time and no GCRF; it is refused (:class:`~scenarios.errors.ScenarioError`
  naming ``epoch``), never given an invented date.
* **Numbers.** 16 significant digits (``d.dddddddddddddddE±xx``, the most 6.8.4 allows):
  a value read back differs from the double written by at most half a unit in the 16th digit
  (below 1e-16 for a quaternion component). ``-0`` is written ``0``; NaN and infinities are not
  allowed (6.8.5), so a series holding one is refused.
* **Sign.** ``q`` and ``-q`` are one attitude; the series is written without sign jumps
  (:func:`ocp.quat.continuous`), so that a reader's interpolation between samples is meaningful.
* **Interpolation.** ``QUATERNION``: ``LINEAR``, degree 1; ``QUATERNION/ANGVEL``: ``HERMITE``,
  degree 3 (the rates are the derivatives at the nodes). The whole span is usable.

:func:`aem_text` writes one message (one segment), :func:`read_aem` reads a KVN AEM (any number
of segments; the data of the quaternion types) and :func:`time_tags` gives the time tags.
"""
from __future__ import annotations

import datetime
import re
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp.dynamics.ephemeris import parse_utc, tdb_julian_date
from ocp.quat import continuous
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
    "read_aem",
    "time_tags",
    "write_aem_files",
]

Array = NDArray[np.float64]

AEM_VERSION = "2.0"
"""``CCSDS_AEM_VERS`` written: CCSDS 504.0-B-2."""
TIME_SYSTEMS = ("UTC", "TAI", "TT", "TDB")
"""``TIME_SYSTEM`` values slewbench writes (SANA time systems)."""
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
            elif time_system == "TT":
                day1, day2 = erfa.taitt(day1, day2)
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
             header_comments: Sequence[str] = (), comments: Sequence[str] = ()) -> str:
    """One AEM (KVN, version 2.0, one segment) of an attitude history.

    Parameters
    ----------
    epoch : datetime.datetime, str or None
        The instant of ``t = 0``, UTC; ``None`` is refused (no absolute time, no GCRF).
    t : (N,) array_like
        Sample times [s] from the epoch, increasing, at least two.
    q : (N, 4) array_like
        Attitude, body to inertial (GCRF), scalar first (slewbench's convention).
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
        ``COMMENT`` lines after the version line and at the start of the metadata.

    Returns
    -------
    str
        The message, lines ended by a line feed.

    Raises
    ------
    ScenarioError
        Without an epoch (at ``epoch``).
    ValueError
        Fewer than two samples, times not increasing, shapes that disagree or non-finite values.
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
              f"ORIGINATOR = {_kvn_text(originator)}", "", "META_START"]
    for text in comments:
        lines += _comment(text)
    lines += [f"OBJECT_NAME = {_kvn_text(object_name)}", f"OBJECT_ID = {_kvn_text(object_id)}",
              "CENTER_NAME = EARTH", f"REF_FRAME_A = {INERTIAL_FRAME}", f"REF_FRAME_B = {BODY_FRAME}",
              f"TIME_SYSTEM = {time_system}", f"START_TIME = {tags[0]}", f"USEABLE_START_TIME = {tags[0]}",
              f"USEABLE_STOP_TIME = {tags[-1]}", f"STOP_TIME = {tags[-1]}", f"ATTITUDE_TYPE = {attitude_type}"]
    if omega is not None:
        lines.append(f"ANGVEL_FRAME = {BODY_FRAME}")
    lines += [f"INTERPOLATION_METHOD = {method}", f"INTERPOLATION_DEGREE = {degree}", "META_STOP", "", "DATA_START"]
    lines += [" ".join([tag, *(format_number(v) for v in row)]) for tag, row in zip(tags, data)]
    lines += ["DATA_STOP", ""]
    return "\n".join(lines)


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
        ``TIME_SYSTEM``: ``UTC`` (default), ``TAI``, ``TT`` or ``TDB``.
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
        An option that is not a valid value (at ``--option NAME``), or a run without an epoch
        (at ``epoch``).
    """
    if options.time_system not in TIME_SYSTEMS:
        raise ScenarioError("--option time_system", f"{options.time_system!r} is not one of {', '.join(TIME_SYSTEMS)}")
    if options.attitude_type not in ATTITUDE_TYPES:
        raise ScenarioError("--option attitude_type",
                            f"{options.attitude_type!r} is not one of {', '.join(ATTITUDE_TYPES)}")
    if run.epoch is None:
        raise ScenarioError("epoch", f"the run in {run.directory} has no epoch (results.json \"epoch\": null), so its "
                                     "times are not absolute and its inertial frame is not the GCRF; a CCSDS AEM "
                                     "needs both: give the scenario an `epoch` (UTC, e.g. 2027-03-20T12:00:00Z) and "
                                     "run it again")


def write_aem_files(run: RunRecord, directory: Path, options: AemOptions) -> list[str]:
    """The ``aem`` export: ``<row>.closed_loop.aem`` and ``<row>.reference.aem`` per simulated row.

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
            try:
                text = aem_text(run.epoch, series["t"], q,
                                omega if options.attitude_type == "QUATERNION/ANGVEL" else None,
                                object_name=options.object_name or run.scenario, object_id=options.object_id,
                                originator=options.originator, time_system=options.time_system,
                                header_comments=[f"{produced}: scenario {run.scenario}"],
                                comments=[f"row {row.label} ({pair}), status {row.status}: {words} attitude",
                                          (f"quaternion from GCRF to SC_BODY_1 (slewbench's body-to-inertial q), "
                                           f"t = 0 at {run.epoch}")])
            except ValueError as error:
                notes.append(f"row {row.label!r}: {words} not exported: {error}")
                continue
            (directory / f"{row.stem}.{scope}.aem").write_text(text, encoding="ascii")
    return notes
