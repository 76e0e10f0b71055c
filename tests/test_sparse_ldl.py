"""The compiled sparse LDLᵀ (ocp.nlp.sparse_ldl): inertia and solves against dense NumPy, static
pivots, pattern checks, and the compiled kernel's cache (a fresh process with its own cache)."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest
import scipy.sparse

from ocp.nlp.sparse_ldl import SparseLDL, available

pytestmark = pytest.mark.skipif(not available()[0], reason=available()[1])


def lower_pattern(K):
    """Rows, columns (one triangle, the whole diagonal) and values of a dense symmetric K, column-major."""
    pattern = np.tril((K != 0) | np.eye(K.shape[0], dtype=bool))
    columns, rows = np.nonzero(pattern.T)
    return rows, columns, K[rows, columns]


def random_kkt(seed, n, m, curvature):
    """[[H, Jᵀ], [J, −δ I]] with a sparse indefinite H (its diagonal scaled by ``curvature``)."""
    rng = np.random.default_rng(seed)
    H = scipy.sparse.random(n, n, density=0.15, random_state=seed).toarray()
    H = H + H.T + np.diag(rng.normal(size=n) * curvature)
    J = scipy.sparse.random(m, n, density=0.3, random_state=seed + 1000).toarray() + np.eye(m, n)
    return np.block([[H, J.T], [J, -1e-7 * np.eye(m)]])


@pytest.mark.parametrize("seed", range(40))
def test_inertia_and_the_reported_error_match_dense_linear_algebra(seed):
    """On indefinite KKT matrices (no numerical pivoting, so a solve may be inaccurate): the inertia of
    exact factors is the eigenvalues' (Sylvester), and the backward error the solve reports is the
    one its solution has; where it reports machine precision, the solution is NumPy's."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(3, 40))
    m = int(rng.integers(0, n))
    K = random_kkt(seed, n, m, curvature=float(rng.choice([0.0, 1.0, 10.0])))
    rows, columns, values = lower_pattern(K)
    ldl = SparseLDL(rows, columns, n + m, np.concatenate([np.ones(n), -np.ones(m)]))
    negative, perturbed = ldl.factor(values, 1e-14)
    eigenvalues = np.linalg.eigvalsh(K)
    if perturbed == 0:  # exact factors of K: Sylvester's law
        assert negative == int(np.sum(eigenvalues < 0))
    rhs = rng.normal(size=n + m)
    solution, error = ldl.solve(rhs, 1e-14, 10)
    # the backward error of the unscaled system, computed here (the kernel's is of the scaled one,
    # scaled by 1/√max(1, |K_ii|): within a factor max(1, |K_ii|) of this)
    actual = np.max(np.abs(K @ solution - rhs)) / (np.abs(K).sum(axis=1).max() * np.max(np.abs(solution))
                                                   + np.max(np.abs(rhs)))
    assert actual <= 100 * max(1.0, np.max(np.abs(np.diag(K)))) * max(error, 1e-16)
    if error < 1e-13 and np.min(np.abs(eigenvalues)) > 1e-6 * np.max(np.abs(eigenvalues)):
        assert np.allclose(solution, np.linalg.solve(K, rhs), rtol=1e-7, atol=1e-9 * np.max(np.abs(solution)))


@pytest.mark.parametrize("seed", range(20))
def test_quasi_definite_matrices_are_solved_to_machine_precision(seed):
    """[[H, Jᵀ], [J, −δ I]] with H positive definite: an LDLᵀ exists in every order (the interior point's
    matrix once its inertia is right), and the refined solve is NumPy's."""
    rng = np.random.default_rng(seed)
    n, m = int(rng.integers(3, 40)), 0
    m = int(rng.integers(0, n))
    B = rng.normal(size=(n, n)) * (rng.random((n, n)) < 0.2)
    J = scipy.sparse.random(m, n, density=0.3, random_state=seed).toarray() + np.eye(m, n)
    K = np.block([[B.T @ B + 0.1 * np.eye(n), J.T], [J, -1e-8 * np.eye(m)]])
    rows, columns, values = lower_pattern(K)
    ldl = SparseLDL(rows, columns, n + m, np.concatenate([np.ones(n), -np.ones(m)]))
    assert ldl.factor(values, 1e-14) == (m, 0)
    rhs = rng.normal(size=n + m)
    solution, error = ldl.solve(rhs, 1e-14, 10)
    assert error < 1e-14
    assert np.allclose(solution, np.linalg.solve(K, rhs), rtol=1e-8, atol=1e-10 * np.max(np.abs(solution)))


