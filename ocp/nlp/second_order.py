"""Second-order sufficient conditions at a converged NLP point: a strict local minimum or not.

A first-order point (the KKT conditions hold) can be a minimum, a saddle or a maximum: the eigenaxis
slew is such a saddle for minimum time under per-axis torque bounds (Bilimoria & Wie's 3.5449
against 3.2431). The second-order sufficient conditions (Nocedal & Wright, *Numerical
Optimization*, 2nd ed., Theorem 12.6) decide it: the Hessian of the Lagrangian ``∇²L`` is positive
definite on the critical cone of the active constraints. Here that cone is bounded from outside
by the subspace

    Z = { d : ∇g_i·d = 0 for equality and strongly active rows,  d_j = 0 for strongly active bounds },

a constraint or bound being *strongly active* when it is at its bound with a multiplier above
``multiplier_tolerance``. A weakly active one (at its bound, multiplier about zero) is left free,
which only enlarges ``Z``: positive definiteness on ``Z`` then implies it on the critical cone, so
the check is conservative. It can report "not certified" at a true minimum (degenerate or singular
arcs), never "certified" at a saddle: a caller falls back to its other evidence (restarts).

How: by inertia, with a sparse LDLᵀ, on NLPs of any size. With ``H`` the Hessian on the free
variables ``F`` (the strongly active bounds fixed) and ``A`` the active rows on them, the check asks
whether ``dᵀ H d > δ ‖d‖²`` on ``Z = null(A)``, ``δ`` the curvature threshold
(``curvature_tolerance × ‖H‖∞``, ``H``'s own scale: see :data:`CURVATURE_TOLERANCE`). The matrix

    K(s) = [[H + s I, Aᵀ], [A, −ε I]]      (ε = :data:`PENALTY` × max(1, ‖A‖∞)² / ‖H‖∞)

(factorised normalised, as ``S K(s) S = [[H / η + (s / η) I, Aᵀ], [A, −η ε I]]`` with ``η = ‖H‖∞``
and ``S = diag(I / √η, √η I)``: a congruence, so the same inertia by Sylvester's law) has, by
Haynsworth's inertia additivity over its negative definite block ``−ε I``, the ``m``
negative eigenvalues of that block plus the inertia of ``M(s) = H + s I + AᵀA / ε``, which on ``Z``
is ``H + s I``. So ``M(−δ)`` positive definite (``K(−δ)`` of inertia ``(n_F, m, 0)``) proves the
conditions with curvature above ``δ``. Otherwise the negative eigenvalues of ``M(+δ)`` (those of
``K(+δ)`` beyond ``m``) bound from above the dimension of the largest subspace of ``Z`` where the
curvature is below ``−δ``: none proves that no direction of ``Z`` curves below ``−δ`` (a
*degenerate* point: curvature near zero somewhere, e.g. a weakly active bound left free or a
singular arc, but no saddle direction beyond ``−δ``); some are evidence of a saddle (as many as the
directions when ``ε`` is small against ``A``'s singular values, more otherwise). Unlike the
unregularised ``[[H, Aᵀ], [A, 0]]`` of the inertia theorem (Nocedal & Wright, Lemma 16.3; Gould
1985), this needs no full row rank of ``A``: a collocation NLP's active rows are dependent at every
optimum of the bench (one redundant row on Bilimoria & Wie), and a dependent row only adds a
multiple of another's ``aaᵀ / ε``. ``Z = {0}`` (a vertex, e.g. a bang-bang optimum) makes ``AᵀA``
positive definite and is certified when ``ε`` is small against ``A``'s least singular value squared
(7e-12 on the bench's two-wheel minimum time, certified with :data:`PENALTY` 1e-8, not with 1e-6).

CasADi's ``ldl`` factorises the normalised ``K̃ = S K S`` (``casadi.Linsol``, its AMD ordering)
and counts the negative pivots; it does not pivot numerically, which the shift and ``ε`` make
possible (``H`` has zero diagonal entries where the controls enter linearly; without them the
factorisation meets zero pivots) but not necessarily accurate: a pivot of size ``δ / η`` grows its
neighbours by ``η / δ``. So its backward error is estimated (the residual of one solve with a
random right-hand side, relative to ``‖K̃‖∞ ‖x‖∞ + ‖b‖∞``) and the inertia is used only when that
error times ``‖K̃‖∞`` is below ``(δ / η)`` / :data:`GUARD` (``curvature_tolerance / GUARD``): the
factors are then exact for ``K̃ + E`` with ``‖E‖`` well below ``δ / η``, which moves the curvature
of ``H / η`` found on ``Z`` by at most ``‖E‖ + ‖E‖² / (η ε − ‖E‖)``, a fraction of ``δ / η`` (of
``δ`` for ``H``'s) (an estimate, not a bound: a random right-hand side exposes an inaccurate
factorisation with probability one, not with a proven margin). A zero pivot or a larger error
leaves the point not checked. Normalised because that error is normwise: with ``H`` unscaled,
``‖K‖∞`` is ``A``'s where ``‖H‖∞`` is much smaller, and an error of ``A``'s size is set against a
threshold of ``H``'s (Bilimoria & Wie's 50-interval optimum, ``‖H‖∞ = 0.045``, ``δ = 4.5e-8``:
backward error 3e-10 × ``‖K‖`` 21, above ``δ`` / 10, not checked; normalised, it passes with
``GUARD`` 1000 and is certified).

The theorem assumes a KKT point, so the first-order conditions are verified first (stationarity of
the Lagrangian ``L = f + lam_gᵀ g + lam_xᵀ x``, CasADi's signs; every multiplier of the sign of the
bound it belongs to and zero away from it; feasibility): a solve that stalled (the multistart
accepts IPOPT's ``Search_Direction_Becomes_Too_Small`` at a feasible point) or multipliers of another
convention are reported as not checked, never certified.
"""
from __future__ import annotations

