"""Exports of a finished run into other tools' formats: the ``EXPORT_FORMATS`` registry, the run
directory read back, and ``export_run``, which writes an export into a directory slewbench owns.

An export reads what ``slewbench run`` wrote (``results.json`` and ``timeseries/<row>.csv``), so
that nothing is run again: the closed-loop attitude and rate and the reference's, at the
simulation's samples, with the run's epoch and frame.

A format is an :class:`ExportFormat`: a name, a one-line description, a frozen dataclass of
options (text fields, given on the command line as ``--option NAME=VALUE``) and a writer
``write(run, directory, options) -> list[str]`` that writes its files into ``directory`` (a
staging folder) and returns notes (rows it left out, and why). It raises
:class:`~scenarios.errors.ScenarioError` when the run cannot be exported at all (an AEM without an
epoch).
"""
from __future__ import annotations

import csv
import dataclasses
import json
import shutil
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from scenarios.errors import ScenarioError
from scenarios.output.aem import AemOptions, check_aem_export, write_aem_files
from scenarios.output.basilisk import (
    BasiliskOptions,
    check_waypoint_export,
    write_waypoint_files,
)
from scenarios.output.directory import (
    changed_files,
    claimed_output_directory,
    commit_outputs,
    new_staging,
    read_manifest,
)
from scenarios.output.names import row_stems, sanitize

__all__ = ["EXPORT_FORMATS", "ExportFormat", "ExportReport", "RunRecord", "RunRow", "default_export_directory",
           "export_run", "read_run"]

Array = NDArray[np.float64]
NOTE_MESSAGE_CHARS = 300
"""Characters of a row's message at most in an export's note on a row the run did not score ``ok``
(cut between words, ``...`` marking the cut)."""



def _cut(message: str) -> str:
    """``message`` on one line, at most :data:`NOTE_MESSAGE_CHARS` characters: cut between words,
    visibly (a cut inside a number would state another number), or, where a word longer than the
    room leaves nothing whole (a long path), at the room's end; ``...`` marks a cut."""
    flat = " ".join(message.split())
    if len(flat) <= NOTE_MESSAGE_CHARS:
        return flat
    room = NOTE_MESSAGE_CHARS - len(" ...")
    words = flat[:room + 1].rsplit(" ", 1)[0] if " " in flat[:room + 1] else ""
    return (words if len(words) >= room // 2 else flat[:room]) + " ..."

@dataclass(frozen=True)
class RunRow:
    """One row of a finished run, as ``results.json`` and its time series give it.

    Parameters
    ----------
    label, planner, controller, status : str or None
        As in ``results.json`` (``planner`` ``None`` in regulation mode).
    stem : str
        The row's file stem: ``results.json``'s ``file_stem``; for a run written before it
        recorded one, :func:`~scenarios.output.names.row_stems` of the labels.
    timeseries : Path or None
        Its ``timeseries/<stem>.csv``; ``None`` when the row was not simulated.
    rate_jump_times : tuple of float, optional
        When its reference's body rate jumps, as its scores record it (the largest jump's
        ``requirements.reference.actuators.rate_jump_time_s``); empty: none recorded.
    message : str, optional
        The row's message in ``results.json`` (why it is not ``ok``, where it is not).
    """

    label: str
    planner: str | None
    controller: str | None
    status: str
    stem: str
    timeseries: Path | None
    rate_jump_times: tuple[float, ...] = ()
    message: str = ""

    def series(self) -> dict[str, Array]:
        """The row's time series as arrays (blank cells NaN).

        Returns
        -------
        dict of str to ndarray
            ``t`` (N,) [s]; ``q`` (N, 4) closed-loop attitude, body to inertial, scalar first;
            ``omega`` (N, 3) body rate [rad/s, body]; ``ref_q``, ``ref_omega`` and ``ref_omega_dot``
            [rad/s², reference body axes] the reference's (NaN without a reference, and
            ``ref_omega_dot`` NaN in a run written before slewbench recorded it).

        Raises
        ------
        ScenarioError
            A file that cannot be read as a time series (a cell that is not a number, a column
            missing, times that are not finite and strictly increasing), at the file.
        """
        if self.timeseries is None:
            raise ValueError(f"row {self.label!r} has no time series")
        try:
            with self.timeseries.open(newline="") as handle:
                reader = csv.reader(handle)
                header = next(reader)
                table = np.array([[float(cell) if cell else np.nan for cell in line] for line in reader],
                                 dtype=float)
            table = table.reshape(-1, len(header))
            column = {name: index for index, name in enumerate(header)}
            missing = [name for name in ("t", "q0", "q1", "q2", "q3", "omega_x", "omega_y", "omega_z", "ref_q0",
                                         "ref_q1", "ref_q2", "ref_q3", "ref_omega_x", "ref_omega_y", "ref_omega_z")
                       if name not in column]
        except (OSError, ValueError, StopIteration) as error:  # a run written before stamps, edited since
            raise ScenarioError(str(self.timeseries), f"cannot be read as the time series of row {self.label!r}: "
                                                      f"{error or 'empty file'}") from None
        if missing:
            raise ScenarioError(str(self.timeseries), f"cannot be read as the time series of row {self.label!r}: "
                                                      f"no column {', '.join(missing)}")
        t = table[:, column["t"]]
        if not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0.0):  # a simulation's samples always increase
            raise ScenarioError(str(self.timeseries), f"cannot be read as the time series of row {self.label!r}: "
                                                      "its times t are not finite and strictly increasing")

        def block(*names: str) -> Array:
            return table[:, [column[name] for name in names]]

        return {"t": table[:, column["t"]], "q": block("q0", "q1", "q2", "q3"),
                "omega": block("omega_x", "omega_y", "omega_z"),
                "ref_q": block("ref_q0", "ref_q1", "ref_q2", "ref_q3"),
                "ref_omega": block("ref_omega_x", "ref_omega_y", "ref_omega_z"),
                "ref_omega_dot": (block("ref_omega_dot_x", "ref_omega_dot_y", "ref_omega_dot_z")
                                  if "ref_omega_dot_x" in column else np.full((table.shape[0], 3), np.nan))}


