"""Explicit caches of built solvers, shared by planners across problems of the same structure.

Building a CasADi NLP or integrator costs far more than solving it once it exists. A
:class:`SolverCache` keeps what was built under a key that states the problem's *structure* (the
model's numbers baked into the graph, the transcription, the mesh, the solver options): problems
that differ only in parameters (boundary values, T) reuse the entry. A trade study gives one cache
to each worker process, so a collocation NLP is built once per worker and structure.

Threads: a CasADi ``Function`` is not safe to call from two threads at once (two threads calling
one IPOPT solver crash the process), so a cache keeps **one set of entries per thread**: a thread
never receives an object that another thread built. Threads may share a cache (and a planner); each
thread builds a structure once, the first time it meets it, and its plans then run concurrently
with the other threads'. A thread's entries go when the thread ends.

Pickling: a cache pickles (and deep-copies) empty. Its entries are built solvers, megabytes each
(a model's cache after one 50-interval collocation plan pickles to 14 MB, after a multiple-shooting
plan to 330 MB), which the receiving process builds again faster than it would receive them; so a
reference, which keeps its model and with it the model's cache, pickles to kilobytes.

Bounds: a :class:`SolverCache` keeps every entry, for structures that are few (a study's NLPs).
Where a long-lived process meets an open-ended number of structures (a gain swept in a study: one
closed loop per law), a :class:`RecentCache` keeps only the most recently used entries.

Keys: :func:`exact_key` states a value (a dataclass tree of numbers, arrays and text) exactly, so
that two different values never make the same key; the model's fingerprint and a study's planning
key are built with it.
"""
from __future__ import annotations

import dataclasses
import enum
import threading
import weakref
from collections.abc import Callable, Hashable
from typing import Any, TypeVar

import numpy as np

V = TypeVar("V")


class Unkeyable(TypeError):
    """A value that :func:`exact_key` cannot state exactly (a callable, an object of unknown kind)."""


def exact_key(value: Any) -> Any:
    """``value`` as nested tuples of type tags, exact numbers and text: equal results for equal
    values, different results for different ones.

    Numbers are exact (a float as its hex, an array as its dtype, shape and bytes), so two values
    that differ anywhere, however deep (an array inside a dict inside a dataclass) or however little
    (one bit of one float), give different results; a list and a tuple of the same items differ. A
    dataclass is its qualified type and its compared fields (those excluded from equality,
    ``compare=False``, are caches of the others, as ``Spacecraft._cache``); a dict and a set are
    sorted. An enum member is its qualified type and its value: an ``IntEnum`` or ``StrEnum``
    member differs from the int or str it compares equal to, and from another type's member of the
    same value.

    Parameters
    ----------
    value : object
        None, a bool, int, float (or their NumPy scalars), str, enum member, numeric ndarray,
        dataclass instance, list, tuple, dict, set or frozenset of these.

    Returns
    -------
    object
        A hashable tree of tuples, strings, ints and bytes whose ``repr`` is as exact as itself.

    Raises
    ------
    Unkeyable
        For anything else (a callable, an object of unknown kind, an array of objects): such a
        value has no exact statement, and a key must never make it equal to another. The caller
        decides what then follows (a planning key is then ``None``; a model's fingerprint is then
        its own alone).
    """
    if isinstance(value, enum.Enum):  # first: an IntEnum or StrEnum member is an int or a str too
        return ("e", f"{type(value).__module__}.{type(value).__qualname__}", _member_value(value))
    if value is None or isinstance(value, (bool, np.bool_)):
        return None if value is None else ("b", bool(value))
    if isinstance(value, (int, np.integer)):
        return ("i", int(value))
    if isinstance(value, (float, np.floating)):
        return ("f", float(value).hex())
    if isinstance(value, str):
        return ("s", value)
    if isinstance(value, np.ndarray):
        if value.dtype.kind not in "biuf":
            raise Unkeyable(f"an array of dtype {value.dtype}")
        return ("a", value.dtype.str, value.shape, np.ascontiguousarray(value).tobytes())
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return (f"{type(value).__module__}.{type(value).__qualname__}",
                tuple((f.name, exact_key(getattr(value, f.name))) for f in dataclasses.fields(value) if f.compare))
    if isinstance(value, (list, tuple)):
        return (type(value).__name__, tuple(exact_key(item) for item in value))
    if isinstance(value, dict):
        return ("d", tuple(sorted(((exact_key(k), exact_key(v)) for k, v in value.items()), key=repr)))
    if isinstance(value, (set, frozenset)):
        return ("set", tuple(sorted((exact_key(item) for item in value), key=repr)))
    raise Unkeyable(f"a {type(value).__module__}.{type(value).__qualname__}")


