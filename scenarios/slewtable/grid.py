"""The slew table's grid: eigen-axes spread over the unit sphere and the slew angles.

Axes are a Fibonacci (golden-angle spiral) lattice: ``n`` nearly uniform points, each the centre of
an equal-area band. The held-out grid used to measure the fit is the same lattice of another size
turned by an irrational angle about z, so that none of its axes is a table axis; it is solved at
every table angle (the largest included: what a scheduler asks most) and at the midpoints between
them (:func:`held_out_angles`), so that it measures the fit between axes and between angles.
"""
from __future__ import annotations

import itertools
import math

import numpy as np

__all__ = ["GOLDEN_ANGLE", "fibonacci_axes", "held_out_angles", "offset_axes", "polytope_grid"]

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
    """The held-out grid's angles: every table angle and the midpoints between consecutive ones [deg].

    At a table angle the fit interpolates over axes only (the table's entries at that angle), at a
    midpoint over axes and angles; a held-out axis is not a table axis, so both are measured, and
    the largest angle (the slews a scheduler meets most) among them.

    Parameters
    ----------
    angles_deg : list of float
        The table's angles [deg], increasing.

    Returns
    -------
    list of float
        The table's angles and their midpoints, increasing [deg] (``2 k - 1`` of them for ``k`` angles).
    """
    mids = [0.5 * (a + b) for a, b in itertools.pairwise(angles_deg)]
    return sorted([float(a) for a in angles_deg] + mids)


def polytope_grid(facets: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """About ``n`` axes whose triangles follow the kinks of the slew time over the sphere.

    The minimum slew time has kinks along the great circles where the actuator that limits the
    acceleration changes: where the active facet of the torque zonotope changes
    (:func:`scenarios.slewtable.fit.zonotope_facets`). These are the edges of the polytope
    ``P = {v : |a_f · v| <= 1 for every facet f}`` (``a_f`` the facets' normals over their supports,
    times the inertia). Each face of ``P`` is cut into triangles (a fan from its centre, each
    triangle subdivided ``L`` times, ``L`` chosen for about ``n`` points) and the points are
    projected onto the unit sphere: no triangle crosses a kink.

    Parameters
    ----------
    facets : numpy.ndarray, shape (f, 3)
        The vectors ``a_f`` [1/(N m) times kg m², i.e. s²/rad].
    n : int
        Axes wanted (the result has about as many, at least the polytope's vertices and face centres).

    Returns
    -------
    axes : numpy.ndarray, shape (m, 3)
        Unit axes, body frame.
    triangles : numpy.ndarray, shape (t, 3)
        Vertex indices of the triangles covering the sphere once (by central projection).
    """
    from scipy.spatial import HalfspaceIntersection
    a = np.asarray(facets, dtype=float).reshape(-1, 3)
    halfspaces = np.vstack([np.column_stack([a, -np.ones(len(a))]), np.column_stack([-a, -np.ones(len(a))])])
    vertices = HalfspaceIntersection(halfspaces, np.zeros(3)).intersections
    scale = np.max(np.linalg.norm(vertices, axis=1))
    unique: list[np.ndarray] = []
    for v in vertices:
        if not any(np.linalg.norm(v - u) < 1e-9 * scale for u in unique):
            unique.append(v)
    vertices = np.array(unique)
    fans = []  # (centre, vertex, next vertex) of every face's fan
    for normal in halfspaces[:, :3]:
        on = vertices[np.abs(vertices @ normal - 1.0) < 1e-7]
        if len(on) < 3:
            continue
        centre = on.mean(axis=0)
        u = on[0] - centre
        u /= np.linalg.norm(u)
        w = np.cross(normal / np.linalg.norm(normal), u)
        order = np.argsort(np.arctan2((on - centre) @ w, (on - centre) @ u))
        ring = on[order]
        for i in range(len(ring)):
            fans.append((centre, ring[i], ring[(i + 1) % len(ring)]))

    def build(level: int) -> tuple[np.ndarray, np.ndarray]:
        points: list[np.ndarray] = []
        index: dict[tuple[int, int, int], int] = {}

        def point(p: np.ndarray) -> int:
            key = tuple(round(c) for c in (p / scale * 1e9).tolist())
            if key not in index:
                index[key] = len(points)
                points.append(p)
            return index[key]

        triangles = []
        for c, p, q in fans:
            ids = {}
            for i in range(level + 1):
                for j in range(level + 1 - i):
                    k = level - i - j
                    ids[i, j] = point((k * c + i * p + j * q) / level)
            for i in range(level):
                for j in range(level - i):
                    triangles.append((ids[i, j], ids[i + 1, j], ids[i, j + 1]))
                    if i + j < level - 1:
                        triangles.append((ids[i + 1, j], ids[i + 1, j + 1], ids[i, j + 1]))
        cloud = np.array(points)
        return cloud / np.linalg.norm(cloud, axis=1, keepdims=True), np.array(triangles)

    best = build(1)
    for level in range(2, 40):
        candidate = build(level)
        if abs(len(candidate[0]) - n) < abs(len(best[0]) - n):
            best = candidate
        if len(candidate[0]) > n:
            break
    return best
