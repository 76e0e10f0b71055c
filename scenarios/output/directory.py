"""Output directories that slewbench owns: the marker and manifest, staging, claims and commits.

The rules (:doc:`/outputs`, "What slewbench writes, and what it never touches"):

* Every output directory carries slewbench's marker, :data:`MARKER`, a JSON manifest naming the
  files slewbench wrote there and whether the set is complete. A directory is claimed only when it
  does not exist yet, is empty, or already carries the marker; anything else (a regular file, a
  user's directory, the working directory) is refused with a :class:`OutputError` and left untouched.
* No output directory is made inside another (:func:`enclosing_output`): a path below a folder
  that carries the marker is refused, but for a sweep's case re-runs (:data:`HOSTS`).
* Inside a marked directory slewbench replaces or removes only files its manifest lists; a file a
  user put there is never touched, and a result name that would land on such a file is an error.
  The manifest also keeps each committed file's size and content digest (``stamps``): a listed
  file that has changed since (a user's own figure saved over ``comparison.png``) is no longer
  slewbench's, and a claim or commit that would replace it is refused, naming it.
* New results are written into a staging folder inside the marked directory, then moved into place
  file by file, and the manifest is marked complete last: an interrupted run leaves a manifest that
  says "incomplete", and its staging folder is removed by the next run that writes there.
* :func:`~scenarios.output.names.row_stems` gives every row a distinct, bounded file name whatever
  its label; :mod:`scenarios.output.writer` writes a run's files through these rules.
"""
from __future__ import annotations

import contextlib
import errno
import fcntl
import hashlib
import json
import os
import shutil
import tempfile
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

from scenarios.errors import ANOTHER_DIRECTORY, OutputError
from scenarios.schema.read import read_bounded

__all__ = ["HOSTS", "MARKER", "STAGING_PREFIX", "changed_files", "check_output_directory", "claim_output_directory",
           "claimed_output_directory", "commit_outputs", "enclosing_output", "new_staging", "read_manifest", "write_manifest", "written_files"]

MARKER = ".slewbench-output.json"
STAGING_PREFIX = ".slewbench-staging-"
MAX_MANIFEST_BYTES = 16 * 1024 * 1024
"""Largest marker read (bytes); a larger one is not slewbench's."""
HOSTS = {"sweep": "cases"}
"""Kind of output -> the folder of such a directory that holds other outputs (a sweep's case
re-runs, ``sweep DIR --case N``: ``DIR/cases/N``). No other output directory is made inside one of
slewbench's (:func:`enclosing_output`)."""


def read_manifest(directory: Path) -> dict[str, Any] | None:
    """The manifest in the marker of ``directory``.

    Parameters
    ----------
    directory : Path
        A directory.

    Returns
    -------
    dict or None
        The manifest (``tool``, ``kind``, ``complete``, ``files``, and ``stamps``: listed file ->
        the ``[size, digest]`` pairs its content may have, one once committed, the old and the new
        one while a commit replaces it; an empty mapping in a marker written before stamps),
        or ``None`` when the directory carries no valid marker (missing, unreadable, not
        slewbench's, or naming a file outside it).
    """
    try:  # never waits: a marker that is a named pipe is no marker
        text = read_bounded(directory / MARKER, MAX_MANIFEST_BYTES)
        manifest = json.loads(text) if len(text) <= MAX_MANIFEST_BYTES else None
    except (OSError, ValueError):
        return None
    if not isinstance(manifest, dict) or manifest.get("tool") != "slewbench" or not isinstance(manifest.get("files"), list):
        return None
    if not all(isinstance(name, str) and _is_plain_relative(name) for name in manifest["files"]):
        return None  # a manifest naming files outside its directory is not ours to act on
    stamps = manifest.get("stamps")
    listed = set(manifest["files"])
    manifest["stamps"] = ({name: stamp for name, stamp in stamps.items() if name in listed and _is_stamp(stamp)}
                          if isinstance(stamps, dict) else {})
    return manifest


def _is_stamp(value: Any) -> bool:
    """A list of ``[size, digest]`` pairs."""
    return isinstance(value, list) and all(
        isinstance(pair, list) and len(pair) == 2 and isinstance(pair[0], int) and not isinstance(pair[0], bool)
        and isinstance(pair[1], str) for pair in value)


