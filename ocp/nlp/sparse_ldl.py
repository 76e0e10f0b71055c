"""Sparse LDLᵀ of a fixed symmetric pattern with its inertia, in compiled code.

What for: an interior point needs, at every trial of its Hessian regularisation, the factors of its
KKT matrix and their inertia (how many negative pivots); CasADi's ``ldl`` gives the inertia only to
a factorisation of a ``casadi.DM``, whose conversion from NumPy costs more than the factorisation
(about 0.2 ms against 0.05 ms on a 557-row collocation KKT matrix). Here the factorisation runs in
a small C kernel (``sparse_ldl.c`` beside this module, the up-looking LDLᵀ of T. A. Davis's LDL
package, *ACM TOMS* 31(4), 2005) called through ``ctypes`` on preallocated NumPy arrays.

The kernel is compiled at first use with the system's C compiler into the user's cache, as the
compiled closed loop is (:func:`ocp.native.build_library`: ``$XDG_CACHE_HOME/slewbench`` or
``~/.cache/slewbench``, a file named by the hash of the source and the compiler, renamed into place
complete). Where no compiler works, :func:`available` says why and callers keep their other solver.

No numerical pivoting: the order is CasADi's approximate minimum degree (``Sparsity.amd``) of the
pattern, fixed at construction (on collocation KKT matrices it gave the fastest factorisations of
the orders measured: reverse Cuthill-McKee, the natural order and a stage-interleaved one have less
fill but needed more refinement). The matrix is scaled symmetrically by ``1 / √max(1, |K_ii|)`` (a
barrier's large diagonal near a bound brought to the others' size); a pivot of the scaled matrix
below ``pivot_tolerance`` in magnitude is replaced by that tolerance times the sign the caller
expects of it (a *static pivot*, as in PARDISO; counted in :meth:`SparseLDL.factor`'s result), and
every solve is refined against the unperturbed matrix (:meth:`SparseLDL.solve`), reporting its
backward error. The inertia is that of the matrix factorised: exact by Sylvester's law when no
pivot was perturbed; an inaccurate factorisation (no pivoting is stable only for quasi-definite
matrices) shows in that backward error, which the caller checks.

May import: NumPy, CasADi, the standard library and the top-level modules of :mod:`ocp` (:mod:`ocp.native`,
:mod:`ocp.errors`).
"""
from __future__ import annotations

import ctypes
import functools
from pathlib import Path

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ocp import native
from ocp.errors import CompilerUnavailable

Array = NDArray[np.float64]
SOURCE = Path(__file__).with_name("sparse_ldl.c")
"""The C kernel's source, shipped with the package."""

_INT = np.int32
_POINTER = ctypes.c_void_p


FLAGS = ("-O2", "-fPIC", "-shared")
"""The kernel's compiler flags (-O3 or -march=native measured no faster: its loops are indirect)."""


@functools.lru_cache(maxsize=1)
def _library() -> tuple[ctypes.CDLL | None, str]:
    """The loaded kernel, or ``None`` and why not (built once per machine, loaded once per process)."""
    try:
        library = native.load_library(SOURCE, FLAGS)
    except CompilerUnavailable as error:
        return None, f"the sparse LDLᵀ kernel is not available: {error}"
    library.sb_ldl_symbolic.argtypes = [ctypes.c_int] + [_POINTER] * 6
    library.sb_ldl_symbolic.restype = None
    library.sb_ldl_rows.argtypes = [ctypes.c_int] + [_POINTER] * 10
    library.sb_ldl_rows.restype = None
    library.sb_ldl_factor.argtypes = [_POINTER, _POINTER, ctypes.c_double, ctypes.c_int]
    library.sb_ldl_factor.restype = ctypes.c_int
    library.sb_ldl_solve_refined.argtypes = [_POINTER, _POINTER, _POINTER, ctypes.c_double, ctypes.c_int]
    library.sb_ldl_solve_refined.restype = ctypes.c_double
    return library, f"compiled kernel {library._name}"


