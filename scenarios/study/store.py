"""The crash-safe store of a trade study (SQLite in WAL mode) and the sweep directory that holds it.

Every finished case is one row, keyed by the hash of its resolved scenario and the package version
(:func:`scenarios.study.types.case_key`); the cases that finish together are committed in one
transaction (:meth:`SweepStore.put_many`) before the sweep reports them done. A process killed at
any moment leaves every committed case readable and no half-written one, so ``--resume`` re-runs
only what is missing and the ``crashed`` cases (:func:`resume_counts`), and a case stored twice (a
crashed case run again, a retry that raced a resume) replaces itself, never duplicates.

A case's rows are stored in their plain form (:meth:`scenarios.output.results.Row.to_dict`),
non-finite numbers as JSON ``null`` (:func:`scenarios.output.tables.json_safe`). A store written by
an earlier slewbench (:data:`EARLIER_FORMATS`) opens for reading only (``--report``); its rows are
read in today's form.

The directory that holds the store is an output directory slewbench owns
(:mod:`scenarios.output.directory`): :func:`claim_sweep_directory` claims it with the store's files
listed in its manifest, and :func:`commit_sweep_outputs` commits a report beside the store without
ever replacing it (a sweep's directory, or a slew table's: ``kind="table"``).
"""
from __future__ import annotations

import contextlib
import errno
import json
import os
import sqlite3
import stat
import time
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

from ocp.errors import excerpt
from scenarios.errors import OutputError
from scenarios.output.directory import (
    MARKER,
    claim_output_directory,
    commit_outputs,
    read_manifest,
    write_manifest,
)
from scenarios.output.tables import json_safe

if TYPE_CHECKING:
    from scenarios.study.types import Study

STORE_NAME = "sweep.sqlite"
FORMAT = "slewbench-sweep-2"
"""The format this version writes: rows keyed ``reference`` and ``closed_loop``."""
STATUSES = ("ok", "crashed")
"""A stored case's status: the runner finished (whatever its rows say), or the case crashed."""


