"""Low-overhead numeric evaluation of a ``casadi.Function`` in hot loops.

A plain ``f(x)`` call costs tens of microseconds in the Python wrapper whatever the work; the
buffer interface (``Function.buffer``, CasADi >= 3.6) evaluates into preallocated NumPy arrays
for well under a microsecond of overhead.
"""
from __future__ import annotations

import threading
import weakref
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray


class BufferedFunction:
    """Evaluate ``function`` on dense numeric inputs through reusable buffers.

    Calling returns the first output as a flat array that is overwritten by the next call;
    copy it if it must be kept. Hot loops may also write :attr:`inputs` in place (only what
    changed), call :meth:`evaluate` and read :attr:`outputs`.

    Parameters
    ----------
    function : casadi.Function
        A function whose inputs are all dense (any shape; buffers hold them flat, column-major).

    Attributes
    ----------
    inputs : list of (nnz_in(i),) ndarray
        The input buffers, read by :meth:`evaluate`.
    outputs : list of (nnz_out(i),) ndarray
        The output buffers, written by :meth:`evaluate`.
    """

    def __init__(self, function: ca.Function):
        self.function = function
        for i in range(function.n_in()):
            if function.sparsity_in(i).nnz() != function.sparsity_in(i).numel():
                raise ValueError(f"input {function.name_in(i)} of {function.name()} is not dense")
        self.inputs = [np.zeros(function.nnz_in(i)) for i in range(function.n_in())]
        self.outputs = [np.zeros(function.nnz_out(i)) for i in range(function.n_out())]
        buffer: Any  # CasADi's FunctionBuffer stubs ask for (pointer, size); memoryviews are what it takes
        buffer, self._evaluate = function.buffer()
        for i, array in enumerate(self.inputs):
            buffer.set_arg(i, memoryview(array))  # type: ignore[arg-type]  # ndarray has the buffer protocol
        for i, array in enumerate(self.outputs):
            buffer.set_res(i, memoryview(array))  # type: ignore[arg-type]  # ndarray has the buffer protocol
        self._buffer = buffer

    def __call__(self, *args: ArrayLike | float) -> NDArray[np.float64]:
        return self.all_outputs(*args)[0]

    def evaluate(self) -> None:
        """Evaluate the function on the current :attr:`inputs` into :attr:`outputs`."""
        self._evaluate()

    def stats(self) -> dict[str, Any]:
        """The statistics of the last evaluation, as ``function.stats()`` after a plain call (an
        ``nlpsol``'s return status and iteration count, say): the buffers evaluate in a memory of
        their own, which ``function.stats()`` does not read.

        Returns
        -------
        dict
        """
        return dict(self._buffer.stats())

    def all_outputs(self, *args: ArrayLike | float) -> list[NDArray[np.float64]]:
        """Every output for the given inputs.

        Parameters
        ----------
        *args : array_like or float
            The function's inputs in order, each with ``nnz_in(i)`` numbers (flattened
            column-major); fewer than ``n_in()`` leaves the remaining buffers as they are.

        Returns
        -------
        list of (nnz_out(i),) ndarray
            Every output, flat (column-major for matrices), overwritten by the next call.
        """
        for target, value in zip(self.inputs, args):
            target[:] = value
        self._evaluate()
        return self.outputs


_PER_THREAD = threading.local()
"""Per thread: ``.buffered``, a weak table of each function's :class:`BufferedFunction`
(:func:`buffered`)."""


def buffered(function: ca.Function) -> BufferedFunction:
    """``function``'s :class:`BufferedFunction`, made once per function and thread and kept while
    the function lives: its buffers are overwritten by every evaluation, and one evaluation at a
    time may use them.

    Parameters
    ----------
    function : casadi.Function
        A function whose inputs are all dense (an ``nlpsol`` function, say: converting its vectors
        to and from CasADi matrices costs about 0.1 µs a number, milliseconds a call on a collocation
        NLP).

    Returns
    -------
    BufferedFunction
    """
    table: weakref.WeakKeyDictionary | None = getattr(_PER_THREAD, "buffered", None)
    if table is None:
        table = _PER_THREAD.buffered = weakref.WeakKeyDictionary()
    found = table.get(function)
    if found is None:
        # over a handle of its own to the same function: the entry must not keep its key alive
        found = table[function] = BufferedFunction(ca.Function(function))
    return found


def matrices(function: ca.Function, *args: ArrayLike | float) -> list[NDArray[np.float64]]:
    """Every output of ``function`` for the given inputs as a 2-D array of its own, as
    ``[out.full() for out in function(*args)]`` gives them (C order), through the function's
    buffers (:func:`buffered`) where its inputs and outputs are all dense.

    Parameters
    ----------
    function : casadi.Function
        The function.
    *args : array_like or float
        Its inputs in order (flattened column-major where buffered).

    Returns
    -------
    list of ndarray
        One ``(size1_out(i), size2_out(i))`` array per output.
    """
    if not all(function.sparsity_out(i).is_dense() for i in range(function.n_out())) \
            or not all(function.sparsity_in(i).is_dense() for i in range(function.n_in())):
        plain: Any = function  # CasADi's stubs take no NumPy arrays here; its call does
        return [np.asarray(out.full(), dtype=float) for out in plain.call(list(args))]
    outputs = buffered(function).all_outputs(*(np.asarray(arg, dtype=float).ravel(order="F") for arg in args))
    return [np.array(flat.reshape(function.sparsity_out(i).shape, order="F"), order="C")
            for i, flat in enumerate(outputs)]


def as_floats(values: ArrayLike) -> list[float]:
    """A short vector as a list of Python floats, for per-sample code.

    Arithmetic on Python floats costs tens of nanoseconds where NumPy costs about a microsecond
    per call on 3-vectors; ``tolist`` converts without per-element NumPy scalars.

    Parameters
    ----------
    values : array_like
        Numbers (any shape; flattened in C order).

    Returns
    -------
    list of float
        (A 1-D NumPy array of integers gives Python ints: the same arithmetic.)
    """
    if type(values) is np.ndarray and values.ndim == 1:
        return values.tolist()
    return np.asarray(values, dtype=float).ravel().tolist()
