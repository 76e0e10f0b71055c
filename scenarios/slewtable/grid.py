"""The slew table's grid: eigen-axes spread over the unit sphere and the slew angles.

Axes are a Fibonacci (golden-angle spiral) lattice: ``n`` nearly uniform points, each the centre of
an equal-area band. The held-out grid used to measure the fit is the same lattice of another size
turned by an irrational angle about z, so that none of its points is a table point.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["GOLDEN_ANGLE", "fibonacci_axes", "held_out_angles", "offset_axes"]

GOLDEN_ANGLE = math.pi * (3.0 - math.sqrt(5.0))
"""The spiral's turn between points [rad]."""


def fibonacci_axes(n: int, turn: float = 0.0) -> np.ndarray:
    """``n`` unit vectors spread nearly uniformly over the sphere.

    Parameters
    ----------
    n : int
        How many (>= 1).
    turn : float, optional
        Rotation of the whole lattice about z [rad].

    Returns
    -------
    numpy.ndarray, shape (n, 3)
        Unit vectors (body frame when used as eigen-axes); point ``i`` at ``z = 1 - (2 i + 1) / n``.
    """
    if n < 1:
        raise ValueError(f"n must be >= 1, got {n}")
    i = np.arange(n)
    z = 1.0 - (2.0 * i + 1.0) / n
    r = np.sqrt(np.maximum(0.0, 1.0 - z * z))
    phi = GOLDEN_ANGLE * i + turn
    return np.column_stack([r * np.cos(phi), r * np.sin(phi), z])


def offset_axes(n: int) -> np.ndarray:
    """The held-out lattice: :func:`fibonacci_axes` of ``n`` points turned by 1 rad about z.

    Parameters
    ----------
    n : int
        How many (>= 1).

    Returns
    -------
    numpy.ndarray, shape (n, 3)
        Unit vectors.
    """
    return fibonacci_axes(n, turn=1.0)


def held_out_angles(angles_deg: list[float]) -> list[float]:
    """Midpoints between consecutive table angles, where the fit in angle is least certain [deg].

    Parameters
    ----------
    angles_deg : list of float
        The table's angles [deg], increasing.

    Returns
    -------
    list of float
        The midpoints [deg].
    """
    return [0.5 * (a + b) for a, b in zip(angles_deg[:-1], angles_deg[1:])]
