"""The closed-form attitude of a body spinning at ``v`` about its first axis with transverse rate
``r [sin θ, cos θ]``, ``θ = (v + c) t + β``, shared by the spin-extremal planner (Biggs & Horri)
and the axisymmetric natural motions (nano paper, whose Lax-pair reduction is the same form).

``q*(t) = E1(−β) ⊗ exp(t [−c, 0, r] / 2) ⊗ E1(θ(t))`` with ``E1(φ) = [cos φ/2, sin φ/2, 0, 0]``;
see :mod:`planners.spin_extremal` for the derivation and the correction to the paper's eq. 11.
"""
from __future__ import annotations

from typing import Any

import numpy as np


def extremal_quaternion(t: Any, v: Any, r: Any, c: Any, beta: Any, math: Any = np) -> tuple[Any, Any, Any, Any]:
    """``q*(t)`` from the identity (scalar first) as four components.

    Parameters
    ----------
    t : s, times (NumPy array or CasADi expression).
    v : rad/s, spin rate about the first body axis.
    r, c : rad/s, transverse rate amplitude and spin offset.
    beta : rad, phase of the transverse rate.
    math : ``numpy`` (default) or ``casadi``.

    Returns
    -------
    tuple
        ``(q0, q1, q2, q3)``.
    """
    K = math.sqrt(r**2 + c**2)
    fast, slow = (c + K + v) * t / 2, (c - K + v) * t / 2
    spin = (v + c) * t / 2 + beta
    nutation = r / K * math.sin(K * t / 2)
    return ((K - c) * math.cos(fast) + (K + c) * math.cos(slow)) / (2 * K), \
        ((K - c) * math.sin(fast) + (K + c) * math.sin(slow)) / (2 * K), \
        nutation * math.sin(spin), nutation * math.cos(spin)
