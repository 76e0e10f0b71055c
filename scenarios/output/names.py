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

    A label whose sanitised stem is empty, reserved, or shared with another label gets a short hash
    of the label appended, so ``a/b`` and ``a_b``, ``α`` and ``β``, or ``comparison`` never
    overwrite each other's files.

    Parameters
    ----------
    labels : sequence of str
        The rows' labels, in order.

    Returns
    -------
    list of str
        One stem per label, pairwise distinct ignoring case.
    """
    stems = [sanitize(label) for label in labels]
    counts: dict[str, int] = {}
    for stem in stems:
        counts[stem.lower()] = counts.get(stem.lower(), 0) + 1
    result, taken = [], set()
    for index, (label, stem) in enumerate(zip(labels, stems)):
        if counts[stem.lower()] > 1 or stem.lower() in RESERVED:
            stem = f"{stem[:MAX_STEM - 9]}-{_digest(label)}"
        while stem.lower() in taken:  # a hash collision or a label equal to another's suffixed stem
            stem = f"{stem[:MAX_STEM - 9]}-{_digest(f'{label}#{index}')}"
        taken.add(stem.lower())
        result.append(stem)
    return result


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
