"""A slew table's output directory: claimed for slewbench, holding the engine's store beside the files.

The rules are :mod:`scenarios.output.directory`'s (a directory is written only when it is new, empty
or slewbench's; only files slewbench listed are replaced), with the kind ``table``; the store of the
study engine (:data:`scenarios.study.store.STORE_FILES`) is listed in the manifest and kept out of
each commit's reach, so a table run again into its directory computes only what it lacks.
"""
from __future__ import annotations

from pathlib import Path

from scenarios.errors import OutputError
from scenarios.output.directory import (
    MARKER,
    claim_output_directory,
    commit_outputs,
    read_manifest,
    write_manifest,
)
from scenarios.study.store import STORE_FILES, STORE_NAME, is_sweep_store

__all__ = ["KIND", "claim_table_directory", "commit_table_outputs"]

KIND = "table"
"""The manifest's ``kind`` of a table directory."""


def claim_table_directory(path: str | Path) -> Path:
    """Claim ``path`` for a slew table and list the engine's store in its manifest.

    Parameters
    ----------
    path : str or Path
        The output directory (created if absent).

    Returns
    -------
    Path
        The claimed directory.

    Raises
    ------
    OutputError
        As :func:`scenarios.output.directory.claim_output_directory`, or a store there that is not
        slewbench's (left untouched).
    """
    directory = claim_output_directory(path, kind=KIND)
    if (directory / STORE_NAME).exists() and not is_sweep_store(directory):
        raise OutputError(path, f"holds a {STORE_NAME} that is not a slewbench store; nothing was touched")
    manifest = read_manifest(directory) or {"files": [], "complete": False}
    write_manifest(directory, set(manifest["files"]) | set(STORE_FILES), complete=bool(manifest.get("complete")),
                   kind=KIND)
    return directory


def commit_table_outputs(directory: Path, staging: Path) -> list[str]:
    """Commit the staged files into the table directory, the store's files kept.

    Parameters
    ----------
    directory : Path
        The claimed directory (:func:`claim_table_directory`).
    staging : Path
        The staging folder inside it (:func:`scenarios.output.directory.new_staging`).

    Returns
    -------
    list of str
        The files written, relative to ``directory``.

    Raises
    ------
    OutputError
        The directory lost slewbench's marker, or a new file would replace one slewbench did not write.
    """
    manifest = read_manifest(directory)
    if manifest is None:
        raise OutputError(directory, f"lost its {MARKER} while running; nothing was replaced")
    write_manifest(directory, [f for f in manifest["files"] if f not in STORE_FILES], complete=False, kind=KIND)
    written = commit_outputs(directory, staging, kind=KIND)
    write_manifest(directory, [*written, *STORE_FILES], complete=True, kind=KIND)
    return written