import contextlib
import functools
import io
import sys
import threading
import weakref
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ocp.fast_call import BufferedFunction

Array = NDArray[np.float64]

CURVATURE_TOLERANCE = 1e-6
"""Default ``curvature_tolerance``: ``δ = 1e-6 × ‖H‖∞`` (``‖H‖∞`` taken as 1 when ``H = 0``, where
every curvature on ``Z`` is zero: degenerate unless ``Z = {0}``).

Relative to ``H``'s own scale, without a floor, because the factorisation's accuracy is relative:
multiplying the objective (and with it ``H`` and the multipliers) by ``c > 0`` multiplies ``δ`` by
``c`` and ``ε`` by ``1 / c``, which makes ``K(±δ)`` the congruent ``S K S`` of the unscaled one
(``S = diag(√c I, I / √c)``): the same inertia, and factors that Gaussian elimination, invariant
under diagonal scaling, computes as the scaled ones up to the rounding of the scaling, so the
verdict does not change, as the second-order conditions do not (the guard's normwise error is the
one quantity not exactly invariant). The former floor ``δ = 1e-6 × max(1, ‖H‖∞)`` was
absolute below ``‖H‖∞ = 1``: a QP's curvatures 1e-8 to 1e-6 (its objective times 1e-7) were
"degenerate" against it. A small ``‖H‖∞`` lowers ``δ``; a ``δ`` below what the factorisation
resolves on a point is refused by the guard (not checked), never certified. A curvature small
against ``‖H‖∞`` itself is the refinement's (:data:`FINEST_CURVATURE_TOLERANCE`): on the bench's
natural-motion minimum energy (``‖H‖∞ = 2.25``, the controls' energy, not small though the
objective is 5.8e-8) the curvature on ``Z`` goes down to 1.7e-9 = 7.7e-10 ``‖H‖∞`` (dense
eigenvalues, all positive; 15 below ``δ``): degenerate at ``δ``, certified at ``3.2e-10 ‖H‖∞``.

The accuracy of the unpivoted factorisation decides the tolerance (its pivots of size ``δ`` grow
their neighbours by ``1 / δ``). On the collocation optima of the bench problems and Bilimoria &
Wie's 8- and 50-interval optimum and eigenaxis saddle (13 points, both shifts), the largest ``GUARD`` of 1, 10, 100, 1000 that every
factorisation passed was at 1e-6 at least 100 (1000 on 11 points); at 1e-7 only 1 on two points
(norm-bounded eigenaxis, spin repoint); at 1e-8 (the dense check's tolerance before) none on three
(full inertia, norm-bounded, spin repoint). The least curvature among the certified points that
are no vertex is 4e-4 (spin repoint, minimum energy), so 1e-6 costs none of them. (Measured with
``δ = 1e-6 × max(1, ‖H‖∞)`` and ``K`` not normalised. Relative to ``‖H‖∞`` and normalised, on 23
points (the tests' 12 coarse optima and saddles, Bilimoria & Wie's 50-interval optimum and saddle,
the bench's natural motion, spin repoint, two-wheel, keep-out, norm-bounded, 90°, full inertia,
XTE and VEPA optima) the factorisations at ``±δ`` pass ``GUARD`` 100, 1000 on 19; ``δ`` is smaller where
``‖H‖∞ < 1``: 0.22 to 0.27 on Bilimoria & Wie's 8 intervals, 0.04 on 50, 0.62 norm-bounded, 0.05
at 90°, 0.47 full inertia. The verdicts are the same but natural motion's, certified by the
refinement; the saddles count more directions below the smaller ``−δ``: 22 and 72 on Bilimoria &
Wie's 8 and 50 intervals, against 20 and 28, as many as the dense eigenvalues.)"""

