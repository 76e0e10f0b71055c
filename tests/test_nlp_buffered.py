"""The multistart calls an ``nlpsol`` function through CasADi's buffers (:func:`ocp.fast_call.buffered`):
the same evaluation as a plain call, without converting its vectors to CasADi matrices and back;
:func:`ocp.fast_call.matrices` reads any function's outputs so.

Oracles: the plain call of the same solver from the same start (its point, multipliers, status and
iteration count, bit for bit), IPOPT's own failure with ``error_on_fail``.
"""
import gc
import threading
import weakref

import casadi as ca
import numpy as np
import pytest

from ocp.fast_call import buffered, matrices
from ocp.nlp.solve import solve_multistart, solver_options


def rosenbrock(extra=None, max_iterations=500):
    x = ca.MX.sym("x", 2)
    p = ca.MX.sym("p")
    nlp = {"x": x, "p": p, "f": (x[0] - p) ** 2 + 100 * (x[1] - x[0] ** 2) ** 2, "g": x[0] + x[1]}
    return ca.nlpsol("rosenbrock", "ipopt", nlp, solver_options("ipopt", 1e-10, max_iterations, extra))


@pytest.mark.parametrize("max_iterations, bounds", [
    (500, {"lbx": [-2.0, -2.0], "ubx": [2.0, 0.9], "lbg": -1.0, "ubg": 1.5}),
    (3, {"lbx": [-2.0, -2.0], "ubx": [2.0, 0.9], "lbg": -1.0, "ubg": 1.5}),
    (500, {"lbg": 0.5}),  # the inputs not given take their defaults (no bounds on x, none above g)
])
def test_a_multistart_start_is_the_plain_call_bit_for_bit(max_iterations, bounds):
    solver = rosenbrock(max_iterations=max_iterations)
    start = np.array([-1.2, 0.8])  # within the bounds (the multistart clips a start into them)
    plain = solver(x0=start, p=0.8, **bounds)
    stats = solver.stats()
    result = solve_multistart(solver, [start], p=0.8, agree=1, **bounds)
    assert result.starts[0].status == stats["return_status"]
    assert result.starts[0].iterations == stats["iter_count"]
    assert result.starts[0].f == float(plain["f"])
    if max_iterations == 500:  # converged: the point and its multipliers, bit for bit
        assert result.success and result.starts[0].status == "Solve_Succeeded"
        for mine, theirs in ((result.x, plain["x"]), (result.lam_x, plain["lam_x"]), (result.lam_g, plain["lam_g"]),
                             (result.g, plain["g"])):
            assert np.array_equal(mine, theirs.full().ravel())
    else:  # not vacuous: a start stopped early is reported as the plain call reports it
        assert not result.success and result.starts[0].status == "Maximum_Iterations_Exceeded"


def test_the_best_start_is_kept_while_later_starts_are_solved():
    # a double well tilted towards x = -1: the first start finds the better minimum, the second the
    # other one; the kept point is the first start's, whatever the second call wrote
    x, p = ca.MX.sym("x"), ca.MX.sym("p")
    solver = ca.nlpsol("well", "ipopt", {"x": x, "p": p, "f": (x**2 - 1) ** 2 + p * x}, solver_options("ipopt", 1e-10))
    first = solver(x0=-1.3, p=0.1)
    result = solve_multistart(solver, [np.array([-1.3]), np.array([1.3])], p=0.1, agree=0)
    assert len(result.starts) == 2 and result.starts[1].f > result.starts[0].f  # not vacuous: two minima
    assert result.best_start == 0
    assert np.array_equal(result.x, first["x"].full().ravel())
    assert np.array_equal(result.lam_x, first["lam_x"].full().ravel())


def test_a_solver_that_raises_on_failure_raises_through_the_buffers():
    solver = rosenbrock({"error_on_fail": True}, max_iterations=2)
    with pytest.raises(RuntimeError, match="nlpsol process failed"):
        solver(x0=[-1.2, 1.0], p=0.8)
    with pytest.raises(RuntimeError, match="nlpsol process failed"):
        solve_multistart(solver, [np.array([-1.2, 1.0])], p=0.8, agree=1)


def test_buffers_are_made_once_per_function_and_thread_and_do_not_keep_it():
    x = ca.SX.sym("x", 2)
    function = ca.Function("double", [x], [2 * x])
    first = buffered(function)
    assert buffered(function) is first
    np.testing.assert_array_equal(first(np.array([1.0, 2.0])), [2.0, 4.0])
    assert in_a_thread(function) is not first  # a thread's evaluations never overwrite another's buffers
    alive = weakref.ref(function)
    del function, first
    gc.collect()
    assert alive() is None


def in_a_thread(function):
    """``buffered(function)`` in another thread."""
    found = []
    thread = threading.Thread(target=lambda: found.append(buffered(function)))
    thread.start()
    thread.join()
    return found[0]


def test_matrices_are_the_plain_call_s_outputs_each_its_own():
    a, b = ca.SX.sym("a", 3, 2), ca.SX.sym("b", 2)
    dense = ca.Function("dense", [a, b], [ca.mtimes(a, b), a.T, ca.sumsqr(b)])
    sparse = ca.Function("sparse", [b], [ca.sparsify(ca.vertcat(b[0], 0, b[1])), 2 * b])
    A, B = np.arange(6.0).reshape(3, 2) / 7.0, np.array([0.3, -1.1])
    for function, args in ((dense, (A, B)), (sparse, (B,))):
        expected = [out.full() for out in function.call(list(args))]
        first = matrices(function, *args)
        assert [m.shape for m in first] == [e.shape for e in expected]
        for mine, theirs in zip(first, expected):
            assert np.array_equal(mine, theirs) and mine.flags["C_CONTIGUOUS"]
        again = [m.copy() for m in first]
        matrices(function, *(2.0 * np.asarray(arg) for arg in args))  # overwrites the buffers, not the results
        assert all(np.array_equal(m, c) for m, c in zip(first, again))