def _stamp(path: Path) -> list[Any]:
    """``[size, digest]`` of a file's content (BLAKE2b, 128 bits): a copy of the directory keeps it,
    where a modification time would not."""
    digest = hashlib.blake2b(digest_size=16)
    with open(path, "rb") as stream:
        for block in iter(lambda: stream.read(1 << 20), b""):
            digest.update(block)
    return [os.lstat(path).st_size, digest.hexdigest()]


def changed_files(directory: Path, manifest: dict[str, Any]) -> list[str]:
    """The files the manifest lists with a stamp that have changed since slewbench committed them
    (size or content; or no longer a regular file). A deleted one has not changed: there
    is nothing to replace.

    Parameters
    ----------
    directory : Path
        A marked output directory.
    manifest : dict
        Its manifest (:func:`read_manifest`).

    Returns
    -------
    list of str
        Relative paths, sorted.
    """
    changed = []
    for name, stamp in sorted(manifest.get("stamps", {}).items()):
        path = directory / name
        if not os.path.lexists(path):
            continue
        if path.is_symlink() or not path.is_file() or _stamp(path) not in stamp:
            changed.append(name)
    return changed


def _refuse_changed(path: str | Path, directory: Path, manifest: dict[str, Any], done: str) -> None:
    for name in manifest.get("stamps", {}):  # a symbolic-link folder first: it says more than "changed"
        _check_inside(directory, name)
    changed = changed_files(directory, manifest)
    if changed:
        shown = ", ".join(changed[:5]) + (f" and {len(changed) - 5} more" if len(changed) > 5 else "")
        raise OutputError(path, f"holds files changed since slewbench wrote them ({shown}); {done}: move them "
                                "or " + ANOTHER_DIRECTORY)


def written_files(directory: Path) -> set[str]:
    """The files slewbench's manifest lists in ``directory`` that exist: what a command's earlier
    output there holds, so that the command can name what its own commit removed.

    Parameters
    ----------
    directory : Path
        An output directory (need not exist).

    Returns
    -------
    set of str
        Relative paths; empty without a manifest.
    """
    manifest = read_manifest(directory)
    return {name for name in (manifest or {}).get("files", []) if (directory / name).is_file()}


def _is_plain_relative(name: str) -> bool:
    """A relative path without ``..``, empty or absolute parts: it stays inside its directory."""
    path = Path(name)
    return bool(name) and not path.is_absolute() and all(part not in ("", ".", "..") for part in path.parts)


def _check_inside(directory: Path, name: str) -> None:
    """Refuse a path whose folders under ``directory`` are symbolic links (they would send writes
    and deletions elsewhere)."""
    folder = directory
    for part in Path(name).parts[:-1]:
        folder = folder / part
        if folder.is_symlink():
            raise OutputError(directory, f"{folder} is a symbolic link; slewbench writes only inside its own "
                                         "directory, nothing was replaced")


@contextlib.contextmanager
def _locked(directory: Path) -> Iterator[None]:
    """An exclusive lock on ``directory`` while a run commits into it (other runs wait)."""
    handle = os.open(directory, os.O_RDONLY)
    try:
        fcntl.flock(handle, fcntl.LOCK_EX)
        yield
    finally:
        fcntl.flock(handle, fcntl.LOCK_UN)
        os.close(handle)


def new_staging(directory: Path) -> Path:
    """A staging folder inside the marked ``directory``, named after this process, so that a later
    run removes it only once this process is gone.

    Parameters
    ----------
    directory : Path
        A directory claimed by :func:`claim_output_directory`.

    Returns
    -------
    Path
        The new, empty staging folder.
    """
    return Path(tempfile.mkdtemp(prefix=f"{STAGING_PREFIX}{os.getpid()}-", dir=directory))


def _abandoned(staging: Path) -> bool:
    """Whether the process that made ``staging`` has ended."""
    try:
        pid = int(staging.name[len(STAGING_PREFIX):].split("-")[0])
    except ValueError:
        return True
    if pid == os.getpid():
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except PermissionError:
        return False
    return False


