"""Reading scenario and study YAML safely: bounded size, depth and alias expansion, duplicate keys
refused, dates kept as text, exponent numbers such as ``6e5`` read as floats (YAML 1.1 reads
them as strings), and numbers YAML 1.1 reads otherwise than written (``045``: octal 37; ``1:20``:
base 60) refused. Errors are :class:`ScenarioError` naming the YAML path.

Values that name their path are :mod:`scenarios.schema.node`'s :class:`~scenarios.schema.node.Node`,
which wraps a value parsed here.
"""
from __future__ import annotations

import errno
import os
import re
import stat
from pathlib import Path
from typing import Any

import yaml

from ocp.errors import excerpt
from scenarios.errors import ScenarioError


class _Loader(yaml.SafeLoader):
    """SafeLoader that also reads exponent numbers without a dot or exponent sign (``6e5``),
    which YAML 1.1 leaves as strings and YAML 1.2 reads as floats."""


_Loader.yaml_implicit_resolvers = {key: list(value) for key, value in yaml.SafeLoader.yaml_implicit_resolvers.items()}
_EXPONENT_FLOAT = re.compile(r"^[-+]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)[eE][-+]?[0-9]+$")
# Dates stay text: the fields that take a date parse it themselves and name their path when it is
# impossible (2025-02-30), instead of the YAML reader failing on the whole file.
_Loader.yaml_implicit_resolvers = {key: [(tag, regexp) for tag, regexp in value if tag != "tag:yaml.org,2002:timestamp"]
                                   for key, value in _Loader.yaml_implicit_resolvers.items()}
for _first in "-+0123456789.":
    _Loader.yaml_implicit_resolvers.setdefault(_first, []).insert(0, ("tag:yaml.org,2002:float", _EXPONENT_FLOAT))


MAX_FILE_BYTES = 2 * 1024 * 1024
"""Largest scenario or study file read (bytes); real files are a few kilobytes."""
MAX_DEPTH = 32
"""Deepest nesting of mappings and lists (scenarios nest about six levels)."""
MAX_NODES = 100_000
"""Most YAML values a file may hold once aliases are counted at every use (alias bombs)."""


def _short(path: str, limit: int = 80) -> str:
    """A YAML path cut to ``limit`` characters for a message."""
    return path if len(path) <= limit else f"{path[:limit - 3]}..."


def _check_tree(root: yaml.Node, source: Path | str) -> None:
    """Reject duplicate keys (naming both lines and the YAML path), nesting deeper than
    :data:`MAX_DEPTH` (a recursive alias nests forever) and alias expansion beyond
    :data:`MAX_NODES`, walking the composed node graph without building Python objects."""
    count = 0
    distinct: set[int] = set()  # the values written (an alias repeats one)
    stack: list[tuple[yaml.Node, str, int]] = [(root, "", 0)]
    while stack:
        node, path, depth = stack.pop()
        count += 1
        distinct.add(id(node))
        if depth > MAX_DEPTH:
            raise ScenarioError(_short(path), f"{source} nests deeper than {MAX_DEPTH} levels; "
                                                   "is an alias used inside itself?")
        if count > MAX_NODES:
            if len(distinct) < count:  # aliases repeat values: an alias bomb, most likely
                message = (f"expands to more than {MAX_NODES} values (aliases count at every use); is it an "
                           "alias bomb?")
            else:  # written out: a list far longer than any scenario's or study's (a study varies at most
                # 10,000 values per path; the message said "alias bomb" of a file without an alias)
                message = (f"holds more than {MAX_NODES} values, far more than any scenario or study (a study "
                           "varies at most 10,000 values per path); is a list generated too long?")
            if isinstance(source, Path):  # the error names the file once, before the path
                raise ScenarioError(_short(path) or "(top level)", message, source)
            raise ScenarioError(_short(path) or "(top level)", f"{source} {message}")
        if isinstance(node, yaml.MappingNode):
            seen: dict[Any, yaml.Node] = {}
            for key_node, value_node in node.value:
                key = key_node.value if isinstance(key_node, yaml.ScalarNode) else id(key_node)
                child = f"{path}.{key}" if path else str(key)
                if key in seen:
                    lines = f"lines {seen[key].start_mark.line + 1} and {key_node.start_mark.line + 1}"
                    if isinstance(source, Path):  # the error names the file once, before the path
                        raise ScenarioError(child, f"duplicate key ({lines}); each key may appear once", source)
                    raise ScenarioError(child, f"duplicate key ({lines} of {source}); each key may appear once")
                seen[key] = key_node
                stack.append((value_node, child, depth + 1))
        elif isinstance(node, yaml.SequenceNode):
            stack.extend((item, f"{path}[{index}]", depth + 1) for index, item in enumerate(node.value))
        elif isinstance(node, yaml.ScalarNode) and node.style is None:
            _check_number(node, path, source)