def _rows_of_format_1(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Rows of ``slewbench-sweep-1`` (metrics under ``ref`` and ``cl``) in today's form."""
    return [{**{k: v for k, v in row.items() if k not in ("ref", "cl")},
             "reference": row.get("ref"), "closed_loop": row.get("cl")} for row in rows]


EARLIER_FORMATS: dict[str, Callable[[list[dict[str, Any]]], list[dict[str, Any]]]] = {
    "slewbench-sweep-1": _rows_of_format_1}
"""Formats of earlier versions that can still be read, and how their rows are read in today's form."""

def encode_rows(rows: list[dict[str, Any]]) -> str:
    """A case's rows as the store keeps them: JSON, non-finite numbers as ``null``
    (:func:`scenarios.output.tables.json_safe`). A trade study's workers encode their rows so
    (:func:`scenarios.study.worker.run_chunk`), and the sweep stores the text as it comes.

    Parameters
    ----------
    rows : list of dict
        The case's rows (:meth:`scenarios.output.results.Row.to_dict`).

    Returns
    -------
    str
        The JSON text.
    """
    return json.dumps(json_safe(rows), allow_nan=False)


_SCHEMA = """
CREATE TABLE IF NOT EXISTS meta (name TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS cases (
    key TEXT PRIMARY KEY,
    status TEXT NOT NULL,
    rows TEXT NOT NULL,
    elapsed_s REAL,
    attempts INTEGER NOT NULL,
    finished_at REAL NOT NULL
);
"""


def store_format(directory: str | Path) -> str | None:
    """The format tag of ``directory/sweep.sqlite`` (read only: the file is not changed).

    Parameters
    ----------
    directory : str or Path
        The output directory that may hold the store.

    Returns
    -------
    str or None
        The tag (:data:`FORMAT`, one of :data:`EARLIER_FORMATS`, or another), or None when there is
        no such file, it is not an SQLite database or it carries no tag.
    """
    path = Path(directory) / STORE_NAME
    if not path.is_file():
        return None
    try:
        with contextlib.closing(sqlite3.connect(f"file:{path}?mode=ro", uri=True, timeout=30.0)) as db:
            found = db.execute("SELECT value FROM meta WHERE name = 'format'").fetchone()
        tag = None if found is None else json.loads(found[0])
    except (sqlite3.Error, ValueError):
        return None
    return tag if isinstance(tag, str) else None


def is_sweep_store(directory: str | Path) -> bool:
    """Whether ``directory/sweep.sqlite`` is a slewbench store (read only: the file is not changed).

    Parameters
    ----------
    directory : str or Path
        The output directory that may hold the store.

    Returns
    -------
    bool
        True if the file exists, is an SQLite database and carries slewbench's format tag (this
        version's or one of :data:`EARLIER_FORMATS`).
    """
    tag = store_format(directory)
    return tag == FORMAT or tag in EARLIER_FORMATS


class SweepStore:
    """Finished cases of a study in ``directory/sweep.sqlite``.

    Parameters
    ----------
    directory : str or Path
        The study's output directory (must exist).
    create : bool, optional
        Create the database if it does not exist, to run cases into. False: open an existing
        store to read it (a store of one of :data:`EARLIER_FORMATS` opens only so).

    Raises
    ------
    TypeError
        ``directory`` is not a path or ``create`` not a bool.
    FileNotFoundError
        ``directory`` does not exist, or ``create`` is false and there is no store.
    NotADirectoryError
        ``directory`` is not a directory.
    ValueError
        The file is not a regular file, an SQLite database of another format, or of an earlier
        slewbench's format and ``create`` is true.
    OSError
        SQLite cannot open or write the store (a full disk, a read-only directory).
    """

    def __init__(self, directory: str | os.PathLike[str], create: bool = True) -> None:
        if not isinstance(directory, (str, os.PathLike)):
            raise TypeError(f"directory must be a str or os.PathLike, got {type(directory).__name__}")
        if not isinstance(create, bool):
            raise TypeError(f"create must be True or False, got {excerpt(create)}")
        folder = Path(directory)
        if not folder.exists():
            raise FileNotFoundError(f"directory {folder} does not exist")
        if not folder.is_dir():
            raise NotADirectoryError(f"directory {folder} is not a directory")
        self.path = folder / STORE_NAME
        if not create and not self.path.is_file():
            raise FileNotFoundError(f"no sweep store in {folder} ({STORE_NAME} expected)")
        for name in STORE_FILES:  # SQLite would wait on a named pipe
            if (folder / name).exists() and not stat.S_ISREG((folder / name).stat().st_mode):
                raise ValueError(f"{folder / name} is not a regular file")
        try:
            self._db = sqlite3.connect(self.path, timeout=30.0, isolation_level=None)
            self._db.execute("PRAGMA journal_mode=WAL")
            self._db.execute("PRAGMA synchronous=NORMAL")  # durable against a killed process
            self._db.executescript(_SCHEMA)
            stored = self.get_meta("format")
        except sqlite3.DatabaseError as error:
            with contextlib.suppress(Exception):
                self._db.close()
            if isinstance(error, sqlite3.OperationalError):
                failure = OSError(f"cannot open the sweep store {self.path}: {error}")
                if getattr(error, "sqlite_errorcode", None) == getattr(sqlite3, "SQLITE_FULL", 13):  # a full disk, not a bug
                    failure.errno, failure.strerror = errno.ENOSPC, str(failure)
                raise failure from None
            raise ValueError(f"{self.path} is not a sweep store: {error}") from None
        self._read_rows: Callable[[list[dict[str, Any]]], list[dict[str, Any]]] = list
        if stored is None:
            self.set_meta("format", FORMAT)
        elif stored in EARLIER_FORMATS and not create:
            self._read_rows = EARLIER_FORMATS[stored]
        elif stored in EARLIER_FORMATS:
            self._db.close()
            raise ValueError(f"{self.path} was written by an earlier slewbench (format {stored!r}); it can be "
                             "read (create=False) but takes no new cases")
        elif stored != FORMAT:
            self._db.close()
            raise ValueError(f"{self.path} holds {stored!r}, not a {FORMAT!r} store")

    def close(self) -> None:
        """Close the connection (committed cases are already on disk).

        The store leaves write-ahead logging on the way out: its ``-wal`` and ``-shm`` files are
        folded into the database and removed, and a later read-only reader (the report) does not
        make them again. If another connection still holds the store (a second writer), it stays in
        WAL mode and that connection's close tidies up.
        """
        with contextlib.suppress(sqlite3.Error):
            self._db.execute("PRAGMA journal_mode=DELETE")
        self._db.close()

    def __enter__(self) -> SweepStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def set_meta(self, name: str, value: Any) -> None:
        """Store a JSON value under ``name`` (the resolved study, the version).

        Parameters
        ----------
        name : str
            The entry's name (``study``, ``version``, ``format``).
        value : Any
            JSON-serialisable data; non-finite floats are stored as null.
        """
        self._db.execute("INSERT OR REPLACE INTO meta VALUES (?, ?)",
                         (name, json.dumps(json_safe(value), allow_nan=False)))

    def get_meta(self, name: str) -> Any:
        """The JSON value stored under ``name``.

        Parameters
        ----------
        name : str
            The entry's name.

        Returns
        -------
        Any
            The stored value, or None if there is no such entry.
        """
        found = self._db.execute("SELECT value FROM meta WHERE name = ?", (name,)).fetchone()
        if found is None:
            return None
        try:
            return json.loads(found[0])
        except (TypeError, ValueError):
            raise ValueError(f"{self.path}: the stored {name!r} is not valid JSON; the store is damaged") from None

    def put(self, key: str, status: str, rows: list[dict[str, Any]], elapsed_s: float | None,
            attempts: int) -> None:
        """Commit one finished case at once (one transaction); a stored key is replaced.

        Parameters
        ----------
        key : str
            The case key (:func:`scenarios.study.types.case_key`).
        status : str
            ``ok`` (the runner finished) or ``crashed``.
        rows : list of dict
            The case's rows (:meth:`scenarios.output.results.Row.to_dict`), one per planner and
            controller; non-finite floats are stored as null.
        elapsed_s : float or None
            Wall time of the case in its worker [s]; None when the driver gave up on it.
        attempts : int
            How many times the case was started (at least 1).

        Raises
        ------
        TypeError, ValueError
            An argument of the wrong type or value, named in the message.
        """
        self.put_many([(key, status, rows, elapsed_s, attempts)])

    def put_many(self, cases: Iterable[tuple[str, str, list[dict[str, Any]], float | None, int]]) -> None:
        """Commit finished cases in one transaction (all or none of them); stored keys are replaced.

        Parameters
        ----------
        cases : iterable of (key, status, rows, elapsed_s, attempts)
            Each as the arguments of :meth:`put`.

        Raises
        ------
        TypeError, ValueError
            An entry of the wrong type or value, named in the message (nothing is committed).
        """
        now = time.time()
        self._insert([self._row(*case, now) for case in cases])

    def put_encoded(self, cases: Iterable[tuple[str, str, str, float | None, int]]) -> None:
        """:meth:`put_many` for rows already encoded by :func:`encode_rows` (a sweep's workers do it).

        Parameters
        ----------
        cases : iterable of (key, status, rows_json, elapsed_s, attempts)
            As :meth:`put`, the rows as JSON text.
        """
        now = time.time()
        self._insert([(key, status, text, elapsed, attempts, now) for key, status, text, elapsed, attempts in cases])

    def _insert(self, values: list[tuple[Any, ...]]) -> None:
        with self._transaction():
            self._db.executemany("INSERT OR REPLACE INTO cases VALUES (?, ?, ?, ?, ?, ?)", values)

    @contextlib.contextmanager
    def _transaction(self) -> Iterator[None]:
        self._db.execute("BEGIN IMMEDIATE")
        try:
            yield
        except BaseException:
            self._db.execute("ROLLBACK")
            raise
        self._db.execute("COMMIT")

    @staticmethod
    def _row(key: Any, status: Any, rows: Any, elapsed_s: Any, attempts: Any, now: float) -> tuple[Any, ...]:
        if not isinstance(key, str) or not key:
            raise TypeError(f"key must be a non-empty str, got {excerpt(key)}")
        if status not in STATUSES:
            raise ValueError(f"status must be one of {', '.join(STATUSES)}, got {excerpt(status)}")
        if not isinstance(rows, list) or not all(isinstance(row, dict) for row in rows):
            raise TypeError(f"rows must be a list of dicts, got {excerpt(rows)}")
        if elapsed_s is not None and (isinstance(elapsed_s, bool) or not isinstance(elapsed_s, (int, float))):
            raise TypeError(f"elapsed_s must be a number or None, got {excerpt(elapsed_s)}")
        if isinstance(attempts, bool) or not isinstance(attempts, int) or attempts < 1:
            raise ValueError(f"attempts must be an integer >= 1, got {excerpt(attempts)}")
        return key, status, encode_rows(rows), elapsed_s, attempts, now

    def keys(self) -> set[str]:
        """The keys of the stored cases.

        Returns
        -------
        set of str
        """
        return {key for (key,) in self._db.execute("SELECT key FROM cases")}

    def records(self) -> dict[str, dict[str, Any]]:
        """Every stored case.

        Returns
        -------
        dict
            Case key -> ``{"status", "rows", "elapsed_s", "attempts"}`` as given to :meth:`put`
            (the rows of an earlier format in today's form).

        Raises
        ------
        ValueError
            A stored case whose rows are not valid JSON rows (a damaged store), naming it.
        """
        records = {}
        for key, status, rows, elapsed, attempts in self._db.execute(
                "SELECT key, status, rows, elapsed_s, attempts FROM cases"):
            try:
                decoded = self._read_rows(json.loads(rows))
                if not isinstance(decoded, list) or not all(isinstance(row, dict) for row in decoded):
                    raise ValueError("not a list of rows")
            except (TypeError, ValueError) as error:
                raise ValueError(f"{self.path}: the rows of case {excerpt(key, 40)} are not valid ({excerpt(str(error), 80)}); "
                                 "the store is damaged") from None
            records[key] = {"status": status, "rows": decoded, "elapsed_s": elapsed, "attempts": attempts}
        return records

    def statuses(self) -> dict[str, str]:
        """The status of each stored case (its rows not read).

        Returns
        -------
        dict
            Case key -> ``ok`` or ``crashed``.
        """
        return dict(self._db.execute("SELECT key, status FROM cases"))

    def __len__(self) -> int:
        return int(self._db.execute("SELECT COUNT(*) FROM cases").fetchone()[0])


class ResumeCounts(NamedTuple):
    """What a store holds of a study's cases (:func:`resume_counts`)."""

    kept: int
    """Cases of the study stored and not ``crashed``: a resumed sweep skips them."""
    crashed: int
    """Cases of the study stored ``crashed``: a resumed sweep runs them again, replacing them."""
    other: int
    """Stored cases that are not the study's as this slewbench keys them (stored by another
    version, whose keys differ, or by an edited study before ``--resume`` refused one): kept in the
    store, left out of the results and outputs."""

    def describe(self) -> str:
        """The counts for the line a resumed sweep starts with (empty when nothing is stored).

        Returns
        -------
        str
            For example ``, 4 already stored, 2 crashed cases run again``.
        """
        parts = [f"{self.kept} already stored"] if self.kept else []
        if self.crashed:
            parts.append(f"{self.crashed} crashed case{'s' if self.crashed != 1 else ''} run again")
        return "".join(f", {part}" for part in parts)

    def notes(self) -> list[str]:
        """What a resumed sweep says of the stored cases that are not the study's.

        Returns
        -------
        list of str
            One line when there are such cases, for example ``note: 182 stored cases are not this
            study's as this slewbench keys them (stored by another version?): kept in the store, left
            out of the outputs``; else none.
        """
        if not self.other:
            return []
        return [(f"note: {self.other} stored case{'s are' if self.other != 1 else ' is'} not this study's as this "
                 "slewbench keys them (stored by another version?): kept in the store, left out of the outputs")]


def resume_counts(store: SweepStore, keys: Iterable[str]) -> ResumeCounts:
    """Count what ``store`` holds of the cases ``keys`` (a study's), as a resumed sweep treats them.

    Parameters
    ----------
    store : SweepStore
        The open store.
    keys : iterable of str
        The keys of the study's cases (``Case.key``).

    Returns
    -------
    ResumeCounts
        The study's cases stored (skipped), stored ``crashed`` (run again), and the stored cases
        that are not the study's.
    """
    statuses, wanted = store.statuses(), set(keys)
    kept = sum(statuses[key] != "crashed" for key in wanted & statuses.keys())
    crashed = sum(statuses[key] == "crashed" for key in wanted & statuses.keys())
    return ResumeCounts(kept, crashed, len(statuses.keys() - wanted))


STORE_FILES = (STORE_NAME, f"{STORE_NAME}-wal", f"{STORE_NAME}-shm")
"""The store's files (SQLite's write-ahead log and shared memory included): listed in the manifest, never
replaced by a report."""


def claim_sweep_directory(path: str | Path, kind: str = "sweep") -> Path:
    """Claim ``path`` for a sweep (:func:`scenarios.output.directory.claim_output_directory`) and list the
    store's files in its manifest. A ``sweep.sqlite`` already there must be a slewbench store.

    Parameters
    ----------
    path : str or Path
        The output directory (created if absent).
    kind : str
        The marker's kind of output: ``"sweep"``, or another command that computes through the study
        engine into its store (``"table"``, :mod:`scenarios.slewtable`).

    Returns
    -------
    Path
        The claimed directory.

    Raises
    ------
    OutputError
        As :func:`~scenarios.output.directory.claim_output_directory`, or for a ``sweep.sqlite`` that is not
        a slewbench sweep store (it is left untouched).
    """
    directory = claim_output_directory(path, kind=kind)
    if (directory / STORE_NAME).exists() and not is_sweep_store(directory):
        raise OutputError(path, f"holds a {STORE_NAME} that is not a slewbench sweep store; nothing was touched")
    manifest = read_manifest(directory) or {"files": [], "complete": False}
    write_manifest(directory, set(manifest["files"]) | set(STORE_FILES), complete=bool(manifest.get("complete")),
                   kind=kind)
    return directory


def commit_sweep_outputs(directory: Path, staging: Path, kind: str = "sweep") -> list[str]:
    """Commit a staged report into a sweep directory, the store's files kept out of the commit's reach.

    :func:`scenarios.output.directory.commit_outputs` removes listed files the new set lacks; the
    store's files are taken off the manifest for the commit and listed again after it.

    Parameters
    ----------
    directory : Path
        The claimed sweep directory (:func:`claim_sweep_directory`).
    staging : Path
        The staging folder inside it holding the new report's files.
    kind : str
        The marker's kind, as claimed.

    Returns
    -------
    list of str
        The report's files, relative to ``directory``.

    Raises
    ------
    OutputError
        The directory lost slewbench's marker while the sweep ran.
    """
    manifest = read_manifest(directory)
    if manifest is None:
        raise OutputError(directory, f"lost its {MARKER} while running; nothing was replaced")
    write_manifest(directory, [f for f in manifest["files"] if f not in STORE_FILES], complete=False, kind=kind)
    written = commit_outputs(directory, staging, kind=kind)
    write_manifest(directory, [*written, *STORE_FILES], complete=True, kind=kind)
    return written


def mark_incomplete(directory: Path, kind: str = "sweep") -> None:
    """Mark a claimed sweep directory's outputs incomplete: its tables stop describing the store
    (a sweep starts or resumes: cases are added, crashed ones replaced) until
    :func:`commit_sweep_outputs` writes them again and marks them complete.

    Parameters
    ----------
    directory : Path
        The claimed sweep directory (:func:`claim_sweep_directory`).
    kind : str
        The marker's kind, as claimed.

    Raises
    ------
    OutputError
        The directory carries no slewbench marker.
    """
    manifest = read_manifest(directory)
    if manifest is None:
        raise OutputError(directory, f"lost its {MARKER}; nothing was replaced")
    if manifest.get("complete"):
        write_manifest(directory, manifest["files"], complete=False, kind=kind)


DEFINING_KEYS = ("scenario", "grid", "zip", "monte_carlo")
"""The keys of a study that determine its cases and each case's scenario (``scenario`` as the base
scenario's content): ``slewbench sweep --resume`` continues a sweep only while they are as its store
records them (:func:`check_resume`). ``summary``, ``execution`` and ``robustness`` may change: they
decide how the cases run and what the tables summarise, and the tables are drawn again from the
store whole."""
ORDERED_KEYS = ("grid", "zip", "monte_carlo.dispersions")
"""Mappings of a study whose keys' order is part of its definition (it orders the cases, and with
them the Monte Carlo seeds and draws)."""
CUT = "... (cut)"
"""How :func:`ocp.errors.excerpt` ends a value it cut."""
SHOWN_CHANGES = 5
"""Changes of a study's definition named in the message of a refused resume (the others are counted)."""


def study_definition(data: dict[str, Any], base: Any) -> dict[str, Any]:
    """What determines a study's cases (:data:`DEFINING_KEYS`), in the form the store keeps it (JSON).

    Parameters
    ----------
    data : dict
        The study mapping (as given, or as stored: :func:`scenarios.study.report.resolved_study`).
    base : Any
        The base scenario mapping (its content, not its file name).

    Returns
    -------
    dict
        ``scenario`` (the base), ``grid`` and ``zip`` (``{}`` when absent), ``monte_carlo``
        (``None`` when absent), as JSON reads them back (tuples as lists, non-finite numbers null).
    """
    defined = {"scenario": base, "grid": data.get("grid") or {}, "zip": data.get("zip") or {},
               "monte_carlo": data.get("monte_carlo")}
    return json.loads(json.dumps(json_safe(defined), allow_nan=False, default=str))


def definition_changes(before: Any, after: Any, path: str = "") -> list[str]:
    """The differences between two definitions (:func:`study_definition`), or two parts of them,
    one line each, naming the path that changed.

    Mappings are compared key by key (and, under :data:`ORDERED_KEYS`, in order), lists entry by
    entry when their lengths agree (``grid.x[3]: 0.95 -> 0.99``, ``scenario.planners[1].options.w``);
    lists of other lengths whole, or, when too long to show, by their counts and the values added
    and removed; any other value whole.

    Parameters
    ----------
    before, after : Any
        The stored definition and the study's now (or parts of them at ``path``).
    path : str, optional
        Where they are in the study (``grid``, ``scenario.maneuver``); empty at the top.

    Returns
    -------
    list of str
        ``grid.maneuver.duration: [60.0, 120.0] -> [60.0, 90.0, 120.0]``,
        ``grid.controller.options.kp: 16 values -> 17, added [0.99]``,
        ``zip.simulation.sample_time: added ([0.5, 1.0])``, ``scenario.planners[1].options.weight:
        removed (was 2.0)``, ...; empty when they are equal.
    """
    if isinstance(before, dict) and isinstance(after, dict):
        found = []
        if path in ORDERED_KEYS and before.keys() == after.keys() and list(before) != list(after):
            found.append(f"{path}: its keys in another order ({', '.join(map(str, before))} -> "
                         f"{', '.join(map(str, after))}), which orders the cases")
        for key in [*before, *(key for key in after if key not in before)]:
            where = f"{path}.{key}" if path else str(key)
            if key not in after:
                found.append(f"{where}: removed (was {excerpt(before[key], 60)})")
            elif key not in before:
                found.append(f"{where}: added ({excerpt(after[key], 60)})")
            else:
                found += definition_changes(before[key], after[key], where)
        return found
    if isinstance(before, list) and isinstance(after, list):
        if len(before) == len(after):
            return [change for index, (old, new) in enumerate(zip(before, after))
                    for change in definition_changes(old, new, f"{path}[{index}]")]
        old_text, new_text = excerpt(before, 60), excerpt(after, 60)
        if not old_text.endswith(CUT) and not new_text.endswith(CUT):
            return [f"{path}: {old_text} -> {new_text}"]
        added, removed = [v for v in after if v not in before], [v for v in before if v not in after]
        return [f"{path}: {len(before)} values -> {len(after)}" + (f", added {excerpt(added, 60)}" if added else "")
                + (f", removed {excerpt(removed, 60)}" if removed else "")]
    if before == after and type(before) is type(after):
        return []
    if before is None or after is None:  # an entry given or dropped (monte_carlo)
        return [f"{path}: added ({excerpt(after, 60)})" if before is None else f"{path}: removed (was {excerpt(before, 60)})"]
    if before == after:  # 60.0 -> 60: the value written another way, which keys the cases anew
        return [f"{path}: {excerpt(before, 60)} -> {excerpt(after, 60)} (the same value as another type, "
                f"{type(before).__name__} -> {type(after).__name__}: the cases' keys are computed from it as written)"]
    return [f"{path}: {excerpt(before, 60)} -> {excerpt(after, 60)}"]


def _stored_study(directory: Path) -> tuple[bool, Any]:
    """Whether ``directory/sweep.sqlite`` could be read, and the study it records (read only; None
    when it records none, or not as JSON)."""
    try:
        with contextlib.closing(sqlite3.connect((Path(directory) / STORE_NAME).absolute().as_uri() + "?mode=ro",
                                                uri=True, timeout=30.0)) as db:
            found = db.execute("SELECT value FROM meta WHERE name = 'study'").fetchone()
    except sqlite3.Error:
        return False, None
    try:
        return True, json.loads(found[0]) if found is not None else None
    except (TypeError, ValueError):
        return True, None


def stored_study_name(directory: Path) -> str | None:
    """The name (``study:``) of the study whose sweep ``directory`` stores, read without writing.

    Parameters
    ----------
    directory : Path
        A directory holding a sweep store.

    Returns
    -------
    str or None
        The stored study's name; None when the store cannot be read as a sweep store or records no
        named study (the checks that open it then say what is wrong).
    """
    _, study = _stored_study(directory)
    name = study.get("study") if isinstance(study, dict) else None
    return name if isinstance(name, str) else None


def check_resume(directory: Path, study: Study) -> None:
    """Refuse to resume the sweep stored in ``directory`` with ``study`` unless it is the same study
    as the store records: the same name, and the same definition (:data:`DEFINING_KEYS`: the base
    scenario's content, the grid, zip and Monte Carlo entries). Nothing is written.

    A resumed sweep keeps its stored cases; resumed with a changed definition it would put cases of
    two definitions in one store and stop counting the changed ones, so it is refused, naming what
    changed. A store that records no study (filled through :func:`scenarios.study.engine.sweep` in
    code, not by ``slewbench sweep``) cannot be compared, and is refused too.

    Parameters
    ----------
    directory : Path
        The sweep directory, holding a store of this version's format.
    study : Study
        The study to resume, as loaded now.

    Raises
    ------
    OutputError
        Another study's sweep, the same study's with another definition (the paths that changed, the
        case counts, and what to do), or a store that records no study.
    """
    readable, stored = _stored_study(directory)
    if not readable:  # not an SQLite store: claiming the directory says so
        return
    source = study.source.name if study.source is not None else "the study"
    if not isinstance(stored, dict) or not isinstance(stored.get("study"), str):
        raise OutputError(directory, f"its {STORE_NAME} records no study (it was not written by `slewbench sweep`), so "
                                     "whether it holds this study's cases cannot be told: --resume continues a sweep "
                                     "of an unchanged study only; nothing was run or touched. Run the study into a "
                                     "new directory (another --out)")
    if stored["study"] != study.name:
        raise OutputError(directory, f"holds the sweep of study {stored['study']!r}, not {study.name!r}: --resume "
                                     "continues the same study (its `study:` name), whose stored cases it keeps; "
                                     "choose another --out (nothing was touched)")
    before = study_definition(stored, stored.get("scenario"))
    after = study_definition(study.raw, study.base)
    changes = [change for key in DEFINING_KEYS if key != "scenario"
               for change in definition_changes(before[key], after[key], key)]
    base = study.raw.get("scenario")
    named = f"base scenario {base}" if isinstance(base, str) else "base scenario (inline)"
    changes += [f"{named}: {change}" for change in definition_changes(before["scenario"], after["scenario"])]
    if not changes:
        return
    shown = "; ".join(changes[:SHOWN_CHANGES]) + (f"; and {len(changes) - SHOWN_CHANGES} more"
                                                   if len(changes) > SHOWN_CHANGES else "")
    resolved = stored.get("resolved")
    then = resolved.get("cases") if isinstance(resolved, dict) else None
    counts = f" ({then} cases then, {len(study.cases)} now)" if isinstance(then, int) else ""
    was = f"{source} and {base} as they were" if isinstance(base, str) else f"{source} as it was"
    raise OutputError(directory, f"holds the sweep of study {study.name!r} with another definition{counts}, "
                                 f"changed since: {shown}. --resume continues an unchanged study only (summary, "
                                 "execution and robustness may change), so that one sweep never holds results of "
                                 "two definitions; nothing was run or touched. Run the edited study into a new "
                                 f"directory (another --out), or resume with {was}")
