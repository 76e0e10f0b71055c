"""File names slewbench derives from labels and scenario names: bounded, distinct, plain ASCII, and
never one of slewbench's own stems.
"""
from __future__ import annotations

import hashlib
import re
import unicodedata
from pathlib import Path
from typing import Sequence

MAX_STEM = 64
"""Characters of a file stem derived from a label or a scenario name (file systems allow 255 bytes)."""
RESERVED = frozenset({"results", "comparison", "margins", "sky", "timeseries", "summary", "cases", "study", "store",
                      "plots"})
"""Stems slewbench uses for its own files; a row label that sanitises to one gets a suffix."""



def sanitize(text: str, fallback: str = "row") -> str:
    """A file-name stem for ``text``: ASCII letters, digits and ``_.=-`` only, no leading dot,
    at most :data:`MAX_STEM` characters; ``fallback`` when nothing is left.

    Parameters
    ----------
    text : str
        A label or a scenario name (any Unicode).
    fallback : str, optional
        The stem used when ``text`` has no usable character.

    Returns
    -------
    str
        The stem; it never contains a path separator and is never ``.`` or ``..``.
    """
    ascii_text = unicodedata.normalize("NFKD", text).encode("ascii", "ignore").decode()
    stem = re.sub(r"[^A-Za-z0-9_.=-]+", "_", ascii_text).strip("._-")[:MAX_STEM].strip("._-")
    return stem or fallback


def _digest(text: str) -> str:
    return hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()[:8]


def row_stems(labels: Sequence[str]) -> list[str]:
    """Distinct file stems for row labels (compared case-insensitively, reserved names avoided).

    A label keeps its sanitised stem (:func:`sanitize`) when no other label shares it and it is
    not one of slewbench's own (:data:`RESERVED`). Labels whose stems collide (``a/b`` and
    ``a_b``, ``A`` and ``a``, ``α`` and ``β``, both ``row``) are told apart by a numeric suffix in
    row order: the first label that is its stem exactly (``a_b``, unchanged by :func:`sanitize`)
    keeps it, or else the first label; the others get ``-2``, ``-3``, ... (``a_b-2``). Labels
    differing only in case are one file name on a case-insensitive file system, so of ``A_B`` and
    ``a_b`` (each its stem exactly) the first in row order keeps its stem and the other gets a
    suffix. A reserved stem is taken by slewbench's own file, so its row gets ``-2``
    (``comparison-2``). A suffix that another label's stem already is, is skipped, so that every
    non-colliding label keeps its stem (with ``a/b``, ``a_b`` and ``a_b-2``, ``a/b`` gets
    ``a_b-3``). A run records each row's stem in ``results.json`` and ``results.csv``
    (``file_stem``).

    Parameters
    ----------
    labels : sequence of str
        The rows' labels, in order.

    Returns
    -------
    list of str
        One stem per label, pairwise distinct ignoring case, each at most :data:`MAX_STEM`
        characters.
    """
    stems = [sanitize(label) for label in labels]
    groups: dict[str, list[int]] = {}
    for index, stem in enumerate(stems):
        groups.setdefault(stem.lower(), []).append(index)
    result: list[str | None] = [None] * len(stems)
    taken = set(RESERVED)
    for key, members in groups.items():  # the stems nothing else claims stay as they are
        if len(members) == 1 and key not in RESERVED:
            result[members[0]] = stems[members[0]]
            taken.add(key)
    for key, members in groups.items():
        if result[members[0]] is not None:
            continue
        keeper = None if key in RESERVED else next((i for i in members if labels[i] == stems[i]), members[0])
        number = 2
        for index in members:
            if index == keeper:
                result[index] = stems[index]
                taken.add(key)
                continue
            while True:
                suffix = f"-{number}"
                stem = stems[index][:MAX_STEM - len(suffix)].rstrip("._-") + suffix
                number += 1
                if stem.lower() not in taken and stem.lower() not in groups:
                    break
            result[index] = stem
            taken.add(stem.lower())
    return [stem for stem in result if stem is not None]


def suffix_note(labels: Sequence[str], recorded_in: str) -> str:
    """The line that says which rows' file stems got a suffix (:func:`row_stems`: a label whose stem
    another label's, or one of slewbench's own, already is), so that a user looking for
    ``timeseries/<label>.csv`` finds its file.

    Parameters
    ----------
    labels : sequence of str
        The rows' labels, in order.
    recorded_in : str
        Where each row's ``file_stem`` is recorded (``results.json and results.csv``, ``cases.csv``).

    Returns
    -------
    str
        ``note: 1 row's file stem got a suffix, the label's stem being another row's or one of
        slewbench's own (file_stem in results.json and results.csv): 'a/b' -> a_b-2``; empty when no
        stem did.
    """
    renamed = [(label, stem) for label, stem in zip(labels, row_stems(labels)) if stem != sanitize(label)]
    if not renamed:
        return ""
    count = f"{len(renamed)} row's file stem" if len(renamed) == 1 else f"{len(renamed)} rows' file stems"
    return (f"note: {count} got a suffix, the label's stem being another row's or one of slewbench's own "
            f"(file_stem in {recorded_in}): " + ", ".join(f"{label!r} -> {stem}" for label, stem in renamed))


def default_output_directory(name: str, root: str | Path = "results") -> Path:
    """``results/<sanitised scenario name>``: always one level under ``root``.

    Parameters
    ----------
    name : str
        The scenario's (or study's) name, any text.
    root : str or Path, optional
        The folder that holds every default output directory.

    Returns
    -------
    Path
        ``root / stem`` with a stem that has no separator, is not ``..`` and is not empty.
    """
    stem = sanitize(name, fallback="")
    if not stem or stem.lower() in RESERVED:
        stem = f"{stem or 'scenario'}-{_digest(name)}"
    return Path(root) / stem
