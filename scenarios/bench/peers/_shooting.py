"""What the multiple-shooting peers share: the rigid-body dynamics as a CasADi function, the
terminal attitude error, the RK4 step and their initial guesses: the start ``collocation`` starts
from (:func:`first_start_guess`, the peers' start in ``slewbench bench`` and in the side-by-side
benchmarks) and the eigenaxis slew (:func:`eigenaxis_guess`)."""
from __future__ import annotations

from typing import NamedTuple

import casadi as ca
import numpy as np

from planners.problem import ManeuverProblem

__all__ = ["N", "PeerGuess", "eigenaxis_guess", "first_start_guess", "rigid_body", "rk4_step", "terminal_error"]

N = 50
"""Shooting intervals of the peers (as in the issue's measurements)."""


def rigid_body(inertia: np.ndarray) -> ca.Function:
    """``f(x, u) -> ẋ`` of a rigid body, ``x = [q (scalar first, body to inertial), ω (rad/s, body)]``,
    ``u`` the body torque [N m].

    Parameters
    ----------
    inertia : (3, 3) ndarray
        Inertia [kg m²], body axes.

    Returns
    -------
    casadi.Function
        The dynamics.
    """
    x, u = ca.SX.sym("x", 7), ca.SX.sym("u", 3)
    q, w = x[:4], x[4:]
    inertia_dm = ca.DM(inertia)
    qdot = 0.5 * ca.vertcat(-ca.dot(q[1:], w), q[0] * w + ca.cross(q[1:], w))
    return ca.Function("f", [x, u], [ca.vertcat(qdot, ca.solve(inertia_dm, u - ca.cross(w, ca.mtimes(inertia_dm, w))))])


def rk4_step(f: ca.Function) -> ca.Function:
    """One RK4 step ``F(x, u, h)`` of ``f`` with the torque held over the step of ``h`` seconds.

    Parameters
    ----------
    f : casadi.Function
        The dynamics (:func:`rigid_body`).

    Returns
    -------
    casadi.Function
        The step.
    """
    x, u, h = ca.SX.sym("x", 7), ca.SX.sym("u", 3), ca.SX.sym("h")
    k1 = f(x, u)
    k2 = f(x + h / 2 * k1, u)
    k3 = f(x + h / 2 * k2, u)
    k4 = f(x + h * k3, u)
    return ca.Function("F", [x, u, h], [x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)])


def terminal_error(qf: np.ndarray | None, q_end: ca.MX) -> ca.MX:
    """The vector part of ``qf* ⊗ q_end`` (up to sign): zero when ``q_end = ±qf``.

    Parameters
    ----------
    qf : (4,) ndarray or None
        Target attitude, scalar first (``None`` is refused).
    q_end : casadi expression (4,)
        Final attitude.

    Returns
    -------
    casadi expression (3,)
        The attitude error's vector part.

    Raises
    ------
    ValueError
        Without a target attitude.
    """
    if qf is None:
        raise ValueError("the problem has no target attitude")
    return qf[0] * q_end[1:] - q_end[0] * ca.DM(qf[1:]) - ca.cross(ca.DM(qf[1:]), q_end[1:])


def eigenaxis_guess(problem: ManeuverProblem, objective: str) -> tuple[np.ndarray, float]:
    """Node states ``(7, N + 1)`` and the final time [s] of the eigenaxis slew: the bang-bang
    (``min_time``) or the smooth profile over the problem's duration (``min_energy``). The peers'
    start is :func:`first_start_guess`; this one is kept to compare (the bang-bang is a stationary
    point of Bilimoria & Wie's slews).

    Parameters
    ----------
    problem : ManeuverProblem
        The problem.
    objective : str
        ``"min_time"`` or ``"min_energy"``.

    Returns
    -------
    tuple
        States (7, N + 1) and the final time [s].
    """
    from planners import PLANNERS

    profile = "min_time" if objective == "min_time" else "smooth"
    reference = PLANNERS["eigenaxis"]({"profile": profile}).plan_start(problem)
    duration = reference.duration if objective == "min_time" else problem.duration
    t = np.linspace(0.0, duration, N + 1)
    sample = reference.sample(t)
    return np.vstack([np.asarray(sample.q).T, np.asarray(sample.omega).T]), float(duration)