PENALTY = 1e-8
"""``ε = PENALTY × max(1, ‖A‖∞)² / ‖H‖∞`` (``‖H‖∞`` as in :data:`CURVATURE_TOLERANCE`, so
``δ ε`` does not depend on ``H``'s scale): the ``−ε I`` block of the regularised KKT
matrix. A vertex is certified, and a count is exact, only when ``s² / ε`` exceeds the curvature
along the directions of ``A``'s small singular values ``s``, which asks for a small ``ε``; the
elimination's cancellations ask for ``δ ε`` well above the unit roundoff times ``‖A‖²`` (here
``δ ε = 1e-14 ‖A‖∞²``; ``ε = δ = 1e-8`` met zero pivots on Bilimoria & Wie). Measured on the
collocation optima of the bench problems and Bilimoria & Wie's 8- and 50-interval optimum and
eigenaxis saddle, against the dense reduced Hessian's eigenvalues: ``ε`` proportional to ``δ``
(``10 δ``) left XTE's 8-interval optimum, a vertex with ``s`` down to 7e-5, with 2 to 5 false
negative curvatures; ``PENALTY = 1e-6`` found 3 and 1 directions below ``±δ`` on the keep-out
optimum (dense: 2 and 0) and 3 and 2 on the two-wheel vertex (``s = 3e-6``; dense: 0); 1e-8 to
1e-10 give the dense counts on all 13 points, and at 1e-8 every factorisation passes the guard
with ``GUARD = 100`` (ten times the margin asked)."""

ZERO_PIVOT_WARNING = "LDL factorization has zeros in D"
"""CasADi's ``ldl`` warning on a zero pivot, which the check reports in its message instead. It is
held back in the main thread only, where ``sys.stderr`` (the process's) is swapped for the
factorisation's fraction of a millisecond and what else was written then is passed on; a line
another thread writes while it is swapped comes out later, or, in a race with the read of the
swapped stream, not at all. In other threads the warning is let through."""

GUARD = 10.0
"""The estimated backward error of the factorisation, times ``‖K̃‖∞`` (the normalised matrix), must
be below ``δ / (‖H‖∞ GUARD)`` (see the module docstring)."""

FINEST_CURVATURE_TOLERANCE = 1e-10
"""A point degenerate at ``δ`` (no curvature below ``−δ``, some between ``±δ``) is checked again at
``δ / REFINEMENT``, ``δ / REFINEMENT²``, ... down to this times ``‖H‖∞``, and certified at the first
threshold where no curvature on ``Z`` is below it, as long as the factorisation passes the guard
there: the floor is the factorisation's measured accuracy on the point, not a fixed one. A zero
curvature stays below every threshold and the point degenerate; the floor, six orders of magnitude
above the unit roundoff, keeps the Hessian's own rounding (its entries a few roundoffs off) out of
it. The bench's natural-motion minimum energy (least curvature 7.7e-10 ``‖H‖∞``) is certified at
``3.2e-10 ‖H‖∞``, its factorisation passing the guard at that threshold (the guard is applied at
each threshold tried, not at ``δ`` alone)."""

REFINEMENT = 10.0 ** 0.5
"""The ratio of successive thresholds of a degenerate point's refinement (one factorisation each)."""


@dataclass(frozen=True)
class SecondOrderCheck:
    """The outcome of :func:`second_order_check`.

    Parameters
    ----------
    certified : bool
        The second-order sufficient conditions hold: a strict local minimum, curvature above
        ``curvature_threshold`` on ``Z``.
    negative_curvatures : int
        When not certified: negative eigenvalues of ``M(+δ) = H + δ I + AᵀA / ε`` (module
        docstring), an upper bound on the directions of ``Z`` curving below ``−δ``; 0 when
        certified or degenerate; -1 when not checked.
    curvature_threshold : float
        ``δ`` (``nan`` when not checked).
    message : str
        What was found, or why the point was not checked.
    """

    certified: bool
    negative_curvatures: int
    curvature_threshold: float
    message: str

    @property
    def degenerate(self) -> bool:
        """Not certified, but no direction of ``Z`` curves below ``−δ``: near-zero curvature, no
        saddle direction found."""
        return not self.certified and self.negative_curvatures == 0


