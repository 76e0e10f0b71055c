"""A reference as the waypoint file of Basilisk's ``waypointReference`` module.

Basilisk (AVS Lab, University of Colorado) flies an externally computed manoeuvre through its
``waypointReference`` flight-software module, which reads a plain-text file of one waypoint per
line::

    t, a_1, a_2, a_3[, a_4], ω_1, ω_2, ω_3, ω̇_1, ω̇_2, ω̇_3

* ``t`` [s], from the start of the simulation; the module converts it to integer nanoseconds by
  truncation (``(uint64_t)(t * 1e9)``), so times must be non-negative, and strictly increasing
  (equal times would make its interpolation divide by zero). A time on a whole nanosecond is
  written as the nearest double that truncates to that nanosecond (0.7 s would read as
  699 999 999 ns);
* the attitude of the reference frame R relative to the inertial frame N, by ``attitudeType``:
  0, MRPs ``σ_RN``; 1, Euler parameters ``(β_0, β_1, β_2, β_3)`` scalar first; 2, scalar last.
  Basilisk's Euler parameters of R relative to N are the same four numbers as slewbench's
  quaternion ``q`` (scalar first, body to inertial, Hamilton): Basilisk's ``EP2C(β)`` is the
  direction cosine matrix ``[RN] = R(q)ᵀ``. The MRPs are ``σ = q_v / (1 + q_0)`` with the sign of
  ``q`` that makes ``q_0 ≥ 0`` (the short set, ``|σ| ≤ 1``; the module maps any set to it);
* the reference's angular velocity ``ω_RN`` [rad/s] and its derivative ``ω̇_RN`` [rad/s²], in
  inertial (N) components (the module's default, ``useReferenceFrame = False``): slewbench's
  ``ω*`` and ``ω̇*`` are in reference-body axes, so the file holds ``R(q*) ω*`` and ``R(q*) ω̇*``
  (the derivative of a vector is the same in both frames when the frame turns at that vector's own
  rate, ``ω × ω = 0``).

Between two waypoints the module interpolates the MRPs, the rates and the accelerations linearly
(through the shadow set of the second MRP when the two sets are more than 1 apart); before the
first waypoint it holds the first attitude, and after the last the last attitude, with zero rate
and acceleration. A reference that ends turning must therefore be exported over the whole run
(its torque-free continuation included), and the grid is best the controller's own sample grid:
a module sampled exactly at the waypoints sees the reference itself, without interpolation error.
The fields are written with 17 significant digits, so they read back to the same double.
"""
from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from types import SimpleNamespace
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp.quat import rotation_matrix
from scenarios.errors import ScenarioError

if TYPE_CHECKING:
    from scenarios.output.export import RunRecord

Array = NDArray[np.float64]

__all__ = ["ATTITUDE_TYPES", "BasiliskOptions", "WaypointFile", "check_waypoint_export", "write_waypoint_files",
           "write_waypoint_reference"]

ATTITUDE_TYPES: dict[str, int] = {"mrp": 0, "quaternion": 1, "quaternion_scalar_last": 2}
"""The attitude sets a waypoint file can hold, and ``waypointReference.attitudeType``'s number for each."""


@dataclass(frozen=True)
class WaypointFile:
    """A written waypoint file and the ``waypointReference`` settings that read it.

    Attributes
    ----------
    path : Path
        The file.
    attitude_type : str
        A key of :data:`ATTITUDE_TYPES`.
    delimiter : str
        The field separator.
    header_lines : int
        Lines before the first waypoint.
    rows : int
        Waypoints written.
    """

    path: Path
    attitude_type: str
    delimiter: str
    header_lines: int
    rows: int

    def basilisk_settings(self) -> dict[str, Any]:
        """The module's attributes that read this file.

        Returns
        -------
        dict
            ``dataFileName``, ``attitudeType`` (0, 1 or 2), ``delimiter``, ``headerLines`` and
            ``useReferenceFrame`` (``False``: rates in inertial components), to set on a
            ``waypointReference.WaypointReference``.
        """
        return {"dataFileName": str(self.path), "attitudeType": ATTITUDE_TYPES[self.attitude_type],
                "delimiter": self.delimiter, "headerLines": self.header_lines, "useReferenceFrame": False}