@dataclass(frozen=True)
class RunRecord:
    """A finished run directory, read back.

    Parameters
    ----------
    directory : Path
        The run directory.
    scenario : str
        The scenario's name.
    frame : str
        The inertial frame (``GCRF``, or ``inertial (no epoch)``).
    epoch : str or None
        The epoch, UTC, ISO 8601 with ``Z``; ``None`` without one.
    rows : list of RunRow
        The rows, in order.
    provenance : dict
        ``results.json``'s provenance (version, date, ...).
    """

    directory: Path
    scenario: str
    frame: str
    epoch: str | None
    rows: list[RunRow]
    provenance: dict[str, Any]


def read_run(directory: str | Path) -> RunRecord:
    """Read a run directory that ``slewbench run`` wrote completely.

    Parameters
    ----------
    directory : str or Path
        The run's output directory.

    Returns
    -------
    RunRecord

    Raises
    ------
    ScenarioError
        Not a directory, not a complete slewbench run, ``results.json`` or a time series that
        the run listed but is gone or has changed since (its recorded size and digest), an
        unreadable ``results.json`` (at the directory), or, in a run written before stamps, a time
        series that cannot be read (:meth:`RunRow.series`, at the file).
    """
    path = Path(directory).expanduser()
    if not path.is_dir():
        raise ScenarioError(str(directory), "is not a directory; give the output directory of `slewbench run` "
                                            "(results/<scenario> by default)")
    manifest = read_manifest(path)
    if manifest is None or manifest.get("kind") != "run" or "results.json" not in manifest["files"]:
        raise ScenarioError(str(directory), "holds no run written by `slewbench run` (no run manifest naming "
                                            "results.json); give a run's output directory")
    if not manifest.get("complete"):
        raise ScenarioError(str(directory), "holds an incomplete run (interrupted while writing); run it again")
    read = [name for name in manifest["files"] if name == "results.json" or name.startswith("timeseries/")]
    missing = [name for name in read if not (path / name).is_file()]
    changed = [name for name in changed_files(path, manifest) if name in read and name not in missing]
    if missing or changed:  # an export of them would hand off numbers the run did not write, or drop a row
        said = "; ".join(f"{what} since slewbench wrote them: {_some(names)}"
                         for what, names in (("removed", missing), ("changed", changed)) if names)
        raise ScenarioError(str(directory), f"holds a run whose files were {said}; an export reads them as the "
                                            "run's: run the scenario again (or restore the files)")
    try:
        data = json.loads((path / "results.json").read_text())
        labels = [row["label"] for row in data["rows"]]
    except (OSError, ValueError, KeyError, TypeError) as error:
        raise ScenarioError(str(path / "results.json"), f"cannot be read as a run's results: {error}") from None
    rows = []
    for row, stem in zip(data["rows"], _recorded_stems(data["rows"], labels)):
        name = f"timeseries/{stem}.csv"
        series = path / name if name in manifest["files"] and (path / name).is_file() else None
        rows.append(RunRow(row["label"], row.get("planner"), row.get("controller"), row.get("status", ""), stem,
                           series, _rate_jump_times(row), str(row.get("message") or "")))
        if series is not None and name not in manifest["stamps"]:
            # a run written before stamps cannot tell an edit: its series is read now, so that one
            # that cannot be read is refused before an export writes anything
            rows[-1].series()
    return RunRecord(path.absolute(), str(data.get("scenario", "")), str(data.get("frame", "")), data.get("epoch"),
                     rows, data.get("provenance") or {})