def _not_checked(message: str) -> SecondOrderCheck:
    return SecondOrderCheck(False, -1, float("nan"), message)


def _output(function: ca.Function, names: tuple[str, ...]) -> int:
    """Index of the output of ``function`` named one of ``names`` (the plugins differ: IPOPT's
    ``nlp_hess_l`` returns ``triu_hess_gamma_x_x`` alone, FATROP's ``grad_gamma_x`` first, then the
    full ``hess_gamma_x_x``; ``nlp_grad_f`` returns ``f`` first or not at all)."""
    for index in range(function.n_out()):
        if function.name_out(index) in names:
            return index
    raise RuntimeError(f"{function.name()} has none of the outputs {names}")


_FUNCTIONS = threading.local()
"""Per thread: ``.by_solver``, a solver's derivative functions with their buffers
(:func:`_derivative`), kept while the solver lives (CasADi functions are not thread-safe, and the
buffers are overwritten by every evaluation); ``.patterns``, per buffered function and output, its
pattern (:func:`_pattern`)."""
_Pattern = tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64], tuple[int, int]]
_Triplets = tuple[NDArray[np.integer], NDArray[np.integer], Array, tuple[int, int]]
"""A sparse matrix as ``(rows, columns, values, shape)``, its entries in storage order."""


def _local_table(name: str) -> weakref.WeakKeyDictionary:
    """This thread's weak table ``name`` of :data:`_FUNCTIONS` (created on its first use)."""
    table = getattr(_FUNCTIONS, name, None)
    if table is None:
        table = weakref.WeakKeyDictionary()
        setattr(_FUNCTIONS, name, table)
    return table


def _derivative(solver: ca.Function, name: str) -> BufferedFunction:
    """``solver.get_function(name)`` with its buffers, built once per solver and thread (a
    certificate evaluates the same NLP's derivatives again and again: fetching the functions,
    allocating their buffers and reading their patterns took about a tenth of a 50-interval
    collocation NLP's certificate)."""
    table = _local_table("by_solver")
    functions: dict[str, BufferedFunction] | None = table.get(solver)
    if functions is None:
        functions = table[solver] = {}
    found = functions.get(name)
    if found is None:
        found = functions[name] = BufferedFunction(solver.get_function(name))
    return found


def _evaluated(function: BufferedFunction, *args: Any) -> list[Array]:
    """``function.all_outputs(*args)``, not evaluated again where its last evaluation through here
    had these very inputs (a certificate's KKT residuals and second-order check read the same
    derivatives at the same point); the inputs are compared number for number (a NaN never
    matches)."""
    table = _local_table("evaluated")
    inputs = [np.array(arg, dtype=float).ravel() for arg in args]
    last: list[Array] | None = table.get(function)
    if last is not None and len(last) == len(inputs) \
            and all(np.array_equal(old, new) for old, new in zip(last, inputs)):
        return function.outputs
    outputs = function.all_outputs(*inputs)
    table[function] = inputs
    return outputs


def _pattern(function: BufferedFunction, index: int) -> _Pattern:
    """Output ``index``'s compressed-column pattern: row indices, column indices, column pointers
    and shape (read once per function and output)."""
    table = _local_table("patterns")
    patterns: dict[int, _Pattern] | None = table.get(function)
    if patterns is None:
        patterns = table[function] = {}
    found = patterns.get(index)
    if found is None:
        sparsity = function.function.sparsity_out(index)
        colind, row = sparsity.get_ccs()
        starts = np.asarray(colind, dtype=np.int64)
        columns = np.repeat(np.arange(sparsity.size2(), dtype=np.int64), starts[1:] - starts[:-1])
        rows = np.asarray(row, dtype=np.int64)
        for array in (rows, columns, starts):
            array.setflags(write=False)  # shared by every evaluation
        found = patterns[index] = (rows, columns, starts, sparsity.shape)
    return found


