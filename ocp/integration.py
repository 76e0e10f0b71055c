"""The classical Runge-Kutta step, shared by the simulator and the transcriptions."""
from __future__ import annotations

from typing import Callable


def rk4_step(rhs: Callable, x, t, h):
    """One RK4 step of ``ẋ = rhs(x, t)`` from ``(x, t)`` over ``h``; works on CasADi and NumPy."""
    k1 = rhs(x, t)
    k2 = rhs(x + h / 2 * k1, t + h / 2)
    k3 = rhs(x + h / 2 * k2, t + h / 2)
    k4 = rhs(x + h * k3, t + h)
    return x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