def test_inertia_counts_the_negative_eigenvalues_of_an_indefinite_kkt_matrix():
    """A KKT matrix of wrong inertia (negative curvature on the null space of J) is told from one of
    the right inertia: the interior point's regularisation test."""
    n, m = 6, 2
    J = np.zeros((m, n))
    J[0, 0] = J[1, 1] = 1.0
    H = np.diag([1.0, 1.0, 1.0, -0.5, 1.0, 1.0])  # -0.5 on x3, which J leaves free
    for shift, expected in ((0.0, m + 1), (1.0, m)):
        K = np.block([[H + shift * np.eye(n), J.T], [J, -1e-9 * np.eye(m)]])
        rows, columns, values = lower_pattern(K)
        ldl = SparseLDL(rows, columns, n + m, np.r_[np.ones(n), -np.ones(m)])
        assert ldl.factor(values, 1e-14) == (expected, 0)
        assert int(np.sum(np.linalg.eigvalsh(K) < 0)) == expected


def test_a_zero_pivot_is_replaced_by_a_static_pivot_of_the_expected_sign():
    """[[0, 1], [1, 0]] has no LDLᵀ without pivoting: the zero pivot becomes +tolerance (its row's
    sign), the count says so, and the inertia (1, 1) is still right."""
    K = np.array([[0.0, 1.0], [1.0, 0.0]])
    rows, columns, values = lower_pattern(K)
    ldl = SparseLDL(rows, columns, 2, np.array([1.0, -1.0]))
    negative, perturbed = ldl.factor(values, 1e-14)
    assert perturbed >= 1
    assert negative == 1


def test_a_static_pivot_takes_the_sign_its_row_expects():
    """A zero curvature on a primal row (expected +) beside a constraint row (expected −): the
    static pivot is +tolerance, so the count of negative pivots is the constraint's one."""
    K = np.diag([1.0, 0.0, -1.0])
    rows, columns, values = lower_pattern(K)
    ldl = SparseLDL(rows, columns, 3, np.array([1.0, 1.0, -1.0]))
    assert ldl.factor(values, 1e-14) == (1, 1)


def test_the_pivot_tolerance_is_relative_to_each_rows_scale():
    """Rows are scaled by 1 / √max(1, |K_ii|) before the tolerance applies: a pivot of 1e-9 in a row
    whose diagonal is 1e6 (relative 1e-15, numerically zero) is a static pivot; the same matrix
    scaled down by 1e6 (its pivot relative 1e-3 of nothing larger) is not."""
    K = np.array([[1.0, 1e3], [1e3, 1e6 + 1e-9]])
    rows, columns, values = lower_pattern(K)
    ldl = SparseLDL(rows, columns, 2, np.ones(2))
    assert ldl.factor(values, 1e-14)[1] == 1
    small = np.array([[1.0, 1.0], [1.0, 1.0 + 1e-3]])
    rows, columns, values = lower_pattern(small)
    assert SparseLDL(rows, columns, 2, np.ones(2)).factor(values, 1e-14) == (0, 0)


def test_a_nan_entry_is_reported():
    K = np.array([[2.0, 1.0], [1.0, np.nan]])
    rows, columns, values = lower_pattern(np.where(np.isnan(K), 1.0, K))
    values = values.copy()
    values[-1] = np.nan
    ldl = SparseLDL(rows, columns, 2, np.ones(2))
    assert ldl.factor(values, 1e-14) == (-1, 0)