def _triplets(function: BufferedFunction, index: int) -> tuple[NDArray[np.int64], NDArray[np.int64], Array]:
    """Output ``index`` of the last evaluation as ``(rows, columns, values)`` (index arithmetic on
    these costs a fraction of SciPy's sparse constructors and slicing; the indices are shared,
    read-only)."""
    rows, columns, _, _ = _pattern(function, index)
    return rows, columns, np.array(function.outputs[index], dtype=float)


def _broadcast(bound: Any, like: Array) -> Array:
    """A bound (scalar or array) as a float array shaped like ``like``."""
    return np.broadcast_to(np.asarray(bound, dtype=float), like.shape)


def _active(values: Array, low: Array, high: Array, multipliers: Array, multiplier_tolerance: float,
            bound_tolerance: float) -> NDArray[np.bool_]:
    """Rows at a (finite) bound with a multiplier above the tolerance, and rows with equal bounds."""
    with np.errstate(invalid="ignore"):  # inf - inf where a value is infinite: not near
        near_low = np.isfinite(low) & (values - low <= bound_tolerance * (1.0 + np.abs(low)))
        near_high = np.isfinite(high) & (high - values <= bound_tolerance * (1.0 + np.abs(high)))
    return (low == high) | ((near_low | near_high) & (np.abs(multipliers) > multiplier_tolerance))


def _complementarity(values: Array, low: Array, high: Array, multipliers: Array) -> float:
    """Largest violation of the sign and complementarity conditions, ``|λ| × min(1, distance to the
    bound λ belongs to)`` (CasADi's signs: a positive multiplier belongs to the upper bound, a
    negative one to the lower; an infinite bound is at distance 1)."""
    with np.errstate(invalid="ignore"):
        to_low = np.where(np.isfinite(low), values - low, 1.0)
        to_high = np.where(np.isfinite(high), high - values, 1.0)
    violation = (np.maximum(multipliers, 0.0) * np.clip(to_high, 0.0, 1.0)
                 + np.maximum(-multipliers, 0.0) * np.clip(to_low, 0.0, 1.0))
    return float(np.max(violation, initial=0.0))


def _infeasibility(values: Array, low: Array, high: Array) -> float:
    """Largest distance outside a bound, relative to ``1 + |bound|``."""
    with np.errstate(invalid="ignore"):
        below = np.where(np.isfinite(low), (low - values) / (1.0 + np.abs(low)), 0.0)
        above = np.where(np.isfinite(high), (values - high) / (1.0 + np.abs(high)), 0.0)
    return float(np.max(np.maximum(below, above), initial=0.0))


_LINSOLS: dict[bytes, tuple[ca.Sparsity, ca.Linsol, list[bool]]] = {}
"""CasADi's ``ldl`` per KKT pattern, symbolically factorised once (:func:`_linsol`): a plan checks
the same NLP with the same active set again and again (creating the solver and its sparsity cost
2.8 of the check's 10-12 ms on a 50-interval collocation NLP)."""
_MAX_LINSOLS = 16
"""Patterns kept (the oldest is dropped first)."""


def _linsol(size: int, indptr: Any, indices: Any) -> tuple[ca.Sparsity, ca.Linsol, list[bool]]:
    """The sparsity, the ``ldl`` solver and whether it has been analysed (a one-element list once
    :meth:`casadi.Linsol.sfact` has run) for a square compressed-column pattern."""
    key = np.asarray([size], dtype=np.int64).tobytes() + np.asarray(indptr, dtype=np.int64).tobytes() \
        + np.asarray(indices, dtype=np.int64).tobytes()
    found = _LINSOLS.get(key)
    if found is None:
        sparsity = ca.Sparsity.compressed(np.concatenate([[size, size], indptr, indices]).tolist())
        found = (sparsity, ca.Linsol("second_order", "ldl", sparsity), [])
        if len(_LINSOLS) >= _MAX_LINSOLS:
            del _LINSOLS[next(iter(_LINSOLS))]
        _LINSOLS[key] = found
    return found


@functools.lru_cache(maxsize=_MAX_LINSOLS)
def _random_rhs(size: int) -> tuple[Array, ca.DM]:
    """The guard's right-hand side of ``size`` standard normal numbers (seed 0), as an array (read
    only) and as CasADi's matrix, made once per size (a 50-interval collocation KKT matrix's took
    about a tenth of a check)."""
    rhs = np.random.default_rng(0).standard_normal(size)
    rhs.setflags(write=False)
    return rhs, ca.DM(rhs.tolist())  # (from a list: a third faster than from the array, the same numbers)


