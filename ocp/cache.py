"""Explicit caches of built solvers, shared by planners across problems of the same structure.

Building a CasADi NLP or integrator costs far more than solving it once it exists. A
:class:`SolverCache` keeps what was built under a key that states the problem's *structure* (the
model's numbers baked into the graph, the transcription, the mesh, the solver options): problems
that differ only in parameters (boundary values, T) reuse the entry. A trade study gives one cache
to each worker process, so a collocation NLP is built once per worker and structure.
"""
from __future__ import annotations

from collections.abc import Callable, Hashable
from typing import Any, TypeVar

V = TypeVar("V")


class SolverCache:
    """Built objects keyed by a hashable description of their structure.

    Attributes
    ----------
    builds : int
        How many entries were built (cache misses).
    hits : int
        How many look-ups found an existing entry.
    """

    def __init__(self) -> None:
        self._entries: dict[Hashable, Any] = {}
        self.builds = 0
        self.hits = 0

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
            The cached or newly built object (the same object on every hit: do not mutate it).
        """
        if key in self._entries:
            self.hits += 1
            return self._entries[key]
        value = build()
        self._entries[key] = value
        self.builds += 1
        return value

    def __len__(self) -> int:
        return len(self._entries)

    def clear(self) -> None:
        """Drop every entry (the counters are kept)."""
        self._entries.clear()