def test_rows_of_very_different_scale_are_solved_accurately():
    """A barrier's Σ (1e10 on the variables at a bound) beside O(1) entries: the symmetric scaling
    and refinement give a backward error at machine precision."""
    rng = np.random.default_rng(3)
    n, m = 30, 10
    K = random_kkt(3, n, m, curvature=1.0)
    K[:n, :n] += np.diag(np.where(rng.random(n) < 0.4, 1e10, 1.0))
    rows, columns, values = lower_pattern(K)
    ldl = SparseLDL(rows, columns, n + m, np.r_[np.ones(n), -np.ones(m)])
    negative, perturbed = ldl.factor(values, 1e-14)
    assert perturbed == 0 and negative == int(np.sum(np.linalg.eigvalsh(K) < 0))
    rhs = rng.normal(size=n + m)
    solution, error = ldl.solve(rhs, 1e-14, 10)
    assert error < 1e-14
    assert np.max(np.abs(K @ solution - rhs)) <= 1e-12 * (np.abs(K).sum(axis=1).max() * np.max(np.abs(solution)))


def test_the_pattern_must_hold_the_diagonal_and_each_pair_once():
    with pytest.raises(ValueError, match="diagonal"):
        SparseLDL(np.array([0, 1]), np.array([0, 0]), 2, np.ones(2))
    with pytest.raises(ValueError, match="once"):
        SparseLDL(np.array([0, 1, 1, 0]), np.array([0, 1, 0, 1]), 2, np.ones(2))


def test_kernel_compiles_into_the_cache_and_reports_a_missing_compiler(tmp_path):
    """In fresh processes (the kernel is built once per process and cache): with a compiler the
    library lands in ``$XDG_CACHE_HOME/slewbench`` and nothing half-written stays beside it; with
    none on the path, :func:`available` says why, and nothing is written."""
    script = "import json; from ocp.nlp.sparse_ldl import available; print(json.dumps(available()))"
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    empty = tmp_path / "empty-path"
    empty.mkdir()
    for works in (True, False):
        cache = tmp_path / ("ok" if works else "missing")
        env = {**os.environ, "XDG_CACHE_HOME": str(cache), "PYTHONPATH": root}
        if not works:
            env.update(PATH=str(empty), CC="")
        done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, timeout=120)
        assert done.returncode == 0, done.stderr
        ok, note = json.loads(done.stdout.strip().splitlines()[-1])
        assert ok is works, note
        if works:
            built = list((cache / "slewbench").iterdir())
            assert len(built) == 1 and built[0].name.startswith("sparse_ldl_") and built[0].suffix == ".so"
        else:
            assert "no C compiler" in note and not cache.exists()


def test_a_zero_right_hand_side_solves_to_zero_with_no_error():
    """0 / 0 made the backward error NaN, which the interior point read as a failed factorisation."""
    K = np.array([[2.0, 1.0], [1.0, -3.0]])
    rows, columns, values = lower_pattern(K)
    ldl = SparseLDL(rows, columns, 2, np.array([1.0, -1.0]))
    ldl.factor(values, 1e-14)
    solution, error = ldl.solve(np.zeros(2))
    assert error == 0.0 and np.array_equal(solution, np.zeros(2))


def test_a_solve_after_an_early_stop_is_refused():
    K = np.diag([1.0, -1.0, -1.0])
    rows, columns, values = lower_pattern(K)
    ldl = SparseLDL(rows, columns, 3, np.array([1.0, 1.0, -1.0]))
    negative, _ = ldl.factor(values, 1e-14, expected_negative=1)
    assert negative > 1 and not ldl.complete
    with pytest.raises(RuntimeError, match="no complete factorisation"):
        ldl.solve(np.ones(3))