def _mrp(q: Array) -> Array:
    """Short-set MRPs ``σ = q_v / (1 + q_0)`` (sign of ``q`` chosen so that ``q_0 ≥ 0``)."""
    q = np.where(q[:, :1] < 0.0, -q, q)
    return np.asarray(q[:, 1:] / (1.0 + q[:, :1]), dtype=float)


def _nanosecond_exact(t: float) -> float:
    """``t`` [s], or the next double above it when Basilisk's ``(uint64_t)(t * 1e9)`` would truncate
    a time on a whole nanosecond to the nanosecond before (0.7 s reads as 699999999 ns otherwise);
    the shift is a few units in the last place."""
    ns = round(t * 1e9)
    if abs(t * 1e9 - ns) > 1e-3:  # not on a nanosecond: truncated as any time is
        return t
    x = t
    while int(x * 1e9) < ns:
        x = float(np.nextafter(x, np.inf))
    return x


def write_waypoint_reference(reference: Any, times: ArrayLike, path: str | Path, attitude_type: str = "mrp",
                             delimiter: str = ",", header: bool = True) -> WaypointFile:
    """Write a reference, sampled on a grid, as a Basilisk ``waypointReference`` data file.

    Parameters
    ----------
    reference : planners.Reference
        The reference (anything with a vectorised ``sample(t)`` giving ``q``, ``omega`` and
        ``omega_dot``); sampled after its end it continues torque free, as in the closed loop.
    times : (N,) array_like
        The waypoint times [s] from the start of the run: finite, non-negative, strictly
        increasing, at least two.
    path : str or Path
        The file to write (overwritten).
    attitude_type : {"mrp", "quaternion", "quaternion_scalar_last"}
        The attitude set (module docstring); inertial frame to reference frame.
    delimiter : str
        Field separator, one character (the module splits on the first character of its
        ``delimiter``); not a digit, sign, point, ``e`` or white space.
    header : bool
        Write one line naming the columns first (``headerLines = 1``); ``False``: none.

    Returns
    -------
    WaypointFile
        The file and the module settings that read it (:meth:`WaypointFile.basilisk_settings`).

    Raises
    ------
    ValueError
        An unknown attitude type, an unusable delimiter, or times that are not finite,
        non-negative and strictly increasing; a reference whose samples are not finite.
    """
    if attitude_type not in ATTITUDE_TYPES:
        raise ValueError(f"attitude_type must be one of {sorted(ATTITUDE_TYPES)}, got {attitude_type!r}")
    if len(delimiter) != 1 or delimiter.isspace() or delimiter in "0123456789+-.eE":
        raise ValueError(f"delimiter must be one character that cannot occur in a number, got {delimiter!r}")
    t = np.asarray(times, dtype=float)
    if t.ndim != 1 or t.size < 2:
        raise ValueError(f"times must be a 1-D array of at least two times, got shape {t.shape}")
    if not np.all(np.isfinite(t)) or t[0] < 0.0 or np.any(np.diff(t) <= 0.0):
        raise ValueError("times must be finite, non-negative and strictly increasing (Basilisk reads them as "
                         "unsigned nanoseconds and divides by their differences)")
    sample = reference.sample(t)
    q = np.asarray(sample.q, dtype=float)
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    rotation = rotation_matrix(q)
    omega_n = np.einsum("kij,kj->ki", rotation, np.asarray(sample.omega, dtype=float))
    omega_dot_n = np.einsum("kij,kj->ki", rotation, np.asarray(sample.omega_dot, dtype=float))
    if attitude_type == "mrp":
        attitude, names = _mrp(q), ["sigma_RN_1", "sigma_RN_2", "sigma_RN_3"]
    elif attitude_type == "quaternion":
        attitude, names = q, ["beta_0", "beta_1", "beta_2", "beta_3"]
    else:
        attitude, names = q[:, [1, 2, 3, 0]], ["beta_1", "beta_2", "beta_3", "beta_0"]
    table = np.column_stack([t, attitude, omega_n, omega_dot_n])
    if not np.all(np.isfinite(table)):
        raise ValueError("the reference gave non-finite values on the grid")
    columns = ["t_s", *names, *(f"omega_RN_N_{i}" for i in (1, 2, 3)), *(f"domega_RN_N_{i}" for i in (1, 2, 3))]
    path = Path(path)
    with path.open("w", encoding="ascii", newline="\n") as handle:
        if header:
            handle.write(delimiter.join(columns) + "\n")
        for row in table:
            fields = [_nanosecond_exact(float(row[0])), *row[1:]]
            handle.write(delimiter.join(f"{value:.17g}" for value in fields) + "\n")
    return WaypointFile(path, attitude_type, delimiter, 1 if header else 0, len(t))


