"""The stage-wise NLP of :mod:`ocp.transcription.base` and its derivatives, assembled block by block.

CasADi would differentiate the whole expanded graph (about 21,000 instructions at N = 50, degree 3):
its symbolic constraint Jacobian and Lagrangian Hessian took 0.3 s of a 0.4 s build. Here one
interval's block (its gap and path constraints and its running cost, as a function of its own
variables ``v_k = [s_k, c_k, s_{k+1}]``) is differentiated once, mapped over the mesh, and its
nonzeros are scattered into the global sparse matrices. Blocks overlap in no nonzero: block ``k``
owns its rows, and its Hessian lies in ``[s_k, c_k]`` (``s_{k+1}`` enters linearly). The ends
(initial and terminal conditions) are differentiated on their own. ``nlpsol`` takes the results as
its ``jac_g`` and ``hess_lag`` (IPOPT).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from ocp.transcription.problem import Interval, OptimalControlProblem


@dataclass
class StagewiseNLP:
    """The symbolic NLP in the stage-wise layout, with its block-assembled derivatives.

    Parameters
    ----------
    w, p : casadi.MX
        Decision vector and parameters (layouts of :mod:`ocp.transcription.base`).
    f, g : casadi.MX
        Objective and constraints.
    S, C : casadi.MX
        Stage states ``(ns, N + 1)`` (T included when free) and interval variables ``(nc, N)``.
    T : casadi.MX
        The final time [s] (a decision variable or the parameter).
    jac_g : casadi.Function
        ``(x, p) -> (g, ∂g/∂x)``.
    hess_lag : casadi.Function
        ``(x, p, lam_f, lam_g) -> triu(∇²ₓ(lam_f f + lam_gᵀ g))``.
    n_terminal : int
        Number of terminal equality constraints (the last entries of ``g``).
    """

    w: Any
    p: Any
    f: Any
    g: Any
    S: Any
    C: Any
    T: Any
    jac_g: ca.Function
    hess_lag: ca.Function
    n_terminal: int


def _scatter(n_row: int, n_col: int, pieces: list[tuple[ca.Sparsity, list[int], list[int]]]) -> tuple[ca.Sparsity, Any]:
    """Global sparsity of copies of small patterns placed at offsets, and the order that takes the
    copies' nonzeros (concatenated, copy after copy) to the global column-major nonzeros."""
    rows, cols = [], []
    for pattern, row_offsets, col_offsets in pieces:
        r, c = (np.asarray(v, dtype=int) for v in pattern.get_triplet())
        for a, b in zip(row_offsets, col_offsets):
            rows.append(r + a)
            cols.append(c + b)
    row, col = np.concatenate(rows), np.concatenate(cols)
    sparsity = ca.Sparsity.triplet(n_row, n_col, row.tolist(), col.tolist())
    if sparsity.nnz() != row.size:
        raise AssertionError("stage blocks overlap")  # a transcription broke the stage-wise layout
    return sparsity, np.lexsort((row, col)).tolist()