def _infinity_norm(rows: NDArray[np.integer], values: Array, size: int) -> float:
    """``‖M‖∞`` of a sparse matrix from its entries' rows and values in storage order (a COO matrix's,
    or a CSC matrix's indices and data): the row sums of ``|M|`` added in that order, as SciPy's
    ``abs(M).sum(axis=1)`` adds them (a product with ones), without its conversions."""
    return float(np.max(np.bincount(rows, np.abs(values), minlength=size)))


def _inertia(H: _Triplets, A: _Triplets, delta: float, scale: float) -> Callable[[float], int | str]:
    """A counter of the negative eigenvalues of ``M(s) = H + s I + AᵀA / ε`` from the inertia of
    ``K(s) = [[H + s I, Aᵀ], [A, −ε I]]`` (module docstring), factorised normalised, as
    ``[[H / η + (s / η) I, Aᵀ], [A, −η ε I]]`` (``η`` = ``scale``): one sparsity and one symbolic
    factorisation for every shift ``s``.

    Parameters
    ----------
    H : (rows, columns, values, (n, n))
        The Hessian of the Lagrangian on the free variables (symmetric, no duplicate entries).
    A : (rows, columns, values, (m, n))
        The active rows on them (no duplicate entries).
    delta : float
        The curvature threshold ``δ`` (positive): the guard's scale at ``s = 0`` (otherwise ``|s|``).
    scale : float
        ``H``'s scale ``η``, positive (``‖H‖∞``, 1 for a zero ``H``).

    Returns
    -------
    callable
        ``count(s)``: the count, or a message (a zero pivot, or a backward error the guard rejects).
    """
    import scipy.sparse

    (h_rows, h_columns, h_values, (n, _)), (a_rows, a_columns, a_values, (m, _)) = H, A
    epsilon = PENALTY * max(1.0, _infinity_norm(a_rows, a_values, m) if m else 0.0) ** 2  # η ε
    # the pattern with its whole diagonal, explicit zeros kept (an entry H_jj = 0, or cancelled by a
    # shift, must stay in it), the shift set in place for each factorisation
    every = np.arange(n + m)
    K = scipy.sparse.coo_matrix(
        (np.concatenate([h_values / scale, a_values, a_values, np.zeros(n), np.full(m, -epsilon)]),
         (np.concatenate([h_rows, a_rows + n, a_columns, every]),
          np.concatenate([h_columns, a_columns, a_rows + n, every]))),
        shape=(n + m, n + m)).tocsc()  # duplicates summed
    K.sort_indices()
    columns = np.repeat(every, np.diff(K.indptr))
    diagonal = np.flatnonzero((K.indices == columns) & (columns < n))  # the diagonal of H in K.data
    base = K.data[diagonal].copy()
    sparsity, solver, analysed = _linsol(n + m, K.indptr, K.indices)
    rhs, b = _random_rhs(n + m)
    # K as CasADi's matrix, made at the first count (converting every entry costs as much as the
    # factorisation); a shift changes only H's diagonal, set in place at the later counts
    made: list[ca.DM] = []
    positions = diagonal.tolist()

    def count(shift: float) -> int | str:
        K.data[diagonal] = base + shift / scale
        if made:
            values = made[0]
            values.set_nz(ca.DM(K.data[diagonal].tolist()), False, positions)
        else:
            values = ca.DM(sparsity, K.data.tolist())
            made.append(values)
        if not analysed:
            solver.sfact(values)  # the symbolic factorisation (the ordering), once per pattern
            analysed.append(True)
        # rank() and neig() read this factorisation; a zero pivot is reported here, so CasADi's
        # warning about it (written through Python's sys.stderr) is held back, anything else passed on
        held = io.StringIO()
        main = threading.current_thread() is threading.main_thread()  # sys.stderr is the process's
        with contextlib.redirect_stderr(held) if main else contextlib.nullcontext():
            solver.nfact(values)
            rank = int(solver.rank(values))
        other = [line for line in held.getvalue().splitlines() if ZERO_PIVOT_WARNING not in line]
        if other:
            print("\n".join(other), file=sys.stderr)
        if rank < n + m:  # and no solve(), which would factorise and warn again
            return f"the KKT matrix's LDLᵀ has {n + m - rank} zero pivots ({n} free variables, {m} active rows)"
        # (solve() with DM arguments factorises again in its own memory: the guard's one solve)
        solution = np.array(solver.solve(values, b).nonzeros())  # (dense: a third faster than np.asarray)
        norm = _infinity_norm(K.indices, K.data, n + m)
        with np.errstate(invalid="ignore"):
            error = float(np.max(np.abs(K @ solution - rhs))) \
                / (norm * float(np.max(np.abs(solution))) + float(np.max(np.abs(rhs))))
        if not np.isfinite(error):
            return f"the KKT matrix's LDLᵀ has zero pivots ({n} free variables, {m} active rows): a non-finite solve"
        # the guard at this factorisation's own threshold |shift| (δ, or a refinement's finer one), so
        # that its error cannot move a curvature across the threshold it certifies
        threshold = abs(shift) if shift else delta
        if error * norm > threshold / scale / GUARD:
            return (f"the KKT matrix's LDLᵀ (no pivoting) is not accurate enough: backward error {error:.1g} × ‖K‖ "
                    f"{norm:.2g} above {1 / GUARD:g} × the curvature threshold {threshold:.1g} / ‖H‖∞ {scale:.2g}")
        return int(solver.neig(values)) - m

    return count