def write_manifest(directory: Path, files: Iterable[str], complete: bool, kind: str,
                   stamps: dict[str, list[Any]] | None = None) -> None:
    """Replace the marker atomically (write a temporary file, then rename it).

    Parameters
    ----------
    directory : Path
        The output directory.
    files : iterable of str
        The files slewbench wrote there, relative to ``directory``.
    complete : bool
        Whether the set is complete (``False`` while a run commits).
    kind : str
        What writes there (``"run"``, ``"sweep"``, ``"codegen"``).
    stamps : dict, optional
        The ``[size, digest]`` pairs of files just committed (a list per file); ``None``: the
        current marker's stamps of the
        files still listed are kept.
    """
    listed = sorted(set(files))
    if stamps is None:
        stamps = (read_manifest(directory) or {}).get("stamps", {})
    kept = {name: stamps[name] for name in listed if name in stamps}
    manifest = {"tool": "slewbench", "kind": kind, "complete": complete, "files": listed, "stamps": kept}
    handle, temporary = tempfile.mkstemp(prefix=".slewbench-manifest-", dir=directory)
    with os.fdopen(handle, "w") as stream:
        json.dump(manifest, stream, indent=1)
    os.replace(temporary, directory / MARKER)


def enclosing_output(directory: Path) -> tuple[Path, str] | None:
    """The slewbench output directory that ``directory`` lies inside, if any: the nearest folder
    above it that carries the marker, with its kind, unless ``directory`` is in the folder that
    kind holds other outputs in (:data:`HOSTS`).

    An output directory inside another one would be presented as part of it (an export inside the
    run it was made from, which a re-run of that run does not renew), and the other directory's
    files and the inner one's would be one folder's: slewbench writes each into a folder of its own.

    Parameters
    ----------
    directory : Path
        An absolute path (need not exist).

    Returns
    -------
    (Path, str) or None
        The enclosing output directory and its kind (``run``, ``sweep``, ...); None when there is
        none, or when ``directory`` is in its host folder.
    """
    for parent in directory.parents:
        manifest = read_manifest(parent)
        if manifest is None:
            continue
        kind = str(manifest.get("kind", "run"))
        host = HOSTS.get(kind)
        if host is not None and directory.is_relative_to(parent / host) and directory != parent / host:
            return None
        return parent, kind
    return None


def _output_path(path: str | Path) -> Path:
    """``path`` as an absolute path with its ``..`` resolved as the file system meets them (through
    the folders and links that exist, lexically past a missing one, as ``mkdir -p`` goes), its last
    component kept as written (a link there is refused, not followed): ``new/../mine`` is the
    existing ``mine``, checked as such, not a new path whose creation fails half-way."""
    directory = Path(path).expanduser().absolute()
    if ".." not in directory.parts:
        return directory
    if directory.name in ("", ".."):
        return Path(os.path.realpath(directory))
    return Path(os.path.realpath(directory.parent)) / directory.name


def check_output_directory(path: str | Path, kind: str = "run", expected: Iterable[str] = ()) -> Path:
    """Every check :func:`claim_output_directory` makes, writing nothing: a command that writes into
    more than one directory (``run --export``) checks each before it claims any, so that a refusal
    leaves every one of them as it was.

    Parameters
    ----------
    path : str or Path
        The output directory.
    kind : str, optional
        What writes there (``"run"``, ``"sweep"``, ``"codegen"``).
    expected : iterable of str, optional
        Files (relative paths) the command may write (as :func:`claim_output_directory`).

    Returns
    -------
    Path
        The absolute directory.

    Raises
    ------
    OutputError
        As :func:`claim_output_directory`; a location the process has no write permission for too
        (the claim's probe file finds what the permissions do not show).
    """
    directory = _output_path(path)
    try:
        enclosing = enclosing_output(directory)
        if enclosing is not None:
            raise OutputError(path, f"is inside {enclosing[0]}, a slewbench {enclosing[1]} output directory (it "
                                    f"carries {MARKER}); slewbench writes the {kind} output into a directory of "
                                    f"its own, not inside another output: choose a directory outside "
                                    f"{enclosing[0]} (--out on the command line), nothing was touched")
        if directory.is_symlink():
            raise OutputError(path, f"is a symbolic link (to {os.path.realpath(directory)}); slewbench writes only "
                                    "into a directory itself, not through a link: give the directory's own path "
                                    "or another one, nothing was touched")
        if directory.exists() and not directory.is_dir():
            raise OutputError(path, "exists and is not a directory; slewbench writes only into a new, "
                                    "empty or slewbench-made directory")
        if directory.is_dir():
            manifest = read_manifest(directory)
            if manifest is None and any(directory.iterdir()):
                raise OutputError(path, f"is a directory that slewbench did not create (no {MARKER} in it) and is "
                                        "not empty; choose a new or empty directory, nothing was touched")
            if manifest is not None and manifest.get("kind", kind) != kind and manifest["files"]:
                raise OutputError(path, f"holds slewbench {manifest.get('kind')} output; write the {kind} output "
                                        "into a directory of its own, nothing was touched")
            if manifest is not None:  # before running: a long run is not refused at its end
                _refuse_changed(path, directory, manifest, "nothing was touched")
                listed = set(manifest["files"])
                foreign = [name for name in dict.fromkeys(expected)
                           if name not in listed and os.path.lexists(directory / name)]
                if foreign:
                    shown = ", ".join(foreign[:5]) + (f" and {len(foreign) - 5} more" if len(foreign) > 5 else "")
                    raise OutputError(path, f"holds files slewbench did not write ({shown}) that this {kind} would "
                                            "write; nothing was touched: move them or " + ANOTHER_DIRECTORY)
            writable = directory
        else:
            writable = next(parent for parent in directory.parents if parent.exists())
            if not writable.is_dir():
                raise OutputError(path, f"its parent {writable} is not a directory")
            longest = os.pathconf(writable, "PC_NAME_MAX")
            if any(len(os.fsencode(part)) > longest for part in directory.relative_to(writable).parts):
                raise OutputError(path, f"cannot be written: {os.strerror(errno.ENAMETOOLONG)}")
        if not os.access(writable, os.W_OK | os.X_OK):
            raise OutputError(path, f"cannot be written: no permission to write in {writable}, nothing was touched")
    except OutputError:
        raise
    except OSError as error:
        raise OutputError(path, f"cannot be written: {error.strerror or error}") from None
    return directory


