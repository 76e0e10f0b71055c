"""Low-overhead numeric evaluation of a ``casadi.Function`` in hot loops.

A plain ``f(x)`` call costs tens of microseconds in the Python wrapper whatever the work; the
buffer interface (``Function.buffer``, CasADi >= 3.6) evaluates into preallocated NumPy arrays
for well under a microsecond of overhead.
"""
from __future__ import annotations

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray


class BufferedFunction:
    """Evaluate ``function`` on dense numeric inputs through reusable buffers.

    Calling returns the first output as a flat array that is overwritten by the next call;
    copy it if it must be kept.
    """

    def __init__(self, function: ca.Function):
        self.function = function
        self._inputs = [np.zeros(function.nnz_in(i)) for i in range(function.n_in())]
        self._outputs = [np.zeros(function.nnz_out(i)) for i in range(function.n_out())]
        for i in range(function.n_in()):
            if function.sparsity_in(i).nnz() != function.sparsity_in(i).numel():
                raise ValueError(f"input {function.name_in(i)} of {function.name()} is not dense")
        self._buffer, self._evaluate = function.buffer()
        for i, array in enumerate(self._inputs):
            self._buffer.set_arg(i, memoryview(array))
        for i, array in enumerate(self._outputs):
            self._buffer.set_res(i, memoryview(array))

    def __call__(self, *args: ArrayLike | float) -> NDArray[np.float64]:
        return self.all_outputs(*args)[0]

    def all_outputs(self, *args: ArrayLike | float) -> list[NDArray[np.float64]]:
        """Every output, flat (column-major for matrices), overwritten by the next call."""
        for target, value in zip(self._inputs, args):
            target[:] = value
        self._evaluate()
        return self._outputs