def _some(names: list[str], shown: int = 5) -> str:
    """The first ``shown`` names, comma-separated, and how many more."""
    return ", ".join(names[:shown]) + (f" and {len(names) - shown} more" if len(names) > shown else "")


def _recorded_stems(rows: list[Any], labels: list[str]) -> list[str]:
    """The rows' file stems as ``results.json`` records them (``file_stem``); for a run written
    before it did (or a stem that is not one slewbench makes: a path, say), worked out again from
    the labels (:func:`~scenarios.output.names.row_stems`, the rule that named its files)."""
    recorded = [row.get("file_stem") if isinstance(row, dict) else None for row in rows]
    if all(isinstance(stem, str) and stem == sanitize(stem, fallback="") for stem in recorded):
        return [str(stem) for stem in recorded]
    return row_stems(labels)


def _rate_jump_times(row: Any) -> tuple[float, ...]:
    """The recorded time of a ``results.json`` row's largest reference rate jump (none when absent)."""
    try:
        time = row["requirements"]["reference"]["actuators"]["rate_jump_time_s"]
    except (KeyError, TypeError):
        return ()
    return (float(time),) if isinstance(time, (int, float)) and not isinstance(time, bool) else ()


@dataclass(frozen=True)
class ExportFormat:
    """An export format of a finished run.

    Parameters
    ----------
    name : str
        The registry key (``slewbench export --format NAME``).
    description : str
        One line: what it writes.
    options : type
        A frozen dataclass whose fields (text) are the format's options.
    check : callable
        ``check(run, options)``: raises :class:`~scenarios.errors.ScenarioError` when the run
        cannot be exported with these options (before anything is written).
    write : callable
        ``write(run, directory, options) -> list of notes``: writes the files into ``directory``.
    """

    name: str
    description: str
    options: type
    check: Callable[[RunRecord, Any], None]
    write: Callable[[RunRecord, Path, Any], list[str]]

    def parse_options(self, pairs: list[str]) -> Any:
        """The options from ``NAME=VALUE`` texts.

        Parameters
        ----------
        pairs : list of str
            ``NAME=VALUE`` texts (the command line's ``--option``).

        Returns
        -------
        object
            An instance of :attr:`options`.

        Raises
        ------
        ScenarioError
            A text without ``=``, a name the format does not have (the names are listed) or one
        given twice.
        """
        names = [item.name for item in dataclasses.fields(self.options)]
        values: dict[str, str] = {}
        for pair in pairs:
            name, equals, value = pair.partition("=")
            if not equals or name.strip() not in names:
                raise ScenarioError(f"--option {pair}", f"expected NAME=VALUE with NAME one of {', '.join(names)} "
                                                        f"(the {self.name} export's options)")
            if name.strip() in values:  # the last one silently won
                raise ScenarioError(f"--option {name.strip()}", f"given twice ({values[name.strip()]!r}, then "
                                                                f"{value.strip()!r}); give each option once")
            values[name.strip()] = value.strip()
        return self.options(**values)


