"""The crash-safe store of a trade study: SQLite in WAL mode in the output directory.

Every finished case is one row, committed at once, keyed by the hash of its resolved scenario and
the package version (:func:`scenarios.study.case_key`). A process killed at any moment leaves
every committed case readable and no half-written one, so ``--resume`` re-runs only what is
missing, and a case stored twice (a retry that raced a resume) replaces itself, never duplicates.
"""
from __future__ import annotations

import contextlib
import json
import math
import sqlite3
import time
from pathlib import Path
from typing import Any

STORE_NAME = "sweep.sqlite"
FORMAT = "slewbench-sweep-1"

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


def _json_safe(value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_json_safe(v) for v in value]
    return value


def is_sweep_store(directory: str | Path) -> bool:
    """Whether ``directory/sweep.sqlite`` is a slewbench store (read only: the file is not changed)."""
    path = Path(directory) / STORE_NAME
    try:
        with contextlib.closing(sqlite3.connect(f"file:{path}?mode=ro", uri=True, timeout=30.0)) as db:
            found = db.execute("SELECT value FROM meta WHERE name = 'format'").fetchone()
    except sqlite3.Error:
        return False
    return found is not None and json.loads(found[0]) == FORMAT


class SweepStore:
    """Finished cases of a study in ``directory/sweep.sqlite``.

    Parameters
    ----------
    directory : the study's output directory (must exist).
    create : create the database if it does not exist (else an absent store is an error).
    """

    def __init__(self, directory: str | Path, create: bool = True):
        self.path = Path(directory) / STORE_NAME
        if not create and not self.path.is_file():
            raise FileNotFoundError(self.path)
        self._db = sqlite3.connect(self.path, timeout=30.0, isolation_level=None)
        self._db.execute("PRAGMA journal_mode=WAL")
        self._db.execute("PRAGMA synchronous=NORMAL")  # durable against a killed process
        self._db.executescript(_SCHEMA)
        stored = self.get_meta("format")
        if stored is None:
            self.set_meta("format", FORMAT)
        elif stored != FORMAT:
            raise ValueError(f"{self.path} holds {stored!r}, not a {FORMAT!r} store")

    def close(self) -> None:
        self._db.close()

    def __enter__(self) -> "SweepStore":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def set_meta(self, name: str, value: Any) -> None:
        """Store a JSON value under ``name`` (the resolved study, the version)."""
        self._db.execute("INSERT OR REPLACE INTO meta VALUES (?, ?)", (name, json.dumps(_json_safe(value))))

    def get_meta(self, name: str) -> Any:
        found = self._db.execute("SELECT value FROM meta WHERE name = ?", (name,)).fetchone()
        return None if found is None else json.loads(found[0])

    def put(self, key: str, status: str, rows: list[dict[str, Any]], elapsed_s: float | None,
            attempts: int) -> None:
        """Commit one finished case (its rows: plain dicts, one per planner)."""
        self._db.execute("INSERT OR REPLACE INTO cases VALUES (?, ?, ?, ?, ?, ?)",
                         (key, status, json.dumps(_json_safe(rows)), elapsed_s, attempts, time.time()))

    def keys(self) -> set[str]:
        return {key for (key,) in self._db.execute("SELECT key FROM cases")}

    def records(self) -> dict[str, dict[str, Any]]:
        """Every stored case: key -> {status, rows, elapsed_s, attempts}."""
        return {key: {"status": status, "rows": json.loads(rows), "elapsed_s": elapsed, "attempts": attempts}
                for key, status, rows, elapsed, attempts
                in self._db.execute("SELECT key, status, rows, elapsed_s, attempts FROM cases")}

    def __len__(self) -> int:
        return int(self._db.execute("SELECT COUNT(*) FROM cases").fetchone()[0])
