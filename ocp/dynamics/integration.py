"""The classical Runge-Kutta step, shared by the simulator and the transcriptions."""
from __future__ import annotations

from collections.abc import Callable
from typing import Any


def rk4_step(rhs: Callable[[Any, Any], Any], x: Any, t: Any, h: Any) -> Any:
    """One classical Runge-Kutta step of ``ẋ = rhs(x, t)``.

    Works on CasADi expressions (SX/MX, to build integrators) and on NumPy arrays alike.

    Parameters
    ----------
    rhs : callable
        ``rhs(x, t) -> ẋ``, same type and shape as ``x``.
    x : (n,) ndarray or casadi.SX or casadi.MX
        State at ``t``.
    t : float or casadi expression
        Time at the start of the step [s].
    h : float or casadi expression
        Step length [s].

    Returns
    -------
    same type as ``x``
        The state at ``t + h``.
    """
    k1 = rhs(x, t)
    k2 = rhs(x + h / 2 * k1, t + h / 2)
    k3 = rhs(x + h / 2 * k2, t + h / 2)
    k4 = rhs(x + h * k3, t + h)
    return x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