class _State(ctypes.Structure):
    """The C kernel's ``sb_ldl`` (the same fields in the same order): the factorisation's arrays."""

    _fields_ = [("n", ctypes.c_int), ("nnz", ctypes.c_int),
                *((name, _POINTER) for name in ("Ap", "Ai", "Lp", "Rp", "Ri", "Li", "take", "order", "Lnz", "sign",
                                                "Ax", "SAx", "S", "Lx", "D", "Y", "B", "R", "X")),
                ("norm", ctypes.c_double), ("perturbed", ctypes.c_int), ("steps", ctypes.c_int)]


def available() -> tuple[bool, str]:
    """Whether the compiled kernel can be used here, and a note saying from where or why not.

    Returns
    -------
    tuple
        ``(bool, note)``.
    """
    library, note = _library()
    return library is not None, note


class SparseLDL:
    """LDLᵀ factors of symmetric matrices of one sparsity pattern, their inertia, and refined solves.

    Parameters
    ----------
    rows, columns : (nnz,) array_like of int
        The pattern's entries in the caller's storage order: one triangle (either, or a mix: each
        pair of symmetric entries once), the whole diagonal in it.
    size : int
        The matrix's order.
    sign : (size,) array_like
        The sign expected of each row's pivot (+1 or -1): a static pivot takes it (module docstring).

    Raises
    ------
    RuntimeError
        Where the compiled kernel is not available (:func:`available` says why).
    ValueError
        Where the pattern misses a diagonal entry.
    """

    def __init__(self, rows: NDArray[np.integer], columns: NDArray[np.integer], size: int,
                 sign: NDArray[np.floating]) -> None:
        library, note = _library()
        if library is None:
            raise RuntimeError(note)
        self._lib = library
        rows, columns = np.asarray(rows, dtype=np.int64), np.asarray(columns, dtype=np.int64)
        self.size = n = int(size)
        if np.unique(rows[rows == columns]).size != n:
            raise ValueError("the pattern must hold the whole diagonal")
        if np.unique(np.minimum(rows, columns) * n + np.maximum(rows, columns)).size != rows.size:
            raise ValueError("give each pair of symmetric entries once (one triangle)")
        both = np.concatenate([rows, columns]), np.concatenate([columns, rows])
        sparsity = ca.Sparsity.triplet(n, n, both[0].tolist(), both[1].tolist())  # the whole symmetric pattern
        order = np.asarray(sparsity.amd(), dtype=np.int64)  # new position -> old index
        position = np.empty(n, dtype=np.int64)
        position[order] = np.arange(n)
        new_rows = np.minimum(position[rows], position[columns])  # each entry in the permuted upper triangle
        new_columns = np.maximum(position[rows], position[columns])
        # the permuted upper triangle in compressed columns, rows sorted (the diagonal last);
        # ``take`` gathers it from the caller's values
        sort = np.lexsort((new_rows, new_columns))
        self._take = np.ascontiguousarray(sort, dtype=_INT)
        self._Ai = np.ascontiguousarray(new_rows[sort], dtype=_INT)
        self._Ap = np.zeros(n + 1, dtype=_INT)
        self._Ap[1:] = np.cumsum(np.bincount(new_columns, minlength=n))
        self._Ax = np.zeros(self._Ai.size)
        self.order = order
        self._Lp = np.zeros(n + 1, dtype=_INT)
        self._Parent = np.zeros(n, dtype=_INT)
        self._Lnz = np.zeros(n, dtype=_INT)
        self._Flag = np.zeros(n, dtype=_INT)
        self._Pattern = np.zeros(n, dtype=_INT)
        library.sb_ldl_symbolic(n, self._Ap.ctypes.data, self._Ai.ctypes.data, self._Lp.ctypes.data,
                                self._Parent.ctypes.data, self._Lnz.ctypes.data, self._Flag.ctypes.data)
        self.factor_nonzeros = int(self._Lp[-1])
        """Nonzeros of ``L`` below its diagonal (the fill of the order)."""
        self._Li = np.zeros(max(1, self.factor_nonzeros), dtype=_INT)
        self._Lx = np.zeros(max(1, self.factor_nonzeros))
        self._Rp = np.zeros(n + 1, dtype=_INT)
        self._Ri = np.zeros(max(1, self.factor_nonzeros), dtype=_INT)
        library.sb_ldl_rows(n, self._Ap.ctypes.data, self._Ai.ctypes.data, self._Lp.ctypes.data,
                            self._Parent.ctypes.data, self._Lnz.ctypes.data, self._Flag.ctypes.data,
                            self._Pattern.ctypes.data, self._Rp.ctypes.data, self._Ri.ctypes.data,
                            self._Li.ctypes.data)
        self._D = np.zeros(n)
        self._Y = np.zeros(n)
        self._S = np.ones(n)
        self._sign = np.ascontiguousarray(np.asarray(sign, dtype=float)[order])
        self._B, self._R, self._X = (np.zeros(n) for _ in range(3))
        self._SAx = np.zeros(self._Ai.size)
        self._order32 = np.ascontiguousarray(order, dtype=_INT)
        self._state = _State(n, self._Ai.size, *(array.ctypes.data for array in (
            self._Ap, self._Ai, self._Lp, self._Rp, self._Ri, self._Li, self._take, self._order32, self._Lnz,
            self._sign, self._Ax, self._SAx, self._S, self._Lx, self._D, self._Y, self._B, self._R, self._X)),
            0.0, 0, 0)
        self._address = ctypes.addressof(self._state)
        self.refinements = 0
        """Refinement steps of the last :meth:`solve`."""
        self.complete = False
        """Whether the last :meth:`factor` finished (the factors a solve needs)."""

    def factor(self, values: Array, pivot_tolerance: float, expected_negative: int = -1) -> tuple[int, int]:
        """Factorise the matrix with these nonzeros (scaled, module docstring).

        Parameters
        ----------
        values : (nnz,) ndarray
            The nonzeros in the constructor's order (float64, contiguous).
        pivot_tolerance : float
            Pivots of the scaled matrix smaller in magnitude are replaced by ``sign × pivot_tolerance``.
        expected_negative : int
            The count of negative pivots the caller accepts: the factorisation stops as soon as it
            cannot be met (more negative or more positive pivots), and returns a count above it
            (the factors incomplete: :attr:`complete` false). -1: always the whole factorisation.

        Returns
        -------
        tuple
            ``(negative, perturbed)``: negative pivots of the factors (where stopped early, a number
            above ``expected_negative``), and static pivots; ``(-1, 0)`` where a pivot was not a number.
        """
        values = np.ascontiguousarray(values, dtype=float)
        negative = self._lib.sb_ldl_factor(self._address, values.ctypes.data, pivot_tolerance, expected_negative)
        self.complete = 0 <= negative <= self.size
        return (negative, self._state.perturbed) if negative >= 0 else (-1, 0)

    def solve(self, rhs: Array, tolerance: float = 1e-10, steps: int = 10,
              out: Array | None = None) -> tuple[Array, float]:
        """``x`` with ``K x = rhs`` for the matrix of the last :meth:`factor` call, refined against it.

        Parameters
        ----------
        rhs : (size,) ndarray
        tolerance : float
            Refinement stops once the scaled system's backward error ``‖r‖∞ / (‖K̃‖∞ ‖x̃‖∞ + ‖b̃‖∞)``
            is at most this.
        steps : int
            Refinement steps at most.
        out : (size,) ndarray or None
            Where to write ``x`` (float64, contiguous); ``None``: a new array.

        Returns
        -------
        tuple
            ``(x, error)``: the solution and that backward error (NaN where the solve was not finite).

        Raises
        ------
        RuntimeError
            The last factorisation stopped early or failed (no factors to solve with).
        """
        if not self.complete:
            raise RuntimeError("no complete factorisation to solve with")
        rhs = np.ascontiguousarray(rhs, dtype=float)
        solution = np.empty(self.size) if out is None else out
        error = self._lib.sb_ldl_solve_refined(self._address, rhs.ctypes.data, solution.ctypes.data, tolerance, steps)
        self.refinements = self._state.steps
        return solution, error