def claim_output_directory(path: str | Path, kind: str = "run", expected: Iterable[str] = ()) -> Path:
    """Make ``path`` a slewbench output directory, or refuse without touching anything.

    Accepted: a path that does not exist (it is created, with missing parents, and marked), an
    empty directory (marked), or a directory that already carries slewbench's marker
    (:func:`check_output_directory` checks all this first). Leftover
    staging folders of an interrupted run inside a marked directory are removed. Writability is
    checked with a probe file, so that a run never fails at its end for want of permission.

    Parameters
    ----------
    path : str or Path
        The output directory.
    kind : str, optional
        What writes there (``"run"``, ``"sweep"``, ``"codegen"``), recorded in the manifest.
    expected : iterable of str, optional
        Files (relative paths) the command may write: one that exists in a marked directory
        without its manifest listing it (a user's file) is refused now, before the command's
        work, rather than at its commit (:func:`commit_outputs`).

    Returns
    -------
    Path
        The absolute directory.

    Raises
    ------
    OutputError
        For a path inside another slewbench output directory (:func:`enclosing_output`), a
        regular file, a non-empty directory without the marker, a parent that is a file,
        a name too long for the file system, a location that cannot be written, or an
        ``expected`` file that slewbench did not write.
    """
    directory = check_output_directory(path, kind, expected)
    try:
        if directory.is_dir():
            if read_manifest(directory) is None:  # an empty directory
                write_manifest(directory, [], complete=False, kind=kind)
            for leftover in directory.glob(f"{STAGING_PREFIX}*"):
                if leftover.is_dir() and not leftover.is_symlink() and _abandoned(leftover):
                    shutil.rmtree(leftover, ignore_errors=True)
        else:
            directory.mkdir(parents=True)
            write_manifest(directory, [], complete=False, kind=kind)
        probe = tempfile.NamedTemporaryFile(prefix=".slewbench-probe-", dir=directory)
        probe.close()
    except OSError as error:
        raise OutputError(path, f"cannot be written: {error.strerror or error}") from None
    return directory


@contextlib.contextmanager
def claimed_output_directory(path: str | Path, kind: str = "run", expected: Iterable[str] = ()) -> Iterator[Path]:
    """:func:`claim_output_directory`, withdrawn when the body raises before anything was committed
    there: a command refused half-way leaves no output directory marked incomplete behind.

    Only what the claim itself made is removed: the marker it wrote into a new or empty directory,
    and the folders it created (while they hold nothing else). A directory that already carried
    the marker (an earlier output, or one claimed ahead by the same command) is left as it was, and
    so is one whose manifest lists files (a commit happened).

    Parameters
    ----------
    path : str or Path
        The output directory.
    kind : str, optional
        What writes there, as :func:`claim_output_directory`.
    expected : iterable of str, optional
        As :func:`claim_output_directory`.

    Yields
    ------
    Path
        The absolute, claimed directory.

    Raises
    ------
    OutputError
        As :func:`claim_output_directory`.
    """
    directory = _output_path(path)
    # the folders as the claim's mkdir meets them: symbolic links and '..' resolved, so that
    # 'new/../mine' (no such path as written while 'new' is missing) is the user's 'mine'
    real = Path(os.path.realpath(directory))
    missing = [folder for folder in (real, *real.parents) if not os.path.lexists(folder)]
    made = missing[-1] if missing else None  # the outermost folder the claim creates
    marks = made is None and directory.is_dir() and read_manifest(directory) is None
    directory = claim_output_directory(path, kind, expected)
    try:
        yield directory
    except BaseException:
        if made is not None or marks:
            _withdraw(real, made)
        raise


