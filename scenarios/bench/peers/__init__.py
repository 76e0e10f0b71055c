"""Benchmark peers: other optimal-control tools solving the suite's problems side by side with
slewbench's planners in ``slewbench bench``.

A peer is a module with a ``PEER`` object satisfying :class:`~scenarios.bench.peers.base.Peer`:
``problem_error(problem, objective)`` says cheaply why it cannot express a problem, and
``solve(problem, objective)`` returns a :class:`~scenarios.bench.peers.base.PeerResult`
(objective value, solve time, status, iterations). :data:`PEERS` maps a peer's name to its module
path; the module is imported only when the peer runs (:func:`load_peer`), and a peer whose module
or library is missing is skipped with a note.

May import: :mod:`ocp`, :mod:`planners` (the problem), :mod:`scenarios.bench.peers` itself. Its
names are imported on first use.
"""
from __future__ import annotations

from scenarios._faces import lazy_face

_HOMES = {"Peer": "scenarios.bench.peers.base",
          "PeerResult": "scenarios.bench.peers.base",
          "PeerUnavailable": "scenarios.bench.peers.base",
          "load_peer": "scenarios.bench.peers.base"}

__all__ = ["PEERS", "Peer", "PeerResult", "PeerUnavailable", "load_peer"]

PEERS: dict[str, str] = {
    "fatrop": "scenarios.bench.peers.fatrop",
    "rockit": "scenarios.bench.peers.rockit",
    "acados": "scenarios.bench.peers.acados",
}
"""Peer name -> module path (the module defines ``PEER``); imported lazily by :func:`load_peer`."""

__getattr__, __dir__ = lazy_face(__name__, _HOMES)
