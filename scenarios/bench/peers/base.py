"""The peer contract: a peer solves a problem's minimum-time or minimum-energy optimal control
problem with its own transcription and solver and reports what it reached.

What a peer can express: rest-to-rest or free-final-rate slews of a rigid body driven by ideal
body-axis torquers with box bounds ``|u_i| <= u_max,i``, no environment torques, no pointing
requirements (:func:`box_torque_problem_error` checks it); objectives ``"min_time"`` (free final
time, final rate as stated) and ``"min_energy"`` (∫‖u‖² dt over the problem's duration).
"""
from __future__ import annotations

import importlib
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from planners.problem import ManeuverProblem

__all__ = ["OBJECTIVES", "Peer", "PeerResult", "PeerUnavailable", "box_torque_problem_error", "load_peer",
           "torque_bounds"]

OBJECTIVES = ("min_time", "min_energy")
"""The objectives a peer may be asked to solve."""


class PeerUnavailable(Exception):
    """A peer's module or library is not installed: the peer is skipped with this note."""


@dataclass
class PeerResult:
    """What a peer reached on one problem.

    Parameters
    ----------
    objective : float or None
        The objective value: the final time [s] (``min_time``) or ∫‖u‖² dt [N² m² s]
        (``min_energy``); ``None`` when the solve failed.
    solve_time_s : float
        Wall time of the solve [s], the peer's build (code generation, NLP construction) excluded.
    status : str
        ``"ok"`` or ``"failed"``.
    iterations : int or None
        The solver's iteration count, when it reports one.
    message : str, optional
        The solver's return status or why it failed.
    build_time_s : float or None, optional
        Wall time of the peer's build [s], when measured.
    extra : dict, optional
        Anything else the peer reports (JSON-serialisable).
    solve_cpu_s : float or None, optional
        CPU time of the same solve [s] (``time.process_time`` of the process that solved it), when
        measured.
    """

    objective: float | None
    solve_time_s: float
    status: str
    iterations: int | None
    message: str = ""
    build_time_s: float | None = None
    extra: dict[str, Any] = field(default_factory=dict)
    solve_cpu_s: float | None = None


class Peer(Protocol):
    """A benchmark peer (the ``PEER`` object of a module named in :data:`scenarios.bench.peers.PEERS`)."""

    name: str

    def unavailable(self) -> str | None:
        """Why the peer cannot run on this machine (a missing library), or ``None``.

        Returns
        -------
        str or None
            The reason, or ``None``.
        """
        ...

    def version(self) -> str:
        """The version of the tool the peer drives (recorded in ``leaderboard.json``).

        Returns
        -------
        str
            Its distribution and version, for example ``"FATROP plugin of CasADi 3.8.2"``.
        """
        ...

    def problem_error(self, problem: ManeuverProblem, objective: str) -> str | None:
        """Why the peer cannot express ``problem`` with ``objective`` (``None``: it can).

        Parameters
        ----------
        problem : ManeuverProblem
            The problem.
        objective : str
            One of :data:`OBJECTIVES`.

        Returns
        -------
        str or None
            The reason, or ``None``.
        """
        ...

    def solve(self, problem: ManeuverProblem, objective: str) -> PeerResult:
        """Build and solve the problem; the build is timed apart from the solve.

        Parameters
        ----------
        problem : ManeuverProblem
            A problem :meth:`problem_error` accepts.
        objective : str
            One of :data:`OBJECTIVES`.

        Returns
        -------
        PeerResult
            What the solve reached (a failed solve is a result, not an exception).
        """
        ...


def load_peer(name: str, registry: dict[str, str] | None = None) -> Peer:
    """Import a peer's module and return its ``PEER``.

    Parameters
    ----------
    name : str
        A name of ``registry``.
    registry : dict or None, optional
        Name -> module path; ``None`` (default): :data:`scenarios.bench.peers.PEERS`.

    Returns
    -------
    Peer
        The peer.

    Raises
    ------
    KeyError
        ``name`` is not registered.
    PeerUnavailable
        Its module or the library it drives cannot be imported, its module defines no ``PEER``
        with ``problem_error`` and ``solve``, or ``PEER.unavailable()`` gives a reason.
    """
    if registry is None:
        from scenarios.bench.peers import PEERS  # the face fills it

        registry = PEERS
    path = registry[name]
    try:
        module = importlib.import_module(path)
    except (ImportError, PeerUnavailable) as error:
        raise PeerUnavailable(f"peer {name} skipped: {error}") from None
    peer = getattr(module, "PEER", None)
    if peer is None or not callable(getattr(peer, "solve", None)) or not callable(getattr(peer, "problem_error", None)):
        raise PeerUnavailable(f"peer {name} skipped: {path} defines no PEER with problem_error and solve")
    check = getattr(peer, "unavailable", None)
    reason = check() if callable(check) else None
    if reason:
        raise PeerUnavailable(f"peer {name} skipped: {reason}")
    return peer


def box_torque_problem_error(problem: ManeuverProblem, objective: str) -> str | None:
    """Why a problem is not a box-bounded rigid-body slew a peer can state (``None``: it is).

    Parameters
    ----------
    problem : ManeuverProblem
        The problem.
    objective : str
        The objective asked for.

    Returns
    -------
    str or None
        The reason, or ``None``.
    """
    spacecraft = problem.spacecraft
    if objective not in OBJECTIVES:
        return f"objective {objective} (peers solve {', '.join(OBJECTIVES)})"
    if spacecraft.torquers is None or len(spacecraft.actuators) != 1:
        return "only ideal body-axis torquers (box torque bounds) are expressed"
    environment = problem.environment
    if environment.gravity_gradient or environment.magnetic_field is not None or np.any(
            np.asarray(environment.disturbance_torque) != 0.0):
        return "environment torques are not expressed"
    if problem.pointing or problem.max_rate is not None:
        return "pointing and rate requirements are not expressed"
    if problem.qf is None:
        return "needs a target attitude"
    if objective == "min_time" and problem.omegaf is None:
        return "minimum time needs a final rate"
    return None


def torque_bounds(problem: ManeuverProblem) -> np.ndarray:
    """The per-axis torque bounds a peer imposes: the torquers' limits less the actuator margin.

    Parameters
    ----------
    problem : ManeuverProblem
        A problem :func:`box_torque_problem_error` accepts.

    Returns
    -------
    (3,) ndarray
        ``u_max,i`` [N m], body axes.
    """
    torquers = problem.spacecraft.torquers
    if torquers is None:
        raise ValueError("the problem has no torquers (box_torque_problem_error refuses it)")
    limits = np.asarray(torquers.max_torque, dtype=float) * np.ones(3)
    return limits * (1.0 - (problem.actuator_margin or 0.0))