def assemble(transcription: Any, problem: OptimalControlProblem, interval: Interval, expand: bool = True) -> StagewiseNLP:
    """The stage-wise NLP of ``transcription`` and its block-assembled derivatives.

    Parameters
    ----------
    transcription : Transcription
        Its ``intervals``, ``state_of`` and ``terminal``.
    problem : OptimalControlProblem
        What to optimise.
    interval : Interval
        ``transcription.interval(problem)``.
    expand : bool
        Expand ``jac_g`` and ``hess_lag`` to SX (what IPOPT evaluates every iteration). False leaves
        them MX (FATROP takes neither: it differentiates the NLP itself): expanding them was most of
        a FATROP build (with gravity gradient, multiple shooting at N = 30: 23 of 37 s).

    Returns
    -------
    StagewiseNLP
    """
    model, N = problem.model, transcription.intervals
    nx = model.nx
    ns0, nc = interval.n_state, interval.n_interval
    free = problem.free_time
    ns = ns0 + (1 if free else 0)
    nz, nv = ns + nc, 2 * ns + nc
    n_par = nx + 4 + 3 + 1 + 3

    # one interval on its own variables v = [s_k, c_k, s_{k+1}], k its index
    mesh = transcription.mesh  # None: uniform (t_k = k T / N); else each interval's start and length, as fractions of T
    v, k, ps = ca.SX.sym("v", nv), ca.SX.sym("k", 1 if mesh is None else 2), ca.SX.sym("p", n_par)
    s, s_next = v[:ns], v[nz:]
    T_s = s[ns0] if free else ps[nx + 7]
    t0, h = (k * T_s / N, T_s / N) if mesh is None else (k[0] * T_s, k[1] * T_s)
    following, path, cost = interval.function(s[:ns0], v[ns:nz], t0, h, ps[nx + 8:nx + 11])
    gap = s_next[:ns0] - following
    if free:
        gap = ca.vertcat(gap, s_next[ns0] - s[ns0])  # explicit continuity of T
    block = ca.vertcat(gap, path)
    nb = block.numel()
    lam_f, lam_b = ca.SX.sym("lam_f"), ca.SX.sym("lam_b", nb)
    block_fn = ca.Function("stage_block", [v, k, ps], [block, cost])
    jac_fn = ca.Function("stage_block_jac", [v, k, ps], [ca.jacobian(block, v)])
    hess_fn = ca.Function("stage_block_hess", [v, k, ps, lam_f, lam_b],
                          [ca.triu(ca.hessian(lam_f * cost + ca.dot(lam_b, block), v)[0])])
    # the ends
    s_end = ca.SX.sym("s_end", ns)
    initial_sx = transcription.state_of(s_end[:ns0]) - ps[:nx]
    terminal_sx = ca.vertcat(*transcription.terminal(problem, transcription.state_of(s_end[:ns0]),
                                                     ps[nx:nx + 4], ps[nx + 4:nx + 7]))
    nt = terminal_sx.numel()
    lam_t = ca.SX.sym("lam_t", nt)
    jac_initial = ca.Function("initial_jac", [s_end, ps], [ca.jacobian(initial_sx, s_end)])
    jac_terminal = ca.Function("terminal_jac", [s_end, ps], [ca.jacobian(terminal_sx, s_end)])
    hess_terminal = ca.Function("terminal_hess", [s_end, ps, lam_t],
                                [ca.triu(ca.hessian(ca.dot(lam_t, terminal_sx), s_end)[0])])

    # the mesh
    p = ca.MX.sym("p", n_par)
    w = ca.MX.sym("w", nz * N + ns)
    Z = ca.reshape(w[:nz * N], nz, N)
    s_last = w[nz * N:]
    S = ca.horzcat(Z[:ns, :], s_last)
    V = ca.vertcat(Z, S[:, 1:])
    K = ca.DM(np.arange(N)).T if mesh is None else ca.DM(np.vstack([mesh[:-1], np.diff(mesh)]))
    blocks, costs = block_fn.map(N)(V, K, p)
    initial = transcription.state_of(Z[:ns0, 0]) - p[:nx]
    terminal = ca.vertcat(*transcription.terminal(problem, transcription.state_of(s_last[:ns0]),
                                                  p[nx:nx + 4], p[nx + 4:nx + 7]))
    g = ca.vertcat(blocks[:, 0], initial, ca.vec(blocks[:, 1:]), terminal)
    T = Z[ns0, 0] if free else p[nx + 7]
    f = ca.sum2(costs) + problem.time_weight * T
    ng, nw = g.numel(), w.numel()
    block_rows = [0] + [nb + nx + (j - 1) * nb for j in range(1, N)]
    block_cols = [j * nz for j in range(N)]

    sparsity, order = _scatter(ng, nw, [(jac_fn.sparsity_out(0), block_rows, block_cols),
                                        (jac_initial.sparsity_out(0), [nb], [0]),
                                        (jac_terminal.sparsity_out(0), [ng - nt], [nz * N])])
    nonzeros = ca.vertcat(jac_fn.map(N)(V, K, p).nz[:], jac_initial(S[:, 0], p).nz[:],
                          jac_terminal(s_last, p).nz[:])
    jac_g = ca.Function("nlp_jac_g", [w, p], [g, ca.MX(sparsity, nonzeros[order])], ["x", "p"], ["g", "jac_g_x"])

    lf, lg = ca.MX.sym("lam_f"), ca.MX.sym("lam_g", ng)
    lam_blocks = ca.horzcat(lg[:nb], ca.reshape(lg[nb + nx:nb + nx + (N - 1) * nb], nb, N - 1))
    sparsity, order = _scatter(nw, nw, [(hess_fn.sparsity_out(0), block_cols, block_cols),
                                        (hess_terminal.sparsity_out(0), [nz * N], [nz * N])])
    nonzeros = ca.vertcat(hess_fn.map(N)(V, K, p, lf, lam_blocks).nz[:], hess_terminal(s_last, p, lg[ng - nt:]).nz[:])
    hess_lag = ca.Function("nlp_hess_l", [w, p, lf, lg], [ca.MX(sparsity, nonzeros[order])],
                           ["x", "p", "lam_f", "lam_g"], ["hess_gamma_x_x"])
    if expand:
        jac_g, hess_lag = jac_g.expand(), hess_lag.expand()
    return StagewiseNLP(w, p, f, g, S, Z[ns:, :], T, jac_g, hess_lag, nt)