def second_order_check(solver: ca.Function, x: Array, lam_x: Array, lam_g: Array, *, p: Any = None,
                       lbx: Any = -np.inf, ubx: Any = np.inf, lbg: Any = -np.inf, ubg: Any = np.inf,
                       multiplier_tolerance: float = 1e-6, bound_tolerance: float = 1e-6,
                       curvature_tolerance: float = CURVATURE_TOLERANCE,
                       kkt_tolerance: float = 1e-6) -> SecondOrderCheck:
    """Whether a converged point of ``solver`` satisfies the second-order sufficient conditions.

    Parameters
    ----------
    solver : casadi.Function
        The ``casadi.nlpsol`` function that found the point (its ``nlp_hess_l``, ``nlp_jac_g``
        and ``nlp_grad_f``).
    x : (n,) ndarray
        The point.
    lam_x, lam_g : ndarray
        Its bound and constraint multipliers, CasADi's signs: ``∇f + J_gᵀ lam_g + lam_x = 0``, a
        positive multiplier for an upper bound, a negative one for a lower bound.
    p, lbx, ubx, lbg, ubg : array_like
        The solver's parameters and bounds at that solve.
    multiplier_tolerance : float
        A multiplier above this (absolute) makes its constraint strongly active.
    bound_tolerance : float
        Relative distance to a bound (``× (1 + |bound|)``) within which a value is at it; also the
        largest accepted violation of a bound.
    curvature_tolerance : float
        The curvature on ``Z`` must exceed ``δ`` = this times ``‖H‖∞`` (``H`` the Hessian of the
        Lagrangian on the free variables; 1 when it is zero); :data:`CURVATURE_TOLERANCE` says why
        relative to ``‖H‖∞`` and why 1e-6.
    kkt_tolerance : float
        The first-order conditions the theorem assumes must hold to this: the stationarity residual
        ``‖∇f + J_gᵀ lam_g + lam_x‖∞`` relative to the largest of its terms (at least 1), and the
        sign and complementarity of every multiplier (``|λ| × min(1, distance to its bound)``)
        relative to the largest multiplier (at least 1). Otherwise the point is not checked.

    Returns
    -------
    SecondOrderCheck
        ``certified`` only when the conditions provably hold (see the module docstring).
    """
    x = np.asarray(x, dtype=float).ravel()
    try:
        hessian = _derivative(solver, "nlp_hess_l")
        jacobian = _derivative(solver, "nlp_jac_g")
        gradient = _derivative(solver, "nlp_grad_f")
        h_out = _output(hessian.function, ("triu_hess_gamma_x_x", "hess_gamma_x_x"))
        g_out, j_out = _output(jacobian.function, ("g",)), _output(jacobian.function, ("jac_g_x",))
        f_out = _output(gradient.function, ("grad_f_x",))
    except RuntimeError as error:  # a plugin without these functions
        return _not_checked(f"no derivatives from the solver: {str(error).splitlines()[0]}")
    p = np.zeros(solver.nnz_in("p")) if p is None else p
    lam_x = np.asarray(lam_x, dtype=float).ravel()
    lam_g = np.asarray(lam_g, dtype=float).ravel()
    _evaluated(hessian, x, p, 1.0, lam_g)
    h_rows, h_columns, h_values = _triplets(hessian, h_out)  # IPOPT's is upper triangular, FATROP's full
    g = _evaluated(jacobian, x, p)[g_out].copy()
    j_rows, j_columns, j_values = _triplets(jacobian, j_out)
    grad = _evaluated(gradient, x, p)[f_out].copy()
    g_low, g_high, x_low, x_high = _broadcast(lbg, g), _broadcast(ubg, g), _broadcast(lbx, x), _broadcast(ubx, x)
    # The theorem assumes a KKT point: a stalled solve or multipliers of other signs are not one.
    terms = [grad, np.bincount(j_columns, j_values * lam_g[j_rows], minlength=x.size), lam_x]
    moving = x_low != x_high  # a fixed variable's multiplier takes any value
    stationarity = float(np.max(np.abs(sum(terms))[moving], initial=0.0)) \
        / max([1.0] + [float(np.max(np.abs(t), initial=0.0)) for t in terms])
    complementarity = max(_complementarity(g, g_low, g_high, lam_g), _complementarity(x, x_low, x_high, lam_x)) \
        / max(1.0, float(np.max(np.abs(lam_g), initial=0.0)), float(np.max(np.abs(lam_x), initial=0.0)))
    infeasibility = max(_infeasibility(g, g_low, g_high), _infeasibility(x, x_low, x_high))
    if stationarity > kkt_tolerance or complementarity > kkt_tolerance or infeasibility > bound_tolerance:
        return _not_checked(f"not a first-order point: stationarity {stationarity:.2g}, complementarity "
                            f"{complementarity:.2g}, infeasibility {infeasibility:.2g}")
    rows = _active(g, g_low, g_high, lam_g, multiplier_tolerance, bound_tolerance)
    free = np.flatnonzero(~_active(x, x_low, x_high, lam_x, multiplier_tolerance, bound_tolerance))
    if free.size == 0:
        return SecondOrderCheck(True, 0, 0.0, "a vertex: the active bounds fix every variable")
    # H and A on the free variables and active rows, H symmetric from its upper triangle
    position = np.full(x.size, -1)
    position[free] = np.arange(free.size)
    keep = (h_rows <= h_columns) & (position[h_rows] >= 0) & (position[h_columns] >= 0)
    r, c, v = position[h_rows[keep]], position[h_columns[keep]], h_values[keep]
    off = r != c
    H_free = (np.concatenate([r, c[off]]), np.concatenate([c, r[off]]), np.concatenate([v, v[off]]),
              (free.size, free.size))
    active = np.flatnonzero(rows)
    row_position = np.full(g.size, -1)
    row_position[active] = np.arange(active.size)
    keep = (row_position[j_rows] >= 0) & (position[j_columns] >= 0)
    A = (row_position[j_rows[keep]], position[j_columns[keep]], j_values[keep], (active.size, free.size))
    scale = _infinity_norm(H_free[0], H_free[2], free.size)  # ‖H‖∞, its own scale, however small
    scale = scale if scale > 0.0 else 1.0  # H = 0: every curvature on Z is 0, below any δ > 0
    delta = curvature_tolerance * scale
    where = f"on {free.size} free variables and {active.size} active rows"
    count = _inertia(H_free, A, delta, scale)
    below = count(-delta)
    if isinstance(below, str):
        return _not_checked(below)
    if below == 0:
        return SecondOrderCheck(True, 0, delta, f"curvature above {delta:.1g} {where} (KKT inertia)")
    beyond = count(delta)
    if isinstance(beyond, str):  # not certified; below −δ unknown: no saddle evidence either
        return SecondOrderCheck(False, -1, delta, f"at most {below} directions of curvature below {delta:.1g} {where}, "
                                                  f"below −{delta:.1g} not counted: {beyond}")
    if beyond == 0:  # degenerate at δ: are the near-zero curvatures positive, where the factorisation resolves them?
        finer = delta
        # (the floor itself included: REFINEMENT² is 10 only to rounding)
        while finer / REFINEMENT >= FINEST_CURVATURE_TOLERANCE * scale * (1.0 - 1e-9):
            finer /= REFINEMENT
            refined = count(-finer)
            if isinstance(refined, str):  # beyond the factorisation's accuracy: no certificate
                break
            if refined == 0:
                return SecondOrderCheck(True, 0, finer, f"curvature above {finer:.1g} {where} (KKT inertia; "
                                                        f"{below} directions between −{delta:.1g} and {delta:.1g})")
        return SecondOrderCheck(False, 0, delta, f"at most {below} directions of curvature between "
                                                 f"−{delta:.1g} and {delta:.1g}, none below, {where} (KKT inertia)")
    return SecondOrderCheck(False, beyond, delta, f"at most {beyond} directions of curvature below −{delta:.1g} {where} "
                                                  f"(KKT inertia)")