_MAX_INT_DIGITS = 4000
"""Longest plain integer read [characters]: below Python's limit on converting text to an integer
(4,300 digits), far beyond a float's 309; a longer one is refused at its path (a schema reader
says why a shorter one beyond a float is not a number)."""
_OCTAL = re.compile(r"^[-+]?0[0-7_]+$")
"""A plain integer with a leading zero, which YAML 1.1 (PyYAML) reads as octal: ``045`` is 37."""


def _check_number(node: yaml.ScalarNode, path: str, source: Path | str) -> None:
    """Refuse a plain number that YAML 1.1 reads as another value than its digits say: a leading zero
    (``045``: octal, 37) or colons (``1:20``: base 60, 80). Zero-padded angles and durations were
    read silently as other values (YAML 1.2 reads ``045`` as 45 and ``1:20`` as text)."""
    tag, text = node.tag, node.value
    if tag == "tag:yaml.org,2002:int" and len(text) > _MAX_INT_DIGITS:  # Python refuses to read it: the error
        # named no path and suggested sys.set_int_max_str_digits()
        where = f"line {node.start_mark.line + 1}" + ("" if isinstance(source, Path) else f" of {source}")
        message = (f"{text[:20]}... ({len(text)} characters, {where}) is an integer beyond any number slewbench "
                   "reads (a float reaches about 1.8e308, 309 digits); expected a number")
        if isinstance(source, Path):
            raise ScenarioError(_short(path) or "(top level)", message, source)
        raise ScenarioError(_short(path) or "(top level)", message)
    if tag == "tag:yaml.org,2002:int" and _OCTAL.match(text):
        decimal: int | None = int(text.replace("_", ""))  # the digits read in base 10
        how, meant = "the octal number", f"{decimal} (without the leading zero)"
    elif tag in ("tag:yaml.org,2002:int", "tag:yaml.org,2002:float") and ":" in text:
        decimal, how, meant = None, "the base-60 number", ""
    else:
        return
    value = yaml.SafeLoader(text).get_single_data()  # the number YAML 1.1 makes of it
    if value == decimal:  # 07, 00: the same either way
        return
    where = f"line {node.start_mark.line + 1}" + ("" if isinstance(source, Path) else f" of {source}")
    message = (f"{text} ({where}) is read by YAML 1.1 as {how} {value:g}"
               + (f", not {decimal}; write {meant}" if meant else f"; write {value:g} if that is meant")
               + ", or quote it if text is meant")
    if isinstance(source, Path):  # the error names the file once, before the path
        raise ScenarioError(_short(path) or "(top level)", message, source)
    raise ScenarioError(_short(path) or "(top level)", message)


def parse_yaml_text(text: str, source: Path | str = "<text>") -> Any:
    """Parse YAML text with slewbench's checks (see :func:`read_yaml`).

    Parameters
    ----------
    text : str
        The YAML document.
    source : Path or str, optional
        Where the text comes from, named in error messages.

    Returns
    -------
    object
        The parsed data (mappings, lists, numbers, strings; dates stay strings), ``None`` for an
        empty document.

    Raises
    ------
    ScenarioError
        Text that is not YAML, a value YAML cannot build, a duplicate key, nesting deeper than
        :data:`MAX_DEPTH` or alias expansion beyond :data:`MAX_NODES` values.
    """
    try:
        loader = _Loader(text)  # refuses the whole text at once for a character YAML does not allow
    except yaml.reader.ReaderError as error:  # a NUL or another control character: a binary file?
        row = text.count("\n", 0, error.position) + 1
        column = error.position - text.rfind("\n", 0, error.position)
        raise ScenarioError("", f"{source}: not YAML text (line {row}, column {column}): character "
                                f"#x{error.character:04x} is not allowed in YAML (a binary file?)") from None
    try:  # composed once, checked, then built from the same nodes
        root = loader.get_single_node()
        if root is None:
            return None
        _check_tree(root, source)
        return loader.construct_document(root)
    except ScenarioError:
        raise
    except (ValueError, TypeError, OverflowError) as error:  # a value YAML recognised but cannot build
        raise ScenarioError("", f"{source}: a value cannot be read: {excerpt(str(error), 200)}") from None
    except yaml.YAMLError as error:
        where = getattr(error, "problem_mark", None)
        line = f" (line {where.line + 1}, column {where.column + 1})" if where else ""
        problem = getattr(error, "problem", None) or error
        raise ScenarioError("", f"{source}: not valid YAML{line}: {excerpt(str(problem), 200)}") from None
    except RecursionError:
        raise ScenarioError("", f"{source}: nests too deeply") from None
    finally:
        loader.dispose()


