"""What the multiple-shooting peers share: the rigid-body dynamics as a CasADi function, the
terminal attitude error, the RK4 step and a guess from the eigenaxis slew."""
from __future__ import annotations

import casadi as ca
import numpy as np

from planners.problem import ManeuverProblem

__all__ = ["N", "eigenaxis_guess", "rigid_body", "rk4_step", "terminal_error"]

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
    (``min_time``) or the smooth profile over the problem's duration (``min_energy``).

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
    reference = PLANNERS["eigenaxis"]({"profile": profile}).plan(problem)
    duration = reference.duration if objective == "min_time" else problem.duration
    t = np.linspace(0.0, duration, N + 1)
    sample = reference.sample(t)
    return np.vstack([np.asarray(sample.q).T, np.asarray(sample.omega).T]), float(duration)