def _member_value(member: enum.Enum) -> Any:
    """An enum member's value as :func:`exact_key` states it; a value it cannot state (an object of
    unknown kind) by the member's name, as exact within its type (a flag's unnamed combination has
    an int value)."""
    try:
        return exact_key(member.value)
    except Unkeyable:
        return ("name", member.name)


class _Entries:
    """One thread's entries (held weakly by the cache, strongly by the thread's local storage)."""

    __slots__ = ("__weakref__", "items")

    def __init__(self) -> None:
        self.items: dict[Hashable, Any] = {}


class SolverCache:
    """Built objects keyed by a hashable description of their structure, one set per thread.

    A look-up from a thread sees only the entries that thread built: a built solver is never
    called from two threads at once (CasADi functions are not thread-safe), whichever threads
    share the cache. A pickled or deep-copied cache is a new, empty one (the module docstring).

    Attributes
    ----------
    builds : int
        How many entries were built (cache misses), over all threads.
    hits : int
        How many look-ups found an existing entry, over all threads.
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()  # guards the counters and the set of threads' entries
        self._local = threading.local()  # .entries: this thread's _Entries
        self._all: weakref.WeakSet[_Entries] = weakref.WeakSet()  # every live thread's entries
        self.builds = 0
        self.hits = 0

    @property
    def _entries(self) -> dict[Hashable, Any]:
        """The calling thread's entries (created on its first look-up)."""
        entries: _Entries | None = getattr(self._local, "entries", None)
        if entries is None:
            entries = self._local.entries = _Entries()
            with self._lock:
                self._all.add(entries)
        return entries.items

    def get(self, key: Hashable, build: Callable[[], V]) -> V:
        """The entry for ``key``, built by ``build()`` the first time.

        Parameters
        ----------
        key : hashable
            A description of the structure (tuples of numbers and strings) that fixes everything
            the built object bakes in.
        build : callable
            Called without arguments when ``key`` is not cached yet; its result is stored.

        Returns
        -------
        object
            The cached or newly built object (the same object on every hit from this thread: do
            not mutate it, and do not hand it to another thread).
        """
        entries = self._entries
        if key in entries:
            with self._lock:
                self.hits += 1
            return entries[key]
        value = build()
        entries[key] = value
        with self._lock:
            self.builds += 1
        return value

    def __len__(self) -> int:
        """The number of entries, over all live threads."""
        with self._lock:
            return sum(len(entries.items) for entries in self._all)

    def clear(self) -> None:
        """Drop every entry of every thread (the counters are kept)."""
        with self._lock:
            for entries in list(self._all):
                entries.items.clear()

    def __getstate__(self) -> dict[str, Any]:
        return {}  # a new, empty cache on the other side (the module docstring)

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__init__()  # type: ignore[misc]


class RecentCache(SolverCache):
    """A :class:`SolverCache` that keeps only its most recently used entries (per thread, as a
    :class:`SolverCache` keeps them).

    A look-up, hit or build, makes its entry the most recent; past ``size`` entries, a thread's
    least recently used one is dropped (it is built again if met again). A study worker keeps its
    simulators in one, and a model its closed loops (:meth:`ocp.Simulator.closed_loop_function`),
    so that a study varying the model or the law does not pile them up. A pickled or deep-copied
    cache is a new, empty one of the same size.

    Parameters
    ----------
    size : int, optional
        Entries kept per thread (at least 1).
    """

    def __init__(self, size: int = 4) -> None:
        super().__init__()
        self.size = max(1, int(size))

    def get(self, key: Hashable, build: Callable[[], V]) -> V:
        value = super().get(key, build)
        entries = self._entries
        entries[key] = entries.pop(key)  # the most recent last
        while len(entries) > self.size:
            del entries[next(iter(entries))]
        return value

    def __getstate__(self) -> dict[str, Any]:
        return {"size": self.size}  # empty, of the same size

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__init__(state["size"])  # type: ignore[misc]
