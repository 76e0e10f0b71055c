"""The result objects of :func:`ocp.nlp.solve_multistart` (split from :mod:`ocp.nlp`, which
re-exports them): one start, and the whole search in the style of ``scipy.optimize.OptimizeResult``.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ocp.second_order import SecondOrderCheck

Array = NDArray[np.float64]


@dataclass
class StartResult:
    """One start of :func:`solve_multistart`.

    Parameters
    ----------
    status : str
        The solver's return status (e.g. IPOPT ``Solve_Succeeded``).
    f : float
        Objective at the point where the start stopped (the problem's units).
    iterations : int
        Solver iterations of this start.
    time_s : float
        Wall time of this start [s].
    violation : float
        Largest constraint violation at that point (constraint units).
    converged : bool
        Whether the module's status policy accepts the start.
    """

    status: str
    f: float
    iterations: int
    time_s: float
    violation: float
    converged: bool


@dataclass
class NLPResult:
    """The outcome of :func:`solve_multistart` (attributes as in ``scipy.optimize.OptimizeResult``).

    Parameters
    ----------
    x : ndarray or None
        The best converged decision vector, or ``None``.
    f : float
        Its objective (``inf`` without one).
    g : ndarray or None
        Its constraint values, or ``None``.
    success : bool
        A start converged (see the module's status policy).
    status : str
        ``"ok"``, ``"failed"`` or ``"infeasible"`` (the planners' statuses).
    message : str
        A human-readable summary.
    iterations : int
        Solver iterations over all starts.
    time_s : float
        Wall time of all starts [s].
    best_start : int or None
        Index of the winning start, or ``None``.
    starts : list of StartResult
        Per-start outcomes, in the order tried.
    lam_x, lam_g : ndarray or None
        Bound and constraint multipliers at ``x`` (``None`` without a converged start).
    second_order : SecondOrderCheck or None
        The second-order check of the best point (``None``: not made).
    """

    x: Array | None
    f: float
    g: Array | None
    success: bool
    status: str
    message: str
    iterations: int
    time_s: float
    best_start: int | None
    starts: list[StartResult] = field(default_factory=list)
    lam_x: Array | None = None
    lam_g: Array | None = None
    second_order: SecondOrderCheck | None = None

    @property
    def statuses(self) -> list[str]:
        """The solver status of every start, in order."""
        return [s.status for s in self.starts]

    def stats(self) -> dict[str, Any]:
        """A planner's ``stats`` entries.

        Returns
        -------
        dict
            ``objective``, ``iterations``, ``solver_status`` (list), ``solve_time_s`` [s],
            ``best_start``, ``starts`` (one dict per start, fields of :class:`StartResult`) and,
            when made, ``second_order`` (fields of :class:`~ocp.second_order.SecondOrderCheck`).
        """
        stats = {"objective": self.f, "iterations": self.iterations, "solver_status": self.statuses,
                 "solve_time_s": self.time_s, "best_start": self.best_start,
                 "starts": [vars(s) for s in self.starts]}
        if self.second_order is not None:
            stats["second_order"] = vars(self.second_order)
        return stats