def _withdraw(directory: Path, made: Path | None) -> None:
    """Remove the marker of a claim that committed nothing, then the empty folders from
    ``directory`` up to ``made`` (the outermost one the claim created; ``None``: none).

    Another run that claimed the same directory meanwhile and is writing there (a staging folder
    of a live process) keeps the marker: its commit needs it."""
    try:
        with _locked(directory):  # as a commit: none moves files in while the marker goes
            manifest = read_manifest(directory)
            if manifest is None or manifest["files"] or manifest.get("complete"):
                return
            if any(leftover.is_dir() and not _abandoned(leftover)
                   for leftover in directory.glob(f"{STAGING_PREFIX}*")):
                return
            (directory / MARKER).unlink()
    except OSError:
        return
    if made is None:
        return
    for folder in (directory, *directory.parents):
        if not folder.is_relative_to(made):
            return
        try:
            folder.rmdir()  # only an empty folder: anything else someone put there stays
        except OSError:
            return
        if folder == made:
            return


def _relative_files(root: Path) -> list[str]:
    return sorted(str(p.relative_to(root)) for p in root.rglob("*") if p.is_file())


def commit_outputs(directory: Path, staging: Path, kind: str) -> list[str]:
    """Move everything under ``staging`` into the marked ``directory``, replacing only files the
    manifest lists, remove the previous run's files that the new set lacks, and mark complete.

    Parameters
    ----------
    directory : Path
        A directory claimed by :func:`claim_output_directory`.
    staging : Path
        The staging folder (:func:`new_staging`) holding the new files; it is removed.
    kind : str
        What writes there (``"run"``, ``"sweep"``, ``"codegen"``).

    Returns
    -------
    list of str
        The files now listed by the manifest (relative paths).

    Raises
    ------
    OutputError
        The marker was lost or changed kind, a folder is a symbolic link, or a new file would
        replace one slewbench did not write; nothing is replaced then.
    """
    with _locked(directory):
        return _commit(directory, staging, kind)


def _commit(directory: Path, staging: Path, kind: str) -> list[str]:
    manifest = read_manifest(directory)
    if manifest is None:
        raise OutputError(directory, f"lost its {MARKER} while running; nothing was replaced")
    if manifest.get("kind", kind) != kind and manifest["files"]:
        raise OutputError(directory, f"now holds slewbench {manifest.get('kind')} output; nothing was replaced")
    previous = set(manifest["files"])
    new = _relative_files(staging)
    for name in previous | set(new):
        _check_inside(directory, name)
    clashes = [name for name in new if name not in previous and os.path.lexists(directory / name)]
    if clashes:
        raise OutputError(directory, f"holds files slewbench did not write ({', '.join(clashes[:5])}); "
                                     "nothing was replaced: move them or " + ANOTHER_DIRECTORY)
    _refuse_changed(directory, directory, manifest, "nothing was replaced")
    # while moving, a file this commit writes may hold its old content or its new one: both are
    # slewbench's (an interrupted commit leaves every listed file of slewbench's stamped)
    fresh = {name: _stamp(staging / name) for name in new}
    stamps = dict(manifest["stamps"])
    for name, stamp in fresh.items():
        stamps[name] = [*stamps.get(name, []), stamp]
    write_manifest(directory, previous | set(new), complete=False, kind=kind, stamps=stamps)
    for name in new:
        (directory / name).parent.mkdir(parents=True, exist_ok=True)
        os.replace(staging / name, directory / name)
    for name in sorted(previous - set(new)):
        stale = directory / name
        if stale.is_file() and not stale.is_symlink():
            stale.unlink()
    for folder in sorted({(directory / name).parent for name in previous - set(new)}, reverse=True):
        if folder != directory and folder.is_dir() and not any(folder.iterdir()):
            folder.rmdir()
    write_manifest(directory, new, complete=True, kind=kind, stamps={name: [fresh[name]] for name in new})
    shutil.rmtree(staging, ignore_errors=True)
    return new