def read_bounded(path: str | Path, limit: int) -> bytes:
    """At most ``limit + 1`` bytes of the file at ``path``, without ever waiting for a writer.

    The file is opened non-blocking and its type checked before anything is read: a named pipe
    (with or without a writer) or a socket is refused at once, a directory too; a device that has
    nothing to give (a terminal) fails instead of waiting. ``/dev/zero`` and other endless files
    are read only up to the limit.

    Parameters
    ----------
    path : str or Path
        The file.
    limit : int
        Bytes wanted; one more is read so that the caller can tell a longer file.

    Returns
    -------
    bytes
        The first ``limit + 1`` bytes at most.

    Raises
    ------
    OSError
        The file cannot be opened or read, or is a named pipe, a socket or a directory
        (``strerror`` says which).
    """
    flags = os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_NOCTTY", 0) | getattr(os, "O_CLOEXEC", 0)
    handle = os.open(path, flags)
    try:
        mode = os.fstat(handle).st_mode
        for check, what in ((stat.S_ISFIFO, "a named pipe"), (stat.S_ISSOCK, "a socket"),
                            (stat.S_ISDIR, "a directory")):
            if check(mode):
                raise OSError(errno.EINVAL, f"it is {what}, not a file", str(path))
        chunks: list[bytes] = []
        size = 0
        while size <= limit:
            try:
                chunk = os.read(handle, min(1 << 20, limit + 1 - size))
            except BlockingIOError:
                raise OSError(errno.EAGAIN, "it has nothing to read now (a terminal or a device?)", str(path)) from None
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
        return b"".join(chunks)
    finally:
        os.close(handle)


def read_yaml(path: str | Path) -> Any:
    """Parse a YAML file.

    Numbers such as ``6e5`` are read as numbers; a missing or unreadable file, a named pipe, a
    file larger than :data:`MAX_FILE_BYTES`, text that is not YAML, a duplicate key, or alias
    expansion beyond :data:`MAX_NODES` values is a :class:`ScenarioError`. Nothing here waits for
    a writer (:func:`read_bounded`). So is an empty file (nothing but blank lines and comments):
    every file slewbench reads is a mapping.

    Parameters
    ----------
    path : str or Path
        The YAML file.

    Returns
    -------
    object
        The parsed data (mappings, lists, numbers, strings), never ``None``.
    """
    path = Path(path)
    try:
        data = read_bounded(path, MAX_FILE_BYTES)  # /dev/zero or a pipe reports no size
        if len(data) > MAX_FILE_BYTES:
            raise ScenarioError("", f"{path}: more than {MAX_FILE_BYTES} bytes; scenario and study files are "
                                    "limited to that")
        text = data.decode("utf-8")
    except FileNotFoundError:
        raise ScenarioError("", f"scenario file not found: {path}") from None
    except UnicodeDecodeError as error:  # Latin-1, UTF-16 ...: not the codec's words, what to do
        line = data.count(b"\n", 0, error.start) + 1
        raise ScenarioError("", f"cannot read {path}: not UTF-8 text (byte 0x{data[error.start]:02x} on line {line}); "
                                "save it as UTF-8") from None
    except (OSError, UnicodeDecodeError) as error:
        reason = error.strerror if isinstance(error, OSError) and error.strerror else error
        raise ScenarioError("", f"cannot read {path}: {reason}") from None
    parsed = parse_yaml_text(text, path)
    if parsed is None:
        raise ScenarioError(str(path), "the file is empty (nothing but blank lines or comments); expected a mapping "
                                       "of keys")
    return parsed