class PeerGuess(NamedTuple):
    """A peer's initial guess on its shooting nodes.

    Parameters
    ----------
    states : (7, intervals + 1) ndarray
        Node states ``[q (scalar first), ω (rad/s)]`` at ``t_k = k T / intervals``.
    duration : float
        The final time [s]: the guess of a free one (``min_time``), else the problem's.
    start : str
        Which start it is, for the leaderboard's notes (``"start: ..."``).
    """

    states: np.ndarray
    duration: float
    start: str


def first_start_guess(problem: ManeuverProblem, objective: str, intervals: int = N) -> PeerGuess:
    """The first start of ``collocation`` (default options, ``objective``, ``intervals`` mesh
    intervals) on the peers' shooting nodes: like for like with our planner.

    It is :meth:`planners.collocation.planner.CollocationPlanner.first_start`: the warm start (the
    eigenaxis slew's ``smooth`` profile over the problem's duration, which bounds a free final time)
    as collocation seeds it and, for ``min_time``, perturbed by 3 % of ``|value| + floor`` per
    decision variable (normal noise, random generator seed 0: every call gives the same guess).
    For ``min_energy`` the planner does not perturb its first start, and this guess is the
    eigenaxis slew of :func:`eigenaxis_guess` (the same node states to 1e-16 on the suite's two
    minimum-energy problems). The node states are the stage states' model state; the final time
    of ``min_time`` is the median of the stages' perturbed copies of ``T``. The torques are not
    part of the guess (the peers start them at zero).

    Why not the eigenaxis slew for ``min_time``: with per-axis torque bounds its bang-bang is a
    stationary point of Bilimoria & Wie's slews (a saddle) and of XTE's, where FATROP, rockit and
    acados stay (3.5449 against 3.2431 at 180°), as they do from the smooth profile unperturbed;
    from this start they reach their discretisation's optimum on Bilimoria & Wie (measured
    2026-12-02, N = 50: 3.24339 at 180°).

    Parameters
    ----------
    problem : ManeuverProblem
        A problem of a rigid body on torquers (its model state is ``[q, ω]``).
    objective : str
        ``"min_time"`` or ``"min_energy"``.
    intervals : int, optional
        Shooting intervals (default :data:`N`).

    Returns
    -------
    PeerGuess
        Node states (7, intervals + 1), the final time [s] and which start it is.

    Raises
    ------
    ValueError
        Another objective, a model state other than ``[q, ω]``, or the warm start fails.
    """
    from planners.collocation import CollocationPlanner

    if objective not in ("min_time", "min_energy"):
        raise ValueError(f"objective must be 'min_time' or 'min_energy', got {objective!r}")
    if problem.model.nx != 7:
        raise ValueError(f"the peers' state is [q, ω] (7), this problem's model state has {problem.model.nx}")
    planner = CollocationPlanner({"objective": objective, "intervals": intervals})
    w, nlp, label = planner.first_start(problem)
    ns, nc = nlp.n_stage_state, nlp.n_interval
    # w = [s_0, c_0, ..., s_{N-1}, c_{N-1}, s_N]: the model state first in s_k, T last when free
    stages = np.vstack([w[:(ns + nc) * intervals].reshape(intervals, ns + nc)[:, :ns], w[None, -ns:]])
    duration = float(np.median(stages[:, -1])) if nlp.free_time else float(problem.duration)
    return PeerGuess(np.array(stages[:, :7].T), duration,
                     f"start: collocation's first ({label}), T0 {duration:.4g} s")
