"""Adaptive refinement of a slew table's axes to a stated tolerance on the fit's error.

The table's axes and triangles (:func:`scenarios.slewtable.grid.polytope_grid`, or the convex hull
of other axes) are the roots of a forest of spherical triangles (:class:`TriangleMesh`). A round:

1. *Check.* For every edge of the active triangles (all of them in round 1) whose midpoint is not
   known yet, the midpoint (on the great circle, so that a child never crosses a kink its parent
   did not) is solved at the *check angles* and at the midpoints of the table-angle intervals beside
   them (:func:`check_positions`: the fit interpolates in angle there, as the held-out grid's
   midpoints measure), and the current fit predicts it there; the point's *miss* is the largest
   ``|predicted / solved - 1|`` over those angles. An entry that is not ``ok``, or where the fit
   has no value, counts as a miss (the fit cannot vouch for it), except a proven-``infeasible``
   entry where the fit says ``inf`` too (the slew's end attitude breaks a pointing requirement:
   the fit knows it).
2. *Split.* An active triangle whose largest edge-midpoint miss is over the tolerance is cut in
   four at its edge midpoints (as is one whose three midpoints are known at every angle already:
   the data costs nothing more), and so is a *boundary* triangle: one whose corners, at a table
   angle, have both entries with a time and entries without one (the fit has no value in the cells
   beside that angle wherever the slew's end clears the pointing requirements: cutting it shrinks
   that region to the cells along the boundary). Neighbours are then cut too until no
   triangle has an edge subdivided twice or more than one subdivided edge (the mesh stays
   graded); the fit cuts a triangle with one subdivided edge in two, so that the triangulation is
   conforming (no vertex inside an edge) and the interpolant continuous.
3. *Complete.* Every new vertex is solved at the table's other angles.
4. The next round checks the children of the triangles split for a miss or on the boundary.

It stops when no check misses (the largest miss is under the tolerance: ``reached``) and no
boundary triangle was split, when no triangle is left to check, or when the next round would pass
the budget of axes or rounds (``reached`` then says whether the last round's checks all met the
tolerance). Only axes are refined: in angle the region without a value stays the interval between
the table's angles on either side of the boundary (more table angles shrink it). A check entry of a
midpoint that is not split is kept (the table's files list it) but is not in the fit, and neither
is a check at an angle midpoint. The refinement's checks are not a measure of the final fit's
error: they measure the fit *before* the round's points were added. The held-out grid does.

The solves go through a callable (:data:`Solver`): the slew table's runs them on the trade-study
engine (:func:`scenarios.slewtable.compute.compute_table`); tests give analytic functions.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from scenarios.schema.table import TABLE_REFINE

__all__ = ["RefineOptions", "RefineResult", "Solver", "TriangleMesh", "check_positions", "refine"]

Solver = Callable[[np.ndarray, list[float]], np.ndarray]
"""``solve(axes, positions) -> times``: slew times [s] of unit axes (n, 3) at angle *positions*, shape
(n, len(positions)): position ``k`` (a whole number) is the table's angle ``k``, ``k + 0.5`` the
midpoint between its angles ``k`` and ``k + 1``; ``inf`` where an entry is proven ``infeasible``, NaN
where it is otherwise not ``ok``. The fit that ``predict`` returns takes the same positions."""


def check_positions(check: list[int], k: int) -> list[float]:
    """Where a midpoint is checked: the check angles and the midpoints of the table-angle intervals
    beside them.

    Parameters
    ----------
    check : list of int
        Indices of the table's angles to check at, increasing.
    k : int
        How many angles the table has.

    Returns
    -------
    list of float
        Angle positions (:data:`Solver`), increasing: every check index, and ``j + 0.5`` for each
        interval ``[j, j + 1]`` with a check index at one end (all ``2 k - 1`` for every angle,
        as :func:`scenarios.slewtable.grid.held_out_angles`).
    """
    chosen = set(check)
    between = {j + 0.5 for j in range(k - 1) if j in chosen or j + 1 in chosen}
    return sorted({float(c) for c in chosen} | between)


def _edge(i: int, j: int) -> tuple[int, int]:
    return (i, j) if i < j else (j, i)


class TriangleMesh:
    """A forest of spherical triangles refined by midpoint subdivision, kept graded and conforming.

    Parameters
    ----------
    axes : array_like, shape (n, 3)
        Unit vectors (the vertices), body frame.
    triangles : array_like of int, shape (t, 3)
        The root triangles (vertex indices), covering the sphere once by central projection.

    Attributes
    ----------
    points : list of numpy.ndarray
        Every vertex so far (roots' first, then midpoints in the order they were made).
    leaves : dict
        Leaf triangle (its vertex indices, orientation kept) -> its depth below its root.
    mids : dict
        Edge ``(i, j)`` (``i < j``) -> the index of its midpoint, for every edge cut or checked so far.
    cut : set
        The edges cut (a leaf beside them was split).
    """

    def __init__(self, axes: Any, triangles: Any):
        points = np.asarray(axes, dtype=float).reshape(-1, 3)
        self.points: list[np.ndarray] = [p / np.linalg.norm(p) for p in points]
        self.leaves: dict[tuple[int, int, int], int] = {
            (int(a), int(b), int(c)): 0 for a, b, c in np.asarray(triangles, dtype=int).reshape(-1, 3)}
        self.mids: dict[tuple[int, int], int] = {}
        self.cut: set[tuple[int, int]] = set()

    def midpoint(self, i: int, j: int) -> int:
        """The index of the great-circle midpoint of edge ``(i, j)``, made if new (the edge is not cut by this).

        Parameters
        ----------
        i, j : int
            Vertex indices.

        Returns
        -------
        int
            The midpoint's index in :attr:`points`.
        """
        key = _edge(i, j)
        if key not in self.mids:
            p = self.points[i] + self.points[j]
            self.mids[key] = len(self.points)
            self.points.append(p / np.linalg.norm(p))
        return self.mids[key]

    def split(self, leaf: tuple[int, int, int]) -> list[tuple[int, int, int]]:
        """Cut a leaf in four at its edge midpoints.

        Parameters
        ----------
        leaf : tuple of 3 int
            A leaf of :attr:`leaves`.

        Returns
        -------
        list of tuple
            Its four children (corner children first, then the middle one), oriented as the leaf.
        """
        i, j, k = leaf
        depth = self.leaves.pop(leaf)
        a, b, c = self.midpoint(i, j), self.midpoint(j, k), self.midpoint(k, i)
        self.cut.update((_edge(i, j), _edge(j, k), _edge(k, i)))
        children = [(i, a, c), (a, j, b), (c, b, k), (a, b, c)]
        for child in children:
            self.leaves[child] = depth + 1
        return children

    def _hanging(self, leaf: tuple[int, int, int]) -> tuple[int, bool]:
        """How many of a leaf's edges are cut, and whether one is cut twice (a neighbour two
        levels finer)."""
        i, j, k = leaf
        cut, twice = 0, False
        for p, q in ((i, j), (j, k), (k, i)):
            if _edge(p, q) in self.cut:
                m = self.mids[_edge(p, q)]
                cut += 1
                twice = twice or _edge(p, m) in self.cut or _edge(m, q) in self.cut
        return cut, twice

    def grade(self) -> list[tuple[int, int, int]]:
        """Split leaves until none has an edge cut twice or more than one cut edge.

        Returns
        -------
        list of tuple
            The leaves split here.
        """
        split: list[tuple[int, int, int]] = []
        changed = True
        while changed:
            changed = False
            for leaf in list(self.leaves):
                if leaf not in self.leaves:
                    continue
                cut, twice = self._hanging(leaf)
                if twice or cut >= 2:
                    self.split(leaf)
                    split.append(leaf)
                    changed = True
        return split

    def conforming(self) -> np.ndarray:
        """The triangles of the fit: the leaves, each with one cut edge bisected at its midpoint.

        Returns
        -------
        numpy.ndarray of int, shape (t, 3)
            Vertex indices into :attr:`points`, oriented as their roots; the mesh must be graded
            (:meth:`grade`).
        """
        out = []
        for leaf in self.leaves:
            i, j, k = leaf
            for p, q, r in ((i, j, k), (j, k, i), (k, i, j)):
                if _edge(p, q) in self.cut:
                    m = self.mids[_edge(p, q)]
                    out.extend([(p, m, r), (m, q, r)])
                    break
            else:
                out.append(leaf)
        return np.array(out, dtype=int).reshape(-1, 3)

    def edges(self, leaves: Any) -> list[tuple[int, int]]:
        """The distinct edges of some leaves, in a fixed order.

        Parameters
        ----------
        leaves : iterable of tuple
            Leaves.

        Returns
        -------
        list of tuple
            Edges ``(i, j)`` with ``i < j``.
        """
        seen: dict[tuple[int, int], None] = {}
        for i, j, k in leaves:
            for p, q in ((i, j), (j, k), (k, i)):
                seen.setdefault(_edge(p, q), None)
        return list(seen)

    def axes(self) -> np.ndarray:
        """Every vertex.

        Returns
        -------
        numpy.ndarray, shape (n, 3)
            The unit vectors of :attr:`points`.
        """
        return np.array(self.points)


@dataclass
class RefineOptions:
    """What the refinement aims at and what it may spend.

    Parameters
    ----------
    tolerance : float
        Largest relative miss of the fit at a check point, as a fraction of the slew time (> 0).
    check_angles : list of int or None
        Indices of the table's angles a midpoint is checked at first; None: every angle.
    max_axes : int
        The refined table's axes at most (a round that would pass it splits only its worst
        triangles, then the refinement stops); default ``table.refine.max_axes``'s
        (:data:`scenarios.schema.table.TABLE_REFINE`).
    max_rounds : int
        Rounds at most; default ``table.refine.max_rounds``'s.
    """

    tolerance: float
    check_angles: list[int] | None = None
    max_axes: int = TABLE_REFINE["max_axes"].default
    max_rounds: int = TABLE_REFINE["max_rounds"].default


@dataclass
class RefineResult:
    """A refined table.

    Parameters
    ----------
    axes : numpy.ndarray, shape (n, 3)
        The fit's axes: the initial ones first, then the refinement's.
    times : numpy.ndarray, shape (n, k)
        Their slew times [s] at every angle (``inf`` where an entry is proven ``infeasible``, NaN
        where it is otherwise not ``ok``).
    triangles : numpy.ndarray of int, shape (t, 3)
        The conforming triangulation over ``axes``.
    checks : list of dict
        Each check point not in the fit: ``axis``, ``times`` at the table's angles and
        ``midpoint_times`` at the midpoints between them (NaN where not solved or not ok, ``inf``
        where infeasible).
    rounds : list of dict
        Per round: ``checked`` (points), ``solves``, ``max_miss``, ``missed`` (points over the
        tolerance), ``split`` (triangles split for a miss or on the boundary), ``boundary`` (of
        them, those on the boundary of the entries without a time), ``graded`` (split to keep the
        mesh graded), ``axes`` (after the round).
    reached : bool
        The last round's checks all met the tolerance.
    stopped : str
        Why it stopped.
    """

    axes: np.ndarray
    times: np.ndarray
    triangles: np.ndarray
    checks: list[dict[str, Any]] = field(default_factory=list)
    rounds: list[dict[str, Any]] = field(default_factory=list)
    reached: bool = False
    stopped: str = ""

    def summary(self) -> dict[str, Any]:
        """Plain data for ``fit.json`` (``meta.refinement``).

        Returns
        -------
        dict
            ``rounds``, ``reached``, ``stopped``, ``axes`` (in the fit) and ``check_points``
            (checked, not in the fit).
        """
        return {"rounds": self.rounds, "reached": self.reached, "stopped": self.stopped,
                "axes": len(self.axes), "check_points": len(self.checks)}


def refine(axes: Any, triangles: Any, times: Any, solve: Solver, predict: Callable[[np.ndarray, np.ndarray, np.ndarray],
           Callable[[np.ndarray, list[float]], np.ndarray] | None], options: RefineOptions) -> RefineResult:
    """Refine a table's axes until the fit's misses at edge midpoints are under the tolerance
    (module docstring).

    Parameters
    ----------
    axes : array_like, shape (n, 3)
        The initial unit axes, body frame.
    triangles : array_like of int, shape (t, 3)
        Their triangles, covering the sphere once.
    times : array_like, shape (n, k)
        Their slew times at every table angle [s] (``inf``: proven infeasible; NaN: otherwise not ok).
    solve : Solver
        Solves new axes at some angle positions (the table's angles and the midpoints between them).
    predict : callable
        ``predict(axes, times, triangles)`` -> a fit as ``f(axes, positions) -> times`` (shape
        (n, len(positions)), positions as :data:`Solver`'s; ``inf`` where the end attitude breaks a
        pointing requirement), or None when no fit can be made from them.
    options : RefineOptions
        Tolerance and budget.

    Returns
    -------
    RefineResult
        The refined axes, times and triangles, the check points left out, and each round's figures.

    Raises
    ------
    ValueError
        A tolerance that is not positive, check angles out of range, or a budget under 1.
    """
    known = np.array(times, dtype=float)
    k = known.shape[1]
    if not options.tolerance > 0.0:
        raise ValueError(f"the tolerance must be > 0, got {options.tolerance!r}")
    check = list(range(k)) if options.check_angles is None else sorted(set(options.check_angles))
    if not check or min(check) < 0 or max(check) >= k:
        raise ValueError(f"check angles must be indices of the {k} table angles, got {options.check_angles!r}")
    if options.max_rounds < 1 or options.max_axes < 1:
        raise ValueError("max_rounds and max_axes must be >= 1")
    mesh = TriangleMesh(axes, triangles)
    rows: dict[int, np.ndarray] = {i: known[i] for i in range(len(known))}  # point -> times (NaN: not solved)
    between: dict[int, np.ndarray] = {}  # point -> times at the angle midpoints (NaN: not solved)
    complete = set(rows)  # points solved at every angle
    positions = check_positions(check, k)
    on_table = [int(p) for p in positions if p == int(p)]
    midway = [int(p) for p in positions if p != int(p)]  # interval j: the midpoint of angles j, j + 1
    result = RefineResult(np.zeros((0, 3)), np.zeros((0, k)), np.zeros((0, 3), dtype=int))
    active = list(mesh.leaves)
    stopped = f"the budget of {options.max_rounds} rounds"
    missed = 0
    for number in range(1, options.max_rounds + 1):
        fit = predict(*_fit_data(mesh, rows, complete, k))
        if fit is None:
            stopped = "no fit over the sphere to check against"
            break
        candidates = [e for e in mesh.edges(active) if e not in mesh.mids or mesh.mids[e] not in complete]
        boundary = {leaf for leaf in active if _mixed(leaf, rows)}
        if not candidates and not boundary:
            result.reached, stopped = True, "no triangle left to check"
            break
        # 1. check
        points = [mesh.midpoint(*e) for e in candidates]
        ask = [p for p in points if p not in rows or np.isnan(rows[p][on_table]).all()]
        solves = 0
        if ask:
            got = solve(np.array([mesh.points[p] for p in ask]), positions)
            solves += got.size
            for p, values in zip(ask, got):
                row = np.full(k, np.nan)
                row[on_table] = values[[positions.index(float(c)) for c in on_table]]
                rows[p] = row
                mid = np.full(k - 1, np.nan)
                mid[midway] = values[[positions.index(j + 0.5) for j in midway]]
                between[p] = mid
        truth = np.array([np.concatenate([rows[p][on_table], between.get(p, np.full(k - 1, np.nan))[midway]])
                          for p in points]).reshape(len(points), len(positions))
        estimate = (fit(np.array([mesh.points[p] for p in points]), on_table + [j + 0.5 for j in midway])
                    if points else np.zeros_like(truth))
        with np.errstate(invalid="ignore", divide="ignore"):  # the fit knows an impossible entry: inf there
            miss = np.where(np.isfinite(truth) & np.isfinite(estimate), np.abs(estimate / truth - 1.0),
                            np.where((truth == np.inf) & (estimate == np.inf), 0.0, np.inf)).max(axis=1)
        by_point = dict(zip(points, miss.tolist()))
        # 2. split
        scores = []
        for leaf in active:
            if leaf not in mesh.leaves:
                continue
            i, j, l = leaf
            mids = [mesh.mids[_edge(p, q)] for p, q in ((i, j), (j, l), (l, i))]
            worst = max(by_point.get(m, 0.0) for m in mids)
            free = all(m in complete for m in mids)
            if worst > options.tolerance or free or leaf in boundary:
                scores.append((worst, leaf, worst > options.tolerance or leaf in boundary))
        scores.sort(key=lambda item: -item[0])
        before = len(complete)
        missed = sum(1 for value in miss if value > options.tolerance)
        chosen: list[tuple[int, int, int]] = []
        nextactive: list[tuple[int, int, int]] = []
        over = False
        for _worst, leaf, flagged in scores:
            if _count_after(mesh, complete, chosen, leaf) > options.max_axes:
                over = True
                break
            chosen.append(leaf)
            children = mesh.split(leaf)
            if flagged:
                nextactive.extend(children)
        graded = mesh.grade()
        # 3. complete
        vertices = {v for leaf in mesh.leaves for v in leaf}
        todo = sorted(v for v in vertices if v not in complete)
        if todo:
            # solve each point at its own missing angles, grouped by the set of angles missing
            groups: dict[tuple[int, ...], list[int]] = {}
            for v in todo:
                row = rows.get(v, np.full(k, np.nan))
                groups.setdefault(tuple(a for a in range(k) if np.isnan(row[a])), []).append(v)
            for angle_set, members in groups.items():
                got = solve(np.array([mesh.points[v] for v in members]), list(angle_set))
                solves += got.size
                for v, values in zip(members, got):
                    row = rows.get(v, np.full(k, np.nan)).copy()
                    row[list(angle_set)] = values
                    rows[v] = row
            complete.update(todo)
        result.rounds.append({"round": number, "checked": len(points), "solves": int(solves),
                              "max_miss": float(np.max(miss)) if len(miss) else 0.0, "missed": missed,
                              "split": sum(1 for *_, flagged in scores[:len(chosen)] if flagged),
                              "boundary": sum(1 for _, leaf, _ in scores[:len(chosen)] if leaf in boundary),
                              "graded": len(graded), "axes": len(complete), "new_axes": len(complete) - before})
        if missed == 0 and not boundary:
            result.reached, stopped = True, f"every check within the tolerance {options.tolerance:g}"
            break
        if over:
            stopped = f"the budget of {options.max_axes} axes"
            break
        active = [leaf for leaf in nextactive if leaf in mesh.leaves]
        if not active:
            stopped = "no triangle left to check"
            break
    result.stopped = stopped
    result.reached = result.reached or (bool(result.rounds) and missed == 0)
    result.axes, result.times, result.triangles = _fit_data(mesh, rows, complete, k)
    result.checks = [{"axis": mesh.points[p].tolist(), "times": rows[p].tolist(),
                      "midpoint_times": between.get(p, np.full(k - 1, np.nan)).tolist()}
                     for p in sorted(rows) if p not in complete]
    return result


def _mixed(leaf: tuple[int, int, int], rows: dict[int, np.ndarray]) -> bool:
    """Whether a leaf's corners have, at one table angle, both entries with a time and entries
    without one (not ``ok``): the boundary of the entries without a time crosses it, and cutting it
    shrinks the cells where the fit has no value (a leaf whose corners all lack a time at an angle,
    beside one where all have one, is not: cutting it along the axes changes nothing there)."""
    corners = [rows.get(v) for v in leaf]
    if any(row is None for row in corners):
        return False
    timed = np.isfinite(np.array(corners))  # (3, k)
    return bool(np.any(timed.any(axis=0) & ~timed.all(axis=0)))


def _count_after(mesh: TriangleMesh, complete: set[int], chosen: list[tuple[int, int, int]],
                 leaf: tuple[int, int, int]) -> int:
    """Complete vertices once ``leaf`` is split as well as ``chosen`` (grading left out)."""
    extra: set[int | tuple[int, int]] = set()
    for i, j, k in [*chosen, leaf]:
        for p, q in ((i, j), (j, k), (k, i)):
            m = mesh.mids.get(_edge(p, q))
            if m is None:
                extra.add(_edge(p, q))
            elif m not in complete:
                extra.add(m)
    return len(complete) + len(extra)


def _fit_data(mesh: TriangleMesh, rows: dict[int, np.ndarray], complete: set[int], k: int
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The complete vertices (renumbered in order), their times and the conforming triangles."""
    order = sorted(complete)
    index = {p: n for n, p in enumerate(order)}
    triangles = mesh.conforming()
    renumbered = np.array([[index[v] for v in tri] for tri in triangles.tolist()], dtype=int).reshape(-1, 3)
    return (np.array([mesh.points[p] for p in order]).reshape(-1, 3),
            np.array([rows[p] for p in order]).reshape(-1, k), renumbered)