@dataclass(frozen=True)
class BasiliskOptions:
    """Options of the ``basilisk`` export (:data:`scenarios.output.export.EXPORT_FORMATS`).

    Parameters
    ----------
    attitude_type : str, optional
        A key of :data:`ATTITUDE_TYPES` (default ``mrp``).
    delimiter : str, optional
        The field separator, one character (default ``,``).
    """

    attitude_type: str = "mrp"
    delimiter: str = ","


def check_waypoint_export(run: RunRecord, options: BasiliskOptions) -> None:
    """Refuse, before anything is written, options a waypoint file cannot take.

    Parameters
    ----------
    run : scenarios.output.export.RunRecord
        The finished run (any: a waypoint file needs no epoch, its times run from t = 0).
    options : BasiliskOptions
        The export's options.

    Raises
    ------
    ScenarioError
        An attitude type or delimiter the format does not take (at ``--option NAME``), or a run
        without a simulated planner row (at ``--format basilisk``: nothing to export).
    """
    if options.attitude_type not in ATTITUDE_TYPES:
        raise ScenarioError("--option attitude_type",
                            f"{options.attitude_type!r} is not one of {', '.join(ATTITUDE_TYPES)}")
    if len(options.delimiter) != 1 or options.delimiter.isspace() or options.delimiter in "0123456789+-.eE":
        raise ScenarioError("--option delimiter", f"{options.delimiter!r} is not one character that cannot occur in "
                                                  "a number")
    if not any(row.planner is not None and row.timeseries is not None for row in run.rows):
        # it wrote an empty waypoints.json and said 'wrote DIR/: waypoints.json', exit 0
        raise ScenarioError("--format basilisk", f"the run in {run.directory} has no simulated planner row ("
                            + ", ".join(f"{row.label!r}: " + ("regulation, no reference" if row.planner is None
                                                              else f"not simulated, {row.status}")
                                        for row in run.rows[:5])
                            + "): a waypoint file holds a planner's reference; nothing to export")


def write_waypoint_files(run: RunRecord, directory: Path, options: BasiliskOptions) -> list[str]:
    """The ``basilisk`` export: ``<row>.waypoints.csv`` per planner row that was simulated, its
    reference at the controller's samples (:func:`write_waypoint_reference`), and
    ``waypoints.json``, the ``waypointReference`` settings that read each file.

    Parameters
    ----------
    run : scenarios.output.export.RunRecord
        The finished run.
    directory : Path
        Where to write the files.
    options : BasiliskOptions
        The files' attitude set and separator.

    Returns
    -------
    list of str
        Notes: the rows left out, and why.
    """
    check_waypoint_export(run, options)
    notes, settings = [], {}
    for row in run.rows:
        if row.timeseries is None:
            notes.append(f"row {row.label!r}: not simulated ({row.status}), no reference samples to export")
            continue
        series = row.series()
        if np.all(np.isnan(series["ref_q"])):
            notes.append(f"row {row.label!r}: no reference (regulation mode), no waypoint file")
            continue
        if not np.all(np.isfinite(series["ref_omega_dot"])):
            notes.append(f"row {row.label!r}: its time series holds no reference acceleration (a run written by an "
                         "earlier slewbench): run it again to export it")
            continue
        tabulated = SimpleNamespace(sample=lambda t, s=series: SimpleNamespace(
            q=s["ref_q"][np.searchsorted(s["t"], t)], omega=s["ref_omega"][np.searchsorted(s["t"], t)],
            omega_dot=s["ref_omega_dot"][np.searchsorted(s["t"], t)]))
        name = f"{row.stem}.waypoints.csv"
        written = write_waypoint_reference(tabulated, series["t"], directory / name, options.attitude_type,
                                           options.delimiter)
        settings[name] = {**written.basilisk_settings(), "dataFileName": name, "rows": written.rows}
    (directory / "waypoints.json").write_text(json.dumps(settings, indent=2) + "\n")
    return notes