EXPORT_FORMATS: dict[str, ExportFormat] = {
    "aem": ExportFormat("aem", "CCSDS Attitude Ephemeris Messages (504.0-B-2, KVN): each simulated row's closed-loop "
                               "and reference attitude, body to GCRF", AemOptions, check_aem_export, write_aem_files),
    "basilisk": ExportFormat("basilisk", "Basilisk waypointReference data files: each planner row's reference at the "
                                         "controller's samples", BasiliskOptions, check_waypoint_export,
                             write_waypoint_files),
}
"""The export formats by name."""


@dataclass(frozen=True)
class ExportReport:
    """What :func:`export_run` wrote.

    Parameters
    ----------
    directory : Path
        The export directory.
    files : list of str
        The files written there.
    notes : list of str
        Rows or histories left out, and why; rows exported although the run did not score them
        ``ok`` (a hand-off of an attitude that breaks a requirement), and why.
    """

    directory: Path
    files: list[str]
    notes: list[str]


def default_export_directory(run_directory: str | Path, format_name: str) -> Path:
    """``<run directory>-<format>``, beside the run directory (never inside it: a later run there
    would not know the export's files).

    Parameters
    ----------
    run_directory : str or Path
        The run's output directory.
    format_name : str
        The export format.

    Returns
    -------
    Path
    """
    path = Path(run_directory).expanduser().absolute()
    return path.with_name(f"{path.name}-{format_name}")


def export_run(run_directory: str | Path, format_name: str, out: str | Path | None = None,
               options: Any = None) -> ExportReport:
    """Export a finished run into ``out``, a directory slewbench owns (new, empty or an earlier export).

    Parameters
    ----------
    run_directory : str or Path
        The output directory of ``slewbench run``.
    format_name : str
        A key of :data:`EXPORT_FORMATS`.
    out : str or Path, optional
        The export directory (default :func:`default_export_directory`).
    options : object, optional
        The format's options (an instance of its ``options`` class; default: its defaults).

    Returns
    -------
    ExportReport

    Raises
    ------
    ScenarioError
        An unknown format, a directory that is not a finished run, or a run the format cannot
        take (an AEM without an epoch). Nothing is written then; a failure while writing
        removes the export directory this call created (or the marker it put in an empty one).
    OutputError
        ``out`` is not slewbench's to write (:func:`~scenarios.output.directory.claim_output_directory`).
    """
    export = EXPORT_FORMATS.get(format_name)
    if export is None:
        raise ScenarioError("--format", f"{format_name!r} is not an export format; known: {', '.join(EXPORT_FORMATS)}")
    run = read_run(run_directory)
    options = export.options() if options is None else options
    export.check(run, options)
    # a failure before the commit (an interruption, a full disk) withdraws the claim: no export
    # directory marked incomplete is left behind, and nothing this export did not make is removed
    with claimed_output_directory(out if out is not None else default_export_directory(run.directory, format_name),
                                  kind="export") as target:
        staging = new_staging(target)
        try:
            notes = export.write(run, staging, options)
            files = commit_outputs(target, staging, kind="export")
        finally:
            shutil.rmtree(staging, ignore_errors=True)
    # a file is the row's whose stem is the longest to prefix it (stems hold dots: k=0 and k=0.5)
    owners = {max((r for r in run.rows if f.startswith(r.stem + ".")), key=lambda r: len(r.stem), default=None)
              for f in files}
    for row in run.rows:
        if row in owners and row.status != "ok":
            why = f": {_cut(row.message)}" if row.message else ""
            notes.append(f"row {row.label!r}: exported, but the run scored it {row.status}{why}")
    return ExportReport(target, files, notes)
